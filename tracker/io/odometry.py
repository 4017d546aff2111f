"""The sensor's pose in the fixed frame at each scan stamp, from a recording.

Two sources, chosen automatically (``odometry.source: auto``) or by configuration:

* ``odom``: a ``nav_msgs/Odometry`` topic (fixed frame → base frame) composed with the
  static mount (base frame → laser frame) learned from ``/tf_static`` or the start of
  ``/tf``. Cheapest: each odometry message's stamp is read from its first bytes and only
  the two messages that bracket a scan are deserialized.
* ``tf``: the dynamic ``/tf`` chain from the tree's root to the laser frame; every ``/tf``
  message that may carry an edge of that chain is deserialized.

Frame names are compared without a leading ``/``. Poses are planar (SE(2)): heading is
the rotation about z, which is exact for a level laser on a planar robot; a chain that
tilts the laser by more than 20° is reported with a warning.
"""

from __future__ import annotations

import bisect
import logging
import math
from dataclasses import dataclass
from typing import Callable

from people_tracker.models.pose import Pose2D, interpolate_pose, yaw_from_quaternion
from people_tracker.tracker.config import OdometryConfig
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.bag import (ODOMETRY, TF_MESSAGE, connections_of, peek_odometry_frames,
                                          peek_odometry_pose, peek_stamp, peek_transforms, stamp_seconds,
                                          topics_of_type)

log = logging.getLogger(__name__)

_TILT_WARN_RAD = math.radians(20.0)


def norm_frame(name: str) -> str:
    """Frame name without leading ``/``."""
    return name.lstrip("/")


def pose_from_msg(translation, rotation) -> tuple[Pose2D, float]:
    """Planar pose of a ROS translation + quaternion, and the tilt of its z axis (rad)."""
    return planar_pose(translation.x, translation.y, rotation.x, rotation.y, rotation.z, rotation.w)


def planar_pose(x: float, y: float, qx: float, qy: float, qz: float, qw: float) -> tuple[Pose2D, float]:
    """Planar pose of a translation (x, y; m) and quaternion, and the tilt of its z axis (rad)."""
    # z axis of the rotated frame: R[2,2] = 1 - 2(x² + y²)
    cos_tilt = max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy)))
    return Pose2D(x, y, yaw_from_quaternion(qx, qy, qz, qw)), math.acos(cos_tilt)


def transforms_of(reader, raw) -> list[tuple[float, str, str, Pose2D, float]]:
    """Every transform of a serialized ``tf2_msgs/TFMessage``: (stamp in s, parent frame,
    child frame, parent_T_child, tilt in rad); read in place, or deserialized when the bytes
    have another layout."""
    fast = peek_transforms(raw, not reader.is2)
    if fast is not None:
        return [(stamp, parent, child, *planar_pose(tx, ty, qx, qy, qz, qw))
                for stamp, parent, child, (tx, ty, _tz, qx, qy, qz, qw) in fast]
    msg = reader.deserialize(raw, TF_MESSAGE)
    return [(stamp_seconds(tr.header.stamp), tr.header.frame_id, tr.child_frame_id,
             *pose_from_msg(tr.transform.translation, tr.transform.rotation)) for tr in msg.transforms]


class PoseSeries:
    """A time series of planar poses, interpolated within configured limits.

    Samples may be stored decoded (a :class:`Pose2D`) or as raw bytes with a decoder, so
    that only the samples a query needs are ever deserialized.
    """

    def __init__(self, max_gap_s: float, max_extrapolation_s: float,
                 decode: Callable[[object], Pose2D] | None = None) -> None:
        self._stamps: list[float] = []
        self._items: list[object] = []
        self._decoded: dict[int, Pose2D] = {}
        self._offset = 0  # number of samples pruned from the front (keeps cache keys stable)
        self._decode = decode
        self._max_gap = max_gap_s
        self._max_extrap = max_extrapolation_s
        self._constant = True  # every decoded sample so far equals the first

    def __len__(self) -> int:
        return len(self._stamps)

    @property
    def newest(self) -> float:
        return self._stamps[-1] if self._stamps else -math.inf

    def add(self, stamp: float, item: object) -> None:
        """Append a sample; samples that do not advance in time are dropped."""
        if self._stamps and stamp <= self._stamps[-1]:
            return
        if self._constant and self._decode is None and self._items and item != self._items[0]:
            self._constant = False
        self._stamps.append(stamp)
        self._items.append(item)

    def _pose(self, i: int) -> Pose2D:
        item = self._items[i]
        if self._decode is None:
            return item  # type: ignore[return-value]
        key = i + self._offset
        pose = self._decoded.get(key)
        if pose is None:
            pose = self._decoded[key] = self._decode(item)
        return pose

    def at(self, stamp: float) -> Pose2D | None:
        """Pose at ``stamp`` (s), or None when the samples do not support one."""
        st = self._stamps
        n = len(st)
        if n == 0:
            return None
        j = bisect.bisect_right(st, stamp)  # st[j-1] <= stamp < st[j]
        if 0 < j < n:
            t0, t1 = st[j - 1], st[j]
            if t1 - t0 > self._max_gap:
                return None
            return interpolate_pose(self._pose(j - 1), self._pose(j), (stamp - t0) / (t1 - t0))
        if j == n and stamp - st[-1] <= self._max_extrap:
            if stamp == st[-1] or n == 1:
                return self._pose(n - 1)
            t0, t1 = st[-2], st[-1]
            if t1 - t0 > self._max_gap:
                return self._pose(n - 1)
            return interpolate_pose(self._pose(n - 2), self._pose(n - 1), (stamp - t0) / (t1 - t0))
        if j == 0 and (st[0] - stamp <= self._max_extrap or (self._constant and self._decode is None and n > 1)):
            # a transform that has never moved (a fixed joint republished on /tf, often
            # stamped ahead of time) holds for earlier stamps too
            return self._pose(0)
        return None

    def prune(self, before: float) -> None:
        """Forget samples not needed for queries at or after ``before`` (s); keeps one older."""
        k = bisect.bisect_left(self._stamps, before) - 1
        if k > 0:
            del self._stamps[:k]
            del self._items[:k]
            self._offset += k
            self._decoded = {key: p for key, p in self._decoded.items() if key >= self._offset}


@dataclass
class TfEdge:
    parent: str
    child: str
    pose: Pose2D  # parent_T_child, first seen
    tilt: float  # rad
    static: bool  # from /tf_static (True) or /tf (False)
    changes: bool = False  # seen with a different value during discovery


class TfTree:
    """The transform tree learned from ``/tf_static`` and the start of ``/tf``."""

    def __init__(self) -> None:
        self.edges: dict[str, TfEdge] = {}  # keyed by child frame

    def add(self, parent: str, child: str, pose: Pose2D, tilt: float, static: bool) -> None:
        parent, child = norm_frame(parent), norm_frame(child)
        old = self.edges.get(child)
        if old is None or (static and not old.static):
            self.edges[child] = TfEdge(parent, child, pose, tilt, static)
        elif not old.static and (abs(old.pose.x - pose.x) > 1e-6 or abs(old.pose.y - pose.y) > 1e-6
                                 or abs(old.pose.yaw - pose.yaw) > 1e-6):
            old.changes = True

    def chain(self, frame: str) -> list[TfEdge]:
        """Edges from ``frame`` up to the root, nearest first."""
        out: list[TfEdge] = []
        seen = {frame}
        while frame in self.edges:
            edge = self.edges[frame]
            out.append(edge)
            frame = edge.parent
            if frame in seen:
                raise InputError(f"the /tf tree has a loop through frame '{frame}'")
            seen.add(frame)
        return out

    def root(self, frame: str) -> str:
        chain = self.chain(frame)
        return chain[-1].parent if chain else frame


def compose_chain(edges: list[TfEdge]) -> Pose2D:
    """top_T_frame for a chain listed nearest-first (as :meth:`TfTree.chain` gives it)."""
    pose = Pose2D.identity()
    for edge in edges:
        pose = edge.pose @ pose
    return pose


def _warn_tilt(edges: list[TfEdge], laser_frame: str) -> None:
    tilt = sum(e.tilt for e in edges)
    if tilt > _TILT_WARN_RAD:
        log.warning("the laser frame '%s' is tilted %.0f° from level in /tf; poses are projected to the plane",
                    laser_frame, math.degrees(tilt))


def discover_tf(reader, window_s: float) -> TfTree:
    """Learn the transform tree from all of ``/tf_static`` and the first ``window_s`` of ``/tf``."""
    tree = TfTree()
    tf_types = [c for c in reader.connections if c.msgtype == TF_MESSAGE]
    static = [c for c in tf_types if norm_frame(c.topic) == "tf_static"]
    dynamic = [c for c in tf_types if norm_frame(c.topic) == "tf"]
    for conns, is_static, stop in ((static, True, None),
                                   (dynamic, False, reader.start_time + int(window_s * 1e9))):
        if not conns:
            continue
        for _conn, _t, raw in reader.messages(connections=conns, stop=stop):
            for _stamp, parent, child, pose, tilt in transforms_of(reader, raw):
                tree.add(parent, child, pose, tilt, is_static)
    return tree


class NoPoseSource:
    """A recording without odometry: every scan's pose is None."""

    description = "none"
    fixed_frame = None
    connections: list = []

    def feed(self, conn, raw) -> None:  # pragma: no cover - never called: no connections
        pass

    def ready(self, stamp: float) -> bool:
        return True

    def pose_at(self, stamp: float) -> None:
        return None

    def prune(self, before: float) -> None:
        pass


class OdomTopicSource:
    """Sensor pose = (fixed_T_base from a ``nav_msgs/Odometry`` topic) ∘ (base_T_laser mount)."""

    def __init__(self, reader, topic: str, fixed_frame: str, base_frame: str, laser_frame: str,
                 mount: Pose2D, cfg: OdometryConfig) -> None:
        self.connections = connections_of(reader, topic)
        self.fixed_frame = fixed_frame
        self.mount = mount
        self.description = f"{topic} ({fixed_frame} → {base_frame}) + static mount {base_frame} → {laser_frame}"
        self._ros1 = not reader.is2
        deserialize = reader.deserialize

        def decode(raw) -> Pose2D:
            pose = peek_odometry_pose(raw, self._ros1)  # read in place, else deserialized
            if pose is not None:
                px, py, _, qx, qy, qz, qw = pose
                return Pose2D(px, py, yaw_from_quaternion(qx, qy, qz, qw))
            msg = deserialize(raw, ODOMETRY)
            return pose_from_msg(msg.pose.pose.position, msg.pose.pose.orientation)[0]

        self._series = PoseSeries(cfg.max_interpolation_gap_s, cfg.max_extrapolation_s, decode)

    def feed(self, conn, raw) -> None:
        self._series.add(peek_stamp(raw, self._ros1), raw)

    def ready(self, stamp: float) -> bool:
        return self._series.newest >= stamp

    def pose_at(self, stamp: float) -> Pose2D | None:
        base = self._series.at(stamp)
        # fixed_T_laser = fixed_T_base ∘ base_T_laser
        return None if base is None else base @ self.mount

    def prune(self, before: float) -> None:
        self._series.prune(before)


class TfSource:
    """Sensor pose from the ``/tf`` chain root → … → laser, dynamic edges interpolated."""

    def __init__(self, reader, tree: TfTree, laser_frame: str, cfg: OdometryConfig) -> None:
        self._chain = tree.chain(laser_frame)
        self.fixed_frame = self._chain[-1].parent
        self.connections = [c for c in reader.connections
                            if c.msgtype == TF_MESSAGE and norm_frame(c.topic) == "tf"]
        self._dynamic = {e.child: PoseSeries(cfg.max_interpolation_gap_s, cfg.max_extrapolation_s)
                         for e in self._chain if not e.static}
        self._needles = [c.encode() for c in self._dynamic]
        self._reader = reader
        path = " → ".join([self.fixed_frame] + [e.child for e in reversed(self._chain)])
        self.description = f"/tf ({path})"

    def feed(self, conn, raw) -> None:
        # cheap filter: a message that does not name a dynamic child frame is not needed
        if not any(n in raw for n in self._needles):
            return
        for stamp, _parent, child, pose, _tilt in transforms_of(self._reader, raw):
            series = self._dynamic.get(norm_frame(child))
            if series is not None:
                series.add(stamp, pose)

    def ready(self, stamp: float) -> bool:
        return all(s.newest >= stamp for s in self._dynamic.values())

    def pose_at(self, stamp: float) -> Pose2D | None:
        pose = Pose2D.identity()
        for edge in self._chain:  # nearest first: root_T_laser = … ∘ a_T_b ∘ b_T_laser
            step = self._dynamic[edge.child].at(stamp) if edge.child in self._dynamic else edge.pose
            if step is None:
                return None
            pose = step @ pose
        return pose

    def prune(self, before: float) -> None:
        for s in self._dynamic.values():
            s.prune(before)


def _odometry_child(reader, topic: str) -> tuple[str, str]:
    """(frame_id, child_frame_id) of the first message of an Odometry topic."""
    conns = connections_of(reader, topic)
    for conn, _t, raw in reader.messages(connections=conns):
        frames = peek_odometry_frames(raw, not reader.is2)
        if frames is None:
            msg = reader.deserialize(raw, conn.msgtype)
            frames = msg.header.frame_id, msg.child_frame_id
        return norm_frame(frames[0]), norm_frame(frames[1])
    return "", ""


def choose_pose_source(reader, laser_frame: str, cfg: OdometryConfig):
    """The cheapest source that gives the laser's pose, as ``cfg.source`` allows.

    Raises :class:`InputError` when a source named in the configuration cannot serve.
    """
    if cfg.source == "none":
        return NoPoseSource()
    tree = discover_tf(reader, cfg.tf_discovery_s)
    laser_frame = norm_frame(laser_frame)

    if cfg.source in ("auto", "odom"):
        odom_topics = topics_of_type(reader, ODOMETRY)
        if cfg.odom_topic:
            matches = [t for t in odom_topics if norm_frame(t) == norm_frame(cfg.odom_topic)]
            if not matches:
                raise InputError(f"configuration key 'odometry.odom_topic': no Odometry topic "
                                 f"'{cfg.odom_topic}' (Odometry topics: {', '.join(odom_topics) or 'none'})")
            odom_topics = matches
        for topic in odom_topics:
            fixed, base = _odometry_child(reader, topic)
            if not base:
                continue
            chain = tree.chain(laser_frame)
            frames = [laser_frame] + [e.parent for e in chain]
            if base not in frames:
                continue
            mount_edges = chain[: frames.index(base)]
            if any(e.changes for e in mount_edges):
                continue  # not a rigid mount
            _warn_tilt(mount_edges, laser_frame)
            return OdomTopicSource(reader, topic, fixed, base, laser_frame, compose_chain(mount_edges), cfg)
        if cfg.source == "odom":
            raise InputError(f"odometry.source is 'odom' but no Odometry topic reaches the laser frame "
                             f"'{laser_frame}' through /tf (Odometry topics: {', '.join(odom_topics) or 'none'})")

    chain = tree.chain(laser_frame)
    if any(not e.static for e in chain):  # a /tf edge may move, even if it did not at the start
        _warn_tilt(chain, laser_frame)
        return TfSource(reader, tree, laser_frame, cfg)
    if cfg.source == "tf":
        raise InputError(f"odometry.source is 'tf' but /tf has no moving chain to the laser frame '{laser_frame}'")
    return NoPoseSource()
