"""A ROS 1 bag reader that reads only what a run asks for.

``rosbags``' reader, on opening a ROS 1 bag, decodes the index entry of every message of
every topic into a Python object and parses the message definition of every type the bag
holds; each message read then parses its record header field by field. On the annotated
recording (34,000 messages, most of them ``/tf`` and ``/odom``) that is about 0.1 s to open
and 7 µs a message, as much as a fifth of what tracking the recording costs.

This reader keeps the same answers at a fraction of the cost: it maps the file, holds each
connection's index as numpy arrays (one ``frombuffer`` per index record), merges the wanted
connections in ``rosbags``' order (time, then chunk, then offset), and slices each message
out of its chunk. Message definitions are parsed, and their MD5 sums checked, when a
message of that type is first deserialized, with ``rosbags``' own parser and deserializer.
Chunks stored uncompressed are read in place; bz2 and lz4 chunks are decompressed as
``rosbags`` does, one at a time.

:func:`open_bag1` returns None for anything it does not read (another bag version, an
encrypted bag, a record it cannot parse), and the caller then opens the file with
``rosbags``, whose error messages stay those users see for a damaged file.

A bag with no index or a damaged one, as a recording cut short leaves it (``rosbag record``
killed, its ``.bag.active`` file; a disk that filled up; a copy cut off), is read from its
chunks instead, walked from the start as ``rosbag reindex`` walks them (:attr:`Bag1Reader.repaired`
says why): every complete chunk, and of an uncompressed chunk cut short, every message
written in full before the cut.
``tests/tracker/test_bag1.py`` checks that both readers give the same connections, the same
messages in the same order and the same decoded messages on every real recording.
"""

from __future__ import annotations

import bz2
import mmap
import struct
from pathlib import Path

import numpy as np
from rosbags.interfaces import Connection, ConnectionExtRosbag1, MessageDefinition, MessageDefinitionFormat
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.msg import normalize_msgtype

from people_tracker.tracker.io.mapped import MappedRecording

_MAGIC = b"#ROSBAG V2.0\n"
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_TIME = struct.Struct("<II")
_OP_MSG_DATA, _OP_INDEX_DATA, _OP_CHUNK, _OP_CHUNK_INFO, _OP_CONNECTION = 2, 4, 5, 6, 7
_INDEX_ENTRY = np.dtype([("sec", "<u4"), ("nsec", "<u4"), ("offset", "<u4")])


class _Unreadable(Exception):
    """Something this reader does not read; ``rosbags`` gets the file instead."""


def _fields(buf: bytes) -> dict[bytes, bytes]:
    """A record header's ``name=value`` fields (each a uint32 length, then the bytes)."""
    out, pos, end = {}, 0, len(buf)
    while pos < end:
        if pos + 4 > end:
            raise _Unreadable("a header field is cut short")
        size = _U32.unpack_from(buf, pos)[0]
        pos += 4
        name, sep, value = buf[pos:pos + size].partition(b"=")
        if not sep or pos + size > end:
            raise _Unreadable("a header field cannot be parsed")
        out[name] = value
        pos += size
    return out


def _header_at(buf, at: int, end: int) -> tuple[dict[bytes, bytes], int, int] | None:
    """The record at ``at`` of ``buf`` (read up to ``end``): its header fields, where its
    data starts and the data's length as the record gives it (which may reach past
    ``end``); None when its header is cut short or cannot be parsed."""
    if at + 8 > end:
        return None
    data = at + 4 + _U32.unpack_from(buf, at)[0]
    if data + 4 > end:
        return None
    try:
        fields = _fields(buf[at + 4:data])
    except _Unreadable:
        return None
    return fields, data + 4, _U32.unpack_from(buf, data)[0]


def _get(fields: dict[bytes, bytes], name: bytes, fmt: struct.Struct):
    value = fields.get(name)
    if value is None or len(value) != fmt.size:
        raise _Unreadable(f"a record lacks its {name.decode()} field")
    return fmt.unpack(value)


class Bag1Reader(MappedRecording):
    """An open, indexed ROS 1 (v2.0) bag with the parts of ``rosbags.highlevel.AnyReader``
    the tracker uses: ``connections``, ``start_time`` and ``end_time`` (ns), ``is2``,
    ``messages``, ``deserialize``, ``close`` and ``stack`` (not None while open)."""

    is2 = False
    repaired: str | None = None  # why the index was rebuilt from the chunks (None: read from the bag's index)

    def __init__(self, path: Path) -> None:
        super().__init__(path)  # maps the file and reads its index (_read)
        self._typestore = get_typestore(Stores.EMPTY)
        self._registered: set[str] = set()
        self._chunk_pos = -1
        self._chunk: bytes | mmap.mmap = b""
        self._chunk_base = 0
        # the file's bytes, for reading every message's header at once where no chunk is compressed
        plain = all(kind == b"none" for _, _, kind in self._chunks.values())
        self._u8 = np.frombuffer(self._map, dtype=np.uint8) if plain else None

    # ----- the index, read on opening
    def _read(self) -> None:
        self._read_index()

    def _record(self, pos: int) -> tuple[dict[bytes, bytes], int, int, int]:
        """The record at ``pos``: (header fields, data start, data length, next record)."""
        head = _header_at(self._map, pos, len(self._map))
        if head is None or head[1] + head[2] > len(self._map):
            raise _Unreadable("a record lies beyond the end of the file, or its header cannot be parsed")
        fields, start, dlen = head
        return fields, start, dlen, start + dlen

    def _read_index(self) -> None:
        m = self._map
        if m[:len(_MAGIC)] != _MAGIC:
            raise _Unreadable("not a v2.0 bag")
        header, _, _, _ = self._record(len(_MAGIC))
        if header.get(b"encryptor"):
            raise _Unreadable("encrypted")
        (index_pos,) = _get(header, b"index_pos", _U64)
        (conn_count,) = _get(header, b"conn_count", _U32)
        (chunk_count,) = _get(header, b"chunk_count", _U32)
        if index_pos == 0:
            self._read_chunks("no index")
            return
        if chunk_count == 0:
            raise _Unreadable("empty")
        try:
            self._read_indexed(index_pos, conn_count, chunk_count)
        except (_Unreadable, struct.error, ValueError, UnicodeDecodeError):
            self._read_chunks("a damaged index" if index_pos < len(m) else "its index cut off")

    def _read_indexed(self, index_pos: int, conn_count: int, chunk_count: int) -> None:
        """The connections and every message's place from the index at ``index_pos``."""
        m = self._map
        pos = index_pos
        self.connections: list[Connection] = []
        for _ in range(conn_count):
            fields, start, size, pos = self._record(pos)
            if fields.get(b"op") != bytes([_OP_CONNECTION]):
                raise _Unreadable("expected a connection record")
            self.connections.append(self._connection(fields, m[start:start + size]))
        chunk_pos: list[int] = []
        starts, ends = [], []
        for _ in range(chunk_count):
            fields, start, size, pos = self._record(pos)
            if fields.get(b"op") != bytes([_OP_CHUNK_INFO]) or _get(fields, b"ver", _U32)[0] != 1:
                raise _Unreadable("expected a version-1 chunk info record")
            (count,) = _get(fields, b"count", _U32)
            chunk_pos.append(_get(fields, b"chunk_pos", _U64)[0])
            if count:
                sec, nsec = _get(fields, b"start_time", _TIME)
                starts.append(sec * 10**9 + nsec)
                sec, nsec = _get(fields, b"end_time", _TIME)
                ends.append(sec * 10**9 + nsec + 1)
        self.start_time = min(starts, default=2**63 - 1)
        self.end_time = max(ends, default=0)
        # each chunk: its data's place (and compression), then one index record per connection
        self._chunks: dict[int, tuple[int, int, bytes]] = {}
        parts: dict[int, list] = {c.id: [] for c in self.connections}
        for cpos in chunk_pos:
            fields, start, size, pos = self._record(cpos)
            if fields.get(b"op") != bytes([_OP_CHUNK]):
                raise _Unreadable("expected a chunk record")
            compression = fields.get(b"compression", b"")
            if compression not in (b"none", b"bz2", b"lz4"):
                raise _Unreadable("unknown compression")
            self._chunks[cpos] = (start, size, compression)
            while pos < index_pos:
                fields, start, size, after = self._record(pos)
                if fields.get(b"op") != bytes([_OP_INDEX_DATA]):
                    break
                if _get(fields, b"ver", _U32)[0] != 1:
                    raise _Unreadable("index data of another version")
                (conn,) = _get(fields, b"conn", _U32)
                (count,) = _get(fields, b"count", _U32)
                if conn not in parts or size != 12 * count:
                    raise _Unreadable("index data that does not match its connection")
                entries = np.frombuffer(m[start:start + size], dtype=_INDEX_ENTRY)
                parts[conn].append((entries, cpos))
                pos = after
        self._build_index(parts)

    def _build_index(self, parts: dict[int, list]) -> None:
        """Each connection's messages from ``parts`` (connection id -> a list of (index
        entries, chunk position)), and the connections' message counts."""
        # per connection: each message's bag time (ns), chunk, offset in the chunk's records,
        # and where those records start in the file (the record's place, for uncompressed chunks)
        self._index: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}
        for conn, chunks in parts.items():
            if chunks:
                time = np.concatenate([e["sec"].astype(np.int64) * 10**9 + e["nsec"] for e, _ in chunks])
                where = np.concatenate([np.full(len(e), cpos, dtype=np.int64) for e, cpos in chunks])
                offset = np.concatenate([e["offset"].astype(np.int64) for e, _ in chunks])
                base = np.concatenate([np.full(len(e), self._chunks[cpos][0], dtype=np.int64) for e, cpos in chunks])
            else:
                time = where = offset = base = np.zeros(0, dtype=np.int64)
            self._index[conn] = (time, where, offset, base)
        self.connections = [Connection(c.id, c.topic, c.msgtype, c.msgdef, c.digest, len(self._index[c.id][0]),
                                        c.ext, c.owner) for c in self.connections]

    def _read_chunks(self, why: str) -> None:
        """The connections and every message's place read from the chunks themselves, walked
        from the first record after the bag's header to where the file ends or stops making
        sense, as ``rosbag reindex`` does (the bag has ``why``: no index, or a damaged one).
        A chunk cut short keeps the messages written in full before the cut when it is
        uncompressed (its size may also still be 0, as ``rosbag record`` leaves the chunk it
        was writing); a compressed one cut short is lost."""
        m = self._map
        _, _, _, pos = self._record(len(_MAGIC))  # the bag's header record
        conns: dict[int, Connection] = {}
        entries: dict[int, list[tuple[int, int, int, int]]] = {}  # conn -> (sec, nsec, offset, chunk position)
        self._chunks = {}
        self._chunk_pos, self._chunk = -1, b""
        while (head := _header_at(m, pos, len(m))) is not None:
            fields, start, dlen = head
            op, end = fields.get(b"op"), start + dlen
            if op == bytes([_OP_CHUNK]):
                compression = fields.get(b"compression", b"")
                if compression not in (b"none", b"bz2", b"lz4"):
                    break
                if compression == b"none" and (dlen == 0 or end > len(m)):  # still being written, or cut short
                    walked = self._walk_chunk(m, start, len(m), pos, conns, entries)
                    self._chunks[pos] = (start, walked - start, compression)
                    break  # nothing after it can be trusted
                if end > len(m):
                    break  # a compressed chunk cut short: lost
                self._chunks[pos] = (start, dlen, compression)
                try:
                    records, chunk_base = self._chunk_data(pos)
                except Exception:  # noqa: BLE001 - a chunk that does not decompress (bz2, lz4 raise several types): the cut
                    del self._chunks[pos]
                    break
                self._walk_chunk(records, chunk_base, chunk_base + (dlen if compression == b"none" else len(records)),
                                 pos, conns, entries)
            elif op == bytes([_OP_CONNECTION]):  # the index's copy of a connection
                if end > len(m):
                    break
                try:
                    conn = self._connection(fields, m[start:end])
                except (_Unreadable, UnicodeDecodeError):
                    break
                conns.setdefault(conn.id, conn)
            elif op not in (bytes([_OP_INDEX_DATA]), bytes([_OP_CHUNK_INFO])):
                break
            pos = end
        self._chunk_pos, self._chunk = -1, b""
        if not entries:
            raise _Unreadable(f"{why}, and no message could be read from its chunks")
        self.connections = [conns[k] for k in sorted(conns)]
        parts: dict[int, list] = {k: [] for k in conns}
        for conn, rows in entries.items():
            by_chunk: dict[int, list] = {}
            for sec, nsec, off, cpos in rows:
                by_chunk.setdefault(cpos, []).append((sec, nsec, off))
            parts[conn] = [(np.array(v, dtype=_INDEX_ENTRY), cpos) for cpos, v in by_chunk.items()]
        self._build_index(parts)
        times = np.concatenate([time for time, _, _, _ in self._index.values()])
        self.start_time, self.end_time = int(times.min()), int(times.max()) + 1
        self.repaired = why

    def _walk_chunk(self, records, at: int, end: int, cpos: int, conns: dict, entries: dict) -> int:
        """Note every connection and message record of one chunk's ``records``, from ``at``
        to ``end`` (the chunk at ``cpos``); stops at a record cut short or not a chunk's.
        Returns where the last whole record ends."""
        first = at
        while (head := _header_at(records, at, end)) is not None:
            fields, data, dlen = head
            if data + dlen > end:
                break
            op = fields.get(b"op")
            try:
                if op == bytes([_OP_MSG_DATA]):
                    (conn,) = _get(fields, b"conn", _U32)
                    sec, nsec = _get(fields, b"time", _TIME)
                    if conn not in conns:
                        break  # a message of no connection seen: not a record of this chunk
                    entries.setdefault(conn, []).append((sec, nsec, at - first, cpos))
                elif op == bytes([_OP_CONNECTION]):
                    conn = self._connection(fields, records[data:data + dlen])
                    conns.setdefault(conn.id, conn)
                else:
                    break
            except (_Unreadable, UnicodeDecodeError):
                break
            at = data + dlen
        return at

    def _connection(self, fields: dict[bytes, bytes], data: bytes) -> Connection:
        (conn,) = _get(fields, b"conn", _U32)
        topic = fields.get(b"topic", b"").decode()
        info = _fields(data)
        if b"type" not in info or b"md5sum" not in info or not info.get(b"message_definition"):
            raise _Unreadable("a connection without its type or definition")
        latching = info.get(b"latching")
        return Connection(
            conn,
            f'{"/" * topic.startswith("/")}{"/".join(x for x in topic.split("/") if x)}',  # as rosbags
            normalize_msgtype(info[b"type"].decode()),
            MessageDefinition(MessageDefinitionFormat.MSG, info[b"message_definition"].decode()),
            info[b"md5sum"].decode(),
            0,
            ConnectionExtRosbag1(info[b"callerid"].decode() if b"callerid" in info else None,
                                 int(latching) if latching not in (None, b"") else None),
            self,
        )

    # ----- reading
    def _chunk_data(self, cpos: int) -> tuple[bytes | mmap.mmap, int]:
        """The chunk's uncompressed records and where in them its first one starts."""
        if cpos != self._chunk_pos:
            start, size, compression = self._chunks[cpos]
            if compression == b"none":
                self._chunk, self._chunk_base = self._map, start
            elif compression == b"bz2":
                self._chunk, self._chunk_base = bz2.decompress(self._map[start:start + size]), 0
            else:
                from lz4.frame import decompress  # a dependency of rosbags
                self._chunk, self._chunk_base = decompress(self._map[start:start + size]), 0
            self._chunk_pos = cpos
        return self._chunk, self._chunk_base

    def messages(self, connections=(), start: int | None = None, stop: int | None = None):
        """(connection, bag time in ns, serialized bytes) of every message on
        ``connections`` (all by default) in bag-time order, from ``start`` to before
        ``stop`` (ns)."""
        if self.stack is None:
            raise ValueError("the bag is closed")
        conns = list(connections) or self.connections
        index = [self._index[c.id] for c in conns]
        time, where, offset, base = (np.concatenate([part[i] for part in index]) for i in range(4))
        which = np.concatenate([np.full(len(part[0]), k) for k, part in enumerate(index)])
        order = np.lexsort((offset, where, time))
        lo = 0 if start is None else int(np.searchsorted(time[order], start, side="left"))
        hi = len(time) if stop is None else int(np.searchsorted(time[order], stop, side="left"))
        order = order[lo:hi]
        time, where, offset, base, which = time[order], where[order], offset[order], base[order], which[order]
        if self._u8 is not None and len(time):  # uncompressed: the headers read many at once
            data = self._map
            lo, batch = 0, _FIRST_BATCH
            while lo < len(time):  # in growing batches: a reader that stops early reads few
                hi = min(lo + batch, len(time))
                at, size, ok = _message_spans(self._u8, base[lo:hi] + offset[lo:hi])
                for t, cpos, off, k, a, n, good in zip(time[lo:hi].tolist(), where[lo:hi].tolist(),
                                                       offset[lo:hi].tolist(), which[lo:hi].tolist(), at.tolist(),
                                                       size.tolist(), ok.tolist()):
                    if not good:  # another layout: read field by field
                        a, n = self._walk(data, cpos, off, self._chunks[cpos][0] + off)
                    yield conns[k], t, data[a:a + n]
                lo, batch = hi, min(4 * batch, _LAST_BATCH)
            return
        for t, cpos, off, k in zip(time.tolist(), where.tolist(), offset.tolist(), which.tolist()):
            data, chunk_base = self._chunk_data(cpos)
            a, n = self._walk(data, cpos, off, chunk_base + off)
            yield conns[k], t, data[a:a + n]

    @staticmethod
    def _walk(data, cpos: int, off: int, at: int) -> tuple[int, int]:
        """Where the message data of the record at ``at`` starts, and its length, reading
        its header field by field (connection records may come first, as rosbags allows)."""
        while True:
            end = at + 4 + _U32.unpack_from(data, at)[0]
            op = _fields(data[at + 4:end]).get(b"op")  # the index gave the rest
            size = _U32.unpack_from(data, end)[0]
            at = end + 4
            if op != bytes([_OP_CONNECTION]):
                break
            at += size
        if op != bytes([_OP_MSG_DATA]) or at + size > len(data):
            raise ValueError(f"no message data at offset {off} of the chunk at {cpos}, where the index points")
        return at, size

    def deserialize(self, raw: bytes, msgtype: str):
        """The message ``raw`` decoded as ``msgtype``, with the definitions the bag holds
        for it (parsed, and checked against their MD5 sum, on first use)."""
        if msgtype not in self._registered:
            types: dict = {}
            digests = set()
            for c in self.connections:
                if c.msgtype == msgtype:
                    types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
                    digests.add(c.digest)
            self._typestore.register(types)
            for digest in digests:
                have = self._typestore.generate_msgdef(msgtype)[1]
                if have != digest:
                    raise ValueError(f"message type {msgtype!r} hash mismatch {have} != {digest}")
            self._registered.add(msgtype)
        return self._typestore.deserialize_ros1(raw, msgtype)

    def _release(self) -> None:
        self._chunk = b""
        self._u8 = None  # the file's bytes as an array hold the map open


# the message headers an uncompressed bag's messages() reads at once: few first (the caller
# may want one message, as the topic and frame discovery do), then more and more
_FIRST_BATCH, _LAST_BATCH = 16, 16384


def _u32_at(u8: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The little-endian uint32 at each position of ``at`` in the bytes ``u8``, as int64."""
    b = u8[at[:, None] + np.arange(4)].astype(np.int64)
    return b[:, 0] | (b[:, 1] << 8) | (b[:, 2] << 16) | (b[:, 3] << 24)


def _message_spans(u8: np.ndarray, record: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For message data records at ``record`` (positions in the file), where each one's
    data starts, its length, and whether that was read for sure: the header must be three
    fields that fill it exactly (as rosbag writes them: time, conn, op, in any order), one
    of them ``op=`` with the message data's code. Others are read field by field."""
    n = len(u8)
    ok = record + 8 <= n
    rec = np.where(ok, record, 0)
    header_end = rec + 4 + _u32_at(u8, rec)
    at = rec + 4
    op_ok = np.zeros(len(rec), dtype=bool)
    for _ in range(3):
        ok &= at + 8 <= header_end
        at = np.where(ok, at, 0)
        size = _u32_at(u8, at)
        name = u8[(at + 4)[:, None] + np.arange(4)]
        op_ok |= ok & (size == 4) & (name[:, 0] == ord("o")) & (name[:, 1] == ord("p")) & (name[:, 2] == ord("=")) & (
            name[:, 3] == _OP_MSG_DATA)
        at = at + 4 + size
    ok &= op_ok & (at == header_end) & (header_end + 4 <= n)
    header_end = np.where(ok, header_end, 0)
    size = _u32_at(u8, header_end)
    ok &= header_end + 4 + size <= n
    return header_end + 4, size, ok


def open_bag1(path: Path) -> Bag1Reader | None:
    """``path`` opened with :class:`Bag1Reader`, or None when that reader does not read it
    (the caller then uses ``rosbags``)."""
    try:
        return Bag1Reader(path)
    except (_Unreadable, struct.error, ValueError, UnicodeDecodeError, OSError):
        return None
