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
    """

    def __init__(self, target: Callable[[float], "np.ndarray | None"], distance: float = 1.0,
                 max_speed: float = 1.2, max_turn: float = 1.5) -> None:
        self._target, self._dist, self._vmax, self._wmax = target, distance, max_speed, max_turn

    def __call__(self, t: float, pose: Pose2D) -> Command:
        goal = self._target(t)
        if goal is None:
            return Command()
        dx, dy = goal[0] - pose.x, goal[1] - pose.y
        err = float(wrap_angle(math.atan2(dy, dx) - pose.yaw))
        gap = math.hypot(dx, dy) - self._dist
        v = float(np.clip(0.8 * gap, 0.0, self._vmax)) * max(0.0, math.cos(err))
        return Command(v, float(np.clip(2.0 * err, -self._wmax, self._wmax)))
