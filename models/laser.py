"""The laser model of the simulator: geometry, timing and noise of a planar scanner."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from people_tracker.models.pose import Pose2D
from people_tracker.models.raycast import CircleMotion, cast_rays
from people_tracker.models.scan import Scan


@dataclass(frozen=True)
class LaserModel:
    """A planar laser scanner.

    Attributes
    ----------
    fov : float
        Field of view, radians, centred on the sensor's x axis.
    resolution : float
        Angle between beams, radians (> 0).
    rate_hz : float
        Scans per second.
    range_min, range_max : float
        Metres; readings outside are reported as ``range_max + 1`` (out of range).
    noise_std : float
        Standard deviation of the Gaussian range noise, metres.
    dropout : float
        Probability that a reading is lost, reported as ``dropout_value``.
    dropout_value : float
        ``nan`` or ``0.0``, as different drivers report a lost reading.
    spurious : float
        Probability that a reading is a spurious short one (sunlight, dust): a range drawn
        uniformly between ``range_min`` and what the beam would have hit.
    clockwise : bool
        Beams counted clockwise (negative ``angle_increment``).
    frame_id : str
        Name of the sensor frame.
    sweep_fraction : float
        Share of the scan period spent sweeping the beams (sets ``time_increment``):
        a spinning 270° scanner sweeps 270/360 of its period.
    """

    fov: float = math.radians(270.0)
    resolution: float = math.radians(0.35)
    rate_hz: float = 10.0
    range_min: float = 0.05
    range_max: float = 20.0
    noise_std: float = 0.01
    dropout: float = 0.0
    dropout_value: float = float("nan")
    spurious: float = 0.0
    clockwise: bool = False
    frame_id: str = "laser"
    sweep_fraction: float = 0.75

    @property
    def full_turn(self) -> bool:
        """The beams go all the way round: the last one is the first one's neighbour."""
        return self.fov >= 2.0 * math.pi - 1e-9

    @property
    def n_beams(self) -> int:
        if self.full_turn:
            return int(round(2.0 * math.pi / self.resolution))
        return int(round(self.fov / self.resolution)) + 1

    @property
    def angle_min(self) -> float:
        """Bearing of beam 0, radians (the right edge, or the left one when clockwise)."""
        return self.fov / 2.0 if self.clockwise else -self.fov / 2.0

    @property
    def angle_increment(self) -> float:
        step = 2.0 * math.pi / self.n_beams if self.full_turn else self.fov / (self.n_beams - 1)
        return -step if self.clockwise else step

    @property
    def period(self) -> float:
        return 1.0 / self.rate_hz

    @property
    def time_increment(self) -> float:
        return self.period * self.sweep_fraction / max(self.n_beams - 1, 1)

    def beam_angles(self) -> np.ndarray:
        return self.angle_min + np.arange(self.n_beams) * self.angle_increment

    def render(self, stamp: float, sensor_poses: list[Pose2D] | Pose2D, segments: np.ndarray,
               circles: np.ndarray, rng: np.random.Generator | None = None,
               moving: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[Scan, np.ndarray]:
        """Render one scan.

        Parameters
        ----------
        stamp : float
            Time of beam 0, seconds.
        sensor_poses : Pose2D, sequence of Pose2D, or ndarray of shape (n, 3)
            Sensor pose in the world frame; one pose, or one for each beam (a moving sensor
            fires each beam from where it is at that instant), as Pose2D or rows x, y, yaw.
        segments, circles : ndarray
            The scene in the world frame (see :func:`people_tracker.models.raycast.cast_rays`).
        rng : numpy.random.Generator, optional
            Source of noise and dropouts; without it the scan is noise-free.
        moving : (knot_times, knot_circles), optional
            Circles that move during the sweep (people): ``knot_circles`` (shape (K, k, 3),
            rows x, y, radius, world frame, metres) are where they are ``knot_times`` (shape
            (K,), increasing) seconds after beam 0, in a straight line in between. Each beam
            sees them where they are when it fires, as a real scanner sees a walker move on
            during its sweep. Their hit indices follow those of ``circles``.

        Returns
        -------
        scan : Scan
        hit : ndarray of int, shape (n,)
            What each beam hit (index into segments then circles; -1 nothing; a dropped
            or out-of-range reading still reports what the beam would have hit; a spurious
            one reports -1).
        """
        n = self.n_beams
        angles = self.beam_angles()
        if isinstance(sensor_poses, Pose2D):
            xs = np.full(n, sensor_poses.x)
            ys = np.full(n, sensor_poses.y)
            yaws = np.full(n, sensor_poses.yaw)
        else:
            arr = sensor_poses if isinstance(sensor_poses, np.ndarray) else \
                np.array([(p.x, p.y, p.yaw) for p in sensor_poses], dtype=float)
            xs, ys, yaws = arr[:, 0], arr[:, 1], arr[:, 2]
        heading = yaws + angles
        origins = np.column_stack([xs, ys])
        directions = np.column_stack([np.cos(heading), np.sin(heading)])
        motion = None
        if moving is not None and moving[1].shape[1]:
            knot_times, knot_circles = moving
            fixed = np.broadcast_to(circles[None, :, :2], (len(knot_times), len(circles), 2))
            motion = CircleMotion(np.arange(n) * max(self.time_increment, 0.0), np.asarray(knot_times, dtype=float),
                                  np.concatenate([fixed, knot_circles[:, :, :2]], axis=1))
            circles = np.vstack([circles, knot_circles[0]])
        dist, hit = cast_rays(origins, directions, segments, circles, self.range_max, motion)
        ranges = dist.copy()
        if rng is not None:
            finite = np.isfinite(ranges)
            ranges[finite] += rng.normal(0.0, self.noise_std, int(finite.sum())) if self.noise_std > 0 else 0.0
            if self.spurious > 0:
                fake = rng.random(n) < self.spurious
                far = np.minimum(np.nan_to_num(ranges[fake], posinf=self.range_max), self.range_max)
                ranges[fake] = rng.uniform(self.range_min, np.maximum(far, self.range_min))
                hit = np.where(fake, -1, hit)
            if self.dropout > 0:
                ranges[rng.random(n) < self.dropout] = self.dropout_value
        ranges[np.isfinite(ranges) & ((ranges >= self.range_max) | (ranges <= self.range_min))] = np.inf
        scan = Scan(ranges.astype(np.float32), self.angle_min, self.angle_increment, self.range_min,
                    self.range_max, stamp=stamp, frame_id=self.frame_id, time_increment=self.time_increment)
        return scan, hit
