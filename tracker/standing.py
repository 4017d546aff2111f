"""Standing people: found by the shape of their legs, kept apart from furniture by persistence.

Someone who stands still never moves, so motion detection (the paper's method) never
reports them; on the annotated hallway recording most of the people are standing. Their
legs still look like legs: two segments the leg model (:mod:`people_tracker.models.leg_model`) finds
likely enough, a stance apart. Such a pair starts a tentative track
only when it comes back at the same place in the world in most of the scans of the last
fraction of a second (a one-off coincidence of two unrelated segments does not; seconds, so
a 40 Hz laser asks for the same persistence as a 7.5 Hz one), never near an existing track,
and never where a standing track was already ended as furniture. The track is confirmed
by its evidence (:mod:`people_tracker.tracker.existence`): its place was seen empty before,
or it moves. One that never moved, on a place never seen empty, and was never confirmed
ends as furniture and its place is remembered, so a pair of table legs costs one short
tentative track, not one every few seconds.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from people_tracker.models.pose import pairwise_distances
from people_tracker.tracker.pairing import nearest_pairs


@dataclass(frozen=True)
class StandingParams:
    """Attributes (metres, seconds)
    ----------
    enabled : bool
        Look for standing people at all.
    min_leg_probability : float
        A segment is a standing leg when the leg model gives it at least this probability.
    min_leg_separation_m, max_leg_separation_m : float
        Distance between the two legs of a standing person, metres.
    confirm_window_s, confirm_share : float
        A pair starts a track when pairs were found within ``confirm_radius_m`` of it in at
        least this share of the scans of the last ``confirm_window_s`` seconds (this one
        included; stamps within the window's length of this scan's), once those scans span
        half the window and number two or more. At 7.5 Hz, 0.6 s and 0.6 are 3 of 5 scans.
    confirm_radius_m : float
        How far apart (world frame) the pairs of those scans may be, metres.
    furniture_radius_m : float
        No standing track starts this close to where one ended unmoved, metres.
    arrivals : bool
        Also start a standing track from one segment at least as leg-like as the leg model's
        base rate that persists (as a pair must) where the place memory saw the floor empty
        before, from about where the laser is now: someone arrived and stands with their legs
        merged into one segment, or one leg hidden.
    """

    enabled: bool = True
    min_leg_probability: float = 0.3
    min_leg_separation_m: float = 0.1
    max_leg_separation_m: float = 0.5
    confirm_window_s: float = 0.6
    confirm_share: float = 0.6
    confirm_radius_m: float = 0.2
    furniture_radius_m: float = 0.5
    arrivals: bool = True


def standing_pairs(legs_xy: np.ndarray, params: StandingParams) -> tuple[np.ndarray, np.ndarray]:
    """The nearest disjoint leg pairs a stance apart: their midpoints, shape (k, 2), and
    their two legs, shape (k, 2, 2), in the frame of ``legs_xy``."""
    pairs = nearest_pairs(legs_xy, params.min_leg_separation_m, params.max_leg_separation_m)
    if not pairs:
        return np.zeros((0, 2)), np.zeros((0, 2, 2))
    i, j = np.array(pairs).T
    legs = np.stack([legs_xy[i], legs_xy[j]], axis=1)
    return legs.mean(axis=1), legs


class StandingInitiator:
    """Decides where standing people start: persistent pairs away from furniture.

    Feed every scan's pairs (world frame) to :meth:`persistent`; tell it with
    :meth:`furniture` where a standing track ended without moving.
    """

    def __init__(self, params: StandingParams, max_places: int = 1000) -> None:
        self.params = params
        self._recent: deque[tuple[float, np.ndarray]] = deque()  # (stamp (s), pairs (world frame, m))
        self._furniture: deque[np.ndarray] = deque(maxlen=max_places)

    def persistent(self, pairs_world: np.ndarray, stamp: float) -> np.ndarray:
        """Record this scan's pairs (world frame, m) at ``stamp`` (s); return which of them
        persisted (bool, shape (k,))."""
        p = self.params
        recent = self._recent
        recent.append((stamp, pairs_world))
        while recent and recent[0][0] <= stamp - p.confirm_window_s + 1e-6:  # the window is (stamp - w, stamp]
            recent.popleft()
        seen = np.zeros(len(pairs_world), dtype=np.int64)
        for _, earlier in recent:
            if len(earlier) and len(pairs_world):
                d = pairwise_distances(pairs_world, earlier)
                seen += d.min(axis=1) <= p.confirm_radius_m
        span = stamp - recent[0][0]
        if len(recent) < 2 or span < 0.5 * p.confirm_window_s:
            return np.zeros(len(pairs_world), dtype=bool)
        ok = seen >= p.confirm_share * len(recent) - 1e-9
        if ok.any() and self._furniture:
            f = np.array(self._furniture)
            d = pairwise_distances(pairs_world, f)
            ok &= d.min(axis=1) > p.furniture_radius_m
        return ok

    def twin(self) -> "StandingInitiator":
        """Another initiator with the same parameters and the same furniture memory (a place
        told to either is remembered once, for both), and its own recent history."""
        other = StandingInitiator(self.params, self._furniture.maxlen)
        other._furniture = self._furniture
        return other

    def furniture(self, xy_world: np.ndarray) -> None:
        """Remember a place (world frame, m) where a standing 'person' never moved."""
        self._furniture.append(np.asarray(xy_world, dtype=float).copy())

    def reset(self) -> None:
        """Forget the recent pairs (a stamp jump, a new scanner); furniture stays."""
        self._recent.clear()


__all__ = ["StandingInitiator", "StandingParams", "standing_pairs"]
