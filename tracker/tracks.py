"""One track per person: a filterpy Kalman filter with a constant-velocity model in the
world frame, and its lifecycle (tentative → confirmed → coasting → deleted)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import KalmanFilter

from people_tracker.detection.free_space import UNSEEN
from people_tracker.models.motion import H, constant_velocity_step, cv_predict, position_update
from people_tracker.tracker.existence import Existence


@dataclass(frozen=True)
class TrackParams:
    """Tunables of the track filter and lifecycle (units in the names).

    Attributes
    ----------
    accel_std_mps2 : float
        White-noise acceleration of a walking person, m/s² (process noise).
    init_speed_std_mps : float
        Uncertainty of a new track's velocity, m/s.
    max_position_std_m : float
        A track whose position uncertainty (1σ, largest axis) grows beyond this is deleted.
    confirm_min_travel_m : float
        A track born moving is confirmed only once it is this far from where it started:
        people walk, clutter that the detector flags now and then does not ...
    confirm_leg_probability : float
        ... or once the leg model's probability at its place, averaged, reaches this:
        someone a robot follows with nothing else in view (no odometry, no scan match)
        stays put in the sensor frame, their legs swinging.
    max_tentative_s : float
        A track still tentative after this long is deleted.
    still_after_s : float
        A track updated by static evidence alone for this long after its last moving
        update is a person standing still: its velocity is zero and its position drifts
        only by ``still_drift_mps``, s.
    still_drift_mps : float
        How fast a standing person's position may wander unseen (occluded), m/s (the
        standard deviation grows as this times the square root of the time, in seconds).
    min_person_separation_m : float
        Two people's torsos are never closer than this, metres: a track that comes this
        close to one standing still is that person twice, and the newcomer is deleted; and
        a person standing still takes a moving candidate only this close (setting off).
    same_person_after_s : float
        Two walking tracks closer than ``min_person_separation_m`` for this long, seconds,
        are one person twice (a track on each of their legs, or one that slid onto them from
        someone passing): the one whose place is less certain goes. Two people passing close
        come that near for a moment only. 0: never.
    unobserved_sensor_speed_mps, unobserved_sensor_turn_radps : float
        How far off the sensor's own motion may be, as speed (m/s) and turn rate (rad/s),
        while nothing measures it: no odometry, and scan matching failed (nothing in range
        to match). The world frame then moves with a predicted motion, and everything seen
        in it, the tracks' people included, may be off by as much: each such scan widens
        every track's position uncertainty by what the unmeasured motion can move it since
        its last update (see :meth:`TrackState.widen_for_sensor_motion`). 0 trusts the
        prediction.
    """

    accel_std_mps2: float = 1.5
    init_speed_std_mps: float = 1.0
    max_position_std_m: float = 1.0
    confirm_min_travel_m: float = 0.4
    confirm_leg_probability: float = 0.5
    max_tentative_s: float = 2.0
    still_after_s: float = 1.0
    still_drift_mps: float = 0.1
    min_person_separation_m: float = 0.35
    same_person_after_s: float = 1.0
    unobserved_sensor_speed_mps: float = 0.5
    unobserved_sensor_turn_radps: float = 0.5


@dataclass(frozen=True)
class Track:
    """A reported track at one scan (world frame, metres, m/s).

    ``status`` is ``tentative``, ``confirmed`` or ``coasting`` (confirmed, not updated by
    this scan); ``confidence`` is the probability that a person is there (see
    :mod:`people_tracker.tracker.existence`); ``target`` marks the followed person.
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
                 existence: Existence, standing: bool = False) -> None:
        self.track_id = track_id
        self.born_id = track_id  # its id when it began (another means it took someone's)
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
        self.set_off_at = -math.inf  # when a moving candidate last updated it while it stood still, s
        self.brisk_at = -math.inf  # when the tracker last saw it at association.stopping_speed_mps or faster, s
        self.velocity_since = stamp  # when its velocity was last forgotten (born, stood, turned), s
        self.moving_position = np.array([x, y])  # where the last moving candidate put it, m
        self.seen_position = np.array([x, y])  # where the last update of any kind put it, m
        self.hidden_position: np.ndarray | None = None  # the last predicted place found hidden since the last update, m
        self.seen_evidence = existence.l_dyn  # its existence evidence (log-odds) when last updated
        self.visibility = UNSEEN  # what this scan saw of its place (free_space's code; UNSEEN when updated)
        self.origin = np.array([x, y])
        self.recent_position = np.array([x, y])  # its position averaged over the last still_after_s, m
        self.existence = existence
        self.confirmed_at: float | None = None  # when it was confirmed, s (None: tentative)
        self.born_standing = standing
        self.moved = not standing  # has a moving candidate ever updated it
        self.update_kind: str | None = "static" if standing else "moving"  # how this scan updated it
        self.place: str | None = None  # PlaceMemory's verdict on where it stands still (None: not judged)
        # taken up where someone stood while their id was alive on another track: that id (None: not so)
        self.retaken_beside: int | None = None

    @property
    def position(self) -> np.ndarray:
        """Estimated position (x, y), world frame, metres."""
        return self.kf.x[::2]  # state order [x, vx, y, vy]

    @property
    def velocity(self) -> np.ndarray:
        """Estimated velocity (vx, vy), world frame, m/s."""
        return self.kf.x[1::2]

    @property
    def position_cov(self) -> np.ndarray:
        """Its 2x2 covariance, m²."""
        return self.kf.P[::2, ::2]

    @property
    def updated_now(self) -> bool:
        return self.update_kind is not None

    def predict(self, stamp: float) -> None:
        """Move the state to ``stamp`` (s): constant velocity, or standing still."""
        dt = stamp - self.stamp
        if dt > 0:
            if self.still:
                # a standing person: no velocity; the position wanders slowly
                self.kf.x[1] = self.kf.x[3] = 0.0
                self.forget_velocity()
                d = self.params.still_drift_mps ** 2 * dt
                self.kf.P[0, 0] += d
                self.kf.P[2, 2] += d
            else:
                step, Q = constant_velocity_step(dt, self.params.accel_std_mps2 ** 2)
                # x = F x ;  P = F P Fᵀ + Q
                self.kf.x, self.kf.P = cv_predict(self.kf.x, self.kf.P, step, Q)
            self.stamp = stamp
        self.update_kind = None

    def widen_for_sensor_motion(self, sensor_xy: np.ndarray, dt: float) -> None:
        """Widen the position uncertainty for a sensor motion nobody measured over the last
        ``dt`` seconds (the sensor at ``sensor_xy`` in the world frame, m): its speed may be
        off by ``unobserved_sensor_speed_mps`` and its turn rate by
        ``unobserved_sensor_turn_radps``, which moves a place ``r`` metres away across the
        beam by ``r`` times the turn. Since the track's last update the error grows with the
        time ``T`` (an unmeasured motion persists from scan to scan): this scan adds
        ``σ²·(T² − (T − dt)²)``, so that after ``T`` seconds the total is ``σ²·T²`` at any
        scan rate."""
        p = self.params
        if dt <= 0 or (p.unobserved_sensor_speed_mps <= 0 and p.unobserved_sensor_turn_radps <= 0):
            return
        since = max(self.stamp - self.last_update, dt)
        grow = since * since - (since - dt) ** 2
        d = self.position - np.asarray(sensor_xy, dtype=float)
        r = float(np.hypot(d[0], d[1]))
        across = np.array([-d[1], d[0]]) / r if r > 1e-9 else np.zeros(2)
        cov = grow * (p.unobserved_sensor_speed_mps ** 2 * np.eye(2)
                      + (r * p.unobserved_sensor_turn_radps) ** 2 * np.outer(across, across))
        self.kf.P[0::2, 0::2] += cov

    def forget_velocity(self) -> None:
        """Reset the velocity's uncertainty to a new track's (after a sharp turn)."""
        v = self.params.init_speed_std_mps ** 2
        self.velocity_since = self.stamp
        for i in (1, 3):
            self.kf.P[i, :] = 0.0
            self.kf.P[:, i] = 0.0
            self.kf.P[i, i] = v

    def update(self, z: np.ndarray, R: np.ndarray, moving: bool) -> None:
        """Correct with a candidate position ``z`` (m) of covariance ``R`` (m²)."""
        # y = z - H x ; S = H P Hᵀ + R ; K = P Hᵀ S⁻¹ ; x = x + K y ; P = (I - K H) P (I - K H)ᵀ + K R Kᵀ
        stood = self.still  # before this update: a walker unseen for a while has not stood
        self.kf.x, self.kf.P = position_update(self.kf.x, self.kf.P, np.asarray(z, dtype=float),
                                               np.asarray(R, dtype=float))
        self.last_update = self.stamp
        self.seen_position = self.position.copy()
        self.hidden_position = None
        self.seen_evidence = self.existence.l_dyn
        if moving:
            if stood:
                self.set_off_at = self.stamp
            self.moved = True
            self.last_moving_update = self.stamp
            self.moving_position = self.position.copy()
            self.update_kind = "moving"
            self.place = None
        elif self.update_kind is None:
            self.update_kind = "static"

    def hidden_stretch(self, step_m: float) -> np.ndarray | None:
        """Places along the hidden stretch of its path (world frame, m, shape (k, 2)), from
        where its last update put it to the last predicted place found hidden since, both
        ends included, at most ``step_m`` apart: where someone who stopped out of sight may
        stand. None when no prediction was found hidden."""
        if self.hidden_position is None:
            return None
        run = self.hidden_position - self.seen_position
        n = int(np.ceil(np.hypot(*run) / step_m)) + 1 if step_m > 0 else 2
        return self.seen_position + np.linspace(0.0, 1.0, max(n, 2))[:, None] * run

    @property
    def still(self) -> bool:
        """Seen standing still: never moved, or updated by static evidence alone (leg pairs,
        static support) for ``still_after_s`` since its last moving update. Someone who
        walks out of sight is not standing still: they keep their velocity."""
        return not self.moved or self.last_update - self.last_moving_update >= self.params.still_after_s

    def weigh(self, visibility: int, leg_probability: float | None) -> None:
        """Book this scan's evidence of existence (``visibility``: what the scan saw of its
        place, kept as :attr:`visibility`); confirm when it is strong enough."""
        self.visibility = visibility
        # the existence's stamp is the last scan weighed
        a = 1.0 - math.exp(-(self.stamp - self.existence.stamp) / max(self.params.still_after_s, 1e-6))
        self.recent_position += a * (self.position - self.recent_position)
        self.existence.update(self.stamp, self.update_kind, visibility, leg_probability,
                              self.still and self.place == "occupied", walking=self.moved and not self.still,
                              stale=self.stale)
        if (not self.confirmed and self.existence.probability >= self.existence.params.confirm
                and (self.born_standing or
                     np.hypot(*(self.position - self.origin)) >= self.params.confirm_min_travel_m or
                     self.existence.shape_p >= self.params.confirm_leg_probability)):
            self.confirmed = True

    @property
    def confirmed(self) -> bool:
        """Confirmed as a person (reported while likely enough); setting it records when."""
        return self.confirmed_at is not None

    @confirmed.setter
    def confirmed(self, value: bool) -> None:
        if not value:
            self.confirmed_at = None
        elif self.confirmed_at is None:
            self.confirmed_at = self.stamp

    @property
    def stale(self) -> bool:
        """No update for longer than ``existence.report_unseen_s``: kept, but not reported."""
        return self.stamp - self.last_update > self.existence.params.report_unseen_s

    @property
    def reported(self) -> bool:
        """Confirmed, likely enough, and seen lately enough to be reported."""
        return self.confirmed and self.existence.probability >= self.existence.params.keep and not self.stale

    def dead(self) -> bool:
        """Whether this track ends now: unlikely, lost, or tentative too long."""
        return self.end_reason() is not None

    def end_reason(self) -> str | None:
        """Which rule ends this track now (None: none does): ``absence``, ``existence``,
        ``tentative`` or ``uncertainty`` (see :meth:`dead`)."""
        p, e = self.params, self.existence
        # the evidence of absence alone ends any track, whatever its shape; the shape too
        # ends a confirmed one (a tentative track's shape is not known well yet)
        if e.l_dyn <= e.l_delete:
            return "absence"
        if self.confirmed and e.probability < e.params.delete:
            return "existence"
        if not self.confirmed and self.stamp - self.born > p.max_tentative_s:
            return "tentative"
        (a, b), (_, c) = self.position_cov
        # largest eigenvalue of the 2x2 covariance [[a, b], [b, c]]
        largest = 0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)
        return "uncertainty" if math.sqrt(max(largest, 0.0)) > p.max_position_std_m else None

    def furniture(self) -> bool:
        """Born standing, never moved, its place never seen empty, never confirmed: not a person."""
        return self.born_standing and not self.moved and not self.confirmed and \
            not self.existence.walked_or_arrived

    def report(self, target: bool = False, seen_after_s: float = 0.0) -> Track:
        """The track as reported at its stamp. The laser saw its place ``seen_after_s``
        seconds after the stamp (its beams fire later in the sweep), and the filter follows
        the person as seen: a walker is reported their velocity times that short of it."""
        x, vx, y, vy = (float(v) for v in self.kf.x)
        if seen_after_s > 0.0 and not self.still:
            x, y = x - vx * seen_after_s, y - vy * seen_after_s
        cov = self.position_cov
        status = "tentative" if not self.confirmed else ("confirmed" if self.updated_now else "coasting")
        return Track(self.track_id, x, y, vx, vy, ((float(cov[0, 0]), float(cov[0, 1])), (float(cov[1, 0]), float(cov[1, 1]))),
                     status, self.existence.confidence, self.stamp - self.born, target)
