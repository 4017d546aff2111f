"""Static support: keeping a person through stance phases, occlusion and pauses.

A standing leg, a paused person and a briefly occluded one are not moving, so the
detector does not report them. For a confirmed track that got no moving candidate, the
scan's own readings near its prediction are looked at: the segments (all readings, any
set) that come within ``radius`` of the prediction are united, and if together they are
person-sized they support the track at their centre — the paper's Join with A_C, lifted
from one scan to a track. Static support never starts a track; what it is worth as
evidence that the person is still there is :mod:`people_tracker.tracker.existence`'s to say.
"""

from __future__ import annotations

import math

import numpy as np

from people_tracker.detection.segments import run_bounds, segment_of_readings
from people_tracker.detection.thresholds import range_threshold, readings_needed
from people_tracker.models import compiled
from people_tracker.models.pose import Pose2D, pairwise_distances
from people_tracker.models.scan import Scan
from people_tracker.tracker.pairing import leg_centres


def static_support(predictions_world: np.ndarray, pose: Pose2D, scan: Scan, k_segment: float,
                   segment_floor_m: float, radius_m: float, max_size_m: float,
                   min_points: int, max_leg_radius_m: float = 0.0,
                   explained: np.ndarray | None = None,
                   needed: np.ndarray | None = None,
                   segmentation: tuple[np.ndarray, int] | None = None,
                   min_width_m: float = 0.0) -> list[np.ndarray | None]:
    """For each predicted position (world frame, m), a supporting position or None.

    Parameters
    ----------
    predictions_world : ndarray, shape (t, 2)
    pose : Pose2D
        The sensor pose in the world frame.
    scan : Scan
    k_segment, segment_floor_m : float
        The detector's segment threshold (the readings' spacing within one object).
    radius_m : float
        How close to the prediction a segment must come, metres.
    max_size_m : float
        Largest extent (bounding-box diagonal) of a person, metres.
    min_points : int
        Fewest readings that support a person, where the beams are dense enough that ...
    min_width_m : float
        ... something this wide (metres) at the prediction's range is sure to show that many;
        elsewhere as many as it shows there, at least 2
        (:func:`~people_tracker.detection.thresholds.readings_needed`). 0: ``min_points``
        everywhere.
    max_leg_radius_m : float
        The position is where the legs' centres are, behind the readings (as
        :func:`~people_tracker.tracker.pairing.leg_centres` steps back a leg, taking half the
        group's extent as the radius, at most this), so a track updated in turn by leg
        pairs and by static support is not pulled back and forth; 0: the readings' mean.
    explained : ndarray of bool, shape (n_beams,), optional
        Readings another person's moving candidate took this scan: they support nobody
        else (a passer-by's leg beside someone standing must not pull them along).
    needed : ndarray of bool, shape (n_beams,), optional
        A group must hold at least as many of these readings as it needs in all.
    segmentation : (ndarray, int), optional
        :func:`scan_segments` of this scan with these ``k_segment`` and ``segment_floor_m``,
        when the caller keeps it for several calls on one scan.
    """
    out: list[np.ndarray | None] = [None] * len(predictions_world)
    if len(predictions_world) == 0 or scan.n_valid == 0:
        return out
    valid = scan.valid_index
    pts = scan.valid_points
    seg_of, n_segments = segmentation if segmentation is not None else scan_segments(scan, k_segment, segment_floor_m)
    pred_sensor = pose.inverse().transform_points(predictions_world)
    need = readings_needed(np.hypot(pred_sensor[:, 0], pred_sensor[:, 1]), scan.resolution, min_width_m, min_points)
    free = np.ones(len(valid), dtype=bool) if explained is None else ~explained[valid]
    needed_valid = None if needed is None else needed[valid]  # per valid reading, as ``free``
    if compiled.on:  # the loop below, compiled: each prediction's group, checked and centred
        found, centres = _support_kernel(
            pred_sensor, pts, seg_of, n_segments, free, needed_valid is not None,
            needed_valid if needed_valid is not None else free, radius_m, max_size_m, need, max_leg_radius_m)
        if found.any():
            for t in np.flatnonzero(found).tolist():
                out[t] = pose.transform_points(centres[t:t + 1])[0]
        return out
    d = pairwise_distances(pred_sensor, pts)
    d[:, ~free] = np.inf
    chosen = np.zeros(n_segments, dtype=bool)
    for t in range(len(pred_sensor)):
        near = seg_of[d[t] <= radius_m]
        if len(near) == 0:
            continue
        chosen[:] = False
        chosen[near] = True
        members = chosen[seg_of] & free
        p = pts[members]
        extent = np.hypot(*np.ptp(p, axis=0)) if len(p) else 0.0
        if len(p) < need[t] or extent > max_size_m:
            continue
        if needed_valid is not None and np.count_nonzero(needed_valid[members]) < need[t]:
            continue
        centre = p.mean(axis=0, keepdims=True)
        if max_leg_radius_m > 0:
            centre = leg_centres(centre, np.array([extent]), max_leg_radius_m)
        out[t] = pose.transform_points(centre)[0]
    return out


def scan_segments(scan: Scan, k_segment: float, segment_floor_m: float) -> tuple[np.ndarray, int]:
    """The scan's segments, any label (the detector's spacing threshold): the segment of
    each valid reading, in beam order, and how many there are."""
    valid = scan.valid_index
    gap = range_threshold(scan.ranges[valid], scan.resolution, k_segment, segment_floor_m)
    bounds = run_bounds(scan.valid_points, gap)
    return segment_of_readings(bounds), len(bounds) - 1


def _support_loop(pred_sensor, pts, seg_of, n_segments, free, use_needed, needed, radius_m, max_size_m, need,
                  max_leg_radius_m):
    """:func:`static_support`'s loop over the predictions (sensor frame) as its numpy code
    runs it, the same arithmetic in the same order: whether each is supported, and where
    (sensor frame, metres; the leg centres' step back included)."""
    t_count, n = len(pred_sensor), len(pts)
    found = np.zeros(t_count, np.bool_)
    centres = np.zeros((t_count, 2))
    chosen = np.zeros(n_segments, np.bool_)
    for t in range(t_count):
        qx, qy = pred_sensor[t, 0], pred_sensor[t, 1]
        chosen[:] = False
        any_near = False
        for i in range(n):
            if free[i] and np.hypot(qx - pts[i, 0], qy - pts[i, 1]) <= radius_m:
                chosen[seg_of[i]] = True
                any_near = True
        if not any_near:
            continue
        count, count_needed = 0, 0
        sx, sy = 0.0, 0.0
        x_lo, x_hi, y_lo, y_hi = np.inf, -np.inf, np.inf, -np.inf
        for i in range(n):
            if chosen[seg_of[i]] and free[i]:
                x, y = pts[i, 0], pts[i, 1]
                if count == 0:
                    sx, sy = x, y  # numpy's mean over the rows: the first row, then each in turn
                else:
                    sx += x
                    sy += y
                count += 1
                if use_needed and needed[i]:
                    count_needed += 1
                x_lo, x_hi = min(x_lo, x), max(x_hi, x)
                y_lo, y_hi = min(y_lo, y), max(y_hi, y)
        extent = np.hypot(x_hi - x_lo, y_hi - y_lo)
        if count < need[t] or extent > max_size_m:
            continue
        if use_needed and count_needed < need[t]:
            continue
        mx, my = sx / count, sy / count
        if max_leg_radius_m > 0:  # leg_centres: a step back along the beam
            r = min(max(0.5 * extent, 0.0), max_leg_radius_m)
            norm = max(np.hypot(mx, my), 1e-9)
            step = 0.25 * math.pi * r
            mx, my = mx + (mx / norm) * step, my + (my / norm) * step
        found[t] = True
        centres[t, 0], centres[t, 1] = mx, my
    return found, centres


_support_kernel = compiled.njit(_support_loop)
