"""Alignment of each scan with the previous one: the sensor pose in the world frame.

:class:`ScanAligner` chains scan-to-scan matches. Its prior for each match is the
odometry's relative motion when the recording has odometry, and otherwise a
constant-velocity prediction from the last matched motion. The scan is de-skewed first
(the odometry's motion over the sweep, or the predicted one). Readings near people the
tracker follows are left out of matching (they move). When matching fails the prior is
kept, and the result says so; without odometry the prediction then fades to rest
(``AlignParams.fade_s``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from people_tracker.detection.deskew import deskew, sweep_duration
from people_tracker.detection.icp import IcpParams, MatchResult, ReferenceScan, match
from people_tracker.detection.kdtree import PointTree
from people_tracker.models.pose import Pose2D, interpolate_pose, near_any
from people_tracker.models.scan import Scan


@dataclass(frozen=True)
class AlignParams:
    """Attributes
    ----------
    enabled : bool
        Match scans (otherwise the odometry pose, or none, is used as it is).
    exclude_radius_m : float
        Readings this close to a tracked person are left out of matching.
    icp : IcpParams
    fade_s : float
        Without odometry, while matching fails (nothing in range to match), the predicted
        motion fades to rest with this time constant, seconds. The sensor's motion is not
        observed then: kept at the last matched speed, a robot that stops (behind its
        person, say) would have the world frame run on without end, and everything it sees,
        a person standing in front of it included, walk away in that frame; fading bounds
        that error to the speed times ``fade_s``. 0: the last matched motion goes on unchanged.
    """

    enabled: bool = True
    exclude_radius_m: float = 0.5
    icp: IcpParams = IcpParams()
    fade_s: float = 0.5


@dataclass(frozen=True, eq=False)
class Alignment:
    """One scan's alignment.

    Attributes
    ----------
    scan : Scan
        The scan de-skewed to its first beam's pose.
    pose : Pose2D
        Sensor pose (first beam) in the world frame: the odometry frame corrected by scan
        matching, or the first scan's pose when there is no odometry.
    match : MatchResult or None
        The scan-to-scan match (None for the first scan or with matching disabled).
    prior : str
        ``odometry`` or ``prediction``.
    tree : PointTree or None
        KD-tree of the de-skewed scan's valid readings (sensor frame), for the detector.
    """

    scan: Scan
    pose: Pose2D
    match: MatchResult | None
    prior: str
    tree: PointTree | None = None


def _scale_motion(motion: Pose2D, fraction: float) -> Pose2D:
    return interpolate_pose(Pose2D(), motion, fraction)


class ScanAligner:
    """Keeps the previous scan and pose and aligns each new scan to it."""

    def __init__(self, params: AlignParams | None = None) -> None:
        self.params = params or AlignParams()
        self.reset()

    def reset(self) -> None:
        """Start afresh (after a stamp jump); the world pose continues from where it was."""
        self._ref: ReferenceScan | None = None
        self._prev_stamp: float | None = None
        self._prev_odom: Pose2D | None = None
        self._velocity: tuple[Pose2D, float] | None = None  # last matched motion and its duration
        self._world = getattr(self, "_world", Pose2D())

    def exclude_from_reference(self, mask: np.ndarray) -> None:
        """Leave these readings of the scan just aligned (its valid readings, in order) out
        of the next match: leg-shaped ones, say, that may walk with the robot (a person it
        follows stays put in the sensor frame, and would hold the match at no motion)."""
        ref = self._ref
        if ref is not None and len(mask) == len(ref.points) and mask.any():
            ref.exclude(mask)

    def _exclusion(self, points: np.ndarray, rel: Pose2D, people_world: np.ndarray | None) -> np.ndarray | None:
        """Readings near the people, whose world positions are placed with the guess ``rel``."""
        if people_world is None or not len(people_world) or not len(points):
            return None
        local = (self._world @ rel).inverse().transform_points(np.asarray(people_world, dtype=float))
        return near_any(points, local, self.params.exclude_radius_m)

    def align(self, scan: Scan, odom: Pose2D | None = None, odom_last_beam: Pose2D | None = None,
              people_world: np.ndarray | None = None) -> Alignment:
        """Align ``scan``.

        Parameters
        ----------
        scan : Scan
        odom, odom_last_beam : Pose2D, optional
            Sensor pose from odometry at the first and the last beam.
        people_world : ndarray, shape (k, 2), optional
            Where tracked people are expected now, world frame, metres.
        """
        p = self.params
        dt = None if self._prev_stamp is None else scan.stamp - self._prev_stamp
        # the prior: odometry's relative motion, or the last motion scaled to this interval
        if odom is not None and self._prev_odom is not None:
            prior, kind = self._prev_odom.between(odom), "odometry"
        elif self._velocity is not None and dt is not None and dt > 0:
            motion, span = self._velocity
            prior, kind = _scale_motion(motion, dt / span), "prediction"
        else:
            prior, kind = Pose2D(), "odometry" if odom is not None else "prediction"
        # de-skew: the sweep's motion from odometry, or predicted
        raw = scan
        sweep = sweep_duration(scan)
        with_odometry = odom is not None and odom_last_beam is not None
        if with_odometry:
            scan = deskew(raw, odom, odom_last_beam)
        elif self._velocity is not None and sweep > 0:
            motion, span = self._velocity
            scan = deskew(raw, Pose2D(), _scale_motion(motion, sweep / span))
        result = None
        rel = prior
        points = scan.valid_points
        if p.enabled and self._ref is not None:
            result = match(points, self._ref, prior, p.icp, self._exclusion(points, prior, people_world))
            rel = result.pose
            # without odometry a wrong prediction also skewed the scan: de-skew with the
            # matched motion and match once more when the two disagree
            miss = prior.between(rel)
            if (not with_odometry and result.ok and sweep > 0 and dt
                    and (abs(miss.yaw) > 0.005 or np.hypot(miss.x, miss.y) > 0.01)):
                scan = deskew(raw, Pose2D(), _scale_motion(rel, sweep / dt))
                points = scan.valid_points
                again = match(points, self._ref, rel, p.icp, self._exclusion(points, rel, people_world))
                if again.ok:
                    result, rel = again, again.pose
        if self._prev_stamp is None:
            self._world = odom if odom is not None else Pose2D()
        elif p.enabled or odom is None:
            self._world = self._world @ rel
        else:
            self._world = odom
        if dt is not None and dt > 0 and (result is None or result.ok or kind == "odometry"):
            self._velocity = (rel, dt)
        elif dt is not None and dt > 0 and self._velocity is not None and p.fade_s > 0:
            motion, span = self._velocity  # not observed: fading to rest
            self._velocity = (_scale_motion(motion, math.exp(-dt / p.fade_s)), span)
        tree = PointTree(points)
        self._ref = ReferenceScan(points, p.icp, tree) if p.enabled else None
        self._prev_stamp, self._prev_odom = scan.stamp, odom
        return Alignment(scan, self._world, result, kind, tree)
