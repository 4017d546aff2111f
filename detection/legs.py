"""Leg-shaped segments of one scan, found by shape alone (no motion needed).

A person who stands still is static, so the motion detector (the paper's Algorithms 1–3)
cannot see them. Their legs still have a shape of their own in the scan: a short run of
readings (a chord of a 5–8 cm radius cylinder) that stands free, with no reading close
behind or in front of it on either side — the beams just past each end either return
nothing or hit something clearly farther away. Walls, doors and furniture sides are long;
posts and cables are thin; objects leaning on a wall have a neighbour at their own depth.
"""

from __future__ import annotations

import numpy as np

from people_tracker.detection.segments import run_bounds
from people_tracker.detection.thresholds import range_threshold
from people_tracker.models.scan import Scan


def free_standing_legs(scan: Scan, k_segment: float, segment_floor_m: float, min_points: int,
                       min_size_m: float, max_size_m: float, edge_jump_m: float,
                       max_range_m: float) -> np.ndarray:
    """Centres of the leg-shaped segments of ``scan``, sensor frame, metres, shape (n, 2).

    Parameters
    ----------
    scan : Scan
    k_segment, segment_floor_m : float
        The detector's segment threshold: consecutive readings closer than
        ``max(k·tan(res/2)·r, floor)`` belong to one segment.
    min_points : int
        Fewest readings of a leg.
    min_size_m, max_size_m : float
        Shortest and longest chord (first to last reading) of a leg, metres.
    edge_jump_m : float
        The valid reading on each side of the segment (the neighbouring beam) must be at
        least this much farther than the segment's nearest reading, metres; a beam with no
        valid reading counts as free.
    max_range_m : float
        Farther segments have too few readings to judge their shape, metres.
    """
    valid = np.flatnonzero(scan.valid)
    if len(valid) < min_points:
        return np.zeros((0, 2))
    pts = scan.points[valid]
    r = scan.ranges[valid]
    # segments: runs of valid readings closer than the threshold, in beam order
    bounds = run_bounds(pts, range_threshold(r, scan.resolution, k_segment, segment_floor_m))
    start, stop = bounds[:-1], bounds[1:]
    count = stop - start
    chord = np.hypot(*(pts[stop - 1] - pts[start]).T)
    nearest = np.minimum.reduceat(r, start)
    keep = (count >= min_points) & (chord >= min_size_m) & (chord <= max_size_m) & (nearest <= max_range_m)
    # free-standing: the beam just before the first reading and just after the last one
    ranges = np.where(scan.valid, scan.ranges, np.inf)
    for beam in (valid[start] - 1, valid[stop - 1] + 1):
        inside = (beam >= 0) & (beam < scan.n_beams)
        side = np.where(inside, ranges[np.clip(beam, 0, scan.n_beams - 1)], np.inf)
        keep &= side >= nearest + edge_jump_m
    if not keep.any():
        return np.zeros((0, 2))
    sums = np.add.reduceat(pts, start, axis=0)
    return (sums / count[:, None])[keep]


__all__ = ["free_standing_legs"]
