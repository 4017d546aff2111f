"""The paper's moving-object detector, scan by scan.

:class:`MovingObjectDetector` keeps the recent scans and their poses; each call compares the
current scan with one or more earlier scans chosen by time (Δt in seconds, turned into a
number of scans from the stamps) and returns per-beam labels and the moving objects.
"""

from __future__ import annotations

import functools
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from people_tracker.detection.closest import closest_point_static
from people_tracker.detection.kdtree import PointTree, grid_within_kernel
from people_tracker.detection.labels import INVALID, MOVING, OCCLUDED, OUT_OF_VIEW, STATIC
from people_tracker.detection.objects import MovingObject, describe_all
from people_tracker.detection.recover import isolated_from_bounds, recover_from_bounds
from people_tracker.detection.scan_lines import bin_to_beams, line_labels_kernel, scan_line_labels
from people_tracker.detection.segments import means_and_chords, run_bounds
from people_tracker.detection.thresholds import enough_readings, range_threshold, readings_needed
from people_tracker.models import compiled
from people_tracker.models.pose import Pose2D, pairwise_distances, transform_kernel
from people_tracker.models.scan import Scan


@dataclass(frozen=True)
class DetectorParams:
    """Tunables of the detector (units in the names; k factors are dimensionless).

    Attributes
    ----------
    k_closest, closest_floor_m
        Δd_c = max(k · tan(res/2) · r, floor): static when the other scan has a reading this close.
    k_segment, segment_floor_m
        The same form for the spacing of consecutive readings within a segment, and for Join.
    scan_line_window
        Beams either side searched for a previous reading on the same line of sight.
    compare_dt_s
        Δt to each earlier scan compared with, seconds (several: slow legs move enough over
        the longer ones).
    min_seed_points, min_seed_width_m
        An M segment needs as many readings as a moving part ``min_seed_width_m`` metres across
        is sure to show at its range to seed an object, at most ``min_seed_points`` and at
        least 1 (:func:`~people_tracker.detection.thresholds.readings_needed`; 0: the count
        everywhere).
    min_object_points, min_object_width_m
        Objects with fewer readings than an object ``min_object_width_m`` metres across is
        sure to show at their range are noise, never asking more than ``min_object_points``
        readings nor fewer than 2 (:func:`~people_tracker.detection.thresholds.readings_needed`);
        the same width on every laser. ``min_object_width_m`` 0: ``min_object_points``
        readings everywhere (the paper's plain count, another size on every laser).
    max_object_size_m
        Join refuses to grow an object beyond this end-to-end length.
    single_object_max_o
        Algorithm 3 runs when O_C has at most this many segments (the single-object condition).
    isolated_o_objects
        Also take free-standing, person-sized O segments as objects moving away, whatever
        else moves (an extension of Algorithm 3; see :func:`people_tracker.detection.recover.isolated_occluded`).
    no_return_free_m
        A previous beam with no return (``inf``, REP 117) counts as a line of sight seen
        through up to this range (m; capped at range_max) in Algorithm 1, so a reading in
        front of it is moving rather than out of view; 0 turns it off. Dark surfaces also
        give no return, hence a limit, and only runs of such beams that open onto the open
        count (:meth:`Scan.open_no_return`): a dark patch with a return on both sides, or a
        dropout narrower than a leg, does not.
    static_memory_s, static_memory_k, static_memory_share
        An extension for static things that flicker (thin or dark objects that return a
        reading in one scan and none in the next, so they look newly arrived): an object is
        dropped when at least ``static_memory_share`` of its readings had a reading of one of
        the scans about ``static_memory_s`` seconds earlier within ``static_memory_k`` times
        Δd_c of them (world frame). A walking leg is never twice at one place that long
        apart; a post the robot drives past always is. ``static_memory_k`` 0 turns it off.
        A reading counts as remembered when ``static_memory_min_scans`` of those scans saw
        it; objects with moving readings within ``static_memory_keep_m`` of a tracked person
        are kept (a person turning back stands where they stood a moment before). An object
        of occluded readings alone is tested wherever it lies: a table leg a walker uncovers
        is one, seen where it stood a second before.
    drop_carried
        Also drop objects carried by the robot (its own mast, a handle, a bumper the laser
        sees): at least half of their readings lie at the same place *in the sensor frame*
        in every one of those earlier scans, while the sensor moved enough that a
        world-fixed reading would have shifted by over twice Δd_c. Nothing walks that rigidly
        with the laser.
    """

    k_closest: float = 6.0
    closest_floor_m: float = 0.04
    k_segment: float = 12.0
    segment_floor_m: float = 0.06
    scan_line_window: int = 1
    compare_dt_s: tuple[float, ...] = (0.15, 0.45)
    min_seed_points: int = 2
    min_seed_width_m: float = 0.1
    min_object_points: int = 3
    min_object_width_m: float = 0.15
    max_object_size_m: float = 1.0
    single_object_max_o: int = 1
    isolated_o_objects: bool = True
    no_return_free_m: float = 0.0
    static_memory_s: tuple[float, ...] = (0.9, 1.2, 1.5)
    static_memory_k: float = 1.5
    static_memory_share: float = 0.3
    static_memory_min_scans: int = 1
    static_memory_keep_m: float = 1.0
    drop_carried: bool = True


@dataclass(frozen=True, eq=False)
class Detection:
    """What the detector found in one scan.

    Attributes
    ----------
    labels : ndarray of int8, shape (n_beams,)
        Set of each reading of the current scan (``people_tracker.detection.labels``).
    objects : list of MovingObject
    compared_dt_s : tuple of float
        Actual Δt (s) to each earlier scan compared with; empty when there was none yet.
    """

    labels: np.ndarray
    objects: list[MovingObject]
    compared_dt_s: tuple[float, ...]


@dataclass(eq=False)
class _Past:
    scan: Scan
    pose: Pose2D | None
    tree: PointTree  # the valid readings, in the scan's own sensor frame
    moving: np.ndarray | None = None  # per beam: labelled moving when it was the current scan
    static: np.ndarray | None = None  # per beam: labelled static when it was the current scan


def _tree(scan: Scan) -> PointTree:
    return PointTree(scan.valid_points)


def label_pair(scan: Scan, prev: Scan, rel: Pose2D, params: DetectorParams,
               tree_c: PointTree | None = None, tree_p: PointTree | None = None) -> np.ndarray:
    """Labels of the current scan's readings from one comparison with an earlier scan.

    ``rel`` is the earlier sensor pose seen from the current one (current_T_previous);
    ``tree_c``/``tree_p`` are the scans' KD-trees when the caller keeps them.
    """
    if tree_c is None:
        tree_c = _tree(scan)
    if tree_p is None:
        tree_p = _tree(prev)
    grids = (tree_c.grid, tree_p.grid)
    if compiled.on and grids[0] is not None and grids[1] is not None:  # all of the below as one compiled call
        inv = rel.inverse()
        return _label_pair_kernel(scan.valid_index, scan.valid_points, scan.ranges, scan.resolution, scan.angle_min,
                                  scan.angle_increment, scan.n_beams, prev.valid_points, prev.resolution,
                                  *rel._cos_sin, rel.x, rel.y, *inv._cos_sin, inv.x, inv.y,
                                  _free_points(prev, rel, params), *grids[0], *grids[1], params.k_closest,
                                  params.closest_floor_m, params.scan_line_window)
    labels = np.zeros(scan.n_beams, dtype=np.int8)  # INVALID
    valid_c = scan.valid_index
    pts_c = scan.valid_points
    r_c = scan.ranges[valid_c]
    pts_p = rel.transform_points(prev.valid_points)  # previous readings in the current frame
    r_p = np.hypot(pts_p[:, 0], pts_p[:, 1])
    # 1. closest points → A_C, A_P
    static_c, static_p = closest_point_static(
        tree_c, pts_p, range_threshold(r_p, prev.resolution, params.k_closest, params.closest_floor_m),
        tree_p, rel.inverse().transform_points(pts_c),
        range_threshold(r_c, scan.resolution, params.k_closest, params.closest_floor_m))
    labels[valid_c[static_c]] = STATIC
    # 2. Algorithm 1 on B_C, B_P: the previous readings binned to the current beams
    b_c = valid_c[~static_c]
    pts_far = _free_points(prev, rel, params)
    if compiled.on:  # the binning and Algorithm 1 below as one compiled loop
        labels[b_c] = line_labels_kernel(b_c, scan.ranges[b_c], pts_p, r_p, static_p, pts_far, scan.angle_min,
                                         scan.angle_increment, scan.n_beams, params.scan_line_window)
        return labels
    pts_far = pts_far if len(pts_far) else None
    beam_all = bin_to_beams(pts_p, scan.angle_min, scan.angle_increment, scan.n_beams)
    beam_seen, r_seen = beam_all, r_p
    if pts_far is not None:
        beam_seen = np.concatenate([beam_all, bin_to_beams(pts_far, scan.angle_min, scan.angle_increment, scan.n_beams)])
        r_seen = np.concatenate([r_p, np.hypot(pts_far[:, 0], pts_far[:, 1])])
    label_c, _ = scan_line_labels(b_c, scan.ranges[b_c], beam_all[~static_p], r_p[~static_p], scan.n_beams,
                                  params.scan_line_window, beam_seen, r_seen)
    labels[b_c] = label_c
    return labels


def _free_points(prev: Scan, rel: Pose2D, params: DetectorParams) -> np.ndarray:
    """The lines of sight the earlier scan saw through (no return), free up to
    ``no_return_free_m``: their far ends in the current sensor frame (metres, shape (k, 2);
    ``rel`` is current_T_previous)."""
    reach = min(prev.range_max, params.no_return_free_m)
    far = np.flatnonzero(prev.open_no_return(reach)) if params.no_return_free_m > 0 else ()
    if not len(far):
        return np.zeros((0, 2))
    a = prev.angles[far]
    return rel.transform_points(reach * np.column_stack([np.cos(a), np.sin(a)]))


def _label_pair_loop(valid_c, pts_c, ranges_c, res_c, angle_min, angle_increment, n_beams, pts_prev, res_p,
                     c, s, x, y, ci, si, xi, yi, pts_far, c_points, c_geometry, c_shape, c_start, c_order,
                     p_points, p_geometry, p_shape, p_start, p_order, k_closest, floor, window):
    """:func:`label_pair`'s numpy code as one loop (compiled by numba): the same operations in
    the same order. ``c, s, x, y``: current_T_previous's cosine, sine and translation;
    ``ci, si, xi, yi``: its inverse's; the two grids: the current and the earlier scan's."""
    labels = np.zeros(n_beams, np.int8)  # INVALID
    n, m = len(pts_c), len(pts_prev)
    pts_p = transform_kernel(pts_prev, c, s, x, y)  # previous readings in the current frame
    r_p = np.empty(m)
    thr_p = np.empty(m)
    f_p = k_closest * math.tan(res_p / 2.0)
    for i in range(m):
        r_p[i] = np.hypot(pts_p[i, 0], pts_p[i, 1])
        thr_p[i] = max(f_p * r_p[i], floor)
    thr_c = np.empty(n)
    f_c = k_closest * math.tan(res_c / 2.0)
    for i in range(n):
        thr_c[i] = max(f_c * ranges_c[valid_c[i]], floor)
    # 1. closest points → A_C, A_P
    if n == 0 or m == 0:
        static_c, static_p = np.zeros(n, np.bool_), np.zeros(m, np.bool_)
    else:
        static_c = grid_within_kernel(p_points, p_geometry, p_shape, p_start, p_order,
                                      transform_kernel(pts_c, ci, si, xi, yi), thr_c, thr_c.max(), False)
        static_p = grid_within_kernel(c_points, c_geometry, c_shape, c_start, c_order, pts_p, thr_p, thr_p.max(),
                                      False)
    k = 0
    for i in range(n):
        if static_c[i]:
            labels[valid_c[i]] = STATIC
        else:
            k += 1
    # 2. Algorithm 1 on B_C, B_P
    b_c = np.empty(k, np.int64)
    r_b = np.empty(k)
    k = 0
    for i in range(n):
        if not static_c[i]:
            b_c[k], r_b[k] = valid_c[i], ranges_c[valid_c[i]]
            k += 1
    label_b = line_labels_kernel(b_c, r_b, pts_p, r_p, static_p, pts_far, angle_min, angle_increment, n_beams, window)
    for i in range(k):
        labels[b_c[i]] = label_b[i]
    return labels


def _nearest_loop(stamps, targets):
    """For each of ``targets`` (s), the index of the first of ``stamps`` (s) nearest it:
    ``np.argmin(np.abs(stamps - target))`` for each, as one loop (compiled by numba)."""
    out = np.zeros(len(targets), np.int64)
    for k in range(len(targets)):
        best_gap = abs(stamps[0] - targets[k])
        for i in range(1, len(stamps)):
            gap = abs(stamps[i] - targets[k])
            if gap < best_gap:  # np.argmin: the first of equal ones
                out[k], best_gap = i, gap
    return out


@functools.lru_cache(maxsize=64)
def _as_array(values: tuple[float, ...]) -> np.ndarray:
    """A parameter tuple (seconds) as a read-only float array, made once per tuple."""
    out = np.asarray(values, dtype=float)
    out.setflags(write=False)
    return out


def _lookback_loop(stamps, posed, stamp, lookbacks, need_pose):
    """:meth:`MovingObjectDetector._lookback`'s choices as one loop (compiled by numba): for
    each lookback, the index of the kept scan it picks, -1 for none."""
    out = np.full(len(lookbacks), -1, np.int64)
    for k in range(len(lookbacks)):
        best, best_gap = -1, np.inf
        for i in range(len(stamps)):
            age = stamp - stamps[i]
            if age >= 0.5 * lookbacks[k] and (posed[i] or not need_pose):
                gap = abs(age - lookbacks[k])
                if best < 0 or gap < best_gap:  # np.argmin: the first of equal ones
                    best, best_gap = i, gap
        out[k] = best
    return out


def _carried_loop(q, thr, c, s, x, y, points, geometry, shape, start, order, rigid):
    """One earlier scan's part of :meth:`MovingObjectDetector._carried` as one loop
    (compiled by numba; the numpy code's operations), ``rigid`` updated in place: a reading
    stays rigid when the earlier scan had one within its threshold (inclusive) at the same
    sensor-frame place, and the sensor's motion since (``c, s, x, y``: the earlier pose's
    ``between`` the current one) would have moved a fixed reading there by over twice it."""
    moved = transform_kernel(q, c, s, x, y)
    near = grid_within_kernel(points, geometry, shape, start, order, q, thr, thr.max(), True)
    for i in range(len(q)):
        shift = np.hypot(moved[i, 0] - q[i, 0], moved[i, 1] - q[i, 1])
        rigid[i] = rigid[i] and near[i] and shift > 2.0 * thr[i]


def _seen_loop(q, thr, c, s, x, y, points, geometry, shape, start, order, seen):
    """One earlier scan's part of the static memory as one loop (compiled by numba; the numpy
    code's operations): ``seen`` counts, in place, the readings ``q`` the earlier scan had a
    reading within ``thr`` (inclusive) of, once moved into its frame (``c, s, x, y``)."""
    near = grid_within_kernel(points, geometry, shape, start, order, transform_kernel(q, c, s, x, y), thr, thr.max(),
                              True)
    for i in range(len(q)):
        seen[i] += near[i]


def combine(pairs: list[np.ndarray]) -> np.ndarray:
    """One label per reading from several comparisons: moving in any → M; else occluded in
    any → O; else static in any → A; else N."""
    stack = np.array(pairs)  # np.stack's result, made faster
    if compiled.on:
        return _combine_kernel(stack)
    out = pairs[0].copy()
    valid = out != INVALID
    out[valid] = OUT_OF_VIEW
    for label in (STATIC, OCCLUDED, MOVING):  # later ones win
        out[valid & (stack == label).any(axis=0)] = label
    return out


def _combine_loop(stack):
    """:func:`combine` of the comparisons stacked as rows, one loop over the readings."""
    k, n = stack.shape
    out = stack[0].copy()
    for i in range(n):
        if out[i] == INVALID:
            continue
        moving = occluded = static = False
        for j in range(k):
            lab = stack[j, i]
            moving |= lab == MOVING
            occluded |= lab == OCCLUDED
            static |= lab == STATIC
        out[i] = MOVING if moving else (OCCLUDED if occluded else (STATIC if static else OUT_OF_VIEW))
    return out


def _share_per_span(flags: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """For readings laid out span after span (``flags``: one bool per reading of the spans,
    in order; ``sizes``: each span's count, at least 1), the share of each span's readings
    that are flagged."""
    if compiled.on:
        return _share_kernel(flags, sizes)
    return np.add.reduceat(flags.astype(float), np.concatenate([[0], np.cumsum(sizes)[:-1]])) / sizes


def _share_loop(flags, sizes):
    """:func:`_share_per_span` as one loop (compiled by numba): the count over the size, as
    numpy's sum of ones and zeros (exact) over it."""
    out = np.empty(len(sizes))
    i = 0
    for k in range(len(sizes)):
        count = 0
        for _ in range(sizes[k]):
            count += flags[i]
            i += 1
        out[k] = count / sizes[k]
    return out


def _span_readings(starts: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """The indices of the readings of spans (``starts``, ``sizes``), span after span:
    ``np.concatenate([np.arange(a, a + n) for a, n in zip(starts, sizes)])``."""
    if compiled.on:
        return _span_readings_kernel(starts, sizes)
    return np.concatenate([np.arange(a, a + n) for a, n in zip(starts.tolist(), sizes.tolist())])


def _span_readings_loop(starts, sizes):
    """:func:`_span_readings` as one loop (compiled by numba)."""
    out = np.empty(sizes.sum(), np.int64)
    i = 0
    for k in range(len(starts)):
        for j in range(sizes[k]):
            out[i] = starts[k] + j
            i += 1
    return out


class MovingObjectDetector:
    """Keeps the scan history and finds the moving objects of each new scan.

    Parameters
    ----------
    params : DetectorParams
    """

    def __init__(self, params: DetectorParams | None = None) -> None:
        self.params = params or DetectorParams()
        self._history: deque[_Past] = deque()
        self._index_history()
        self._next_id = 1
        # also the free-space lookbacks of the tracker (up to 1.5 s)
        self._keep_s = max(1.5 * max(self.params.compare_dt_s), max(self.params.static_memory_s)) + 1.5

    def reset(self) -> None:
        """Forget the history (after a stamp jump or a change of scanner)."""
        self._history.clear()
        self._index_history()

    def earlier_scans(self, stamp: float, lookbacks_s: tuple[float, ...]) -> list[tuple[Scan, Pose2D, np.ndarray]]:
        """For each lookback, the kept scan nearest ``stamp - lookback`` (at least half that
        long ago), with its world pose and per-beam moving mask; scans without a pose, or
        lookbacks longer than the history, give nothing."""
        out = []
        for best in self._lookback(stamp, lookbacks_s, need_pose=True):
            moving = best.moving if best.moving is not None else np.zeros(best.scan.n_beams, dtype=bool)
            out.append((best.scan, best.pose, moving))
        return out

    def _index_history(self, dropped: int | None = None) -> None:
        """The kept scans' stamps (s) and whether each has a pose, as arrays for the lookbacks:
        built anew (``dropped`` None), or moved on by one scan appended after ``dropped``
        scans left the front."""
        if dropped is None:
            self._stamps = np.array([p.scan.stamp for p in self._history], dtype=float)
            self._posed = np.array([p.pose is not None for p in self._history], dtype=bool)
            return
        last = self._history[-1]
        self._stamps = np.concatenate((self._stamps[dropped:], (last.scan.stamp,)))
        self._posed = np.concatenate((self._posed[dropped:], (last.pose is not None,)))

    def _lookback(self, stamp: float, lookbacks_s: tuple[float, ...], need_pose: bool) -> list[_Past]:
        """For each lookback, the kept scan nearest ``stamp - lookback`` and at least half
        that long ago (of equally near ones the oldest); each scan once."""
        out: list[_Past] = []
        if not len(self._stamps):
            return out
        if compiled.on:  # the choices below as one compiled loop
            chosen: list[int] = []
            for k in _lookback_kernel(self._stamps, self._posed, float(stamp), _as_array(tuple(lookbacks_s)),
                                      need_pose).tolist():
                if k >= 0 and k not in chosen:
                    chosen.append(k)
            return [self._history[k] for k in chosen]
        age = stamp - self._stamps
        for lookback in lookbacks_s:
            ok = age >= 0.5 * lookback
            if need_pose:
                ok &= self._posed
            if not ok.any():
                continue
            best = self._history[int(np.argmin(np.where(ok, np.abs(age - lookback), np.inf)))]
            if all(best is not o for o in out):
                out.append(best)
        return out

    def _static_memory(self, scan: Scan, pose: Pose2D | None, spans: list[tuple[int, int]], pts: np.ndarray,
                       ranges: np.ndarray, people: np.ndarray | None = None,
                       moving: list[bool] | None = None) -> np.ndarray:
        """Which candidate objects (``spans`` of ``pts``, the valid readings in beam order,
        sensor frame) to keep: those whose place was not occupied in the scans about
        ``static_memory_s`` earlier (see :class:`DetectorParams`). Objects within
        ``static_memory_keep_m`` of ``people`` (tracked persons, sensor frame) are kept
        whatever the memory says when ``moving`` (per span; None: all) says they hold moving
        readings: a person turning back stands where they stood before. Objects of occluded
        readings alone are what a walker uncovers as often as a walker moving away."""
        p = self.params
        keep = np.ones(len(spans), dtype=bool)
        if not spans or p.static_memory_k <= 0:
            return keep
        memory = self._lookback(scan.stamp, p.static_memory_s, need_pose=pose is not None)
        if not memory:
            return keep
        # the current frame seen from each earlier one
        rels = [past.pose.between(pose) if pose is not None else Pose2D() for past in memory]
        starts = np.array([a for a, _ in spans], dtype=np.int64)
        sizes = np.array([b - a for a, b in spans], dtype=np.int64)
        idx_all = _span_readings(starts, sizes)
        if p.drop_carried and pose is not None:
            keep &= ~self._carried(scan, pts[idx_all], ranges[idx_all], sizes, memory, rels)
        test = np.arange(len(spans))
        near = np.zeros(len(spans), dtype=bool)
        if people is not None and len(people):
            xy = means_and_chords([pts[a:b] for a, b in spans])[0]
            near = pairwise_distances(xy, people).min(axis=1) <= p.static_memory_keep_m
            exempt = near & (np.asarray(moving, dtype=bool) if moving is not None else True)
            test = test[~exempt]
        if not len(test):
            return keep
        idx = idx_all if len(test) == len(spans) else _span_readings(starts[test], sizes[test])
        # near a person, only what was seen still a second ago counts: in a crowd someone
        # else walked there
        still_only = np.repeat(near[test], sizes[test])
        q = pts[idx]
        thr = range_threshold(ranges[idx], scan.resolution, p.static_memory_k * p.k_closest,
                              p.static_memory_k * p.closest_floor_m)
        seen = np.zeros(len(q), dtype=np.int64)
        any_still_only = bool(still_only.any())
        for past, rel in zip(memory, rels):
            if not any_still_only:  # whether a reading was there, not which
                grid = past.tree.grid
                if compiled.on and grid is not None:
                    _seen_kernel(q, thr, *rel._cos_sin, rel.x, rel.y, *grid, seen)
                else:
                    seen += past.tree.within(rel.transform_points(q), thr, inclusive=True)
                continue
            d, j = past.tree.query(rel.transform_points(q), float(thr.max()))
            hit = d <= thr
            if past.static is None or not past.scan.n_valid:  # not labelled: nothing seen still
                hit &= ~still_only
            else:
                beam = past.scan.valid_index[np.minimum(j, past.scan.n_valid - 1)]
                hit &= ~still_only | past.static[beam]
            seen += hit
        share = _share_per_span(seen >= p.static_memory_min_scans, sizes[test])
        keep[test[share >= p.static_memory_share]] = False
        return keep

    def _carried(self, scan: Scan, q: np.ndarray, ranges: np.ndarray, sizes: np.ndarray, memory: list[_Past],
                 rels: list[Pose2D]) -> np.ndarray:
        """Which objects ride with the sensor (see ``drop_carried`` in :class:`DetectorParams`):
        ``q`` their readings (sensor frame, metres) and ``ranges`` (m), object after object
        (``sizes`` readings each); ``rels``, the current frame seen from each ``memory`` scan."""
        p = self.params
        thr = range_threshold(ranges, scan.resolution, p.k_closest, p.closest_floor_m)
        rigid = np.ones(len(q), dtype=bool)
        for past, rel in zip(memory, rels):
            if past.pose is None:
                return np.zeros(len(sizes), dtype=bool)
            grid = past.tree.grid
            if compiled.on and grid is not None and len(q):  # the three lines below as one compiled loop
                _carried_kernel(q, thr, *rel._cos_sin, rel.x, rel.y, *grid, rigid)
                continue
            moved = rel.transform_points(q) - q
            shift = np.hypot(moved[:, 0], moved[:, 1])
            rigid &= past.tree.within(q, thr, inclusive=True) & (shift > 2.0 * thr)
        return _share_per_span(rigid, sizes) >= 0.5

    def _earlier(self, stamp: float) -> list[_Past]:
        """For each Δt, the stored scan whose stamp is nearest ``stamp - Δt`` (at least one scan back)."""
        if not self._history:
            return []
        targets = stamp - _as_array(tuple(self.params.compare_dt_s))
        if compiled.on:  # np.argmin of each below, in one compiled loop
            picks = _nearest_kernel(self._stamps, targets).tolist()
        else:
            picks = [int(np.argmin(np.abs(self._stamps - t))) for t in targets]
        chosen = []
        for k in picks:
            past = self._history[k]
            if all(past is not c for c in chosen):
                chosen.append(past)
        return chosen

    def detect(self, scan: Scan, pose: Pose2D | None = None, people: np.ndarray | None = None,
               tree: PointTree | None = None) -> Detection:
        """Labels and moving objects of ``scan``.

        Parameters
        ----------
        scan : Scan
        pose : Pose2D, optional
            Sensor pose in the fixed frame; without it the sensor is taken as still.
        people : ndarray, shape (k, 2), optional
            Tracked people in this scan's sensor frame, metres: the static-memory test
            leaves objects near them alone.
        tree : PointTree, optional
            KD-tree of ``scan.valid_points`` when the caller has one (the aligner's).
        """
        p = self.params
        earlier = self._earlier(scan.stamp)
        tree = tree if tree is not None else _tree(scan)
        current = _Past(scan, pose, tree)
        self._history.append(current)
        dropped = 0
        while self._history[0].scan.stamp < scan.stamp - self._keep_s:
            self._history.popleft()
            dropped += 1
        self._index_history(dropped)
        if not earlier:
            return Detection(np.where(scan.valid, OUT_OF_VIEW, INVALID).astype(np.int8), [], ())
        pairs = []
        for past in earlier:
            rel = pose.between(past.pose) if pose is not None and past.pose is not None else Pose2D()
            pairs.append(label_pair(scan, past.scan, rel, p, tree, past.tree))
        labels = combine(pairs)
        current.moving = labels == MOVING
        current.static = labels == STATIC
        # 3. segments of each set, over the valid readings in beam order
        valid = scan.valid_index
        pts = scan.valid_points
        gap = range_threshold(scan.ranges[valid], scan.resolution, p.k_segment, p.segment_floor_m)
        run_labels = labels[valid]
        bounds = run_bounds(pts, gap, run_labels) if len(pts) else np.zeros(1, np.int64)  # split_runs' runs
        # 4. Algorithms 2 and 3: recover whole objects
        need = readings_needed(scan.ranges[valid], scan.resolution, p.min_object_width_m, p.min_object_points)
        seed_need = readings_needed(scan.ranges[valid], scan.resolution, p.min_seed_width_m, p.min_seed_points, 1)
        found = recover_from_bounds(bounds, run_labels, pts, gap, seed_need, need,
                                    p.max_object_size_m, p.single_object_max_o)
        if p.isolated_o_objects:  # objects moving away, whatever else moves (extends Algorithm 3)
            taken = {(r.start, r.stop) for r in found}
            found += [r for r in isolated_from_bounds(bounds, run_labels, pts, scan.ranges[valid], gap,
                                                      need, p.max_object_size_m)
                      if (r.start, r.stop) not in taken]
        found = [seg for seg in found if enough_readings(need, seg.start, seg.stop)]
        # static things that flicker are not moving (extension, see DetectorParams)
        keep = self._static_memory(scan, pose, [(seg.start, seg.stop) for seg in found], pts,
                                   scan.ranges[valid], people, [MOVING in seg.sets for seg in found])
        # 5. position and box of each object big enough
        kept = [seg for seg, k in zip(found, keep) if k]
        objects = describe_all(self._next_id, [valid[seg.start:seg.stop] for seg in kept],
                               [pts[seg.start:seg.stop] for seg in kept], [seg.sets for seg in kept])
        self._next_id += len(kept)
        return Detection(labels, objects, tuple(scan.stamp - e.scan.stamp for e in earlier))


def v_min(params: DetectorParams, resolution: float, ranges_m=(1.0, 3.0, 5.0)) -> dict[float, list[float]]:
    """Minimum detectable relative speed V_min = Δd_c / Δt (m/s) at the given ranges, per Δt."""
    out = {}
    for dt in params.compare_dt_s:
        thr = range_threshold(np.asarray(ranges_m), resolution, params.k_closest, params.closest_floor_m)
        out[dt] = (thr / dt).tolist()
    return out


_label_pair_kernel = compiled.njit(_label_pair_loop)
_combine_kernel = compiled.njit(_combine_loop)
_lookback_kernel = compiled.njit(_lookback_loop)
_nearest_kernel = compiled.njit(_nearest_loop)
_share_kernel = compiled.njit(_share_loop)
_span_readings_kernel = compiled.njit(_span_readings_loop)
_carried_kernel = compiled.njit(_carried_loop)
_seen_kernel = compiled.njit(_seen_loop)
