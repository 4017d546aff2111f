"""Stage 1: closest points. A reading is static (set A) when the other scan has a reading
within Δd_c of it."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def closest_point_static(points_c: np.ndarray, points_p: np.ndarray, thr_c: np.ndarray,
                         thr_p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which readings of each scan have a reading of the other scan within their threshold.

    Parameters
    ----------
    points_c : ndarray, shape (n, 2)
        Valid readings of the current scan, current sensor frame, metres.
    points_p : ndarray, shape (m, 2)
        Valid readings of the previous scan, transformed into the current sensor frame.
    thr_c, thr_p : ndarray, shapes (n,), (m,)
        Δd_c of each reading, metres.

    Returns
    -------
    static_c, static_p : ndarray of bool, shapes (n,), (m,)
        A_C and A_P.
    """
    if len(points_c) == 0 or len(points_p) == 0:
        return np.zeros(len(points_c), dtype=bool), np.zeros(len(points_p), dtype=bool)
    d_c, _ = cKDTree(points_p).query(points_c, k=1)
    d_p, _ = cKDTree(points_c).query(points_p, k=1)
    return d_c < thr_c, d_p < thr_p
