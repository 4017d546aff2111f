"""Stage 4: recover whole objects. Join (Sec. 2.4), Algorithm 2 (recover) and Algorithm 3 (replace)."""

from __future__ import annotations

import numpy as np

from people_tracker.detection.labels import MOVING, OCCLUDED, STATIC
from people_tracker.detection.segments import Segment


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
                      min_points: int, max_extent: float) -> list[Segment]:
    """O segments that stand in front of both neighbours: objects moving away.

    An object that moves away from the scanner lies wholly in O_C (the paper's case 3).
    Algorithm 3 recovers it only when the scene holds a single moving object. This
    extension takes, whatever else moves, each O segment of ``min_points`` readings and at
    most ``max_extent`` metres end to end whose readings on either side are farther by more
    than the segment spacing threshold (or are missing): a free-standing thing, unlike
    the background a passing person reveals, which continues into the static surface
    beside it.
    """
    out = []
    n = len(points)
    for r in runs:
        if r.label != OCCLUDED or r.size < min_points:
            continue
        if np.hypot(*(points[r.stop - 1] - points[r.start])) > max_extent:
            continue
        left_ok = r.start == 0 or ranges[r.start - 1] > ranges[r.start] + gap[r.start]
        right_ok = r.stop == n or ranges[r.stop] > ranges[r.stop - 1] + gap[r.stop - 1]
        if left_ok and right_ok:
            out.append(r)
    return out


def recover_moving(runs: list[Segment], points: np.ndarray, join_threshold: np.ndarray, min_seed: int,
                   min_points: int, max_extent: float, single_object_max_o: int) -> list[Segment]:
    """Algorithms 2 and 3: the segments that are moving objects.

    Algorithm 2: if M_C^s is not empty, Join(M_C^s, A_C^s) then Join(M_C^s, O_C^s).
    Algorithm 3: if M_C^s is empty and O_C^s is not, and the scene holds a single moving
    object (at most ``single_object_max_o`` O_C segments of ``min_points`` readings),
    M_C^s ← O_C^s.

    M segments of fewer than ``min_seed`` readings are noise and seed nothing.
    """
    runs = [r if r.label != MOVING or r.size >= min_seed else Segment(r.start, r.stop, -1, (-1,)) for r in runs]
    if any(r.label == MOVING for r in runs):
        join(runs, MOVING, STATIC, points, join_threshold, max_extent)
        join(runs, MOVING, OCCLUDED, points, join_threshold, max_extent)
        return [r for r in runs if r.label == MOVING]
    occluded = [r for r in runs if r.label == OCCLUDED and r.size >= min_points]
    if 0 < len(occluded) <= single_object_max_o:
        return occluded
    return []
