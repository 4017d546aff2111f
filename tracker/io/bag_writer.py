"""Writing recordings: LaserScan, Odometry and TF messages to a ROS 1 bag or a ROS 2 bag.

Used by ``people-tracker simulate`` (ROS 2, MCAP storage) and by the tests. Messages are
built from the standard type definitions that ship with rosbags, so any ROS tool reads the
result.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.bag import LASER_SCAN, ODOMETRY, TF_MESSAGE

FORMATS = ("mcap", "sqlite3", "ros1")


class BagWriter:
    """A recording being written; use as a context manager.

    Parameters
    ----------
    path : path-like
        A folder for ROS 2 (``mcap`` or ``sqlite3`` storage), a ``.bag`` file for ``ros1``.
        Must not exist yet.
    fmt : {'mcap', 'sqlite3', 'ros1'}
    """

    def __init__(self, path: str | Path, fmt: str = "mcap") -> None:
        if fmt not in FORMATS:
            raise ValueError(f"fmt must be one of {FORMATS}, got {fmt!r}")
        self.path = Path(path)
        if self.path.exists():
            raise InputError(f"output '{self.path}' exists already")
        self._ros1 = fmt == "ros1"
        self._ts = get_typestore(Stores.ROS1_NOETIC if self._ros1 else Stores.ROS2_HUMBLE)
        if TF_MESSAGE not in self._ts.types:  # the ROS 1 store lacks tf2_msgs; same definition as ROS 2
            self._ts.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF_MESSAGE))
        if self._ros1:
            self._writer = Writer1(self.path)
        else:
            plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
            self._writer = Writer2(self.path, version=9, storage_plugin=plugin)
        self._conns: dict[str, object] = {}
        self._seq = 0
        t = self._ts.types
        self._Time = t["builtin_interfaces/msg/Time"]
        self._Header = t["std_msgs/msg/Header"]

    def __enter__(self) -> "BagWriter":
        self._writer.open()
        return self

    def __exit__(self, *exc) -> None:
        self._writer.close()

    def _conn(self, topic: str, msgtype: str):
        conn = self._conns.get(topic)
        if conn is None:
            conn = self._conns[topic] = self._writer.add_connection(topic, msgtype, typestore=self._ts)
        return conn

    def _header(self, stamp: float, frame_id: str):
        sec = math.floor(stamp)
        nsec = min(int(round((stamp - sec) * 1e9)), 999_999_999)
        kw = {"stamp": self._Time(sec=sec, nanosec=nsec), "frame_id": frame_id}
        if self._ros1:
            self._seq += 1
            kw["seq"] = self._seq
        return self._Header(**kw)

    def _write(self, topic: str, msgtype: str, msg, bag_time: float) -> None:
        data = self._ts.serialize_ros1(msg, msgtype) if self._ros1 else self._ts.serialize_cdr(msg, msgtype)
        self._writer.write(self._conn(topic, msgtype), int(round(bag_time * 1e9)), data)

    def write_scan(self, topic: str, scan: Scan, bag_time: float | None = None, scan_time: float = 0.0) -> None:
        """Write a scan; ``bag_time`` (s) defaults to its stamp."""
        msg = self._ts.types[LASER_SCAN](
            header=self._header(scan.stamp, scan.frame_id),
            angle_min=float(scan.angle_min),
            angle_max=float(scan.angle_max),
            angle_increment=float(scan.angle_increment),
            time_increment=float(scan.time_increment),
            scan_time=float(scan_time),
            range_min=float(scan.range_min),
            range_max=float(scan.range_max),
            ranges=np.asarray(scan.ranges, dtype=np.float32),
            intensities=np.zeros(0, dtype=np.float32),
        )
        self._write(topic, LASER_SCAN, msg, scan.stamp if bag_time is None else bag_time)

    def _geometry(self, pose: Pose2D):
        t = self._ts.types
        half = pose.yaw / 2.0
        return (t["geometry_msgs/msg/Vector3"](x=pose.x, y=pose.y, z=0.0),
                t["geometry_msgs/msg/Point"](x=pose.x, y=pose.y, z=0.0),
                t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(half), w=math.cos(half)))

    def write_odometry(self, topic: str, stamp: float, frame_id: str, child_frame_id: str, pose: Pose2D,
                       velocity: tuple[float, float, float] = (0.0, 0.0, 0.0), bag_time: float | None = None) -> None:
        """Write ``nav_msgs/Odometry``: ``pose`` of ``child_frame_id`` in ``frame_id``; velocity (m/s, m/s, rad/s) in the child frame."""
        t = self._ts.types
        _, point, quat = self._geometry(pose)
        V3 = t["geometry_msgs/msg/Vector3"]
        msg = t[ODOMETRY](
            header=self._header(stamp, frame_id),
            child_frame_id=child_frame_id,
            pose=t["geometry_msgs/msg/PoseWithCovariance"](
                pose=t["geometry_msgs/msg/Pose"](position=point, orientation=quat),
                covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=V3(x=velocity[0], y=velocity[1], z=0.0),
                                                   angular=V3(x=0.0, y=0.0, z=velocity[2])),
                covariance=np.zeros(36)),
        )
        self._write(topic, ODOMETRY, msg, stamp if bag_time is None else bag_time)

    def write_tf(self, stamp: float, transforms: list[tuple[str, str, Pose2D]], static: bool = False,
                 bag_time: float | None = None) -> None:
        """Write one ``tf2_msgs/TFMessage`` of (parent, child, parent_T_child) to /tf or /tf_static."""
        t = self._ts.types
        items = []
        for parent, child, pose in transforms:
            vec, _, quat = self._geometry(pose)
            items.append(t["geometry_msgs/msg/TransformStamped"](
                header=self._header(stamp, parent), child_frame_id=child,
                transform=t["geometry_msgs/msg/Transform"](translation=vec, rotation=quat)))
        msg = t[TF_MESSAGE](transforms=items)
        self._write("/tf_static" if static else "/tf", TF_MESSAGE, msg, stamp if bag_time is None else bag_time)
