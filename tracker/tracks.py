"""One track per person: a filterpy Kalman filter with a constant-velocity model in the
world frame, and its lifecycle (tentative → confirmed → coasting → deleted)."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import KalmanFilter

from people_tracker.models.motion import H, constant_velocity_FQ


@dataclass(frozen=True)
class TrackParams:
    """Tunables of the track filter and lifecycle (units in the names).

    Attributes
    ----------
    accel_std_mps2 : float
        White-noise acceleration of a walking person, m/s² (process noise).
    init_speed_std_mps : float
        Uncertainty of a new track's velocity, m/s.
    confirm_hits, confirm_window : int
        A tentative track is confirmed after ``confirm_hits`` updates within its last
        ``confirm_window`` scans, and deleted when it can no longer reach that.
    max_coast_s : float
        A confirmed track with no update for this long is deleted.
    max_static_s : float
        A track kept only by static support (a paused person) for this long is deleted.
    max_position_std_m : float
        A track whose position uncertainty (1σ, largest axis) grows beyond this is deleted.
    confirm_min_travel_m : float
        A tentative track is confirmed only once it is this far from where it started:
        people walk, clutter that the detector flags now and then does not.
    max_tentative_s : float
        A track still tentative after this long is deleted.
    """

    accel_std_mps2: float = 1.5
    init_speed_std_mps: float = 1.0
    confirm_hits: int = 3
    confirm_window: int = 5
    max_coast_s: float = 1.5
    max_static_s: float = 10.0
    max_position_std_m: float = 1.0
    confirm_min_travel_m: float = 0.4
    max_tentative_s: float = 2.0


@dataclass(frozen=True)
class Track:
    """A reported track at one scan (world frame, metres, m/s).

    ``status`` is ``tentative``, ``confirmed`` or ``coasting`` (confirmed, not updated by
    this scan); ``confidence`` in [0, 1]; ``target`` marks the followed person.
    """

    track_id: int
    x: float
    y: float
    vx: float
    vy: float
    position_cov: tuple[tuple[float, float], tuple[float, float]]
    status: str
    confidence: float
    age_s: float
    target: bool = False


class TrackState:
    """The mutable state of one track (internal to the tracker)."""

    def __init__(self, track_id: int, x: float, y: float, R: np.ndarray, stamp: float, params: TrackParams,
                 standing: bool = False) -> None:
        self.track_id = track_id
        self.params = params
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.x = np.array([x, 0.0, y, 0.0])
        kf.P = np.diag([R[0, 0], params.init_speed_std_mps ** 2, R[1, 1], params.init_speed_std_mps ** 2])
        kf.H = H.copy()
        self.kf = kf
        self.stamp = stamp  # time of the state, s
        self.born = stamp
        self.last_update = stamp
        self.last_moving_update = stamp
        self.moving_position = np.array([x, y])  # where the last moving candidate put it, m
        self.hits: deque[bool] = deque([True], maxlen=params.confirm_window)
        self.origin = np.array([x, y])
        # a standing person is confirmed by the persistence of their legs (see tracker.standing)
        self.confirmed = standing or (params.confirm_hits <= 1 and params.confirm_min_travel_m <= 0)
        self.born_standing = standing
        self.moved = not standing  # has a moving candidate ever updated it
        self.updated_now = True

    @property
    def position(self) -> np.ndarray:
        """Estimated position (x, y), world frame, metres."""
        return self.kf.x[::2]  # state order [x, vx, y, vy]

    @property
    def position_cov(self) -> np.ndarray:
        """Its 2x2 covariance, m²."""
        return self.kf.P[::2, ::2]

    def predict(self, stamp: float) -> None:
        """Move the state to ``stamp`` (s) with the constant-velocity model."""
        dt = stamp - self.stamp
        if dt > 0:
            F, Q = constant_velocity_FQ(dt, self.params.accel_std_mps2 ** 2)
            # x = F x ;  P = F P Fᵀ + Q
            self.kf.predict(F=F, Q=Q)
            self.stamp = stamp
        self.updated_now = False

    def forget_velocity(self) -> None:
        """Reset the velocity's uncertainty to a new track's (after a sharp turn)."""
        v = self.params.init_speed_std_mps ** 2
        for i in (1, 3):
            self.kf.P[i, :] = 0.0
            self.kf.P[:, i] = 0.0
            self.kf.P[i, i] = v

    def update(self, z: np.ndarray, R: np.ndarray, moving: bool) -> None:
        """Correct with a candidate position ``z`` (m) of covariance ``R`` (m²)."""
        # y = z - H x ; S = H P Hᵀ + R ; K = P Hᵀ S⁻¹ ; x = x + K y ; P = (I - K H) P
        self.kf.update(z, R=R)
        self.last_update = self.stamp
        if moving:
            self.moved = True
            self.last_moving_update = self.stamp
            self.moving_position = self.position.copy()
        self.updated_now = True

    def record(self, hit: bool) -> None:
        """Book one scan's outcome; confirm when enough hits fall in the window."""
        self.hits.append(hit)
        if (not self.confirmed and sum(self.hits) >= self.params.confirm_hits
                and np.hypot(*(self.position - self.origin)) >= self.params.confirm_min_travel_m):
            self.confirmed = True

    def dead(self) -> bool:
        """Whether the lifecycle rules delete this track now."""
        p = self.params
        if not self.confirmed:
            # too few updates in its window, or it has not gone anywhere in time
            return (len(self.hits) == p.confirm_window and sum(self.hits) < p.confirm_hits) or \
                self.stamp - self.born > p.max_tentative_s
        if self.stamp - self.last_update > p.max_coast_s:
            return True
        if self.stamp - self.last_moving_update > p.max_static_s:
            return True
        (a, b), (_, c) = self.position_cov
        # largest eigenvalue of the 2x2 covariance [[a, b], [b, c]]
        largest = 0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)
        return math.sqrt(max(largest, 0.0)) > p.max_position_std_m

    @property
    def held_still(self) -> bool:
        """Kept in place by static evidence (standing, paused) since its last moving update."""
        return not self.moved or self.last_update > self.last_moving_update

    def furniture(self) -> bool:
        """Born standing, never moved, and ended by ``max_static_s``: not a person."""
        return self.born_standing and not self.moved and self.stamp - self.born > self.params.max_static_s

    def confidence(self) -> float:
        """Share of recent scans with an update, faded by the time since the last one."""
        share = sum(self.hits) / self.params.confirm_window
        return float(min(1.0, share) * math.exp(-(self.stamp - self.last_update) / self.params.max_coast_s))

    def report(self, target: bool = False) -> Track:
        x, vx, y, vy = (float(v) for v in self.kf.x)
        cov = self.position_cov
        status = "tentative" if not self.confirmed else ("confirmed" if self.updated_now else "coasting")
        return Track(self.track_id, x, y, vx, vy, ((float(cov[0, 0]), float(cov[0, 1])), (float(cov[1, 0]), float(cov[1, 1]))),
                     status, self.confidence(), self.stamp - self.born, target)
