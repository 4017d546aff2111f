"""Vectorised 2D ray casting against line segments and circles."""

from __future__ import annotations

import numpy as np


def cast_rays(origins: np.ndarray, directions: np.ndarray, segments: np.ndarray,
              circles: np.ndarray, max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """Distance along each ray to the first surface it meets.

    Parameters
    ----------
    origins : ndarray, shape (n, 2)
        Ray origins, metres (any common frame).
    directions : ndarray, shape (n, 2)
        Unit ray directions in the same frame.
    segments : ndarray, shape (m, 2, 2)
        Line segments (end points), metres.
    circles : ndarray, shape (k, 3)
        Circles as centre x, y and radius, metres.
    max_range : float
        Rays that meet nothing closer report ``inf``.

    Returns
    -------
    distance : ndarray, shape (n,)
        Metres to the first hit, ``inf`` when nothing is within ``max_range``.
    hit : ndarray of int, shape (n,)
        What was hit: ``-1`` nothing, ``0..m-1`` a segment, ``m..m+k-1`` a circle.
    """
    n = origins.shape[0]
    best = np.full(n, np.inf)
    hit = np.full(n, -1, dtype=np.int64)
    m = segments.shape[0]
    if m:
        a = segments[:, 0, :]  # (m, 2)
        e = segments[:, 1, :] - a  # (m, 2)
        # o + t d = a + u e  →  t = (a-o)×e / d×e ,  u = (a-o)×d / d×e
        denom = directions[:, 0:1] * e[None, :, 1] - directions[:, 1:2] * e[None, :, 0]  # (n, m)
        ao_x = a[None, :, 0] - origins[:, 0:1]
        ao_y = a[None, :, 1] - origins[:, 1:2]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (ao_x * e[None, :, 1] - ao_y * e[None, :, 0]) / denom
            u = (ao_x * directions[:, 1:2] - ao_y * directions[:, 0:1]) / denom
        ok = (np.abs(denom) > 1e-12) & (t > 1e-9) & (u >= 0.0) & (u <= 1.0)
        t = np.where(ok, t, np.inf)
        j = np.argmin(t, axis=1)
        tj = t[np.arange(n), j]
        closer = tj < best
        best[closer] = tj[closer]
        hit[closer] = j[closer]
    k = circles.shape[0]
    if k:
        # |o + t d - c|² = r²  →  t² + 2 b t + cc = 0 with b = (o-c)·d, cc = |o-c|² - r²
        fx = origins[:, 0:1] - circles[None, :, 0]
        fy = origins[:, 1:2] - circles[None, :, 1]
        b = fx * directions[:, 0:1] + fy * directions[:, 1:2]
        cc = fx * fx + fy * fy - circles[None, :, 2] ** 2
        disc = b * b - cc
        with np.errstate(invalid="ignore"):
            root = np.sqrt(disc)
        t_near = -b - root
        t = np.where(t_near > 1e-9, t_near, -b + root)  # from inside a circle: the far side
        t = np.where((disc >= 0.0) & (t > 1e-9), t, np.inf)
        j = np.argmin(t, axis=1)
        tj = t[np.arange(n), j]
        closer = tj < best
        best[closer] = tj[closer]
        hit[closer] = m + j[closer]
    far = best > max_range
    best[far] = np.inf
    hit[far] = -1
    return best, hit
