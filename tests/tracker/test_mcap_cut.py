"""An MCAP recording cut short (a recorder killed, power lost, a copy cut off) is read as far
as it goes: every message written in full before the cut, as rosbags reads the whole file."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.typesys import Stores, get_typestore
from tests_helpers import copy_messages, run_cli, simulated_corridor

from people_tracker.tracker.io.bag import open_bag
from people_tracker.tracker.io.mcap_cut import McapCutReader, open_mcap_cut


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    """40 s of the simulated corridor (odometry, /tf, /tf_static) as an MCAP bag: several chunks."""
    return simulated_corridor(tmp_path_factory.mktemp("mcap"), "mcap", seconds=40.0)


def _mcap(folder: Path) -> Path:
    return next(folder.glob("*.mcap"))


def _messages(reader) -> list[tuple]:
    return [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]


def _ends(reader: McapCutReader) -> list[int]:
    """Where in the file each message (in the order messages() gives them) ends: stored chunks only."""
    return [(reader._chunks[k][0] if k >= 0 else 0) + at + n for _, _, k, at, n in reader._rows.tolist()]


def test_a_whole_file_reads_as_rosbags_reads_it(recorded):
    slow = AnyReader([recorded], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    slow.open()
    fast = McapCutReader(_mcap(recorded))
    try:
        assert fast.repaired is None and len(fast._chunks) >= 3  # what is tested: several chunks
        assert [(c.topic, c.msgtype, c.msgcount) for c in fast.connections] == \
            [(c.topic, c.msgtype, c.msgcount) for c in slow.connections]
        every = _messages(slow)
        assert _messages(fast) == every and len(every) > 1000
        assert (fast.start_time, fast.end_time) == (slow.start_time, slow.end_time)
        decoded: dict[str, int] = {}
        for (c, _, raw), (cs, _, raw_s) in zip(fast.messages(), slow.messages()):
            if decoded.get(c.msgtype, 0) < 3:
                decoded[c.msgtype] = decoded.get(c.msgtype, 0) + 1
                assert repr(fast.deserialize(raw, c.msgtype)) == repr(slow.deserialize(raw_s, cs.msgtype))
        assert len(decoded) >= 3
    finally:
        slow.close()
        fast.close()


def test_a_file_cut_short_keeps_every_message_written_in_full(tmp_path, recorded):
    whole = McapCutReader(_mcap(recorded))
    try:
        every, ends = _messages(whole), _ends(whole)
    finally:
        whole.close()
    data = _mcap(recorded).read_bytes()
    for cut in (len(data) - 100, len(data) * 2 // 3, len(data) // 4 + 7):  # in the summary; in chunks
        path = tmp_path / f"cut{cut}.mcap"
        path.write_bytes(data[:cut])
        reader = open_mcap_cut(path)
        try:
            want = [m for m, end in zip(every, ends) if end <= cut]
            assert reader.repaired == ("its summary cut off" if want == every else "its end cut off")
            assert _messages(reader) == want and len(want) > 100
        finally:
            reader.close()


def _zstd_copy(recorded: Path, out: Path) -> Path:
    """The recording written again as an MCAP bag with zstd-compressed chunks."""
    writer = Writer2(out, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    copy_messages(recorded, writer, "rihs01")
    return out


def test_a_compressed_file_cut_short_keeps_its_whole_chunks(tmp_path, recorded):
    out = _zstd_copy(recorded, tmp_path / "zstd")
    whole = McapCutReader(_mcap(out))
    try:
        assert {compression for _, _, compression, _ in whole._chunks} == {"zstd"} and len(whole._chunks) >= 3
        every, chunk_of = _messages(whole), whole._rows[:, 2].tolist()
        second = whole._chunks[1]
    finally:
        whole.close()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(_mcap(out).read_bytes()[:second[0] + second[1] // 2])  # halfway through the second chunk
    reader = open_mcap_cut(cut)
    try:
        assert _messages(reader) == [m for m, k in zip(every, chunk_of) if k < 1] != []
    finally:
        reader.close()


def test_run_on_a_recording_folder_cut_short(tmp_path, recorded):
    """A recorder killed leaves its folder with one MCAP file cut short and no
    metadata.yaml: the command line reads what is there, says so, and tracks it as it
    tracks the same scans of the whole recording."""
    folder = tmp_path / "killed"
    folder.mkdir()
    data = _mcap(recorded).read_bytes()
    (folder / "killed_0.mcap").write_bytes(data[:len(data) // 2])
    proc = run_cli("run", str(folder), "--tracks", str(tmp_path / "cut.csv"))
    assert proc.returncode == 0, proc.stderr
    assert "no metadata.yaml" in proc.stderr and "cannot be read whole" in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 2, proc.stderr
    assert run_cli("run", str(recorded), "-q", "--tracks", str(tmp_path / "whole.csv")).returncode == 0

    def rows(name: str) -> list[str]:
        return [line for line in (tmp_path / name).read_text().splitlines()[1:] if not line.startswith("#")]
    got = rows("cut.csv")
    last = int(got[-1].split(",")[0])
    assert len(got) > 50 and got == [r for r in rows("whole.csv") if int(r.split(",")[0]) <= last]
    reader = open_bag(folder)  # and it reads as the reader above does
    try:
        assert isinstance(reader, McapCutReader)
    finally:
        reader.close()


def test_nothing_readable_is_still_one_line(tmp_path, recorded):
    head = tmp_path / "head.mcap"
    head.write_bytes(_mcap(recorded).read_bytes()[:20])
    proc = run_cli("run", str(head))
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "cannot be read as a ROS 2 recording" in proc.stderr


def test_a_sqlite_bag_folder_without_its_metadata_is_read_through_its_file(tmp_path):
    folder = simulated_corridor(tmp_path, "sqlite3", seconds=2.0)
    (folder / "metadata.yaml").unlink()
    proc = run_cli("run", str(folder))
    assert proc.returncode == 0 and "20 read, 20 used" in proc.stdout, proc.stderr
    assert proc.stderr.count("no metadata.yaml") == 1, proc.stderr


def test_a_split_recording_without_its_metadata_says_what_to_do(tmp_path, recorded):
    folder = tmp_path / "split"
    folder.mkdir()
    for k in range(2):
        (folder / f"split_{k}.mcap").write_bytes(_mcap(recorded).read_bytes())
    proc = run_cli("run", str(folder))
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "2 recording files" in proc.stderr and "ros2 bag reindex" in proc.stderr
    proc = run_cli("run", str(folder / "split_1.mcap"), "-q")  # one of them, on its own
    assert proc.returncode == 0, proc.stderr


def test_a_chunk_that_does_not_decompress_ends_the_recording_there(tmp_path, recorded):
    """Garbage where a compressed chunk's bytes should be (a disk error, a bad copy): the
    chunks before it are read, with no error from the decompressor."""
    out = _zstd_copy(recorded, tmp_path / "zstd")
    whole = McapCutReader(_mcap(out))
    try:
        every, chunk_of, second = _messages(whole), whole._rows[:, 2].tolist(), whole._chunks[1]
    finally:
        whole.close()
    data = bytearray(_mcap(out).read_bytes())
    data[second[0]:second[0] + 64] = bytes(64)  # the second chunk's first bytes zeroed
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data[:second[0] + second[1]]))  # and the file ends after it
    reader = open_mcap_cut(bad)
    try:
        assert _messages(reader) == [m for m, k in zip(every, chunk_of) if k < 1] != []
    finally:
        reader.close()
