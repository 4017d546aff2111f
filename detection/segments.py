"""Stage 3: continuous segments of each set."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from people_tracker.models import compiled


@dataclass
class Segment:
    """A run of consecutive valid readings with one label.

    ``start``/``stop`` index the scan's valid readings in beam order (stop exclusive);
    ``sets`` names the sets the segment was built from once segments are joined.
    """

    start: int
    stop: int
    label: int
    sets: tuple[int, ...]

    @property
    def size(self) -> int:
        return self.stop - self.start


def split_runs(labels: np.ndarray, points: np.ndarray, gap_threshold: np.ndarray) -> list[Segment]:
    """Maximal runs of one label whose consecutive readings are closer than the threshold.

    Parameters
    ----------
    labels : ndarray of int, shape (n,)
        Label of each valid reading, in beam order.
    points : ndarray, shape (n, 2)
        The readings, metres.
    gap_threshold : ndarray, shape (n,)
        Largest spacing (m) of each reading from its neighbours within a segment; two
        consecutive readings are judged by the larger of their thresholds.
    """
    if len(labels) == 0:
        return []
    return runs_of(run_bounds(points, gap_threshold, labels), labels)


def runs_of(bounds: np.ndarray, labels: np.ndarray) -> list[Segment]:
    """The runs ``bounds`` delimits (see :func:`run_bounds`) as Segments, each labelled as
    its first reading."""
    starts, stops, first = bounds[:-1].tolist(), bounds[1:].tolist(), labels[bounds[:-1]].tolist()  # Python ints
    return [Segment(a, b, lab, (lab,)) for a, b, lab in zip(starts, stops, first)]


def run_bounds(points: np.ndarray, gap_threshold: np.ndarray, labels: np.ndarray | None = None) -> np.ndarray:
    """Boundaries of the runs of :func:`split_runs`: run k is ``bounds[k]:bounds[k + 1]``.

    Parameters are those of :func:`split_runs`; without ``labels`` only gaps split.
    Returns an int array of shape (runs + 1,), starting at 0 and ending at ``len(points)``.
    """
    n = len(points)
    if compiled.on and n:
        pts = np.ascontiguousarray(points, dtype=np.float64)
        gap = np.ascontiguousarray(gap_threshold, dtype=np.float64)
        if labels is None:
            return _run_bounds_kernel(pts, gap, np.zeros(n, np.int64), False)
        return _run_bounds_kernel(pts, gap, np.ascontiguousarray(labels, dtype=np.int64), True)
    step = points[1:] - points[:-1]
    cut = np.hypot(step[:, 0], step[:, 1]) >= np.maximum(gap_threshold[:-1], gap_threshold[1:])
    if labels is not None:
        cut |= labels[1:] != labels[:-1]
    return np.concatenate([[0], np.flatnonzero(cut) + 1, [n]])


def segment_of_readings(bounds: np.ndarray) -> np.ndarray:
    """The run of each reading, from :func:`run_bounds`' ``bounds``:
    ``np.repeat(np.arange(len(bounds) - 1), np.diff(bounds))`` (int64)."""
    if compiled.on and len(bounds):
        return _segment_of_kernel(np.ascontiguousarray(bounds, dtype=np.int64))
    return np.repeat(np.arange(len(bounds) - 1), np.diff(bounds))


def _segment_of_loop(bounds):
    """:func:`segment_of_readings` as one loop (compiled by numba)."""
    out = np.empty(bounds[-1] - bounds[0], np.int64)
    for k in range(len(bounds) - 1):
        for i in range(bounds[k], bounds[k + 1]):
            out[i - bounds[0]] = k
    return out


def _run_bounds_loop(points, gap_threshold, labels, by_label):
    """:func:`run_bounds` (n >= 1) as one loop: the same comparisons, in int64 as numpy's
    concatenation gives them."""
    n = len(points)
    bounds = np.empty(n + 1, np.int64)
    bounds[0] = 0
    k = 1
    for i in range(n - 1):
        step = np.hypot(points[i + 1, 0] - points[i, 0], points[i + 1, 1] - points[i, 1])
        a, b = gap_threshold[i], gap_threshold[i + 1]
        larger = a if (a >= b or a != a) else b  # np.maximum: nan when either is
        if step >= larger or (by_label and labels[i + 1] != labels[i]):
            bounds[k] = i + 1
            k += 1
    bounds[k] = n
    return bounds[:k + 1].copy()


def means_and_chords(groups: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """For each group of readings (shape (k, 2), k >= 1, metres): its mean, and the distance
    from its first reading to its last (the chord a leg's arc spans), as
    ``g.mean(axis=0)`` and ``np.hypot(*(g[-1] - g[0]))`` give them; shapes (n, 2) and (n,)."""
    if not groups:
        return np.zeros((0, 2)), np.zeros(0)
    if compiled.on:
        offsets = np.zeros(len(groups) + 1, np.int64)
        np.cumsum([len(g) for g in groups], out=offsets[1:])
        return _means_chords_kernel(np.concatenate(groups), offsets)
    return (np.array([g.mean(axis=0) for g in groups]),
            np.array([np.hypot(*(g[-1] - g[0])) for g in groups]))


def _means_chords_loop(pts, offsets):
    """:func:`means_and_chords` of the groups ``pts[offsets[k]:offsets[k + 1]]``: a group's
    mean summed as numpy sums a (k, 2) array down its rows (the first row, then each in turn)."""
    n = len(offsets) - 1
    means = np.empty((n, 2))
    chords = np.empty(n)
    for k in range(n):
        a, b = offsets[k], offsets[k + 1]
        sx, sy = pts[a, 0], pts[a, 1]
        for i in range(a + 1, b):
            sx += pts[i, 0]
            sy += pts[i, 1]
        means[k, 0], means[k, 1] = sx / (b - a), sy / (b - a)
        chords[k] = np.hypot(pts[b - 1, 0] - pts[a, 0], pts[b - 1, 1] - pts[a, 1])
    return means, chords


_means_chords_kernel = compiled.njit(_means_chords_loop)
_run_bounds_kernel = compiled.njit(_run_bounds_loop)
_segment_of_kernel = compiled.njit(_segment_of_loop)
