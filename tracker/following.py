"""Choosing and keeping the person a robot follows."""

from __future__ import annotations

import math

import numpy as np

from people_tracker.models.pose import Pose2D


class TargetSelector:
    """Keeps one target track id.

    Parameters
    ----------
    mode : 'auto', an int track id, or None
        ``auto`` picks the closest confirmed person ahead of the sensor (within
        ``ahead_deg`` of its x axis) whenever there is no target; an id follows that
        track once it exists.
    reacquire_s, reacquire_m : float
        When the target's track is deleted, a new confirmed track that appears within
        ``reacquire_s`` seconds and ``reacquire_m`` metres of the target's last estimate
        takes over the target's id: the person is reported re-acquired under the same id.
    """

    def __init__(self, mode: str | int | None, reacquire_s: float = 5.0, reacquire_m: float = 1.5,
                 ahead_deg: float = 60.0) -> None:
        self.mode = mode
        self.target: int | None = None if mode in (None, "auto") else int(mode)
        self._lost: tuple[float, np.ndarray] | None = None  # (stamp, last position) of a deleted target
        self._reacquire_s, self._reacquire_m = reacquire_s, reacquire_m
        self._ahead = math.radians(ahead_deg)
        self.events: list[str] = []

    def lost(self, stamp: float, position: np.ndarray) -> None:
        """The target's track was deleted at ``stamp`` (s), last seen at ``position`` (world, m)."""
        self._lost = (stamp, position.copy())
        self.events.append(f"lost {self.target}")

    def reacquire(self, stamp: float, new_tracks: dict[int, np.ndarray]) -> int | None:
        """Which newly confirmed track (id → world position) takes over the lost target's id, if any."""
        if self._lost is None or self.target is None:
            return None
        t_lost, where = self._lost
        if stamp - t_lost > self._reacquire_s:
            self._lost = None
            if self.mode == "auto":
                self.target = None
            return None
        best, best_d = None, self._reacquire_m
        for tid, p in new_tracks.items():
            d = float(np.hypot(*(p - where)))
            if d <= best_d:
                best, best_d = tid, d
        if best is not None:
            self._lost = None
            self.events.append(f"re-acquired {self.target}")
        return best

    def choose(self, confirmed: dict[int, np.ndarray], pose: Pose2D) -> int | None:
        """The target id now, given confirmed tracks (id → world position) and the sensor pose."""
        if self.target is not None or self.mode != "auto" or self._lost is not None:
            return self.target
        best, best_r = None, math.inf
        inv = pose.inverse()
        for tid, p in confirmed.items():
            x, y = inv.transform_points(p[None, :])[0]
            r, bearing = math.hypot(x, y), math.atan2(y, x)
            if abs(bearing) <= self._ahead and r < best_r:
                best, best_r = tid, r
        if best is not None:
            self.target = best
            self.events.append(f"target {best}")
        return self.target
