"""Opening recordings with rosbags and choosing topics, with one-line errors.

Supports ROS 1 ``.bag`` files, ROS 2 bag folders (sqlite3 or MCAP storage; or their
``metadata.yaml``) and bare ``.mcap`` / ``.db3`` files. Message definitions come from the
recording itself; a ROS 2 bag without them falls back to the standard ROS 2 types.
"""

from __future__ import annotations

import logging
import struct
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.bag1 import open_bag1
from people_tracker.tracker.io.mcap_cut import open_mcap_cut

LASER_SCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
PERSON_TYPES = ("leg_tracker/msg/Person", "leg_tracker/msg/PersonArray")

log = logging.getLogger(__name__)
_said: set[tuple[Path, str]] = set()  # the warnings said of each recording (each once)

_STAMP_ROS1 = struct.Struct("<II")  # uint32 sec, uint32 nsec
_STAMP_CDR_LE = struct.Struct("<iI")  # int32 sec, uint32 nanosec
_STAMP_CDR_BE = struct.Struct(">iI")


def open_bag(path: str | Path) -> AnyReader:
    """Open a recording for reading, or raise :class:`InputError` naming what is wrong.

    A ROS 1 bag opens with :class:`~people_tracker.tracker.io.bag1.Bag1Reader` (the same
    messages, read a few times faster) when that reader can read it, else with ``rosbags``.
    A recording cut short is read as far as it goes, with a warning the first time: a ROS 1
    bag with no index or a damaged one (``rosbag record``'s ``.bag.active`` file) from its
    chunks, an MCAP file with no summary or end record by record
    (:mod:`~people_tracker.tracker.io.mcap_cut`), and a ROS 2 bag folder with one MCAP file
    and no ``metadata.yaml`` (a recorder stopped before writing it) through that file."""
    p = Path(path)
    if not p.exists():
        raise InputError(f"input '{p}' does not exist")
    if p.name == "metadata.yaml" and p.is_file():  # a ROS 2 bag's metadata: the bag is its folder
        p = p.parent
    if p.is_dir():
        if not (p / "metadata.yaml").is_file():
            files = sorted([*p.glob("*.mcap"), *p.glob("*.db3")])
            if len(files) > 1:  # split files: their order and the cut one's place are in the metadata
                raise InputError(f"input '{p}' has no metadata.yaml and {len(files)} recording files "
                                 "(a split recording cut short?): give one file, or write the metadata "
                                 "with 'ros2 bag reindex'")
            if not files:
                raise InputError(f"input '{p}' is a folder but not a ROS 2 bag (it has no metadata.yaml)")
            # a recorder stopped before writing its metadata leaves its one file
            _warn_once(p, f"input '{p}' has no metadata.yaml (a recording cut short?): reading its one file, "
                          f"{files[0].name}")
            p = files[0]
    else:
        if not _is_ros1(p) and p.suffix not in (".mcap", ".db3"):
            raise InputError(f"input '{p}' is not a ROS 1 .bag, a ROS 2 bag folder (or its metadata.yaml), "
                             "or an .mcap or .db3 file")
        if p.stat().st_size == 0:
            raise InputError(f"input '{p}' is empty")
    ros1 = _is_ros1(p)
    kind = "ROS 1 bag" if ros1 else "ROS 2 recording"
    if ros1 and (fast := open_bag1(p)) is not None:
        if fast.repaired:
            _warn_once(p, f"input '{p}' has {fast.repaired} (a recording cut short?): read from its chunks as "
                          f"'rosbag reindex' would, {sum(c.msgcount for c in fast.connections)} messages; "
                          "what was being written when it stopped is lost")
        return fast
    try:
        reader = AnyReader([p], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as exc:  # rosbags raises several types for unreadable files
        mcap = _one_mcap(p)
        cut = open_mcap_cut(mcap) if mcap is not None else None
        if cut is None:
            raise InputError(f"input '{p}' cannot be read as a {kind}: {_one_line(exc)}") from None
        _warn_once(p, f"input '{p}' cannot be read whole ({_one_line(exc).rstrip('.')}; a recording cut "
                      f"short?): read record by record, {sum(c.msgcount for c in cut.connections)} messages; "
                      "what was being written when it stopped is lost")
        return cut
    return reader


def _warn_once(p: Path, text: str) -> None:
    """``text`` as a warning, the first time it is said of the recording ``p``."""
    if (p.resolve(), text) not in _said:
        _said.add((p.resolve(), text))
        log.warning(text)


def _one_mcap(p: Path) -> Path | None:
    """The MCAP file ``p`` is, or the one a ROS 2 bag folder ``p`` holds; else None."""
    if p.is_file():
        return p if p.suffix == ".mcap" else None
    files = sorted(p.glob("*.mcap"))
    return files[0] if len(files) == 1 else None


def _is_ros1(p: Path) -> bool:
    """Whether ``p`` names a ROS 1 bag: ``.bag``, or ``.bag.active`` (``rosbag record``'s
    file while it records, left so when the recording is killed)."""
    return p.suffix == ".bag" or p.name.endswith(".bag.active")


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


def topics_of_type(reader: AnyReader, msgtypes: str | tuple[str, ...]) -> list[str]:
    """Names of the topics whose message type is one of ``msgtypes``, sorted."""
    wanted = (msgtypes,) if isinstance(msgtypes, str) else msgtypes
    return sorted({c.topic for c in reader.connections if c.msgtype in wanted})


def select_topic(reader: AnyReader, topic: str | None, msgtypes: str | tuple[str, ...],
                 what: str, option: str) -> str:
    """The topic to read: ``topic`` if it exists with the right type, else the only one.

    ``topic`` matches with or without a leading ``/``. Raises :class:`InputError` when the
    recording has none, when it has several and none was chosen, or for a wrong name.
    """
    candidates = topics_of_type(reader, msgtypes)
    if topic is not None:
        for name in candidates:
            if name == topic or name.lstrip("/") == topic.lstrip("/"):
                return name
        others = sorted({c.topic for c in reader.connections})
        if any(t.lstrip("/") == topic.lstrip("/") for t in others):
            raise InputError(f"topic '{topic}' is not a {what} topic; {what} topics: {', '.join(candidates) or 'none'}")
        raise InputError(f"no topic '{topic}' in the recording; {what} topics: {', '.join(candidates) or 'none'}")
    if not candidates:
        raise InputError(f"the recording has no {what} topic (topics: {', '.join(sorted({c.topic for c in reader.connections})) or 'none'})")
    if len(candidates) > 1:
        raise InputError(f"the recording has several {what} topics, choose one with {option}: {', '.join(candidates)}")
    return candidates[0]


def connections_of(reader: AnyReader, topic: str) -> list:
    return [c for c in reader.connections if c.topic == topic]


def peek_stamp(raw: bytes | memoryview, ros1: bool) -> float:
    """Header stamp (s) of a serialized message that starts with ``std_msgs/Header``.

    Reads 8 bytes instead of deserializing: ROS 1 puts ``seq`` then ``stamp``; CDR puts a
    4-byte encapsulation header then ``stamp`` (little endian for the usual CDR_LE).
    """
    if ros1:
        sec, nsec = _STAMP_ROS1.unpack_from(raw, 4)
    elif raw[1] & 1:  # encapsulation kind: odd values are little endian
        sec, nsec = _STAMP_CDR_LE.unpack_from(raw, 4)
    else:
        sec, nsec = _STAMP_CDR_BE.unpack_from(raw, 4)
    return sec + nsec * 1e-9


_U32 = {True: struct.Struct("<I"), False: struct.Struct(">I")}
_POSE = {True: struct.Struct("<7d"), False: struct.Struct(">7d")}


def _align(at: int, base: int, size: int, ros1: bool) -> int:
    """``at`` moved to the next multiple of ``size`` from ``base`` (CDR); unchanged in ROS 1,
    which packs its values."""
    return at if ros1 else base + (at - base + size - 1) // size * size


def _string(raw, at: int, ros1: bool, little: bool, decode: bool = True) -> tuple[str, int]:
    """The string at ``at`` (a uint32 length, then the bytes; CDR counts and drops a
    closing NUL; "" unless ``decode``) and where the next value starts. Raises ValueError
    when cut short."""
    if at + 4 > len(raw):
        raise ValueError("cut short")
    n = _U32[little].unpack_from(raw, at)[0]
    end = at + 4 + n
    if end > len(raw) or (not ros1 and n == 0):
        raise ValueError("cut short")
    return (bytes(raw[at + 4:end if ros1 else end - 1]).decode() if decode else ""), end


def _odometry_head(raw, ros1: bool, frames: bool) -> tuple[bool, str, str, int] | None:
    """(little endian, ``header.frame_id``, ``child_frame_id``, where ``pose.pose`` starts)
    of a serialized ``nav_msgs/Odometry``, or None when the bytes do not have that layout.

    The message is a ``std_msgs/Header`` (ROS 1: seq, stamp; CDR: stamp after a 4-byte
    encapsulation header), ``frame_id``, ``child_frame_id``, then the pose's seven float64.
    ROS 1 packs them; CDR aligns each value to its size, counted from the end of the
    encapsulation header. The frame names are "" unless ``frames``."""
    if ros1:
        little, base, at = True, 0, 12  # seq, stamp
    else:
        if len(raw) < 4:
            return None
        little, base, at = bool(raw[1] & 1), 4, 12  # encapsulation header, stamp
    try:
        frame, at = _string(raw, _align(at, base, 4, ros1), ros1, little, frames)
        child, at = _string(raw, _align(at, base, 4, ros1), ros1, little, frames)
    except (ValueError, UnicodeDecodeError):
        return None
    at = _align(at, base, 8, ros1)
    return (little, frame, child, at) if at + 56 <= len(raw) else None


def peek_odometry_pose(raw: bytes | memoryview, ros1: bool) -> tuple[float, ...] | None:
    """``pose.pose`` of a serialized ``nav_msgs/Odometry``: position x, y, z and orientation
    x, y, z, w, read in place (a full deserialization takes ~50 µs, at 100 Hz odometry a
    noticeable share of the tracker's time); None when the bytes do not have that layout.
    ``tests/tracker/test_odometry.py`` checks it against the full deserialization on real
    and simulated recordings."""
    head = _odometry_head(raw, ros1, False)
    return None if head is None else _POSE[head[0]].unpack_from(raw, head[3])


def peek_odometry_frames(raw: bytes | memoryview, ros1: bool) -> tuple[str, str] | None:
    """(``header.frame_id``, ``child_frame_id``) of a serialized ``nav_msgs/Odometry``,
    read in place; None when the bytes do not have that layout."""
    head = _odometry_head(raw, ros1, True)
    return None if head is None else (head[1], head[2])


def peek_transforms(raw: bytes | memoryview, ros1: bool) -> list[tuple[float, str, str, tuple[float, ...]]] | None:
    """The ``transforms`` of a serialized ``tf2_msgs/TFMessage``, read in place: per
    transform (stamp in s, ``header.frame_id``, ``child_frame_id``, (translation x, y, z,
    rotation x, y, z, w)); None when the bytes do not have that layout (the caller then
    deserializes). Deserializing one costs tens of µs and, the first time, generating the
    type's decoder; a recording's /tf carries hundreds of them a second.

    Each ``geometry_msgs/TransformStamped`` is a header (ROS 1: seq, stamp; CDR: stamp),
    ``frame_id``, ``child_frame_id`` and seven float64, after a uint32 count. The bytes must
    be used up exactly (CDR: up to its last value's alignment)."""
    size = len(raw)
    if ros1:
        little, base, at = True, 0, 0
    else:
        if size < 8:
            return None
        little, base, at = bool(raw[1] & 1), 4, 4
    u32, stamp, pose = _U32[little], _STAMP_ROS1 if ros1 else (_STAMP_CDR_LE if little else _STAMP_CDR_BE), _POSE[little]
    out = []
    try:
        if at + 4 > size:
            return None
        count = u32.unpack_from(raw, at)[0]
        at += 4
        if count * 64 > size:  # each takes at least 64 bytes: no need to read a wrong count
            return None
        for _ in range(count):
            if ros1:
                at += 4  # seq
            at = _align(at, base, 4, ros1)
            if at + 8 > size:
                return None
            sec, nsec = stamp.unpack_from(raw, at)
            frame, at = _string(raw, at + 8, ros1, little)
            child, at = _string(raw, _align(at, base, 4, ros1), ros1, little)
            at = _align(at, base, 8, ros1)
            if at + 56 > size:
                return None
            out.append((sec + nsec * 1e-9, frame, child, pose.unpack_from(raw, at)))
            at += 56
    except (ValueError, UnicodeDecodeError):
        return None
    return out if at == size else None


def stamp_seconds(stamp) -> float:
    """A ``builtin_interfaces/Time`` as seconds."""
    return stamp.sec + stamp.nanosec * 1e-9
