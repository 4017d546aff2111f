"""De-skew: put every beam where the sensor was when it fired.

A scanner sweeps its beams over tens of milliseconds (``time_increment`` apart); a robot
driving at 1.2 m/s moves 6 cm meanwhile, as much as the motion the detector looks for.
With the sensor pose at the first and at the last beam (odometry), each reading is moved
into the sensor frame at the scan stamp (the first beam's time) and the scan is resampled
onto its own beam grid, so every later stage still gets an ordinary :class:`Scan`.
"""

from __future__ import annotations

import numpy as np

from models.pose import Pose2D, wrap_angle
from models.scan import Scan


def sweep_duration(scan: Scan) -> float:
    """Seconds from the first to the last beam."""
    return max(scan.time_increment, 0.0) * (scan.n_beams - 1)


def deskew(scan: Scan, pose_first: Pose2D, pose_last: Pose2D) -> Scan:
    """The scan as if every beam had fired from the pose of the first one.

    Parameters
    ----------
    scan : Scan
    pose_first, pose_last : Pose2D
        Sensor pose in the fixed frame when the first and the last beam fired; poses in
        between are interpolated linearly (constant velocity over one sweep).

    Returns
    -------
    Scan
        Same beam grid, stamp and limits. Each reading goes to the beam nearest its new
        bearing (the nearest reading wins where two meet); a beam that saw nothing
        (``inf``, see :attr:`Scan.no_return`) stays ``inf`` unless a reading lands on it; any
        other beam left without one is ``nan``.
    """
    motion = pose_first.between(pose_last)  # the sweep's motion, in the first beam's frame
    if scan.n_beams < 2 or (abs(motion.x) < 1e-6 and abs(motion.y) < 1e-6 and abs(motion.yaw) < 1e-7):
        return scan
    n = scan.n_beams
    frac = np.arange(n) / (n - 1)
    # per-beam sensor pose relative to the first beam: linear in translation and heading
    yaw = frac * motion.yaw
    tx, ty = frac * motion.x, frac * motion.y
    valid = scan.valid
    r = scan.ranges[valid]
    a = scan.angles[valid] + yaw[valid]
    x = tx[valid] + r * np.cos(a)
    y = ty[valid] + r * np.sin(a)
    new_r = np.hypot(x, y)
    bearing = np.arctan2(y, x)
    idx = np.rint(wrap_angle(bearing - scan.angle_min) / scan.angle_increment).astype(np.int64)
    if scan.angle_increment < 0:
        idx = np.rint(-wrap_angle(scan.angle_min - bearing) / abs(scan.angle_increment)).astype(np.int64)
    keep = (idx >= 0) & (idx < n) & (new_r > scan.range_min) & (new_r < scan.range_max)
    out = np.where(scan.no_return, np.inf, np.nan)  # the sweep moves a line of sight by under a beam
    order = np.argsort(-new_r[keep])  # farthest first, so the nearest reading in a beam is written last
    out[idx[keep][order]] = new_r[keep][order]
    return Scan(out, scan.angle_min, scan.angle_increment, scan.range_min, scan.range_max, scan.stamp,
                scan.frame_id, scan.time_increment)
