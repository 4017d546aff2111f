"""The rerun recording read back with rerun's own reader: entities and counts."""

import csv

import pytest

from tests_helpers import run_cli

rc = pytest.importorskip("rerun.chunk")


def _columns(path):
    """entity path -> {column name: list of per-row values}, rows across all chunks."""
    out = {}
    for chunk in rc.RrdReader(str(path)).store().stream():
        table = chunk.to_record_batch().to_pydict()
        cols = out.setdefault(chunk.entity_path, {})
        for name, values in table.items():
            cols.setdefault(name, []).extend(values)
    return out


def test_rrd_holds_scan_labels_tracks_and_truth(tmp_path):
    rrd, tracks = tmp_path / "run.rrd", tmp_path / "t.csv"
    proc = run_cli("run", "--rrd", str(rrd), "--tracks", str(tracks))  # the built-in crossing scene
    assert proc.returncode == 0, proc.stderr
    data = _columns(rrd)
    for entity in ("/world/scan", "/world/objects/hulls", "/world/objects/boxes", "/world/candidates",
                   "/world/tracks", "/world/tracks/trails", "/world/tracks/covariance", "/world/robot",
                   "/world/robot/path", "/world/ground_truth", "/metrics/people", "/metrics/latency_ms",
                   "/world/overview/tracks"):
        assert entity in data, f"{entity} missing (have {sorted(data)})"
    scan = data["/world/scan"]
    assert sorted(scan["scan"]) == list(range(200))
    # the first scan's readings, all of them valid in this room, with their set labels
    from people_tracker.tracker.io.simulated import SimulatedSource
    first = next(SimulatedSource("crossing").scans()).scan
    row0 = scan["scan"].index(0)
    assert len(scan["Points2D:positions"][row0]) == first.n_valid
    labels = set(v for row in scan["Points2D:class_ids"] if row for v in row)
    assert labels <= {1, 2, 3, 4} and {1, 2} <= labels  # static and moving readings
    # tracks per scan equal the rows of tracks.csv
    per_scan = {}
    for r in csv.DictReader(tracks.open()):
        per_scan[int(r["scan_index"])] = per_scan.get(int(r["scan_index"]), 0) + 1
    tr = data["/world/tracks"]
    for idx, positions in zip(tr["scan"], tr["Points2D:positions"]):
        assert len(positions or []) == per_scan.get(idx, 0)
    ids = set(v.split()[0] for row in tr["Points2D:labels"] if row for v in row)
    assert ids == {r["track_id"] for r in csv.DictReader(tracks.open())}
    truth = data["/world/ground_truth"]
    assert max(len(p or []) for p in truth["Points2D:positions"]) == 2


def test_failed_run_leaves_no_rrd(tmp_path):
    (tmp_path / "bad.bag").write_bytes(b"garbage" * 100)
    proc = run_cli("run", str(tmp_path / "bad.bag"), "--rrd", str(tmp_path / "x.rrd"))
    assert proc.returncode == 2 and list(tmp_path.iterdir()) == [tmp_path / "bad.bag"]


def test_ctrl_c_while_the_recording_starts_leaves_no_hidden_file(tmp_path, monkeypatch):
    # on a loaded machine Ctrl-C can come while rerun is still starting, after the hidden
    # .part file beside the target was made
    import rerun as rr

    from people_tracker.tracker.viz_rerun import RerunSink

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(rr.RecordingStream, "send_blueprint", interrupted)
    with pytest.raises(KeyboardInterrupt):
        RerunSink(tmp_path / "r.rrd")
    assert list(tmp_path.iterdir()) == []
