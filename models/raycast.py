"""Vectorised 2D ray casting against line segments and circles."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CircleMotion:
    """Circles that move while a scan's rays are cast (people walking on during a sweep).

    Attributes
    ----------
    beam_times : ndarray, shape (n,)
        When each ray is cast, seconds (any common origin).
    knot_times : ndarray, shape (K,)
        Increasing times, seconds, at which the centres are known.
    knot_centres : ndarray, shape (K, k, 2)
        Each circle's centre at each knot time, metres; in between a centre moves in a
        straight line, and before the first (after the last) knot it stays at it.
    """

    beam_times: np.ndarray
    knot_times: np.ndarray
    knot_centres: np.ndarray

    def centres(self, circle: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Centres (rows x, y) of circles ``circle`` at times ``t``, pairwise."""
        kt, kc = self.knot_times, self.knot_centres
        if len(kt) == 1:
            return kc[0, circle]
        i = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, len(kt) - 2)
        f = np.clip((t - kt[i]) / (kt[i + 1] - kt[i]), 0.0, 1.0)
        return kc[i, circle] + f[:, None] * (kc[i + 1, circle] - kc[i, circle])


def cast_rays_dense(origins: np.ndarray, directions: np.ndarray, segments: np.ndarray,
                    circles: np.ndarray, max_range: float,
                    motion: CircleMotion | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Distance along each ray to the first surface it meets, testing every ray against everything.

    The reference for :func:`cast_rays`, which gives the same answer faster.

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
    motion : CircleMotion, optional
        Circles that move while the rays are cast (see :class:`CircleMotion`); their
        ``circles`` rows give only the radii then.

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
        if motion is None:
            cx, cy = circles[None, :, 0], circles[None, :, 1]
        else:
            every = np.tile(np.arange(k), n)
            at = motion.centres(every, np.repeat(motion.beam_times, k)).reshape(n, k, 2)
            cx, cy = at[:, :, 0], at[:, :, 1]
        fx = origins[:, 0:1] - cx
        fy = origins[:, 1:2] - cy
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


def _ray_segment_t(o, d, a, b):
    """Ray parameter of the hit of rays (o, d) on segments (a, b), pairwise; inf for a miss."""
    e = b - a
    denom = d[:, 0] * e[:, 1] - d[:, 1] * e[:, 0]
    ao = a - o
    with np.errstate(divide="ignore", invalid="ignore"):
        # o + t d = a + u e  →  t = (a-o)×e / d×e ,  u = (a-o)×d / d×e
        t = (ao[:, 0] * e[:, 1] - ao[:, 1] * e[:, 0]) / denom
        u = (ao[:, 0] * d[:, 1] - ao[:, 1] * d[:, 0]) / denom
    ok = (np.abs(denom) > 1e-12) & (t > 1e-9) & (u >= 0.0) & (u <= 1.0)
    return np.where(ok, t, np.inf)


def _ray_circle_t(o, d, c, r):
    """Ray parameter of the first hit of rays (o, d) on circles (c, r), pairwise; inf for a miss."""
    f = o - c
    # |o + t d - c|² = r²  →  t² + 2 b t + cc = 0
    b = f[:, 0] * d[:, 0] + f[:, 1] * d[:, 1]
    cc = f[:, 0] ** 2 + f[:, 1] ** 2 - r * r
    disc = b * b - cc
    root = np.sqrt(np.maximum(disc, 0.0))
    t = np.where(-b - root > 1e-9, -b - root, -b + root)  # from inside a circle: the far side
    return np.where((disc >= 0.0) & (t > 1e-9), t, np.inf)


def _beam_ranges(headings, centre, half_width, everywhere):
    """For each primitive, the beams whose heading lies within centre ± half_width.

    ``headings`` must be increasing. Returns (primitive index, beam index) pairs.
    """
    n = headings.shape[0]
    h0 = headings[0]
    span = headings[-1] - h0
    los, his, prims = [], [], []
    # the bearing interval may sit one turn above or below the beams' unwrapped headings
    rel = (centre - h0 + np.pi) % (2 * np.pi) - np.pi
    for shift in (-2 * np.pi, 0.0, 2 * np.pi):
        lo_a = rel + shift - half_width
        hi_a = rel + shift + half_width
        keep = (hi_a >= 0) & (lo_a <= span) & ~everywhere
        idx = np.flatnonzero(keep)
        los.append(np.searchsorted(headings - h0, lo_a[idx], side="left"))
        his.append(np.searchsorted(headings - h0, hi_a[idx], side="right"))
        prims.append(idx)
    every = np.flatnonzero(everywhere)
    los.append(np.zeros(len(every), dtype=np.int64))
    his.append(np.full(len(every), n, dtype=np.int64))
    prims.append(every)
    lo = np.concatenate(los)
    hi = np.concatenate(his)
    prim = np.concatenate(prims)
    counts = np.maximum(hi - lo, 0)
    total = int(counts.sum())
    prim_idx = np.repeat(prim, counts)
    start = np.repeat(lo - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    beam_idx = start + np.arange(total)
    return prim_idx, beam_idx


def cast_rays(origins: np.ndarray, directions: np.ndarray, segments: np.ndarray,
              circles: np.ndarray, max_range: float,
              motion: CircleMotion | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Distance along each ray to the first surface it meets.

    Same contract as :func:`cast_rays_dense`, for rays whose headings turn monotonically
    (a scan) from origins close together (a sensor that moves little during a sweep): each
    surface is tested only against the beams inside the bearing interval it subtends.

    Parameters
    ----------
    origins : ndarray, shape (n, 2)
    directions : ndarray, shape (n, 2)
        Unit vectors; their headings must increase or decrease monotonically.
    segments : ndarray, shape (m, 2, 2)
    circles : ndarray, shape (k, 3)
    max_range : float
    motion : CircleMotion, optional

    Returns
    -------
    distance : ndarray, shape (n,)
    hit : ndarray of int, shape (n,)
        ``-1`` nothing, ``0..m-1`` a segment, ``m..m+k-1`` a circle.
    """
    n = origins.shape[0]
    headings = np.unwrap(np.arctan2(directions[:, 1], directions[:, 0]))
    order = None
    if n > 1 and headings[-1] < headings[0]:  # clockwise: work on the reversed beams
        order = np.arange(n)[::-1]
        origins, directions, headings = origins[order], directions[order], headings[order]
        if motion is not None:
            motion = CircleMotion(motion.beam_times[order], motion.knot_times, motion.knot_centres)
    if n > 1 and (np.diff(headings) < 0).any():
        dist, hit = cast_rays_dense(origins, directions, segments, circles, max_range, motion)
        return (dist[order], hit[order]) if order is not None else (dist, hit)
    ref = origins.mean(axis=0)
    spread = float(np.hypot(*(origins - ref).T).max()) if n else 0.0
    m = segments.shape[0]
    prim_parts, beam_parts, t_parts = [], [], []
    if m:
        a, b = segments[:, 0, :], segments[:, 1, :]
        ba, bb = np.arctan2(*(a - ref).T[::-1]), np.arctan2(*(b - ref).T[::-1])
        half = 0.5 * np.abs((bb - ba + np.pi) % (2 * np.pi) - np.pi)
        mid = ba + ((bb - ba + np.pi) % (2 * np.pi) - np.pi) / 2
        # distance from the reference origin to each segment: near ones are tested everywhere
        e = b - a
        u = np.clip(np.einsum("ij,ij->i", ref - a, e) / np.maximum(np.einsum("ij,ij->i", e, e), 1e-18), 0, 1)
        near = np.hypot(*(a + u[:, None] * e - ref).T)
        margin = np.arcsin(np.clip(spread / np.maximum(near, 1e-9), 0, 1))
        pi_, bi = _beam_ranges(headings, mid, half + margin + 1e-9, near <= 2 * spread + 1e-6)
        prim_parts.append(pi_)
        beam_parts.append(bi)
        t_parts.append(_ray_segment_t(origins[bi], directions[bi], a[pi_], b[pi_]))
    k = circles.shape[0]
    if k:
        c, r = circles[:, :2], circles[:, 2]
        reach = r + spread
        if motion is not None:  # each beam tests where the circle can be over the whole sweep
            c = motion.knot_centres.mean(axis=0)
            reach = reach + np.hypot(*np.moveaxis(motion.knot_centres - c, 2, 0)).max(axis=0)
        v = c - ref
        dist_c = np.hypot(v[:, 0], v[:, 1])
        inside = dist_c <= reach + 1e-6
        half = np.arcsin(np.clip(reach / np.maximum(dist_c, 1e-9), 0, 1))
        pi_, bi = _beam_ranges(headings, np.arctan2(v[:, 1], v[:, 0]), half + 1e-9, inside)
        prim_parts.append(pi_ + m)
        beam_parts.append(bi)
        at = c[pi_] if motion is None else motion.centres(pi_, motion.beam_times[bi])
        t_parts.append(_ray_circle_t(origins[bi], directions[bi], at, r[pi_]))
    best = np.full(n, np.inf)
    hit = np.full(n, -1, dtype=np.int64)
    if prim_parts:
        prim = np.concatenate(prim_parts)
        beam = np.concatenate(beam_parts)
        t = np.concatenate(t_parts)
        hit_any = np.isfinite(t) & (t <= max_range)
        prim, beam, t = prim[hit_any], beam[hit_any], t[hit_any]
        sel = np.lexsort((prim, t, beam))  # per beam, nearest first (ties: lowest index)
        beam, t, prim = beam[sel], t[sel], prim[sel]
        first = np.ones(len(beam), dtype=bool)
        first[1:] = beam[1:] != beam[:-1]
        best[beam[first]] = t[first]
        hit[beam[first]] = prim[first]
    if order is not None:
        best, hit = best[order], hit[order]
    return best, hit
