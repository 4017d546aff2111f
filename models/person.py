"""The walking person: two legs with a gait, following waypoints at a given speed.

A person's torso moves along a polyline of waypoints at the walker's speed, pausing where
told. The legs are placed by the torso's arc length ``s`` along the path, so a paused
person's legs stand still and a walking person's stance leg does too:

* footprints lie every ``step_length`` metres along the path, at ``(k + ½)·step_length``,
  alternately left and right of it by half the leg spacing;
* while the torso goes from ``k·L`` to ``(k + 1)·L``, one leg stands on footprint ``k``
  (stance) and the other swings from footprint ``k - 1`` to ``k + 1``: twice the distance in
  the same time, so at about twice the walking speed. The torso is thus midway between
  the feet when a foot lands and right above the standing foot at mid-step, and always at
  the legs' midpoint;
* the cadence (steps per second) is ``speed / step_length``, so it follows the speed.

Pauses start at the middle of a step, where the swinging leg passes the standing one, and a
standing person has both feet side by side, across the direction they were walking (also where
the path turns back there). ``step_phase_m`` shifts the footprints along the path, so a walker
can be made to take a mid-step, and stop, exactly on a chosen waypoint.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class PersonModel:
    """Body dimensions, metres.

    Attributes
    ----------
    leg_radius : float
        Radius of a leg at scanner height (5–8 cm).
    leg_spacing : float
        Distance between the legs' centres across the walking direction (10–30 cm).
    step_length : float
        Distance the torso travels per step.
    """

    leg_radius: float = 0.065
    leg_spacing: float = 0.20
    step_length: float = 0.60

    @staticmethod
    def sample(rng: np.random.Generator, speed: float) -> "PersonModel":
        """A random adult: radius 5–8 cm, spacing 10–30 cm, step length growing with speed."""
        step = float(np.clip(0.35 + 0.22 * speed + rng.normal(0.0, 0.03), 0.3, 0.85))
        return PersonModel(float(rng.uniform(0.05, 0.08)), float(rng.uniform(0.12, 0.28)), step)


@dataclass
class Walker:
    """A person following waypoints.

    Parameters
    ----------
    person_id : int
    waypoints : array-like, shape (w, 2)
        Path in the world frame, metres; the person starts at the first point.
    speed : float or sequence of float
        Walking speed on each leg of the path, m/s (one value for all).
    pauses : dict[int, float]
        Seconds to stand at waypoint ``i`` (index into ``waypoints``) before going on.
    start_time : float
        When the person starts walking, seconds; before it they are not in the scene.
    exit_at_end : bool
        Leave the scene at the last waypoint instead of standing there.
    body : PersonModel
    """

    person_id: int
    waypoints: np.ndarray
    speed: float | list[float] = 1.0
    pauses: dict[int, float] = field(default_factory=dict)
    start_time: float = 0.0
    exit_at_end: bool = False
    body: PersonModel = field(default_factory=PersonModel)
    round_radius: float | None = None  # set: a round object of this radius (m) instead of two legs
    step_phase_m: float = 0.0  # m: footprints lie at (k + ½)·step_length + this along the path
    # where others make them step aside: (times s, shape (n,); offsets m, world frame, shape (n, 2)),
    # added to the torso and both legs (see :func:`people_tracker.models.keep_apart.keep_apart`)
    detour: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        wp = np.asarray(self.waypoints, dtype=float).reshape(-1, 2)
        if len(wp) == 1:
            wp = np.vstack([wp, wp])
        self.waypoints = wp
        seg = np.diff(wp, axis=0)
        self._seg_len = np.hypot(seg[:, 0], seg[:, 1])
        self._cum = np.concatenate([[0.0], np.cumsum(self._seg_len)])  # arc length at each waypoint
        self._cum_list = self._cum.tolist()
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = seg / self._seg_len[:, None]
        self._unit = np.where(self._seg_len[:, None] > 0, unit, [1.0, 0.0])
        speeds = np.broadcast_to(np.asarray(self.speed, dtype=float), (len(seg),)).astype(float)
        if (speeds <= 0).any():
            raise ValueError("walking speed must be positive")
        L, phi = self.body.step_length, self.step_phase_m

        def mid_step_at_or_after(s: float) -> float:  # feet side by side there
            return (math.ceil((s - phi) / L - 0.5 - 1e-9) + 0.5) * L + phi

        total = float(self._cum[-1])
        # the walk ends at the last mid-step of the path, so a person standing there has
        # both feet side by side
        s_end = (math.floor((total - phi) / L - 0.5 + 1e-9) + 0.5) * L + phi
        if not 0.0 <= s_end <= total or self.round_radius is not None:
            s_end = total
        # timeline of pieces (t_start, s_start, speed); speed 0 for a pause
        t, s = self.start_time, 0.0
        pieces = []
        for i in range(len(seg) + 1):
            pause = float(self.pauses.get(i, 0.0))
            if pause > 0:
                stop = min(mid_step_at_or_after(s), s_end)
                v = speeds[min(i, len(seg) - 1)]
                if stop > s:
                    pieces.append((t, s, v))
                    t += (stop - s) / v
                    s = stop
                pieces.append((t, s, 0.0))
                t += pause
            if i < len(seg):
                goal = min(float(self._cum[i + 1]), s_end)
                if goal > s:
                    pieces.append((t, s, speeds[i]))
                    t += (goal - s) / speeds[i]
                    s = goal
        self._pieces = np.array(pieces if pieces else [(t, s, 0.0)], dtype=float)
        self.end_time = t
        self._s_end = s

    def present(self, t: float) -> bool:
        """Whether the person is in the scene at time ``t`` (s)."""
        return t >= self.start_time and not (self.exit_at_end and t > self.end_time)

    def arc_length(self, t: float) -> float:
        """Distance walked along the path by time ``t``, metres."""
        return self._walk(t)[0]

    def _walk(self, t: float) -> tuple[float, bool]:
        """Arc length walked by time ``t`` (m) and whether the person is standing then."""
        if t <= self.start_time:
            return 0.0, len(self._pieces) > 0 and self._pieces[0, 2] == 0.0
        if t >= self.end_time:
            return self._s_end, True
        i = int(np.searchsorted(self._pieces[:, 0], t, side="right")) - 1
        t0, s0, v = self._pieces[i]
        return float(min(s0 + v * (t - t0), self._s_end)), bool(v == 0.0)

    def path_positions(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Torso on the path at each of ``times`` (s), before any detour: positions (n, 2) in
        the world frame (m), unit walking directions (n, 2) and whether present, (n,)."""
        t = np.asarray(times, dtype=float)
        p = self._pieces
        i = np.clip(np.searchsorted(p[:, 0], t, side="right") - 1, 0, len(p) - 1)
        s = np.minimum(p[i, 1] + p[i, 2] * np.maximum(t - p[i, 0], 0.0), self._s_end)
        s = np.where(t <= self.start_time, 0.0, np.where(t >= self.end_time, self._s_end, s))
        last = len(self._seg_len) - 1
        k = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, last)
        # a zero-length piece has no direction of its own: take the next one's, as _at does
        nonzero = np.flatnonzero(self._seg_len > 0)
        if len(nonzero):
            k = nonzero[np.minimum(np.searchsorted(nonzero, k), len(nonzero) - 1)]
        u = self._unit[k]
        pos = self.waypoints[k] + u * (s - self._cum[k])[:, None]
        present = (t >= self.start_time) & ~(self.exit_at_end & (t > self.end_time))
        return pos, u, present

    def _detour_at(self, t: float) -> np.ndarray | None:
        if self.detour is None:
            return None
        times, off = self.detour
        return np.array([np.interp(t, times, off[:, 0]), np.interp(t, times, off[:, 1])])

    def _at(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """Point and unit direction of the path at arc length ``s``."""
        cum = self._cum_list
        s = min(max(float(s), 0.0), cum[-1])
        last = len(self._seg_len) - 1
        i = min(max(bisect.bisect_right(cum, s) - 1, 0), last)
        while self._seg_len[i] == 0 and i < last:
            i += 1
        u = self._unit[i]
        return self.waypoints[i] + u * (s - cum[i]), u

    def torso(self, t: float) -> np.ndarray:
        """Torso position (the ground truth) at time ``t``, world frame, metres."""
        p = self._at(self.arc_length(t))[0]
        off = self._detour_at(t)
        return p if off is None else p + off

    def _footprint(self, k: int) -> np.ndarray:
        p, u = self._at((k + 0.5) * self.body.step_length + self.step_phase_m)
        side = 1.0 if k % 2 == 0 else -1.0  # even footprints left of the path, odd right
        normal = np.array([-u[1], u[0]])
        return p + side * 0.5 * self.body.leg_spacing * normal

    def circles(self, t: float) -> np.ndarray:
        """What the laser sees at time ``t``: circles (x, y, r), shape (2, 3) for legs, (1, 3) round."""
        if self.round_radius is not None:
            return np.array([[*self.torso(t), self.round_radius]])
        return np.column_stack([self.legs(t), np.full(2, self.body.leg_radius)])

    def legs(self, t: float) -> np.ndarray:
        """Centres of the two legs at time ``t``, shape (2, 2): row 0 the stance leg."""
        off = self._detour_at(t)
        legs = self._path_legs(t)
        return legs if off is None else legs + off

    def _path_legs(self, t: float) -> np.ndarray:
        L = self.body.step_length
        s, standing = self._walk(t)
        k = int(math.floor((s - self.step_phase_m) / L + 1e-9))
        phase = (s - self.step_phase_m) / L - k  # 0 … 1 through the step
        stance = self._footprint(k)
        if standing and abs(phase - 0.5) < 1e-6:
            # feet side by side across the path, also where it turns back (the footprints
            # either side of a turn do not straddle the torso)
            return np.vstack([stance, 2.0 * self._at(s)[0] - stance])
        a, b = self._footprint(k - 1), self._footprint(k + 1)
        # footprints k-1 and k+1 lie on the same side, so the swinging leg passes beside
        # the standing one
        swing = a + (b - a) * phase
        return np.vstack([stance, swing])
