"""The paper's range-dependent distance threshold (eq. 4)."""

from __future__ import annotations

import math

import numpy as np


def range_threshold(ranges: np.ndarray, resolution: float, k: float, floor: float = 0.0) -> np.ndarray:
    """Δd = k · tan(res / 2) · r, metres, never below ``floor``.

    Parameters
    ----------
    ranges : ndarray
        Ranges r of the readings, metres.
    resolution : float
        The scan's angular resolution ``|angle_increment|``, radians.
    k : float
        Tuning factor (dimensionless).
    floor : float
        Smallest threshold, metres: at short range the scanner's own range noise exceeds
        the angular term.
    """
    return np.maximum(k * math.tan(resolution / 2.0) * np.asarray(ranges, dtype=float), floor)
