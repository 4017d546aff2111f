"""Small synthetic recordings for the tests, written with the project's own BagWriter."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan
from people_tracker.tracker.io.bag_writer import BagWriter

MOUNT = Pose2D(0.30, -0.10, math.radians(30.0))  # base_link -> laser


def robot_pose(t: float) -> Pose2D:
    """odom -> base_link: an arc at 0.8 m/s turning 0.3 rad/s."""
    return Pose2D(0.8 * math.sin(0.3 * t) / 0.3, 0.8 * (1 - math.cos(0.3 * t)) / 0.3, 0.3 * t)


def make_scan(i: int, n: int = 360, stamp: float | None = None, ranges=None) -> Scan:
    rng = np.random.default_rng(i)
    r = rng.uniform(0.5, 9.0, n) if ranges is None else np.asarray(ranges, dtype=float)
    r[::37] = np.nan
    r[5::41] = 0.0
    r[7::43] = np.inf
    return Scan(r, -math.pi / 2, math.pi / (n - 1), 0.05, 10.0,
                stamp=10.0 + 0.1 * i if stamp is None else stamp, frame_id="laser", time_increment=1e-4)


def write_bag(path: Path, fmt: str = "mcap", n_scans: int = 30, odom: bool = True, tf: bool = True,
              scans=None, extra_scan_topic: str | None = None) -> list[Scan]:
    """Scans at 10 Hz from t=10 s; odometry at 50 Hz from t=9.9 s on /odom and /tf; mount on /tf_static."""
    scans = [make_scan(i) for i in range(n_scans)] if scans is None else scans
    t_end = max(s.stamp for s in scans) + 0.2
    with BagWriter(path, fmt) as w:
        if tf:
            w.write_tf(9.8, [("base_link", "laser", MOUNT)], static=True)
        events, bag_time = [], -math.inf
        for s in scans:  # recorded in list order, normally 10 ms after the stamp
            bag_time = max(s.stamp + 0.01, bag_time + 0.001)
            events.append((bag_time, "scan", s))
        if odom or tf:
            events += [(t + 0.002, "odom", t) for t in np.arange(9.9, t_end, 0.02)]
        for bag_time, kind, item in sorted(events, key=lambda e: e[0]):
            if kind == "scan":
                w.write_scan("/scan", item, bag_time=bag_time)
                if extra_scan_topic:
                    w.write_scan(extra_scan_topic, item, bag_time=bag_time)
            else:
                if odom:
                    w.write_odometry("/odom", item, "odom", "base_link", robot_pose(item), bag_time=bag_time)
                if tf:
                    w.write_tf(item, [("odom", "base_link", robot_pose(item))], bag_time=bag_time)
    return scans
