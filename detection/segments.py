"""Stage 3: continuous segments of each set."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
        Largest spacing (m) from each reading to the next one within a segment.
    """
    n = len(labels)
    if n == 0:
        return []
    gap = np.hypot(*np.diff(points, axis=0).T)
    cut = (labels[1:] != labels[:-1]) | (gap >= gap_threshold[:-1])
    bounds = np.concatenate([[0], np.flatnonzero(cut) + 1, [n]])
    return [Segment(int(a), int(b), int(labels[a]), (int(labels[a]),)) for a, b in zip(bounds[:-1], bounds[1:])]
