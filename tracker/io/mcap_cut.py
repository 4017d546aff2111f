"""Reading an MCAP recording cut short, as ``mcap recover`` would.

``ros2 bag record`` writes an MCAP file's summary (its index) and its closing magic bytes
when it stops; a recorder that is killed, a robot whose power fails or a copy cut off leaves
neither, and often no ``metadata.yaml`` beside it either. ``rosbags`` then refuses the file
("File end magic is invalid"). The records before the cut are intact, so this reader walks
them from the start: schemas, channels and messages, at the top level and inside chunks
(stored, lz4 or zstd), up to the first record the file does not hold in full. Of a chunk
cut short, the messages written in full before the cut are kept when it is stored
uncompressed; a compressed one cut short is lost.

:class:`McapCutReader` offers what the tracker uses of ``rosbags.highlevel.AnyReader``
(``connections``, ``start_time``, ``end_time``, ``is2``, ``messages``, ``deserialize``,
``close``, ``stack``), with :attr:`McapCutReader.repaired` saying what was found.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
from rosbags.interfaces import Connection, ConnectionExtRosbag2, MessageDefinition, MessageDefinitionFormat
from rosbags.typesys import Stores, get_types_from_idl, get_types_from_msg, get_typestore

from people_tracker.tracker.io.mapped import MappedRecording

MAGIC = b"\x89MCAP0\r\n"
_OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK, _OP_FOOTER, _OP_DATA_END = 0x03, 0x04, 0x05, 0x06, 0x02, 0x0F
_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time (ns), publish time (ns)
_CHUNK_HEAD = struct.Struct("<QQQI")  # first and last message time (ns), uncompressed size, CRC
_FORMATS = {"ros2msg": MessageDefinitionFormat.MSG, "ros2idl": MessageDefinitionFormat.IDL,
            "omgidl": MessageDefinitionFormat.IDL}


class McapUnreadable(Exception):
    """Not an MCAP file this reader can read anything from."""


def _string(buf, at: int) -> tuple[str, int]:
    """The string at ``at`` (uint32 length, UTF-8 bytes) and where the next field starts."""
    n = _U32.unpack_from(buf, at)[0]
    return bytes(buf[at + 4:at + 4 + n]).decode(), at + 4 + n


def _decompress(data: bytes, compression: str, size: int) -> bytes:
    if compression == "":
        return data  # stored: as it is (a chunk cut short is shorter than its size)
    if compression == "lz4":
        from lz4.frame import decompress  # a dependency of rosbags
        out = decompress(data)
    elif compression == "zstd":
        try:
            from compression import zstd  # Python 3.14
        except ImportError:
            from backports import zstd  # a dependency of rosbags
        out = zstd.decompress(data)
    else:
        raise McapUnreadable(f"chunks compressed with {compression!r}")
    if len(out) != size:
        raise McapUnreadable("a chunk that does not decompress to its size")
    return out


class McapCutReader(MappedRecording):
    """An MCAP file read record by record from its start (see the module's text)."""

    is2 = True
    repaired: str | None = None  # "its end cut off", "its summary cut off"; None: the file ends as it should

    def __init__(self, path: str | Path) -> None:
        self._chunk_at, self._chunk = -1, b""
        super().__init__(path)  # maps the file and walks its records (_read)

    # ----- reading the records on opening
    def _read(self) -> None:
        m = self._map
        if m[:len(MAGIC)] != MAGIC:
            raise McapUnreadable("not an MCAP file")
        self._schemas: dict[int, tuple[str, str, str]] = {}  # id -> (name, encoding, definition)
        self._channels: dict[int, tuple[str, int, str, bytes]] = {}  # id -> (topic, schema id, encoding, metadata)
        self._chunks: list[tuple[int, int, str, int]] = []  # (data start, length, compression, uncompressed size)
        rows: list[tuple[int, int, int, int, int]] = []  # (channel, log time, chunk or -1, data start, length)
        pos, ended = len(MAGIC), False
        while pos + 9 <= len(m):
            op, length = m[pos], _U64.unpack_from(m, pos + 1)[0]
            start, end = pos + 9, pos + 9 + length
            if op in (_OP_DATA_END, _OP_FOOTER):
                ended = True
                break
            if op == _OP_CHUNK:
                if start + _CHUNK_HEAD.size + 4 > len(m):
                    break
                _, _, size, _ = _CHUNK_HEAD.unpack_from(m, start)
                compression, at = _string(m, start + _CHUNK_HEAD.size)
                stored = _U64.unpack_from(m, at)[0] if at + 8 <= len(m) else 0
                data = at + 8
                whole = end <= len(m) and data + stored <= end
                if not whole and compression != "":
                    break  # a compressed chunk cut short: lost
                k = len(self._chunks)
                self._chunks.append((data, stored if whole else len(m) - data, compression, size))
                try:
                    records = self._chunk_records(k)
                except Exception:  # noqa: BLE001 - one that does not decompress (lz4, zstd raise their own types): the cut
                    self._chunks.pop()
                    self._chunk_at, self._chunk = -1, b""
                    break
                self._records(records, 0, len(records), k, rows)
                if not whole:
                    break
            elif end > len(m):
                break
            else:
                self._records(m, pos, end, -1, rows)
            pos = end
        # what a cut left: no end of the data (records cut), or their end and part of the summary
        self.repaired = ("its end cut off" if not ended else
                         None if m[len(m) - len(MAGIC):] == MAGIC else "its summary cut off")
        if not rows:
            raise McapUnreadable("no message could be read from it")
        table = np.array(rows, dtype=np.int64)
        order = np.argsort(table[:, 1], kind="stable")  # by log time, then in the file's order
        self._rows = table[order]
        self.start_time, self.end_time = int(self._rows[0, 1]), int(self._rows[-1, 1]) + 1
        counts = dict(zip(*np.unique(self._rows[:, 0], return_counts=True)))
        self.connections = [self._connection(cid, int(counts.get(cid, 0))) for cid in sorted(self._channels)]
        self._typestore = self._types()

    def _records(self, buf, at: int, end: int, chunk: int, rows: list) -> None:
        """Note the schema, channel and message records of ``buf`` from ``at`` to ``end``
        (the top level of the file when ``chunk`` is -1, else that chunk's records); stops at
        a record that reaches past ``end``."""
        while at + 9 <= end:
            op, length = buf[at], _U64.unpack_from(buf, at + 1)[0]
            start, stop = at + 9, at + 9 + length
            if stop > end:
                return
            if op == _OP_SCHEMA:
                sid = _U16.unpack_from(buf, start)[0]
                name, p = _string(buf, start + 2)
                encoding, p = _string(buf, p)
                n = _U32.unpack_from(buf, p)[0]
                self._schemas[sid] = (name, encoding, bytes(buf[p + 4:p + 4 + n]).decode())
            elif op == _OP_CHANNEL:
                cid, sid = _U16.unpack_from(buf, start)[0], _U16.unpack_from(buf, start + 2)[0]
                topic, p = _string(buf, start + 4)
                encoding, p = _string(buf, p)
                n = _U32.unpack_from(buf, p)[0]
                self._channels.setdefault(cid, (topic, sid, encoding, bytes(buf[p + 4:p + 4 + n])))
            elif op == _OP_MESSAGE and length >= _MESSAGE_HEAD.size:
                cid, _, log_time, _ = _MESSAGE_HEAD.unpack_from(buf, start)
                if cid in self._channels:
                    rows.append((cid, log_time, chunk, start + _MESSAGE_HEAD.size, length - _MESSAGE_HEAD.size))
            elif op == _OP_CHUNK:
                return  # chunks are not nested
            at = stop

    def _chunk_records(self, k: int):
        """The records of chunk ``k``, uncompressed (one chunk kept at a time)."""
        if k != self._chunk_at:
            data, length, compression, size = self._chunks[k]
            self._chunk = _decompress(self._map[data:data + length], compression, size)
            self._chunk_at = k
        return self._chunk

    def _connection(self, cid: int, count: int) -> Connection:
        topic, sid, encoding, metadata = self._channels[cid]
        name, fmt, text = self._schemas.get(sid, ("", "", ""))
        msgdef = MessageDefinition(_FORMATS.get(fmt, MessageDefinitionFormat.NONE), text if fmt in _FORMATS else "")
        qos = []
        try:  # the recorder's QoS, as rosbags reads them
            from rosbags.rosbag2.storage_mcap import get_qos
            qos = get_qos(metadata)
        except Exception:  # another rosbags: the QoS are not needed to read the messages
            qos = []
        return Connection(cid, topic, name, msgdef, "", count, ConnectionExtRosbag2(encoding, qos), self)

    def _types(self):
        """The message types the recording defines (as rosbags' AnyReader registers them),
        or ROS 2 Humble's when it defines none."""
        types: dict = {}
        for c in self.connections:
            if c.msgdef.format == MessageDefinitionFormat.MSG:
                types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
            elif c.msgdef.format == MessageDefinitionFormat.IDL:
                sep = "=" * 80 + "\n"
                parts = c.msgdef.data.split(sep)[1:] if c.msgdef.data.startswith(f"{sep}IDL: ") else None
                for idl in ([p.split("\n", 1)[1] for p in parts] if parts else [c.msgdef.data]):
                    types.update(get_types_from_idl(idl))
        store = get_typestore(Stores.EMPTY if types else Stores.ROS2_HUMBLE)
        if types:
            store.register(types)
        return store

    # ----- reading messages
    def messages(self, connections=(), start: int | None = None, stop: int | None = None):
        """(connection, log time in ns, serialized bytes) of every message on ``connections``
        (all by default) in time order, from ``start`` to before ``stop`` (ns)."""
        if self.stack is None:
            raise ValueError("the recording is closed")
        conns = {c.id: c for c in (list(connections) or self.connections)}
        rows = self._rows
        lo = 0 if start is None else int(np.searchsorted(rows[:, 1], start, side="left"))
        hi = len(rows) if stop is None else int(np.searchsorted(rows[:, 1], stop, side="left"))
        rows = rows[lo:hi]
        rows = rows[np.isin(rows[:, 0], list(conns))]
        for cid, t, chunk, at, n in rows.tolist():
            buf = self._map if chunk < 0 else self._chunk_records(chunk)
            yield conns[cid], t, bytes(buf[at:at + n])

    def deserialize(self, raw: bytes, msgtype: str):
        """The message ``raw`` (CDR) decoded as ``msgtype``."""
        return self._typestore.deserialize_cdr(raw, msgtype)

    def _release(self) -> None:
        self._chunk = b""


def open_mcap_cut(path: Path) -> McapCutReader | None:
    """``path`` read with :class:`McapCutReader`, or None when nothing can be read from it."""
    try:
        return McapCutReader(path)
    except (McapUnreadable, struct.error, ValueError, UnicodeDecodeError, OSError, IndexError):
        return None
