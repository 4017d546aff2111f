"""Stage 4: recover whole objects. Join (Sec. 2.4), Algorithm 2 (recover) and Algorithm 3 (replace)."""

from __future__ import annotations

import numpy as np

from people_tracker.detection.labels import MOVING, OCCLUDED, STATIC
from people_tracker.detection.segments import Segment, runs_of
from people_tracker.detection.thresholds import enough_readings
from people_tracker.models import compiled


def join(runs: list[Segment], into: int, source: int, points: np.ndarray, join_threshold: np.ndarray,
         max_extent: float) -> bool:
    """Join(into, source): a segment of set ``into`` absorbs a neighbouring segment of set ``source``
    whose nearer end lies within the join threshold of its own end.

    The absorbed segment leaves ``source``, so it joins one object at most. Repeats until
    nothing changes, the closest pair of ends first (so the result does not depend on
    which way the scanner counts its beams). The threshold of a pair of ends is the larger
    of theirs. A join that would make the object longer than ``max_extent`` metres (end to
    end) is refused. ``runs`` is edited in place; returns whether anything joined.
    """
    joined_any = False
    if len(runs) < 2:
        return joined_any
    # a join keeps the outer ends, so the ends facing each other across the gap before a
    # run stay the same whatever is joined: every gap and its threshold is known up front,
    # keyed by the start of the run after the gap
    end_a = np.array([r.stop - 1 for r in runs[:-1]])
    end_b = np.array([r.start for r in runs[1:]])
    step = points[end_b] - points[end_a]
    gap_m = np.hypot(step[:, 0], step[:, 1])
    keys = end_b.tolist()
    gaps = dict(zip(keys, gap_m.tolist()))
    close = dict(zip(keys, (gap_m < np.maximum(join_threshold[end_a], join_threshold[end_b])).tolist()))
    pair = {(into, source), (source, into)}
    # only gaps under their threshold can ever join: look at those alone, in beam order (so
    # of equal gaps the first in beam order wins, as a scan over every pair would choose)
    candidates = [k for k in keys if close[k]]
    while True:
        best, best_gap = -1, np.inf
        at = {r.start: i for i, r in enumerate(runs)}
        for key in candidates:
            i = at.get(key, 0) - 1  # the run before the gap; none when the gap was joined over
            if i < 0:
                continue
            a, b = runs[i], runs[i + 1]  # a precedes b in beam order
            if (a.label, b.label) not in pair:
                continue
            gap = gaps[key]
            if gap >= best_gap:
                continue
            if np.hypot(*(points[b.stop - 1] - points[a.start])) > max_extent:
                continue
            best, best_gap = i, gap
        if best < 0:
            return joined_any
        a, b = runs[best], runs[best + 1]
        seg = a if a.label == into else b
        runs[best] = Segment(a.start, b.stop, into, tuple(sorted(set(seg.sets) | {source})))
        del runs[best + 1]
        joined_any = True


def isolated_occluded(runs: list[Segment], points: np.ndarray, ranges: np.ndarray, gap: np.ndarray,
                      need: np.ndarray, max_extent: float) -> list[Segment]:
    """O segments that stand in front of both neighbours: objects moving away.

    An object that moves away from the scanner lies wholly in O_C (the paper's case 3).
    Algorithm 3 recovers it only when the scene holds a single moving object. This
    extension takes, whatever else moves, each O segment of enough readings (``need``, per
    reading: :func:`~people_tracker.detection.thresholds.enough_readings`) and at
    most ``max_extent`` metres end to end whose readings on either side are farther by more
    than the segment spacing threshold (or are missing): a free-standing thing, unlike
    the background a passing person reveals, which continues into the static surface
    beside it.
    """
    out = []
    n = len(points)
    for r in runs:
        if r.label != OCCLUDED or not enough_readings(need, r.start, r.stop):
            continue
        if np.hypot(*(points[r.stop - 1] - points[r.start])) > max_extent:
            continue
        left_ok = r.start == 0 or ranges[r.start - 1] > ranges[r.start] + gap[r.start]
        right_ok = r.stop == n or ranges[r.stop] > ranges[r.stop - 1] + gap[r.stop - 1]
        if left_ok and right_ok:
            out.append(r)
    return out


def recover_moving(runs: list[Segment], points: np.ndarray, join_threshold: np.ndarray, seed_need: np.ndarray,
                   need: np.ndarray, max_extent: float, single_object_max_o: int) -> list[Segment]:
    """Algorithms 2 and 3: the segments that are moving objects.

    Algorithm 2: if M_C^s is not empty, Join(M_C^s, A_C^s) then Join(M_C^s, O_C^s).
    Algorithm 3: if M_C^s is empty and O_C^s is not, and the scene holds a single moving
    object (at most ``single_object_max_o`` O_C segments of enough readings: ``need`` per
    reading, see :func:`~people_tracker.detection.thresholds.enough_readings`), M_C^s ← O_C^s.

    M segments of fewer readings than ``seed_need`` asks (per reading, as ``need``) are noise
    and seed nothing.
    """
    runs = [r if r.label != MOVING or enough_readings(seed_need, r.start, r.stop) else Segment(r.start, r.stop, -1, (-1,))
            for r in runs]
    if any(r.label == MOVING for r in runs):
        join(runs, MOVING, STATIC, points, join_threshold, max_extent)
        join(runs, MOVING, OCCLUDED, points, join_threshold, max_extent)
        return [r for r in runs if r.label == MOVING]
    occluded = [r for r in runs if r.label == OCCLUDED and enough_readings(need, r.start, r.stop)]
    if 0 < len(occluded) <= single_object_max_o:
        return occluded
    return []


def recover_from_bounds(bounds: np.ndarray, labels: np.ndarray, points: np.ndarray, join_threshold: np.ndarray,
                        seed_need: np.ndarray, need: np.ndarray, max_extent: float,
                        single_object_max_o: int) -> list[Segment]:
    """:func:`recover_moving` of the runs ``bounds`` gives (run k is ``bounds[k]:bounds[k + 1]``
    of the valid readings, labelled ``labels[bounds[k]]``, as :func:`~people_tracker.detection.segments.run_bounds`
    returns them): the same segments, from one compiled call when the kernels are on (the
    Segment objects are then made for the recovered runs alone)."""
    if len(bounds) < 2:
        return []
    if not compiled.on:
        return recover_moving(runs_of(bounds, labels), points, join_threshold, seed_need, need, max_extent,
                              single_object_max_o)
    starts, stops, labs, sets = _recover_kernel(bounds, np.ascontiguousarray(labels[bounds[:-1]], dtype=np.int64),
                                                points, join_threshold, seed_need, need, max_extent,
                                                single_object_max_o)
    return [Segment(a, b, lab, _SETS[mask]) for a, b, lab, mask in
            zip(starts.tolist(), stops.tolist(), labs.tolist(), sets.tolist())]


def isolated_from_bounds(bounds: np.ndarray, labels: np.ndarray, points: np.ndarray, ranges: np.ndarray,
                         gap: np.ndarray, need: np.ndarray, max_extent: float) -> list[Segment]:
    """:func:`isolated_occluded` of the runs ``bounds`` gives (as :func:`recover_from_bounds`
    takes them; ``ranges`` and ``gap`` per valid reading): the same segments, from one
    compiled call when the kernels are on."""
    if len(bounds) < 2:
        return []
    if not compiled.on:
        return isolated_occluded(runs_of(bounds, labels), points, ranges, gap, need, max_extent)
    starts, stops = _isolated_kernel(bounds, labels, points, ranges, gap, need, max_extent)
    return [Segment(a, b, OCCLUDED, (OCCLUDED,)) for a, b in zip(starts.tolist(), stops.tolist())]


def _isolated_loop(bounds, run_labels, points, ranges, gap, need, max_extent):
    """The O runs of enough readings (``need``, as :func:`isolated_occluded`; ``bounds``: the runs' first readings
    and one past the last; ``run_labels``: each valid reading's label) that
    :func:`isolated_occluded` keeps, as one loop (compiled by numba; its tests in its
    order): their first readings and one past their last."""
    n = len(points)
    starts, stops = np.empty(len(bounds), np.int64), np.empty(len(bounds), np.int64)
    k = 0
    for r in range(len(bounds) - 1):
        a, b = bounds[r], bounds[r + 1]
        if run_labels[a] != OCCLUDED or b - a < max(need[a], need[b - 1]):
            continue
        if np.hypot(points[b - 1, 0] - points[a, 0], points[b - 1, 1] - points[a, 1]) > max_extent:
            continue
        left_ok = a == 0 or ranges[a - 1] > ranges[a] + gap[a]
        right_ok = b == n or ranges[b] > ranges[b - 1] + gap[b - 1]
        if left_ok and right_ok:
            starts[k], stops[k] = a, b
            k += 1
    return starts[:k], stops[:k]


# a segment's sets as a bit mask (bit label + 1, so the noise label -1 is bit 0), and back
_LABELS = (-1, 0, 1, 2, 3, 4)
_SETS = {mask: tuple(lab for lab in _LABELS if mask >> (lab + 1) & 1) for mask in range(1 << len(_LABELS))}


def _join_runs(start, stop, lab, sets, alive, prev, nxt, gap_m, close, into, source, points, max_extent):
    """:func:`join` on runs held as arrays: run ``i`` is alive while it starts a run
    (``prev``/``nxt`` link the alive ones); a join keeps the outer ends, so the gap before
    run ``b`` is ``gap_m[b]`` whatever was joined. The same choices, in the same order."""
    n = len(start)
    while True:
        best, best_gap = -1, np.inf
        for b in range(1, n):
            if not (alive[b] and close[b]):
                continue
            a = prev[b]
            if not ((lab[a] == into and lab[b] == source) or (lab[a] == source and lab[b] == into)):
                continue
            gap = gap_m[b]
            if gap >= best_gap:
                continue
            if np.hypot(points[stop[b] - 1, 0] - points[start[a], 0],
                        points[stop[b] - 1, 1] - points[start[a], 1]) > max_extent:
                continue
            best, best_gap = b, gap
        if best < 0:
            return
        b = best
        a = prev[b]
        seg = a if lab[a] == into else b
        sets[a] = sets[seg] | (1 << (source + 1))
        stop[a] = stop[b]
        lab[a] = into
        alive[b] = False
        after = nxt[b]
        nxt[a] = after
        if after < n:
            prev[after] = a


def _recover_loop(bounds, run_labels, points, join_threshold, seed_need, need, max_extent, single_object_max_o):
    """:func:`recover_moving` on the runs of ``bounds``: the recovered segments' starts,
    stops, labels and sets (bit masks), in beam order."""
    n = len(bounds) - 1
    start = bounds[:-1].copy()
    stop = bounds[1:].copy()
    lab = run_labels.copy()
    any_moving = False
    for i in range(n):
        if lab[i] == MOVING:
            if stop[i] - start[i] < max(seed_need[start[i]], seed_need[stop[i] - 1]):
                lab[i] = -1  # noise: seeds nothing
            else:
                any_moving = True
    sets = np.empty(n, np.int64)
    for i in range(n):
        sets[i] = 1 << (lab[i] + 1)
    keep = np.zeros(n, np.bool_)
    if any_moving:
        alive = np.ones(n, np.bool_)
        prev = np.arange(n) - 1
        nxt = np.arange(n) + 1
        gap_m = np.zeros(n)
        close = np.zeros(n, np.bool_)
        for b in range(1, n):  # the gap before run b: its first reading and the one before
            j = start[b]
            gap_m[b] = np.hypot(points[j, 0] - points[j - 1, 0], points[j, 1] - points[j - 1, 1])
            ta, tb = join_threshold[j - 1], join_threshold[j]
            close[b] = gap_m[b] < (ta if (ta >= tb or ta != ta) else tb)  # np.maximum: nan when either is
        _join_runs(start, stop, lab, sets, alive, prev, nxt, gap_m, close, MOVING, STATIC, points, max_extent)
        _join_runs(start, stop, lab, sets, alive, prev, nxt, gap_m, close, MOVING, OCCLUDED, points, max_extent)
        for i in range(n):
            keep[i] = alive[i] and lab[i] == MOVING
    else:
        count = 0
        for i in range(n):
            if lab[i] == OCCLUDED and stop[i] - start[i] >= max(need[start[i]], need[stop[i] - 1]):
                keep[i] = True
                count += 1
        if count > single_object_max_o:
            keep[:] = False
    idx = np.flatnonzero(keep)
    return start[idx], stop[idx], lab[idx], sets[idx]


_join_runs = compiled.njit(_join_runs, helper=True) or _join_runs
_recover_kernel = compiled.njit(_recover_loop)
_isolated_kernel = compiled.njit(_isolated_loop)
