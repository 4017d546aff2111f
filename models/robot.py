"""The simulated robot: unicycle motion and odometry with drift."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from people_tracker.models.pose import Pose2D, wrap_angle


@dataclass(frozen=True)
class Command:
    """Velocity command in the robot's base frame: forward m/s, turn rad/s."""

    v: float = 0.0
    omega: float = 0.0


def integrate(pose: Pose2D, cmd: Command, dt: float) -> Pose2D:
    """Exact unicycle motion for ``dt`` seconds at constant ``cmd``."""
    th = pose.yaw
    if abs(cmd.omega) < 1e-9:
        return Pose2D(pose.x + cmd.v * dt * math.cos(th), pose.y + cmd.v * dt * math.sin(th), th)
    r = cmd.v / cmd.omega
    th1 = th + cmd.omega * dt
    return Pose2D(pose.x + r * (math.sin(th1) - math.sin(th)), pose.y - r * (math.cos(th1) - math.cos(th)),
                  float(wrap_angle(th1)))


def integrate_many(pose: Pose2D, cmd: Command, dts: np.ndarray) -> np.ndarray:
    """Exact unicycle poses after each of ``dts`` seconds at constant ``cmd``: (k, 3) x, y, yaw."""
    th = pose.yaw
    dts = np.asarray(dts, dtype=float)
    th1 = th + cmd.omega * dts
    if abs(cmd.omega) < 1e-9:
        xs = pose.x + cmd.v * dts * math.cos(th)
        ys = pose.y + cmd.v * dts * math.sin(th)
    else:
        r = cmd.v / cmd.omega
        xs = pose.x + r * (np.sin(th1) - math.sin(th))
        ys = pose.y - r * (np.cos(th1) - math.cos(th))
    return np.column_stack([xs, ys, th1])


class ScriptedDriver:
    """Commands from a script of ``(duration_s, v, omega)`` pieces, then stop."""

    def __init__(self, pieces: list[tuple[float, float, float]]) -> None:
        self._ends = np.cumsum([p[0] for p in pieces]) if pieces else np.zeros(0)
        self._cmds = [Command(p[1], p[2]) for p in pieces]

    def __call__(self, t: float, pose: Pose2D) -> Command:
        i = int(np.searchsorted(self._ends, t, side="right"))
        return self._cmds[i] if i < len(self._cmds) else Command()


class WaypointDriver:
    """Drives through waypoints at ``speed`` (m/s), turning at up to ``max_turn`` rad/s."""

    def __init__(self, waypoints, speed: float, max_turn: float = 1.0, tolerance: float = 0.2) -> None:
        self._wp = [np.asarray(w, dtype=float) for w in waypoints]
        self._i = 0
        self._speed, self._max_turn, self._tol = speed, max_turn, tolerance

    def __call__(self, t: float, pose: Pose2D) -> Command:
        while self._i < len(self._wp) and math.hypot(*(self._wp[self._i] - (pose.x, pose.y))) < self._tol:
            self._i += 1
        if self._i >= len(self._wp):
            return Command()
        gx, gy = self._wp[self._i]
        err = float(wrap_angle(math.atan2(gy - pose.y, gx - pose.x) - pose.yaw))
        omega = float(np.clip(2.0 * err, -self._max_turn, self._max_turn))
        v = self._speed * max(0.0, math.cos(err)) ** 2  # slow down to turn
        return Command(v, omega)


class Odometer:
    """Wheel odometry: integrates the true motion with a drifting error.

    The error of each scan period's motion is ``trans_noise`` of the distance travelled
    (along and across) and ``rot_noise`` radians per radian turned (1σ), drawn afresh each
    ``noise_period`` seconds, so consecutive scans see the stated relative error.
    """

    def __init__(self, start: Pose2D, rng: np.random.Generator, trans_noise: float = 0.0,
                 rot_noise: float = 0.0, noise_period: float = 0.1) -> None:
        self.pose = start  # in the odometry frame, which starts at the true start pose
        self._rng, self._tn, self._rn, self._period = rng, trans_noise, rot_noise, noise_period
        self._next_draw = -math.inf
        self._scale = (1.0, 0.0, 1.0)

    def update(self, t: float, before: Pose2D, after: Pose2D) -> Pose2D:
        """Add the true motion from ``before`` to ``after`` (world poses) with drift."""
        if t >= self._next_draw:
            n = self._rng.normal(size=3)
            self._scale = (1.0 + self._tn * n[0], self._tn * n[1], 1.0 + self._rn * n[2])
            self._next_draw = t + self._period
        rel = before.between(after)  # motion in the base frame
        dist = math.hypot(rel.x, rel.y)
        noisy = Pose2D(rel.x * self._scale[0] + dist * self._scale[1] * (1 if rel.x >= 0 else -1),
                       rel.y * self._scale[0], rel.yaw * self._scale[2])
        self.pose = self.pose @ noisy
        return self.pose


class FollowDriver:
    """Follows a target at ``distance`` metres, given where the target is (world frame).

    ``target(t)`` returns the target's position or None when it is not known; the robot
    then stops. The simulator's scenarios give it the true position; the following demo
    gives it the tracker's estimate.

    Parameters
    ----------
    distance, max_speed, max_turn : float
        Metres kept to the target (along the way driven), m/s, rad/s.
    trail : bool
        Drive along the target's own path (breadcrumbs ``lookahead_m`` ahead) instead of
        straight at them, as a robot does that must not cut corners round a building.
    hold : (points, radius_m, seconds), optional
        Stop for ``seconds`` when the target comes within ``radius_m`` of one of ``points``
        (k, 2) — a safety stop — once per pass (it re-arms when they are 3 radii away).
    beside : (windows, offset_m), optional
        In the time windows [(t0, t1), …] (s) drive level with the target, ``offset_m`` to
        their right, instead of behind them.
    """

    def __init__(self, target: Callable[[float], "np.ndarray | None"], distance: float = 1.0,
                 max_speed: float = 1.2, max_turn: float = 1.5, trail: bool = False, hold=None, beside=None,
                 lookahead_m: float = 0.6) -> None:
        self._target, self._dist, self._vmax, self._wmax = target, distance, max_speed, max_turn
        self._trail_on, self._look = trail, lookahead_m
        self._trail: list[np.ndarray] = []
        self._hold = hold
        self._armed = np.ones(0 if hold is None else len(hold[0]), dtype=bool)
        self._hold_until = -math.inf
        self._beside = beside
        self._heading = 0.0

    def _steer(self, pose: Pose2D, aim: np.ndarray, gap: float, feed: float = 0.0) -> Command:
        err = float(wrap_angle(math.atan2(aim[1] - pose.y, aim[0] - pose.x) - pose.yaw))
        v = float(np.clip(feed + 0.8 * gap, 0.0, self._vmax)) * max(0.0, math.cos(err))
        return Command(v, float(np.clip(2.0 * err, -self._wmax, self._wmax)))

    def __call__(self, t: float, pose: Pose2D) -> Command:
        goal = self._target(t)
        if goal is None:
            return Command()
        goal = np.asarray(goal, dtype=float)
        before = self._target(t - 0.3)
        speed = 0.0
        if before is not None and np.hypot(*(goal - before)) > 0.03:
            self._heading = math.atan2(*(goal - before)[::-1])
            speed = float(np.hypot(*(goal - before))) / 0.3
        if self._trail_on and (not self._trail or np.hypot(*(goal - self._trail[-1])) >= 0.1):
            self._trail.append(goal)
        here = np.array([pose.x, pose.y])
        if self._hold is not None:
            points, radius, seconds = self._hold
            d = np.hypot(*(points - goal).T)
            trigger = self._armed & (d <= radius)
            if trigger.any():
                self._hold_until = t + seconds
            self._armed = (self._armed & ~trigger) | (d > 3.0 * radius)
        if t < self._hold_until:
            return Command()
        if self._beside is not None and any(t0 <= t < t1 for t0, t1 in self._beside[0]):
            u = np.array([math.cos(self._heading), math.sin(self._heading)])
            spot = goal + self._beside[1] * np.array([u[1], -u[0]])  # to their right
            self._trail = [goal] if self._trail_on else []
            return self._steer(pose, spot + u, float(np.dot(spot - here, u)), speed)
        if not self._trail_on:
            return self._steer(pose, goal, float(np.hypot(*(goal - here))) - self._dist)
        while len(self._trail) > 1 and np.hypot(*(self._trail[0] - here)) < self._look:
            self._trail.pop(0)
        path = np.vstack([here, *self._trail])
        along = float(np.hypot(*np.diff(path, axis=0).T).sum())
        return self._steer(pose, self._trail[0], along - self._dist)
