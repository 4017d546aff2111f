"""De-skew: put every beam where the sensor was when it fired.

A scanner sweeps its beams over tens of milliseconds (``time_increment`` apart); a robot
driving at 1.2 m/s moves 6 cm meanwhile, as much as the motion the detector looks for.
With the sensor pose at the first and at the last beam (odometry), each reading is moved
into the sensor frame at the scan stamp (the first beam's time) and the scan is resampled
onto a beam grid of its own, so every later stage still gets an ordinary :class:`Scan`.
"""

from __future__ import annotations

import math

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.compiled import beam_of, njit
from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan, beam_index


def sweep_duration(scan: Scan) -> float:
    """Seconds from the first to the last beam."""
    return max(scan.time_increment, 0.0) * (scan.n_beams - 1)


def deskew(scan: Scan, pose_first: Pose2D, pose_last: Pose2D) -> Scan:
    """The scan as if every beam had fired from the pose of the first one.

    Parameters
    ----------
    scan : Scan
    pose_first, pose_last : Pose2D
        Sensor pose in the fixed frame when the first and the last beam fired; poses in
        between are interpolated linearly (constant velocity over one sweep).

    Returns
    -------
    Scan
        Same beam count, ``angle_min``, stamp and limits; see :func:`deskew_with_source`.
    """
    return deskew_with_source(scan, pose_first, pose_last)[0]


def deskew_with_source(scan: Scan, pose_first: Pose2D, pose_last: Pose2D) -> tuple[Scan, np.ndarray]:
    """:func:`deskew`, and which raw beam each de-skewed beam's reading came from.

    The sweep's rotation turns every line of sight by an amount that grows linearly with
    the beam index, so it goes into the output grid itself: its increment is the raw one
    plus the rotation per beam (a sensor turning against its sweep direction packs its
    beams closer). A sweep that only turns then moves no reading off its beam and loses
    none. The translation moves each reading's bearing by an amount that depends on its
    range; each goes to the beam nearest its new bearing (:func:`people_tracker.models.scan.beam_index`),
    the nearest reading wins where two meet (the other is hidden from the first pose),
    and readings that leave the field of view are dropped. Each keeps its exact bearing
    (:attr:`Scan.bearings`), so the scan's points are where the first pose would have seen
    them, not moved to the grid.

    Returns
    -------
    scan : Scan
        A beam that saw nothing (``inf``, see :attr:`Scan.no_return`) stays ``inf`` unless a
        reading lands on it; any other beam left without a reading is ``nan``.
    source : ndarray of int64, shape (n_beams,)
        Raw beam index of the reading each de-skewed beam holds, -1 for none.
    """
    motion = pose_first.between(pose_last)  # the sweep's motion, in the first beam's frame
    n = scan.n_beams
    if n < 2 or (abs(motion.x) < 1e-6 and abs(motion.y) < 1e-6 and abs(motion.yaw) < 1e-7):
        return scan, np.where(scan.valid, np.arange(n), -1)
    # the sweep's rotation, spread over its beams, goes into the grid (unless it would fold it)
    increment = scan.angle_increment + motion.yaw / (n - 1)
    if not math.isfinite(increment) or increment * scan.angle_increment <= 0 or \
            abs(increment) < 0.5 * abs(scan.angle_increment):
        increment = scan.angle_increment
    if compiled.on:  # the rest as one compiled loop, the same arithmetic
        raw_bearings = scan.bearings if scan.bearings is not None else np.zeros(0)
        out, source, bearings, valid, no_return, points = _deskew_kernel(
            scan.ranges, raw_bearings, scan.bearings is not None, motion.x, motion.y, motion.yaw, scan.angle_min,
            scan.angle_increment, increment, scan.range_min, scan.range_max, compiled.trig_is_numpys)
        new = Scan._made_here(out, scan, increment, bearings)  # the kernel's fresh arrays, handed over
        # what the new scan's properties would compute, computed in the loop (the points
        # only where the C library's cos and sin are numpy's): the written beams are its valid
        # ones, the beams left inf its lines of sight with no return
        index = np.flatnonzero(valid)
        for name, value in (("valid", valid), ("valid_index", index), ("no_return", no_return)) + (
                (("points", points), ("valid_points", points[index])) if compiled.trig_is_numpys else ()):
            value.setflags(write=False)
            new.__dict__[name] = value  # functools.cached_property's place for it
        return new, source
    frac = np.arange(n) / (n - 1)
    # per-beam sensor pose relative to the first beam: linear in translation and heading
    yaw = frac * motion.yaw
    tx, ty = frac * motion.x, frac * motion.y
    valid = scan.valid_index
    r = scan.ranges[valid]
    a = scan.angles[valid] + yaw[valid]
    # p' = t_i + R(yaw_i) p_i
    x = tx[valid] + r * np.cos(a)
    y = ty[valid] + r * np.sin(a)
    new_r = np.hypot(x, y)
    bearing = compiled.arctan2(y, x)
    idx = beam_index(bearing, scan.angle_min, increment, n)
    keep = (idx >= 0) & (new_r > scan.range_min) & (new_r < scan.range_max)
    out = np.where(scan.no_return, np.inf, np.nan)  # the sweep moves a line of sight by under a beam
    source = np.full(n, -1, dtype=np.int64)
    order = np.argsort(-new_r[keep], kind="stable")  # farthest first: the nearest in a beam is written last
    out[idx[keep][order]] = new_r[keep][order]
    source[idx[keep][order]] = valid[keep][order]
    bearings = scan.angle_min + np.arange(n) * increment  # the grid, and each reading's own bearing
    bearings[idx[keep][order]] = bearing[keep][order]
    return Scan(out, scan.angle_min, increment, scan.range_min, scan.range_max, scan.stamp,
                scan.frame_id, scan.time_increment, bearings), source


def _deskew_loop(ranges, raw_bearings, has_bearings, mx, my, myaw, angle_min, raw_increment, increment, range_min,
                 range_max, with_points):
    """:func:`deskew_with_source` from its new grid on, for the sweep's motion (mx, my,
    myaw) in the first beam's frame, as one loop (compiled by numba; the numpy code above is
    the reference): the new ranges, the source beams and the bearings; and the new scan's
    valid and no-return masks and, if ``with_points``, its :attr:`Scan.points` (else nan)."""
    n = len(ranges)
    out = np.empty(n)
    for i in range(n):  # Scan.no_return of the raw scan: inf, or at or beyond range_max
        r = ranges[i]
        out[i] = np.inf if (np.isinf(r) and r > 0) or (np.isfinite(r) and r >= range_max) else np.nan
    source = np.full(n, -1, np.int64)
    bearings = np.empty(n)
    for i in range(n):
        bearings[i] = angle_min + i * increment
    best = np.full(n, np.inf)  # the nearest reading written to each beam so far
    for i in range(n):
        r = ranges[i]
        if not (np.isfinite(r) and r > range_min and r < range_max):  # Scan.valid of the raw scan
            continue
        angle = raw_bearings[i] if has_bearings else angle_min + np.float64(i) * raw_increment  # Scan.angles
        frac = i / (n - 1)
        a = angle + frac * myaw
        x = frac * mx + r * np.cos(a)
        y = frac * my + r * np.sin(a)
        new_r = np.hypot(x, y)
        bearing = np.arctan2(y, x)
        b = beam_of(bearing, angle_min, increment, n)
        # the nearest in a beam wins; of equally near ones the later (the stable sort's last write)
        if b >= 0 and new_r > range_min and new_r < range_max and new_r <= best[b]:
            best[b] = new_r
            out[b] = new_r
            source[b] = i
            bearings[b] = bearing
    valid = source >= 0
    no_return = np.zeros(n, np.bool_)
    for b in range(n):  # Scan.no_return of the new scan: a written reading lies below range_max
        no_return[b] = np.isinf(out[b]) and out[b] > 0
    points = np.full((n, 2), np.nan)
    if with_points:
        for b in range(n):  # Scan.points: the range (nan where not valid) times cos and sin
            r = out[b] if valid[b] else np.nan
            points[b, 0] = r * np.cos(bearings[b])
            points[b, 1] = r * np.sin(bearings[b])
    return out, source, bearings, valid, no_return, points


_deskew_kernel = njit(_deskew_loop)
