"""Stage 1: closest points. A reading is static (set A) when the other scan has a reading
within Δd_c of it."""

from __future__ import annotations

import numpy as np
from people_tracker.detection.kdtree import PointTree


def closest_point_static(tree_c: PointTree, points_p_in_c: np.ndarray, thr_p: np.ndarray,
                         tree_p: PointTree, points_c_in_p: np.ndarray, thr_c: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Which readings of each scan have a reading of the other scan within their threshold.

    Each scan's KD-tree is built once, in its own sensor frame, and reused for every
    comparison; the other scan's readings are moved into that frame (a rigid motion, so
    distances are unchanged).

    Parameters
    ----------
    tree_c : PointTree
        The current scan's valid readings, current sensor frame.
    points_p_in_c : ndarray, shape (m, 2)
        The previous scan's valid readings in the current sensor frame, metres.
    thr_p : ndarray, shape (m,)
        Δd_c of each previous reading, metres.
    tree_p : PointTree
        The previous scan's valid readings, previous sensor frame.
    points_c_in_p : ndarray, shape (n, 2)
        The current scan's valid readings in the previous sensor frame, metres.
    thr_c : ndarray, shape (n,)
        Δd_c of each current reading, metres.

    Returns
    -------
    static_c, static_p : ndarray of bool, shapes (n,), (m,)
        A_C and A_P.
    """
    n, m = len(points_c_in_p), len(points_p_in_c)
    if n == 0 or m == 0:
        return np.zeros(n, dtype=bool), np.zeros(m, dtype=bool)
    return tree_p.within(points_c_in_p, thr_c), tree_c.within(points_p_in_c, thr_p)

