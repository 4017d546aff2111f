"""Where each step's results go besides the CSV files: a sink interface with a do-nothing default.

The tracking core never imports a display library; the application hands a sink each
step's :class:`~people_tracker.tracker.people_tracker.StepResult`.
"""

from __future__ import annotations

import numpy as np


class Sink:
    """Receives every processed scan. The default does nothing."""

    def scan(self, index: int, stamp: float, result, latency_s: float,
             truth_sensor: np.ndarray | None = None) -> None:
        """One processed scan.

        Parameters
        ----------
        index : int
            The scan's index in its topic.
        stamp : float
            Its stamp, seconds.
        result : StepResult
            What the tracker's step produced (scan, pose, detection, candidates, tracks).
        latency_s : float
            Processing time of the step, seconds.
        truth_sensor : ndarray, shape (k, 2), optional
            Ground-truth people in the sensor frame, metres, when the input has them.
        """

    def close(self) -> None:
        """The run ended normally: finish the output."""

    def abort(self) -> None:
        """The run failed: leave no partial output."""


class NullSink(Sink):
    """Does nothing."""
