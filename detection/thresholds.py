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


def readings_needed(ranges: np.ndarray, resolution: float, width_m: float, most: int, least: int = 2) -> np.ndarray:
    """Fewest readings an object at each range must hold to be kept: as many as an object
    ``width_m`` metres across is sure to show there (its width over the beam spacing
    ``r · res``, rounded down), never more than ``most`` nor fewer than ``least``.

    A count of readings alone would mean another size on every laser: three beam spacings
    are 3.5 cm at 2 m on a 0.33° laser and 21 cm at 4 m on a 1° one, wider than a leg.
    ``width_m`` 0 asks ``most`` everywhere (a plain count).

    Parameters
    ----------
    ranges : ndarray
        Ranges r of the readings, metres.
    resolution : float
        The scan's angular resolution ``|angle_increment|``, radians.
    width_m : float
        Width of the narrowest object to keep (a leg), metres.
    most, least : int
        Bounds on the count: 2 at least for an object (a lone reading is noise on any
        laser), 1 for the moving part that seeds one (the object it grows into must still
        hold 2).
    """
    r = np.asarray(ranges, dtype=float)
    if width_m <= 0:
        return np.full(r.shape, most, dtype=np.int64)
    with np.errstate(divide="ignore", invalid="ignore"):
        shown = np.floor(width_m / np.maximum(r * resolution, 1e-9))
    return np.clip(np.nan_to_num(shown, nan=most, posinf=most), min(least, most), most).astype(np.int64)


def enough_readings(need: np.ndarray, start: int, stop: int) -> bool:
    """Whether the run of readings ``start:stop`` holds as many as :func:`readings_needed`
    (``need``, per reading) asks at its nearer end (the larger count of its two ends, the
    same whichever way the laser counts its beams)."""
    return stop - start >= max(need[start], need[stop - 1])
