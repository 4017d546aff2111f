"""Join (Sec. 2.4) gives what its plain statement gives: the closest valid pair first, again and again."""

import numpy as np
import pytest

from people_tracker.detection.labels import MOVING, OCCLUDED, STATIC
from people_tracker.detection.recover import join
from people_tracker.detection.segments import Segment, split_runs


def join_by_rescanning(runs, into, source, points, join_threshold, max_extent):
    """The rule as written: scan every neighbouring pair, take the closest valid one (the
    earliest among equal gaps), join it, start again."""
    joined_any = False
    while True:
        best, best_gap = -1, np.inf
        for i in range(len(runs) - 1):
            a, b = runs[i], runs[i + 1]
            if {a.label, b.label} != {into, source}:
                continue
            gap = np.hypot(*(points[b.start] - points[a.stop - 1]))
            if gap >= max(join_threshold[a.stop - 1], join_threshold[b.start]) or gap >= best_gap:
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


@pytest.mark.parametrize("seed", range(300))
def test_join_matches_the_rule_as_written(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 120))
    # a wiggly scan line with jumps, labels in runs, gaps on the scale of the thresholds
    bearing = np.sort(rng.uniform(-1.5, 1.5, n))
    r = 3.0 + np.cumsum(rng.normal(0, 0.05, n)) + rng.choice([0.0, 0.4, -0.4], n, p=[0.9, 0.05, 0.05])
    points = np.column_stack([r * np.cos(bearing), r * np.sin(bearing)])
    if seed % 7 == 0:
        points = np.round(points, 1)  # equal gaps: the earliest pair goes first
    labels = rng.choice([MOVING, STATIC, OCCLUDED, -1], n, p=[0.3, 0.3, 0.3, 0.1])
    thr = rng.uniform(0.02, 0.3, n)
    runs = split_runs(labels, points, np.full(n, 0.25))
    max_extent = float(rng.uniform(0.3, 3.0))
    for into, source in ((MOVING, STATIC), (MOVING, OCCLUDED)):
        want, got = list(runs), list(runs)
        assert join(got, into, source, points, thr, max_extent) == join_by_rescanning(
            want, into, source, points, thr, max_extent)
        assert got == want
        runs = got
