"""Streaming a recording's laser scans, each with the sensor's pose at its stamp.

Memory stays bounded whatever the recording's length: scans wait in a short queue only
until odometry stamped after them has been read (or ``odometry.max_wait_s`` of bag time
has passed), and odometry older than the oldest waiting scan is forgotten.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from people_tracker.models.pose import Pose2D
from people_tracker.detection.deskew import sweep_duration
from people_tracker.models.scan import Scan
from people_tracker.tracker.config import OdometryConfig
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.bag import LASER_SCAN, connections_of, open_bag, select_topic, stamp_seconds
from people_tracker.tracker.io.odometry import choose_pose_source

log = logging.getLogger(__name__)

_PRUNE_MARGIN_S = 0.5  # s of odometry kept before the newest released scan


@dataclass(frozen=True, eq=False)
class ScanRecord:
    """One message of the scan topic.

    Attributes
    ----------
    index : int
        Position in the scan topic, from 0, counting every message.
    bag_time : int
        Time the message was recorded (bag time), nanoseconds.
    scan : Scan or None
        The decoded scan; None when the message could not be decoded (see ``problem``).
    pose : Pose2D or None
        The sensor (scan frame) pose in the fixed frame at the scan stamp; None when the
        recording has no odometry or none covers this stamp.
    problem : str or None
        Why ``scan`` is None.
    pose_last_beam : Pose2D or None
        The sensor pose when the scan's last beam fired (``stamp`` + the sweep), for
        de-skew; None without odometry or without ``time_increment``.
    """

    index: int
    bag_time: int
    scan: Scan | None
    pose: Pose2D | None
    problem: str | None = None
    pose_last_beam: Pose2D | None = None


def scan_from_msg(msg) -> Scan:
    """A :class:`Scan` from a deserialized ``sensor_msgs/LaserScan``."""
    return Scan(
        ranges=msg.ranges,
        angle_min=float(msg.angle_min),
        angle_increment=float(msg.angle_increment),
        range_min=float(msg.range_min),
        range_max=float(msg.range_max),
        stamp=stamp_seconds(msg.header.stamp),
        frame_id=msg.header.frame_id,
        time_increment=float(msg.time_increment),
    )


def decode_scan(get_msg) -> tuple[Scan | None, str | None]:
    """The :class:`Scan` of the message ``get_msg()`` returns, or None and why not (the
    warning a bad scan gets, here and in the ROS 2 node)."""
    try:
        return scan_from_msg(get_msg()), None
    except Exception as exc:
        return None, f"cannot be decoded ({' '.join(str(exc).split())[:120]})"


class Recording:
    """A recording opened for reading its laser scans with poses.

    Parameters
    ----------
    path : path-like
        A ROS 1 ``.bag``, a ROS 2 bag folder, or a bare ``.mcap`` / ``.db3`` file.
    topic : str, optional
        The LaserScan topic; by default the only one in the recording.
    odometry : OdometryConfig, optional
        How to find the sensor pose; by default the shipped defaults.

    Raises
    ------
    InputError
        Missing, empty or corrupt file; no LaserScan topic, several and none chosen, a
        wrong topic, or a topic without messages.
    """

    def __init__(self, path: str | Path, topic: str | None = None,
                 odometry: OdometryConfig | None = None) -> None:
        if odometry is None:
            from people_tracker.tracker.config import load_config
            odometry = load_config().odometry
        self.path = Path(path)
        self._cfg = odometry
        self._reader = open_bag(self.path)
        try:
            self.topic = select_topic(self._reader, topic, LASER_SCAN, "LaserScan", "--topic")
            self._scan_conns = connections_of(self._reader, self.topic)
            self.scan_count = sum(c.msgcount for c in self._scan_conns)
            first = self._first_scan()
            self.laser_frame = first.frame_id
            self.n_beams = first.n_beams
            self.resolution = first.resolution  # rad, of the first scan
            self.pose_source = self._guard(lambda: choose_pose_source(self._reader, self.laser_frame, odometry))
        except BaseException:
            self._reader.close()
            raise

    def _guard(self, fn):
        try:
            return fn()
        except InputError:
            raise
        except Exception as exc:
            raise InputError(f"input '{self.path}' is corrupt: {' '.join(str(exc).split())[:200]}") from None

    def _first_scan(self) -> Scan:
        def read():
            for conn, _t, raw in self._reader.messages(connections=self._scan_conns):
                return scan_from_msg(self._reader.deserialize(raw, conn.msgtype))
            raise InputError(f"topic '{self.topic}' has no messages")
        return self._guard(read)

    @property
    def odometry(self) -> str:
        """Where poses come from, for people: 'none' or the topic and frames used."""
        return self.pose_source.description

    @property
    def fixed_frame(self) -> str | None:
        """Name of the fixed (world) frame of the poses, or None without odometry."""
        return self.pose_source.fixed_frame

    def close(self) -> None:
        if self._reader.stack is not None:
            self._reader.close()

    def __enter__(self) -> "Recording":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _decode(self, index: int, bag_time: int, raw) -> ScanRecord:
        scan, problem = decode_scan(lambda: self._reader.deserialize(raw, LASER_SCAN))
        return ScanRecord(index, bag_time, scan, None, problem)

    def scans(self) -> Iterator[ScanRecord]:
        """Every message of the scan topic in recorded order, each with its pose."""
        source = self.pose_source
        scan_ids = {c.id for c in self._scan_conns}
        wait_ns = int(self._cfg.max_wait_s * 1e9)
        pending: deque[ScanRecord] = deque()
        index = 0

        def release(rec: ScanRecord) -> ScanRecord:
            if rec.scan is None:
                return rec
            pose = source.pose_at(rec.scan.stamp)
            sweep = sweep_duration(rec.scan)
            pose_last = source.pose_at(rec.scan.stamp + sweep) if pose is not None and sweep > 0 else None
            source.prune(rec.scan.stamp - _PRUNE_MARGIN_S)  # later scans are stamped later
            return ScanRecord(rec.index, rec.bag_time, rec.scan, pose, rec.problem, pose_last)

        messages = self._reader.messages(connections=self._scan_conns + list(source.connections))
        while True:
            try:
                item = next(messages, None)
            except Exception as exc:
                raise InputError(f"input '{self.path}' is corrupt after scan {index}: "
                                 f"{' '.join(str(exc).split())[:200]}") from None
            if item is None:
                break
            conn, bag_time, raw = item
            if conn.id in scan_ids:
                pending.append(self._decode(index, bag_time, raw))
                index += 1
            else:
                source.feed(conn, raw)
            while pending and (pending[0].scan is None
                               or source.ready(pending[0].scan.stamp + sweep_duration(pending[0].scan))
                               or bag_time - pending[0].bag_time > wait_ns):
                yield release(pending.popleft())
        while pending:
            yield release(pending.popleft())
