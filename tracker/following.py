"""Choosing and keeping the person a robot follows.

The target model lives in the sensor frame: a robot that follows someone keeps them at much
the same place in front of it, whatever it knows of its own motion (without odometry, in a
scene that gives scan matching little to hold on to, the world frame drifts and jumps; the
person's place relative to the sensor does not). Only the sensor's turn, which scan matching
measures well even there, is taken out when the person is looked for after a gap: a robot
turning after its person swings them across its view. When the target's track breaks off, or
coasts while a fresh track appears where the person should be, the person's id goes to the
track at that place — when exactly one is there; when more than one could be them, the
person is reported lost rather than swapped for someone else. An ``auto`` selector (the
robot follows whoever it locked onto in front of it) gives a lost person's id instead to
the one person in front of the robot after a moment, if there is exactly one (of several,
the one clearly walking as the person last walked, by their world-frame velocity, or else
the one clearly in the robot's way, straight ahead of it; a track not confirmed yet beyond
the lock zone, where the person could be, counts as one, since far away the person's own
track is confirmed slowly): a robot
following someone has them in front of it, wherever a drifting or turned estimate says
they went, and the one track near that estimate was more often a passer-by than them. A
track that walks neither as the person last walked nor as the robot that follows them now
moves is a passer-by, not them: it takes no id, and does not count among those in front.
An ``auto`` selector never gives the person up: however long they are gone, the next one
found in front of the robot, as above, is taken as them, under their id.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from people_tracker.models.pose import Pose2D


class TargetSelector:
    """Keeps one target track id, and the person's id when their track breaks.

    Parameters
    ----------
    mode : 'auto', an int track id, or None
        ``auto`` first locks onto the reported person most nearly straight ahead of the
        sensor, within ``lane_m`` of its x axis, ``ahead_deg`` of it and ``lock_range_m`` of
        the sensor (the person to follow stands or walks close in front of the robot, in
        its way; someone crossing or walking by to one side is not them), and keeps that
        person's id for good (see ``relock_s``). An id follows that track once it exists.
    reacquire_s : float
        With an id given: how long (s) after the target's track broke off another track may
        still take the person's id. ``auto`` looks for the person for as long as they are
        gone (a robot following someone waits for them).
    reacquire_m, walk_mps : float
        Where the person may be: within ``reacquire_m`` metres of where they should be
        relative to the sensor, the radius growing at ``walk_mps`` with the time since their
        track was last updated, up to ``max_reach_m``. With an id given, the one other track
        there takes the id of a lost person.
    relock_s : float
        ``auto``: when the person has been lost this long (s), the one person in the lock
        zone ahead (none when there are several) takes their id, and their place is learnt
        afresh from them. Beyond the zone's ``lock_range_m``, a track within reach of where
        they should be counts too, out to their last range plus the reach they had when
        the re-lock began (:meth:`looked_for`): the robot may have fallen back. With several
        there, the one walking as the person last walked takes the id, when it is clearly
        them: its world-frame velocity within ``same_velocity_mps`` (m/s) of theirs and every
        other's more than ``other_velocity_mps`` from it (:meth:`_walking_on`); else the one
        in the robot's way, when it clearly is (:meth:`_in_the_way`). Only tracks that walk
        as the person could (:meth:`walks_as_expected`) are looked among: one coming the
        other way or crossing is not them, and leaves the choice to the others.
    max_walk_change_mps, sensor_velocity_s : float
        A track re-locked onto walks (world-frame velocity) within ``max_walk_change_mps``
        (m/s) of the person's velocity when last seen, or of the sensor's own velocity over
        the last ``sensor_velocity_s`` seconds (a robot following someone moves as they do,
        turns after them included); else it is someone coming the other way or crossing,
        and the person stays lost. None: no such test.
    max_sensor_walk_change_mps : float or None
        ... and never more than this (m/s) from the sensor's own velocity, when that is known
        (and ``max_walk_change_mps`` is not None): the person's velocity when last seen may
        be a passer-by's, their track having slid onto someone coming the other way before
        it broke off, while the robot that follows them still moves as they do. 1.5 m/s
        lets through someone a quarter turn from the robot's way at walking pace (about
        1.1 m/s each), or setting off at 1.5 m/s from a robot standing still. None: no such
        test.
    same_person_m : float
        Reported tracks in the zone ahead all within this distance (m) of the closest of
        them are one person seen twice (a track on each leg), not several people: the
        closest takes the id.
    coast_s : float
        A target track not updated for this long (s), while exactly one other track was
        updated where the person should be, gives the id to that one.
    steady_s, slide_m : float
        The person's place relative to the sensor averaged over ``steady_s`` seconds: a
        target track that moved more than ``slide_m`` from it, while exactly one other track
        was updated within ``reacquire_m`` of it, slid onto someone passing between; the
        person is lost (and the re-lock looks for them). A target back from coasting
        (``coast_s``) more than ``slide_m`` from the average is not learnt into it until it
        has stayed off for ``steady_s``: after a gap the average would take a large share of
        the jump at once, and a track that came back on a passer-by would drag the person's
        place onto them before the person's own new track is seen where they are.
        A target track that stood still in the world frame all the while has not slid
        (:meth:`only_the_sensor_moved`).
    trail_s : float
        ... unless that other track was farther than ``reacquire_m`` from the averaged place
        ``trail_s`` seconds ago (or where it began, if later): it walked in from elsewhere, a
        passer-by stepping where the person was a moment ago while the average lags a person
        who moves relative to the sensor (:meth:`came_from_elsewhere`).
    settle_s, settle_margin_m : float
        ``auto``: for ``settle_s`` seconds after the first lock, a reported person in the lane
        more nearly straight ahead than the target by at least ``settle_margin_m`` metres (any
        one in the lane, once the target is beside or behind the sensor) takes the target,
        unless their offset from the axis changed by more than that over the last ``trail_s``
        (or since they began): someone crossing the robot's way passes its axis. A target
        lost while the lock settles is chosen afresh, as at the first lock: the person
        to follow is the one in the robot's way, and the re-lock (which waits ``relock_s``,
        and then takes one of several only when it clearly walks as the person did or is
        clearly in the robot's way, by this margin too) is for a person it has learnt.
    approach_mps : float
        ``auto``, until the first lock has settled (``settle_s``): a track in the lane
        that came nearer along the sensor's axis faster than this (m/s) over the last
        ``trail_s`` (tracked for at least half of it) is someone the robot overtakes or who
        comes towards it, not the person it follows: it is never locked onto, and a target
        found so gives way to the one in the robot's way. The speed is relative to the
        sensor, so a robot that drives up to someone standing counts too; a robot following
        someone keeps its distance, and someone crossing its way keeps their distance along
        its axis. ``math.inf``: no such test.
        The choice is still being made: whoever is reported first is not always the one in the
        robot's way. A passer-by close in front is seen moving at once, while the person to
        follow, walking away from the laser in their own shadow, may be confirmed a few tenths
        of a second later. 0 s: the first lock holds.
    """

    def __init__(self, mode: str | int | None, reacquire_s: float = 10.0, reacquire_m: float = 0.8,
                 ahead_deg: float = 60.0, lock_range_m: float = 3.5, walk_mps: float = 1.5,
                 coast_s: float = 0.5, max_reach_m: float = 4.0, steady_s: float = 1.5,
                 slide_m: float = 0.6, relock_s: float = 1.0, same_person_m: float = 0.35,
                 lane_m: float = 0.75, same_velocity_mps: float = 0.2, other_velocity_mps: float = 1.2,
                 max_walk_change_mps: float | None = 1.0, sensor_velocity_s: float = 0.5,
                 max_sensor_walk_change_mps: float | None = 1.5,
                 trail_s: float = 1.0, settle_s: float = 2.0, settle_margin_m: float = 0.2,
                 approach_mps: float = 0.5) -> None:
        self.mode = mode
        self.target: int | None = None if mode in (None, "auto") else int(mode)
        self._reacquire_s, self._reacquire_m, self._walk = reacquire_s, reacquire_m, walk_mps
        self._ahead_rad, self._lock_range, self.coast_s = math.radians(ahead_deg), lock_range_m, coast_s
        self._max_reach, self._steady_s, self.slide_m = max_reach_m, steady_s, slide_m
        self.relock_s, self._same_person_m, self._lane_m = relock_s, same_person_m, lane_m
        self.trail_s = trail_s
        self.settle_s, self.settle_margin_m = settle_s, settle_margin_m
        self.approach_mps = approach_mps
        self._passing: set[int] = set()  # ids seen closing in on the sensor while the first lock settled
        self._locked_at: float | None = None  # when the first lock was made (s)
        self.steady: np.ndarray | None = None  # the person's place relative to the sensor, averaged (m)
        self._world: deque = deque()  # (stamp s, place m): where the target's track was in the world frame, lately
        self._slid_since: float | None = None  # since when (s) the target's updates have been off ``steady``
        self._q: np.ndarray | None = None  # the person's place in the sensor frame (m) ...
        self._v = np.zeros(2)  # ... its rate of change (m/s) ...
        self._t: float | None = None  # ... and when their track was last updated (s)
        self._yaw = 0.0  # the sensor's heading (world frame, rad) when the person was last seen ...
        self.yaw = 0.0  # ... and now (the tracker sets it every scan)
        self.lost_since: float | None = None  # when the target's track broke off, while it is missing
        self.velocity: np.ndarray | None = None  # the person's velocity when last seen (world frame, m/s)
        self._same_velocity, self._other_velocity = same_velocity_mps, other_velocity_mps
        self.events: list[str] = []
        self._max_walk_change = max_walk_change_mps
        self._max_sensor_walk_change = max_sensor_walk_change_mps
        self._path_s = sensor_velocity_s
        self._path: deque = deque()  # (stamp s, x m, y m): the sensor's place in the world frame, lately

    def seen(self, stamp: float, q: np.ndarray, velocity: np.ndarray | None = None,
             world: np.ndarray | None = None) -> None:
        """The target's track was updated at ``stamp`` (s), at ``q`` in the sensor frame (m)
        and ``world`` in the world frame (m; None when not known), walking at ``velocity``
        (world frame, m/s; None when not known)."""
        q = np.asarray(q, dtype=float)
        if world is not None:
            self._world.append((stamp, np.array(world, dtype=float)))
            while len(self._world) > 1 and stamp - self._world[1][0] >= self._steady_s:
                self._world.popleft()
        self.velocity = None if velocity is None else np.array(velocity, dtype=float)
        if self._q is not None and self._t is not None and stamp > self._t:
            rate = (q - self._q) / (stamp - self._t)
            speed = float(np.hypot(*rate))
            if speed > 2.0:
                rate *= 2.0 / speed
            self._v = 0.7 * self._v + 0.3 * rate
            a = 1.0 - math.exp(-(stamp - self._t) / self._steady_s)
            if not self.slid(q):
                self._slid_since = None
            elif self._slid_since is None and self.coasting(stamp, self._t):
                self._slid_since = stamp  # back from coasting somewhere off where the person has been
            if self._slid_since is not None and stamp - self._slid_since < self._steady_s:
                a = 0.0  # not learnt until it has stayed off for steady_s
            self.steady = self.steady + a * (q - self.steady)
        else:
            self.steady, self._slid_since = q.copy(), None
        self._q, self._t, self._yaw = q.copy(), stamp, self.yaw
        if self.lost_since is not None:  # their own track is back (a re-lock has said so already)
            self.events.append(f"found {self.target} again")
        self.lost_since = None

    def moved(self, stamp: float, x: float, y: float) -> None:
        """The sensor is at ``(x, y)`` (world frame, m) at ``stamp`` (s)."""
        self._path.append((stamp, x, y))
        while len(self._path) > 2 and stamp - self._path[1][0] >= self._path_s:
            self._path.popleft()

    def forget_path(self) -> None:
        """Forget where the sensor was (the scan history restarts)."""
        self._path.clear()

    def sensor_velocity(self) -> np.ndarray | None:
        """The sensor's velocity over the last ``sensor_velocity_s`` (world frame, m/s), or None."""
        if len(self._path) < 2:
            return None
        (t0, x0, y0), (t1, x1, y1) = self._path[0], self._path[-1]
        if t1 - t0 < 0.5 * self._path_s:
            return None
        return np.array([(x1 - x0) / (t1 - t0), (y1 - y0) / (t1 - t0)])

    def walks_as_expected(self, velocity: np.ndarray | None) -> bool:
        """Whether a track walking at ``velocity`` (world frame, m/s) could be the person: within
        ``max_walk_change_mps`` of how they last walked or of how the sensor that follows them
        moves now, and within ``max_sensor_walk_change_mps`` of the latter (True when neither,
        or the velocity, is known)."""
        if self._max_walk_change is None or velocity is None:
            return True
        sensor = self.sensor_velocity()
        if (sensor is not None and self._max_sensor_walk_change is not None
                and float(np.hypot(*(velocity - sensor))) > self._max_sensor_walk_change):
            return False
        refs = [r for r in (self.velocity, sensor) if r is not None]
        return not refs or min(float(np.hypot(*(velocity - r))) for r in refs) <= self._max_walk_change

    def _forget_place(self) -> None:
        """Forget where the person is relative to the sensor (learnt afresh from the next
        track seen as them)."""
        self._q, self._t, self._v, self.steady, self._slid_since = None, None, np.zeros(2), None, None
        self._world.clear()

    def coasting(self, stamp: float, last_update: float) -> bool:
        """Whether a track last updated at ``last_update`` (s) has coasted ``coast_s`` by
        ``stamp`` (s): where the person is now is then a guess."""
        return stamp - last_update >= self.coast_s

    def lost(self, stamp: float, why: str = "") -> None:
        """The target's track broke off (or was found on someone else) at ``stamp`` (s);
        ``why`` says how, in the event's text."""
        if self.lost_since is None:
            self.lost_since = stamp
            self.events.append(f"lost {self.target}" + (f" ({why})" if why else ""))

    def expected(self, stamp: float) -> tuple[np.ndarray, float] | None:
        """Where the person should be now in the sensor frame (m), and how far from it they may be (m)."""
        if self._q is None or self._t is None:
            return None
        gap = max(stamp - self._t, 0.0)
        return self._turn(self._q + self._v * min(gap, 1.0)), min(self._reacquire_m + self._walk * gap,
                                                                  self._max_reach)

    def _turn(self, q: np.ndarray) -> np.ndarray:
        """A place in the sensor frame when the person was last seen, in the sensor frame now.

        Only the sensor's turn since is taken out (its heading from scan matching holds well
        even where its place drifts): the person's bearing turns back by as much."""
        return Pose2D(0.0, 0.0, self._yaw - self.yaw).transform_points(np.asarray(q)[None])[0]

    def within_reach(self, stamp: float, q: np.ndarray) -> bool:
        """Whether the person could be at ``q`` (sensor frame, m) now."""
        exp = self.expected(stamp)
        return exp is None or float(np.hypot(*(np.asarray(q) - exp[0]))) <= exp[1]

    @property
    def looking(self) -> bool:
        """Whether ``auto`` is looking for its lost person now."""
        return self.mode == "auto" and self.target is not None and self.lost_since is not None

    def back_far_ahead(self, stamp: float, q: np.ndarray) -> bool:
        """Whether the lost person could be at ``q`` (sensor frame, m) now, beyond the lock zone's
        range (``lock_range_m``): where their legs, a few readings each, are too sparse to look
        like legs, and ``auto`` looks for them (:attr:`looking`; else False)."""
        return (self.looking and math.hypot(float(q[0]), float(q[1])) > self._lock_range
                and self.within_reach(stamp, q))

    def only_one_near(self, stamp: float, others: dict[int, np.ndarray], steady: bool = False) -> int | None:
        """The one track (id → sensor-frame place) where the person should be (or, with
        ``steady``, within ``reacquire_m`` of where they have been lately); None when there
        is none or more than one."""
        exp = self.expected(stamp)
        if exp is None:
            return None
        where, reach = (self.steady, self._reacquire_m) if steady else exp
        near = [tid for tid, q in others.items() if float(np.hypot(*(q - where))) <= reach]
        return near[0] if len(near) == 1 else None

    def came_from_elsewhere(self, place_then: np.ndarray) -> bool:
        """Whether a track that was at ``place_then`` (sensor frame then, m) ``trail_s`` ago
        came from farther than ``reacquire_m`` from where the person has been lately."""
        return self.steady is not None and float(np.hypot(*(np.asarray(place_then) - self.steady))) > self._reacquire_m

    def only_the_sensor_moved(self, stamp: float, world: np.ndarray, other_since: float) -> bool:
        """Whether a target track found slid (:meth:`slid`) at ``stamp`` (s) only moved
        relative to the sensor: it has stood within half of ``slide_m`` of where it is now,
        ``world`` (world frame, m), for the last ``steady_s``, and the other track at the
        person's averaged place has been tracked since ``other_since`` (s), ``steady_s`` or
        more before. A robot closing in on someone who stopped moves them off their average
        in the sensor frame, and a walker keeping pace beside the robot stays on it. A track
        begun there since is more often the person, walked off while their old track stayed
        on something where they stood: that is still a slide."""
        if stamp - other_since < self._steady_s or not self._world or stamp - self._world[0][0] < self._steady_s:
            return False
        return all(float(np.hypot(*(w - world))) <= 0.5 * self.slide_m for _, w in self._world)

    def slid(self, q: np.ndarray) -> bool:
        """Whether the target track at ``q`` (sensor frame, m) is far from where the person has been lately."""
        return self.steady is not None and float(np.hypot(*(np.asarray(q) - self.steady))) > self.slide_m

    def reacquire(self, stamp: float, others: dict[int, np.ndarray],
                  velocities: dict[int, np.ndarray] | None = None,
                  pending: dict[int, np.ndarray] | None = None,
                  then: dict[int, np.ndarray] | None = None) -> int | None:
        """Which other track (id → sensor-frame place) takes over the missing target's id
        (``velocities``: id → world-frame velocity, m/s, when known, ``pending`` included;
        ``then``: id → where it was ``trail_s`` ago or where it began, in the sensor frame
        then, m, when known).

        ``pending``: tracks updated this scan but not yet reported (id → sensor-frame place,
        m). ``auto`` counts those beyond the lock zone's range among the ones it looks among,
        though none of them takes the id: far away, a walker's few readings a leg confirm a
        track slowly, and the person seen there may not be reported yet while a passer-by
        nearer is the only reported track; with two there, the person is reported lost
        rather than given to the wrong one."""
        if self.lost_since is None or self.target is None:
            return None
        if self.mode != "auto":  # the id goes to the one track within reach of where they should be
            if stamp - self.lost_since > self._reacquire_s:
                self.events.append(f"gave up {self.target}")
                self.lost_since = None
                return None
            best = self.only_one_near(stamp, others)
        elif stamp - self.lost_since >= self.relock_s:  # the person is the one in front of the robot
            far = {tid: q for tid, q in (pending or {}).items() if math.hypot(*q) > self._lock_range}
            everyone = {**others, **far}
            looked = self.looked_for(stamp, everyone)
            if velocities is not None:  # walking as neither the person nor the robot that follows them: a passer-by
                looked = [tid for tid in looked if self.walks_as_expected(velocities.get(tid))]
            best = self._only_one(looked, everyone)
            if best is None:
                best = self._walking_on(looked, velocities)
            if best is None:
                best = self._in_the_way(looked, everyone, then)
            if best in far:  # not reported yet: the id waits for it
                best = None
            if best is not None:  # where they are now is learnt afresh
                self._forget_place()
        else:
            best = None
        if best is not None:
            self.lost_since = None
            self.events.append(f"re-acquired {self.target}")
        return best

    def _walking_on(self, candidates: list[int], velocities: dict[int, np.ndarray] | None) -> int | None:
        """Of several candidate tracks, the one walking as the person last walked (its
        world-frame velocity within ``same_velocity_mps`` of theirs) when every other walks
        differently (more than ``other_velocity_mps`` from it); None otherwise."""
        if (len(candidates) < 2 or velocities is None or self.velocity is None
                or any(tid not in velocities for tid in candidates)):
            return None
        dv = sorted((float(np.hypot(*(velocities[tid] - self.velocity))), tid) for tid in candidates)
        if dv[0][0] <= self._same_velocity and dv[1][0] > self._other_velocity:
            return dv[0][1]
        return None

    def _in_the_way(self, candidates: list[int], tracks: dict[int, np.ndarray],
                    then: dict[int, np.ndarray] | None) -> int | None:
        """Of several candidate tracks (ids of ``tracks``, id → sensor-frame place, m), the one
        in the robot's way: in the lane (within ``lane_m`` of the sensor's axis, in the follow
        zone out to ``lock_range_m``), nearer the axis than every other by ``settle_margin_m``
        or more, and not crossing it (its offset from the axis changed by no more than that
        since ``then``, id → place ``trail_s`` ago in the sensor frame then, when given). A
        robot that follows someone steers to keep them straight ahead of it, as at the first
        lock; None otherwise."""
        if len(candidates) < 2:
            return None
        off = {tid: self._off_axis(tracks[tid]) for tid in candidates}
        best = min(candidates, key=lambda tid: (off[tid], tid))
        if off[best] > self._lane_m or math.hypot(*tracks[best]) > self._lock_range:
            return None
        if any(off[tid] < off[best] + self.settle_margin_m for tid in candidates if tid != best):
            return None
        return None if self._crossing(best, tracks, then) else best

    def _crossing(self, tid: int | None, tracks: dict[int, np.ndarray], then: dict[int, np.ndarray] | None) -> bool:
        """Whether track ``tid`` (of ``tracks``, id → sensor-frame place, m) is crossing the
        robot's way: its offset from the sensor's axis changed by more than ``settle_margin_m``
        since ``then`` (id → place ``trail_s`` ago in the sensor frame then; False when it is
        not given there)."""
        return bool(then) and tid in then and abs(float(tracks[tid][1] - then[tid][1])) > self.settle_margin_m

    def in_front(self, tracks: dict[int, np.ndarray], range_m: float | None = None) -> list[int]:
        """The tracks (id → sensor-frame place, m) in the follow zone ahead (out to ``range_m``,
        by default ``lock_range_m``), closest first."""
        range_m = self._lock_range if range_m is None else range_m
        ahead = [(math.hypot(x, y), tid) for tid, (x, y) in tracks.items()
                 if self._within_bearings(x, y) and math.hypot(x, y) <= range_m]
        return [tid for _, tid in sorted(ahead, key=lambda rt: rt[0])]

    def looked_for(self, stamp: float, tracks: dict[int, np.ndarray]) -> list[int]:
        """The tracks (id → sensor-frame place, m) among which the re-lock looks for the lost
        person, closest first: those in the follow zone ahead, and beyond it those where the
        person could be (within reach of where they should be) out to as far as they could
        have gone before the re-lock: the robot may have fallen back while they were unseen."""
        exp = self.expected(stamp)
        if exp is None:
            return self.in_front(tracks)
        margin = min(self._reacquire_m + self._walk * self.relock_s, self._max_reach)
        far = max(self._lock_range, float(np.hypot(*exp[0])) + margin)
        where, reach = exp
        return [tid for tid in self.in_front(tracks, far)
                if math.hypot(*tracks[tid]) <= self._lock_range or math.dist(tracks[tid], where) <= reach]

    def _within_bearings(self, x: float, y: float) -> bool:
        """Whether a place (sensor frame, m) lies within the follow zone's bearings."""
        return abs(math.atan2(y, x)) <= self._ahead_rad

    def _off_axis(self, q: np.ndarray) -> float:
        """How far a place ``q`` (sensor frame, m) lies off the sensor's axis, m: infinite
        beside or behind the sensor (outside the follow zone's bearings), where nobody is in
        the robot's way."""
        x, y = float(q[0]), float(q[1])
        return abs(y) if self._within_bearings(x, y) else math.inf

    def _only_one(self, ahead: list[int], tracks: dict[int, np.ndarray]) -> int | None:
        """The first of ``ahead`` (ids of ``tracks``, id → sensor-frame place, m) when the
        tracks there are one person's (all within ``same_person_m`` of it), else None."""
        if not ahead:
            return None
        if any(math.dist(tracks[tid], tracks[ahead[0]]) > self._same_person_m for tid in ahead[1:]):
            return None
        return ahead[0]

    def _settling(self, stamp: float | None) -> bool:
        """Whether the first lock is still settling at ``stamp`` (s; never without one): made
        no more than ``settle_s`` before."""
        return (self.target is not None and stamp is not None
                and self._locked_at is not None and stamp - self._locked_at <= self.settle_s)

    def choosing(self, stamp: float) -> bool:
        """Whether ``auto`` is still choosing whom to follow at ``stamp`` (s): no lock yet,
        or the first lock is settling (``settle_s``)."""
        return self.mode == "auto" and (self.target is None or self._settling(stamp))

    def choose(self, reported: dict[int, np.ndarray], stamp: float | None = None,
               then: dict[int, np.ndarray] | None = None,
               closing: dict[int, float] | None = None) -> int | None:
        """The target id now, given reported tracks (id → sensor-frame place, m) at ``stamp``
        (s; without it the first lock is never revised, see ``settle_s``) and, when known,
        where they were ``trail_s`` ago or where they began (id → place in the sensor frame
        then, m) and how fast they came nearer along the sensor's axis over that time (id →
        m/s, for the tracks followed long enough; see ``approach_mps``)."""
        if self.mode != "auto":
            return self.target
        settling = self._settling(stamp)
        if self.target is not None and not settling:
            return self.target
        # following starts: the person to follow stands in the robot's way, and keeps their distance
        aside = {tid: abs(float(reported[tid][1])) for tid in self.in_front(reported)}  # m off the axis
        self._passing |= {tid for tid, v in (closing or {}).items()
                          if v > self.approach_mps and aside.get(tid, math.inf) <= self._lane_m}
        lane = [tid for tid, off in aside.items() if off <= self._lane_m and tid not in self._passing]
        best = min(lane, key=lambda tid: (aside[tid], tid)) if lane else None
        if settling:  # someone clearly more in the robot's way than the target takes it
            # (a target gone beside or behind the sensor is in nobody's way) ...
            # ... and stays there (someone crossing the robot's way passes its axis);
            # a target lost, or found passing by, is chosen afresh
            crossing = self._crossing(best, reported, then)
            afresh = self.lost_since is not None or self.target in self._passing
            if (best is None or best == self.target or crossing
                    or (not afresh and (self.target not in reported or aside[best] + self.settle_margin_m
                                        > self._off_axis(reported[self.target])))):
                return self.target
            self._forget_place()  # learnt afresh
            self.velocity, self.lost_since = None, None
        if best is not None:
            if self.target is None:
                self._locked_at = stamp
            self.target = best
            self.events.append(f"target {best}")
        return self.target
