"""The simulator: walking people, a static world, a robot and its laser, with ground truth.

Driven through :meth:`Simulation.step`, which advances one scan period and returns the
scan, the odometry since the previous step and the truth. A closed loop passes a
controller's command into ``step``; ``models`` never imports ``tracker``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from people_tracker.models.laser import LaserModel
from people_tracker.models.person import Walker
from people_tracker.models.pose import Pose2D
from people_tracker.models.robot import Command, Odometer, integrate, integrate_many
from people_tracker.models.scan import Scan
from people_tracker.models.world import World

VISIBLE_MIN_POINTS = 3  # Leigh et al.: a person is visible with 3 points ...
VISIBLE_SPACING_M = 0.13  # ... in one cluster at 0.13 m spacing
PEOPLE_KNOT_S = 0.05
"""Seconds (at most) between the instants of a sweep at which the people's legs are placed
exactly; each beam sees them on the straight line between two. A leg's path turns only when
a step lands, and a straight line over T seconds strays at most v T / 4 from it then: 3 cm
for a leg swinging at 2.4 m/s (where the simulator held people still for the whole sweep,
a swinging leg was seen up to 0.24 m from where it was at its beam's time)."""


@dataclass(frozen=True, eq=False)
class Truth:
    """What really happened at one scan.

    Attributes
    ----------
    robot_pose, sensor_pose : Pose2D
        True base and sensor poses in the world frame at the scan stamp.
    person_id : ndarray of int, shape (p,)
        People in the scene.
    torso_world, torso_sensor : ndarray, shape (p, 2)
        Their torso positions in the world and the sensor frame, metres.
    visible : ndarray of bool, shape (p,)
        Visible by Leigh's rule: at least 3 of their readings form one cluster at 0.13 m spacing.
    beam_person : ndarray of int, shape (n,)
        Person id that each beam hit, -1 where it hit something else or nothing.
    """

    stamp: float
    robot_pose: Pose2D
    sensor_pose: Pose2D
    person_id: np.ndarray
    torso_world: np.ndarray
    torso_sensor: np.ndarray
    visible: np.ndarray
    beam_person: np.ndarray


@dataclass(frozen=True)
class OdometrySample:
    """Odometry at one instant: base pose in the odometry frame, velocity in the base frame."""

    stamp: float
    pose: Pose2D
    v: float
    omega: float


@dataclass(frozen=True, eq=False)
class SimStep:
    """One scan period: the scan, the odometry base pose at its stamp (odometry frame),
    the odometry samples published during the period, and the truth."""

    scan: Scan
    odom_pose: Pose2D
    odometry: list[OdometrySample]
    truth: Truth
    odom_pose_last_beam: Pose2D | None = None  # odometry base pose when the last beam fired


def visible_people(scan: Scan, beam_person: np.ndarray) -> set[int]:
    """Ids of the people with at least 3 valid readings in one cluster at 0.13 m spacing."""
    out: set[int] = set()
    pts = scan.points
    ok = scan.valid & (beam_person >= 0)
    for pid in np.unique(beam_person[ok]):
        idx = np.flatnonzero(ok & (beam_person == pid))
        p = pts[idx]
        gaps = np.hypot(*np.diff(p, axis=0).T) > VISIBLE_SPACING_M
        # cluster sizes: runs between gaps
        bounds = np.concatenate([[0], np.flatnonzero(gaps) + 1, [len(idx)]])
        if np.diff(bounds).max() >= VISIBLE_MIN_POINTS:
            out.add(int(pid))
    return out


@dataclass
class Simulation:
    """A running simulated scene.

    Parameters
    ----------
    laser : LaserModel
    world : World
    walkers : list of Walker
    mount : Pose2D
        base_T_laser.
    start : Pose2D
        Robot base pose in the world at t = 0.
    driver : callable (t, pose) -> Command, optional
        The robot's own motion (None: it stands still unless ``step`` gets a command).
    rng : numpy.random.Generator
    odom_trans_noise, odom_rot_noise : float
        Odometry drift, fraction of distance and radians per radian (1σ per scan period).
    odom_rate_hz : float
        Odometry messages per second.
    t0 : float
        Stamp of the first scan, seconds.
    has_odometry : bool
        Whether a recording of the scene carries the odometry (the robot has it either way).
    target_id : int or None
        The person the robot follows, if it follows one.
    people_walk_in_sweep : bool
        People walk on during a sweep, each beam seeing them where they are when it fires
        (False: held where they are at the first beam, so that lasers of opposite beam order
        see the same people).
    """

    laser: LaserModel
    world: World
    walkers: list[Walker]
    rng: np.random.Generator
    mount: Pose2D = field(default_factory=Pose2D)
    start: Pose2D = field(default_factory=Pose2D)
    driver: Callable[[float, Pose2D], Command] | None = None
    odom_trans_noise: float = 0.0
    odom_rot_noise: float = 0.0
    odom_rate_hz: float = 50.0
    t0: float = 1000.0
    physics_hz: float = 200.0
    has_odometry: bool = True
    target_id: int | None = None
    people_walk_in_sweep: bool = True

    def __post_init__(self) -> None:
        self.index = 0
        self.time = 0.0  # scenario time of the next scan
        self.robot = self.start
        self._odometer = Odometer(Pose2D(), self.rng, self.odom_trans_noise, self.odom_rot_noise,
                                  self.laser.period)
        self._odom_origin = self.start
        self._last_cmd = Command()
        self._next_odom = 0.0

    @staticmethod
    def _people_knots(present: list[Walker], t: float, knot_times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The circles of the people ``present`` at ``t + knot_times`` (shape (K, k, 3), world
        frame) and each circle's person id (shape (k,)).

        A walker's legs keep their rows from knot to knot (:meth:`Walker.circles` lists the
        stance leg first, and the legs trade places when a step lands)."""
        if not present:
            return np.zeros((len(knot_times), 0, 3)), np.zeros(0, dtype=np.int64)
        parts = []
        for w in present:
            rows = [w.circles(t + float(dt)) for dt in knot_times]
            for a in range(1, len(rows)):
                prev, cur = rows[a - 1][:, :2], rows[a][:, :2]
                if len(cur) == 2 and (np.hypot(*(prev - cur[::-1]).T).sum() < np.hypot(*(prev - cur).T).sum()):
                    rows[a] = rows[a][::-1]
            parts.append(np.stack(rows))
        owner = np.concatenate([np.full(p.shape[1], w.person_id, dtype=np.int64) for p, w in zip(parts, present)])
        return np.concatenate(parts, axis=1), owner

    def step(self, command: Command | None = None) -> SimStep:
        """Render the scan at the current time, then advance the robot one scan period.

        ``command`` overrides the scenario's driver for this period (a closed loop).
        """
        t = self.time
        laser = self.laser
        stamp = self.t0 + t
        sweep = laser.time_increment * (laser.n_beams - 1)
        # the robot's path through this period; each beam fires from where it is on that path
        path = self._path(command, sweep)
        beam_poses = self._beam_poses(path, t + np.arange(laser.n_beams) * laser.time_increment)
        present = [w for w in self.walkers if w.present(t)]
        # people walk on during the sweep, as the robot does: each beam sees them where they
        # are when it fires; the truth is where they are at the stamp (the first beam)
        knot_times = np.linspace(0.0, sweep, max(2, math.ceil(sweep / PEOPLE_KNOT_S) + 1)) \
            if self.people_walk_in_sweep else np.zeros(1)
        knots, owner = self._people_knots(present, t, knot_times)
        scan, hit = laser.render(stamp, beam_poses, self.world.segments, self.world.circles, self.rng,
                                 (knot_times, knots))
        n_static = len(self.world.segments) + len(self.world.circles)
        beam_person = np.full(laser.n_beams, -1, dtype=np.int64)
        on_person = hit >= n_static
        beam_person[on_person] = owner[hit[on_person] - n_static]
        sensor = self.robot @ self.mount
        ids = np.array([w.person_id for w in present], dtype=np.int64)
        torso = np.array([w.torso(t) for w in present]).reshape(-1, 2)
        torso_sensor = sensor.inverse().transform_points(torso) if len(torso) else torso
        seen = visible_people(scan, beam_person)
        truth = Truth(stamp, self.robot, sensor, ids, torso, torso_sensor,
                      np.array([i in seen for i in ids], dtype=bool), beam_person)
        odom_pose = self._odometer.pose
        odometry = [self.odometry_now()] if self.index == 0 else []
        odometry += self._advance(path, t + sweep)
        self.index += 1
        return SimStep(scan, odom_pose, odometry, truth, self._odom_sweep_end)

    def _path(self, command: Command | None, sweep: float) -> list[tuple[float, float, Pose2D, Command, Pose2D]]:
        """The robot's motion through one scan period, in physics steps.

        Each step is (start time, duration, start pose, command, end pose); the driver is
        asked afresh at every step unless ``command`` (a closed loop) holds for the period.
        A step ends exactly at ``sweep`` seconds in (the last beam).
        """
        dt = 1.0 / self.physics_hz
        t = self.time
        end = t + self.laser.period
        sweep_end = t + sweep
        pose = self.robot
        cmd = command if command is not None else Command()
        steps = []
        while t < end - 1e-12:
            h = min(dt, end - t)
            if t < sweep_end < t + h:
                h = sweep_end - t  # land exactly on the last beam's time
            if command is None and self.driver is not None:
                cmd = self.driver(t, pose)
            new = integrate(pose, cmd, h)
            steps.append((t, h, pose, cmd, new))
            pose, t = new, t + h
        return steps

    def _beam_poses(self, path, times: np.ndarray) -> Pose2D | np.ndarray:
        """Sensor pose (x, y, yaw rows, world frame) at each of ``times`` along ``path``; one
        Pose2D when the robot stands still."""
        if all(abs(cmd.v) == 0 and abs(cmd.omega) == 0 for _, _, _, cmd, _ in path):
            return self.robot @ self.mount
        base = np.empty((len(times), 3))
        step_of = np.clip(np.searchsorted([t0 for t0, *_ in path], times, side="right") - 1, 0, len(path) - 1)
        for k in np.unique(step_of):
            t0, _, pose, cmd, _ = path[k]
            sel = step_of == k
            base[sel] = integrate_many(pose, cmd, times[sel] - t0)
        c, s_ = np.cos(base[:, 2]), np.sin(base[:, 2])
        m = self.mount
        return np.column_stack([base[:, 0] + c * m.x - s_ * m.y, base[:, 1] + s_ * m.x + c * m.y, base[:, 2] + m.yaw])

    def _advance(self, path, sweep_end: float) -> list[OdometrySample]:
        """Move the robot along ``path`` (one scan period); odometry samples on the way.

        Also notes the odometry pose at ``sweep_end`` (the last beam's time).
        """
        self._odom_sweep_end = self._odometer.pose
        samples = []
        for t, h, pose, cmd, new in path:
            odom_pose = self._odometer.update(t, pose, new)
            self.robot = new
            t += h
            if abs(t - sweep_end) < 1e-9:
                self._odom_sweep_end = odom_pose
            if t >= self._next_odom - 1e-9:
                samples.append(OdometrySample(self.t0 + t, odom_pose, cmd.v, cmd.omega))
                self._next_odom += 1.0 / self.odom_rate_hz
        self.time = self.time + self.laser.period
        return samples

    def odometry_now(self) -> OdometrySample:
        """The odometry pose at the current time (before any motion: the start)."""
        return OdometrySample(self.t0 + self.time, self._odometer.pose, 0.0, 0.0)
