"""The fast ROS 1 bag reader gives what rosbags gives, and /tf read in place is /tf deserialized."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
from conftest import DATA
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_typestore

from people_tracker.tracker.io.bag import ODOMETRY, TF_MESSAGE, open_bag, peek_odometry_frames, peek_transforms
from people_tracker.tracker.io.bag1 import Bag1Reader, open_bag1

REAL_BAGS = sorted(DATA.glob("leigh/**/*.bag")) if DATA.exists() else []


def _rosbags(path: Path) -> AnyReader:
    reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    reader.open()
    return reader


def _connections(reader) -> list[tuple]:
    return [(c.id, c.topic, c.msgtype, c.msgdef, c.digest, c.msgcount, c.ext) for c in reader.connections]


def _same_as_rosbags(path: Path, decode_each: int = 3) -> int:
    """Checks both readers agree on ``path``; returns how many messages it holds."""
    slow, fast = _rosbags(path), open_bag1(path)
    assert isinstance(fast, Bag1Reader)
    try:
        assert _connections(fast) == _connections(slow)
        assert (fast.start_time, fast.end_time) == (slow.start_time, slow.end_time)
        every = [(c.id, t, bytes(raw)) for c, t, raw in slow.messages()]
        assert [(c.id, t, bytes(raw)) for c, t, raw in fast.messages()] == every
        # some connections, between two times
        mid = (slow.start_time + slow.end_time) // 2
        for pick in (slow.connections[:1], slow.connections[-2:]):
            ids = {c.id for c in pick}
            want = [(c.id, t, bytes(raw)) for c, t, raw in slow.messages(connections=pick, start=slow.start_time + 1,
                                                                          stop=mid)]
            got = [(c.id, t, bytes(raw)) for c, t, raw in fast.messages(
                connections=[c for c in fast.connections if c.id in ids], start=fast.start_time + 1, stop=mid)]
            assert got == want
        decoded: dict[str, int] = {}
        for conn, _, raw in fast.messages():
            if decoded.get(conn.msgtype, 0) < decode_each:
                decoded[conn.msgtype] = decoded.get(conn.msgtype, 0) + 1
                assert repr(fast.deserialize(raw, conn.msgtype)) == repr(slow.deserialize(raw, conn.msgtype))
        return len(every)
    finally:
        slow.close()
        fast.close()


@pytest.mark.parametrize("path", REAL_BAGS, ids=lambda p: p.name)
def test_the_fast_reader_reads_every_real_recording_as_rosbags_does(path):
    assert _same_as_rosbags(path) > 0


def test_the_real_recordings_are_there():
    if not DATA.exists():
        pytest.skip(f"the real recordings are not here ({DATA}); they live in ../shared/data")
    assert len(REAL_BAGS) >= 10


def _rewritten(plain: Path, out: Path, compression) -> Path:
    """The bag ``plain`` written again to ``out`` in chunks of about 20 kB (several, so that
    the merge across chunks is tested), compressed with ``compression`` (None: stored)."""
    from tests_helpers import copy_messages

    writer = Writer(out)
    writer.chunk_threshold = 20_000
    if compression is not None:
        writer.set_compression(compression)
    copy_messages(plain, writer, "md5sum")
    return out


@pytest.mark.parametrize("compression", [None, Writer.CompressionFormat.BZ2, Writer.CompressionFormat.LZ4],
                         ids=["none", "bz2", "lz4"])
def test_the_fast_reader_reads_compressed_chunks_as_rosbags_does(tmp_path, compression):
    from tests_helpers import simulated_corridor

    out = _rewritten(simulated_corridor(tmp_path, "ros1", seconds=3.0), tmp_path / "copy.bag", compression)
    assert _same_as_rosbags(out) > 100
    reader = open_bag1(out)
    try:  # what was tested: several chunks, stored as asked
        kinds = {kind for _, _, kind in reader._chunks.values()}
        assert len(reader._chunks) > 2 and kinds == {b"none" if compression is None else compression.name.lower().encode()}
    finally:
        reader.close()


def test_what_the_fast_reader_cannot_read_goes_to_rosbags(tmp_path, moving_bag):
    head = tmp_path / "head.bag"
    head.write_bytes(moving_bag.read_bytes()[:5000])  # the bag's header and the start of a chunk, no message
    assert open_bag1(head) is None
    with pytest.raises(Exception) as err:
        open_bag(head)
    assert "cannot be read as a ROS 1 bag" in str(err.value)
    other = tmp_path / "v13.bag"
    other.write_bytes(b"#ROSBAG V1.3\n" + bytes(100))
    assert open_bag1(other) is None


def _all(reader) -> list[tuple]:
    return [(c.id, c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]


def _record_ends(reader) -> dict[tuple, int]:
    """Where in the file each message's record ends (an uncompressed bag), by (connection, time, bytes)."""
    out = {}
    for c in reader.connections:
        time, _, offset, base = reader._index[c.id]
        for t, at in zip(time.tolist(), (base + offset).tolist()):
            a, n = reader._walk(reader._map, 0, 0, at)
            out[(c.id, c.topic, t, bytes(reader._map[a:a + n]))] = a + n
    return out


def test_a_bag_cut_short_is_read_from_its_chunks(tmp_path, moving_bag, caplog):
    """A recording cut short (the index at the end gone, and maybe the end of a chunk) gives
    every message written in full before the cut, as 'rosbag reindex' would recover them,
    and says so once."""
    full = open_bag1(moving_bag)
    try:
        every, ends = _all(full), _record_ends(full)
    finally:
        full.close()
    data = moving_bag.read_bytes()
    for cut in (len(data) - 1000, len(data) // 2 + 12345, 4_100_000):  # in the index; mid-chunk; mid-message
        path = tmp_path / f"cut{cut}.bag"
        path.write_bytes(data[:cut])
        reader = open_bag1(path)
        try:
            assert reader.repaired in ("its index cut off", "a damaged index")
            want = [m for m in every if ends[m] <= cut]
            assert _all(reader) == want and len(want) > 70
            assert sum(c.msgcount for c in reader.connections) == len(want)
            assert (reader.start_time, reader.end_time) == (min(m[2] for m in want), max(m[2] for m in want) + 1)
        finally:
            reader.close()
    with caplog.at_level(logging.WARNING):
        for _ in range(2):
            open_bag(path).close()
    said = [r.getMessage() for r in caplog.records if "cut short" in r.getMessage()]
    assert len(said) == 1 and str(path) in said[0]


def test_a_bag_never_closed_is_read_whole(tmp_path, moving_bag):
    """``rosbag record`` killed leaves NAME.bag.active with no index (index_pos 0); its last
    chunk may still carry size 0, the records written after its header."""
    data = bytearray(moving_bag.read_bytes())
    full = open_bag1(moving_bag)
    try:
        every = _all(full)
        last = max(full._chunks)  # the last chunk's record, and where its records end
        start, size, _ = full._chunks[last]
    finally:
        full.close()
    at = data.index(b"index_pos=") + len(b"index_pos=")
    data[at:at + 8] = bytes(8)  # not indexed
    hlen = int.from_bytes(data[last:last + 4], "little")
    size_at = data.index(b"size=", last, last + 4 + hlen) + len(b"size=")
    data[size_at:size_at + 4] = bytes(4)  # the chunk's size not yet written ...
    data[start - 4:start] = bytes(4)
    active = tmp_path / "rec.bag.active"
    active.write_bytes(bytes(data[:start + size]))  # ... and nothing after its records
    reader = open_bag(active)
    try:
        assert reader.repaired == "no index" and _all(reader) == every
    finally:
        reader.close()


@pytest.mark.parametrize("compression", [Writer.CompressionFormat.BZ2, Writer.CompressionFormat.LZ4], ids=["bz2", "lz4"])
def test_a_compressed_bag_cut_short_keeps_its_whole_chunks(tmp_path, compression):
    from tests_helpers import simulated_corridor

    out = _rewritten(simulated_corridor(tmp_path, "ros1", seconds=3.0), tmp_path / "packed.bag", compression)
    full = open_bag1(out)
    try:
        every = _all(full)
        chunks = sorted(full._chunks.items())  # (record position, (data start, size, compression))
        by_chunk = {}
        for c in full.connections:
            for cpos in full._index[c.id][1].tolist():
                by_chunk[cpos] = by_chunk.get(cpos, 0) + 1
    finally:
        full.close()
    (cpos, (start, size, _)) = chunks[len(chunks) // 2]
    cut = tmp_path / "cut.bag"
    cut.write_bytes(out.read_bytes()[:start + size // 2])  # halfway through a chunk
    reader = open_bag1(cut)
    try:
        got = _all(reader)
        assert reader.repaired == "its index cut off"
        assert set(got) <= set(every) and len(got) == sum(n for p, n in by_chunk.items() if p < cpos) > 0
    finally:
        reader.close()


def test_a_closed_fast_reader_reads_nothing(moving_bag):
    reader = open_bag1(moving_bag)
    reader.close()
    reader.close()  # twice is harmless
    assert reader.stack is None
    with pytest.raises(ValueError):
        next(reader.messages())


def _transforms_both_ways(path) -> tuple[list, int]:
    reader = open_bag(path)
    try:
        pairs, odometry = [], 0
        for conn, _, raw in reader.messages(connections=[c for c in reader.connections
                                                         if c.msgtype in (TF_MESSAGE, ODOMETRY)]):
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.msgtype == ODOMETRY:
                assert peek_odometry_frames(raw, not reader.is2) == (msg.header.frame_id, msg.child_frame_id)
                odometry += 1
                continue
            full = [(tr.header.stamp.sec + tr.header.stamp.nanosec * 1e-9, tr.header.frame_id, tr.child_frame_id,
                     (tr.transform.translation.x, tr.transform.translation.y, tr.transform.translation.z,
                      tr.transform.rotation.x, tr.transform.rotation.y, tr.transform.rotation.z,
                      tr.transform.rotation.w)) for tr in msg.transforms]
            pairs.append((peek_transforms(raw, not reader.is2), full))
        return pairs, odometry
    finally:
        reader.close()


@pytest.mark.parametrize("fmt", ["mcap", "sqlite3", "ros1"])
def test_tf_read_in_place_is_the_deserialized_tf(tmp_path, fmt):
    from tests_helpers import simulated_corridor

    pairs, odometry = _transforms_both_ways(simulated_corridor(tmp_path, fmt))
    assert len(pairs) > 10 and odometry > 10
    assert all(fast == full for fast, full in pairs)


def test_tf_read_in_place_on_the_real_recording(moving_bag):
    pairs, odometry = _transforms_both_ways(moving_bag)
    assert len(pairs) == 21744 and odometry == 11561
    assert all(fast == full for fast, full in pairs)
    assert len({len(full) for _, full in pairs}) > 1  # messages with one transform and with several


def test_tf_of_bytes_cut_short_or_too_long_is_none_not_garbage(moving_bag):
    reader = open_bag(moving_bag)
    try:
        conns = [c for c in reader.connections if c.msgtype == TF_MESSAGE]
        raw = bytes(next(raw for _, _, raw in reader.messages(connections=conns)))
    finally:
        reader.close()
    assert peek_transforms(raw, True)
    for cut in (0, 3, 4, 20, len(raw) - 1):
        assert peek_transforms(raw[:cut], True) is None
    assert peek_transforms(raw + b"\x00", True) is None
    assert peek_transforms(b"\x00\x01\x00\x00\xff\xff\xff\xff", False) is None


def test_headers_read_at_once_and_field_by_field_agree(moving_bag, monkeypatch):
    """The uncompressed path reads every message header at once; where it cannot be sure
    of a header (here: none on the real recording, so every one is forced), it reads field
    by field. Both give the same messages."""
    import people_tracker.tracker.io.bag1 as bag1

    reader = open_bag1(moving_bag)
    try:
        assert reader._u8 is not None  # an uncompressed bag: the at-once path
        conns = [c for c in reader.connections if c.topic in ("/scan", "/odom")]
        spans = []
        real = bag1._message_spans
        monkeypatch.setattr(bag1, "_message_spans", lambda u8, rec: spans.append(real(u8, rec)) or spans[-1])
        at_once = [(c.id, t, raw) for c, t, raw in reader.messages(connections=conns)]
        assert len(at_once) == 873 + 11561 and spans[0][2].all()  # every header read for sure
        monkeypatch.setattr(bag1, "_message_spans", lambda u8, rec: (*real(u8, rec)[:2], np.zeros(len(rec), bool)))
        assert [(c.id, t, raw) for c, t, raw in reader.messages(connections=conns)] == at_once
    finally:
        reader.close()


def test_run_on_a_recording_cut_short_tracks_what_is_there(tmp_path, moving_bag):
    """The command line on a cut recording: status 0, the warning once, and the tracks of
    the scans it holds those of the whole recording (tracking looks only backwards)."""
    from tests_helpers import run_cli

    cut = tmp_path / "cut.bag"
    cut.write_bytes(moving_bag.read_bytes()[:15_500_000])
    proc = run_cli("run", str(cut), "--tracks", str(tmp_path / "cut.csv"))
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.count("a recording cut short?") == 1 and "368 read, 368 used" in proc.stdout, proc.stderr
    assert run_cli("run", str(moving_bag), "-q", "--tracks", str(tmp_path / "full.csv")).returncode == 0

    def rows(name, below=None):
        lines = [line for line in (tmp_path / name).read_text().splitlines()[1:] if not line.startswith("#")]
        return [line for line in lines if below is None or int(line.split(",")[0]) < below]
    got = rows("cut.csv")
    assert len(got) > 100 and got == rows("full.csv", below=368)


def test_a_bag_chunk_that_does_not_decompress_ends_the_recording_there(tmp_path):
    from tests_helpers import simulated_corridor

    out = _rewritten(simulated_corridor(tmp_path, "ros1", seconds=3.0), tmp_path / "bz2.bag",
                     Writer.CompressionFormat.BZ2)
    full = open_bag1(out)
    try:
        every = _all(full)
        chunks = sorted(full._chunks.items())
        in_first = sum(int((full._index[c.id][1] == chunks[0][0]).sum()) for c in full.connections)
    finally:
        full.close()
    start, size, _ = chunks[1][1]
    data = bytearray(out.read_bytes())
    data[start:start + 64] = bytes(64)  # the second chunk's compressed bytes spoilt
    bad = tmp_path / "bad.bag"
    bad.write_bytes(bytes(data[:start + size]))
    reader = open_bag1(bad)
    try:
        got = _all(reader)
        assert len(got) == in_first > 0 and set(got) <= set(every)
    finally:
        reader.close()
