"""Scoring: a small case worked out by hand, ground truth against itself, the CLI."""

import json

import numpy as np
import pytest

from tests_helpers import run_cli
from people_tracker.tracker.evaluation import TrackRows, evaluate, ospa
from people_tracker.tracker.io.ground_truth import GroundTruth, read_bag_ground_truth


def gt_of(rows, n_frames=None):
    a = np.array(rows, dtype=float)
    return GroundTruth(n_frames, a[:, 0].astype(int), a[:, 1].astype(int), a[:, 2], a[:, 3])


def tracks_of(rows):
    a = np.array(rows, dtype=float)
    target = a[:, 4].astype(int) if a.shape[1] > 4 else None
    return TrackRows(a[:, 0].astype(int), a[:, 1].astype(int), a[:, 2], a[:, 3], target)


# Person 1 stands at (1, 0) in frames 0-4, person 2 at (3, 0) in frames 0-2.
GT = gt_of([(k, 1, 1.0, 0.0) for k in range(5)] + [(k, 2, 3.0, 0.0) for k in range(3)], n_frames=5)
TRACKS = tracks_of([
    (0, 10, 1.1, 0.0, 1), (0, 20, 3.0, 0.2, 0),                        # both matched: 0.1 m, 0.2 m
    (1, 10, 1.0, 0.3, 1), (1, 20, 3.0, 0.0, 0), (1, 30, 6.0, 0.0, 0),  # matched 0.3 m, 0 m; 30 is a false positive
    (2, 11, 1.0, 0.0, 1),                                              # person 1 now track 11: an id switch; person 2 missed
    (3, 11, 2.0, 0.0, 1),                                              # 1.0 m > 0.75 m: a miss and a false positive
])                                                                     # frame 4: person 1 missed


def test_bearing_window_drops_people_and_tracks_outside_it_before_matching():
    # person 2 at (3, 0) and person 3 at (0, 2) (bearing 90 deg); track 40 beside person 3
    gt = gt_of([(0, 1, 1.0, 0.0), (0, 3, 0.0, 2.0), (1, 3, 0.0, 2.0)], n_frames=2)
    tr = tracks_of([(0, 10, 1.0, 0.1), (0, 40, 0.1, 2.0), (1, 40, 0.1, 2.0), (1, 50, -2.0, -0.5)])
    full = evaluate(gt, tr)
    assert (full["ground_truth"], full["matches"], full["false_positives"]) == (3, 3, 1)
    win = evaluate(gt, tr, bearing_window_deg=(-80.0, 12.0))
    assert (win["ground_truth"], win["matches"], win["misses"], win["false_positives"]) == (1, 1, 0, 0)
    assert win["frames"] == 2 and win["bearing_window_deg"] == [-80.0, 12.0]


def test_hand_worked_case():
    r = evaluate(GT, TRACKS, "general", threshold=0.75, ospa_cutoff=1.0, ospa_order=1.0)
    assert r["frames"] == 5 and r["ground_truth"] == 8
    assert (r["matches"], r["misses"], r["false_positives"], r["id_switches"]) == (5, 3, 2, 1)
    assert r["mota"] == pytest.approx(1 - (3 + 2 + 1) / 8)            # 0.25
    assert r["motp_m"] == pytest.approx((0.1 + 0.2 + 0.3 + 0.0 + 0.0) / 5)  # 0.12 m, in metres
    # IDF1: best one-to-one ids 1↔10 (frames 0, 1) and 2↔20 (frames 0, 1): IDTP = 4;
    # 8 ground-truth and 7 reported positions: 2·4 / (8 + 7)
    assert r["idf1"] == pytest.approx(8 / 15)
    # OSPA per frame (c = 1 m, p = 1): 0.3/2, (0.3 + 1)/3, (0 + 1)/2, 1, 1
    assert r["ospa_m"] == pytest.approx((0.15 + 1.3 / 3 + 0.5 + 1.0 + 1.0) / 5)


def test_following_protocol_scores_the_person_over_all_tracks_and_the_target():
    target_only = gt_of([(k, 1, 1.0, 0.0) for k in range(5)], n_frames=5)
    r = evaluate(target_only, TRACKS, "following")
    # every track may match person 1: 10 in frames 0, 1, then 11 in frame 2 (a switch); frame 3
    # (1.0 m away: a miss) and 4 (nothing): misses; tracks 20, 30 and the far 11 are false
    # positives, counted but not in MOTA
    assert (r["matches"], r["misses"], r["false_positives"], r["id_switches"]) == (3, 2, 4, 1)
    assert r["mota"] == pytest.approx(1 - (2 + 1) / 5)
    # the target (rows marked 1): on person 1 in frames 0-2 of the 5 after the lock in frame 0,
    # 1.0 m off in frame 3, changed from 10 to 11 once
    assert r["target_person"] == 1 and r["first_lock_scan"] == 0
    assert r["target_on_person"] == pytest.approx(3 / 5)
    assert (r["target_wrong_scans"], r["target_changes"]) == (1, 1)


def test_following_needs_to_know_whom_the_robot_follows():
    from people_tracker.tracker.errors import InputError
    with pytest.raises(InputError, match="--target-person"):
        evaluate(GT, TRACKS, "following")
    assert evaluate(GT, TRACKS, "following", target_person=2)["target_person"] == 2
    marked = GroundTruth(GT.n_frames, GT.scan_index, GT.person_id, GT.x, GT.y, (GT.person_id == 2).astype(int))
    assert evaluate(marked, TRACKS, "following")["target_person"] == 2
    with pytest.raises(InputError, match="not in the ground truth"):
        evaluate(GT, TRACKS, "following", target_person=7)


def test_target_on_someone_else_while_the_person_is_hidden_is_wrong():
    # person 1 visible in frames 0-1 only; person 2 at (3, 0) throughout; the target jumps to them
    gt = gt_of([(0, 1, 1.0, 0.0), (1, 1, 1.0, 0.0)] + [(k, 2, 3.0, 0.0) for k in range(4)], n_frames=4)
    tr = TrackRows(np.array([0, 1, 2, 3]), np.array([5, 5, 5, 5]), np.array([1.0, 1.0, 3.0, 1.0]),
                   np.zeros(4), np.ones(4, dtype=int), np.array([0.0, 0.1, 0.2, 0.3]))
    r = evaluate(gt, tr, "following", target_person=1)
    assert r["target_on_person"] == 1.0 and r["first_lock_s"] == pytest.approx(0.0)
    assert (r["target_wrong_scans"], r["target_changes"]) == (1, 0)  # frame 2 on person 2; frame 3 on nobody


def test_ground_truth_against_itself_is_perfect():
    as_tracks = TrackRows(GT.scan_index, GT.person_id + 100, GT.x, GT.y)
    r = evaluate(GT, as_tracks)
    assert (r["mota"], r["motp_m"], r["idf1"], r["ospa_m"], r["id_switches"]) == (1.0, 0.0, 1.0, 0.0, 0)


def test_every_scan_is_a_frame_and_people_in_empty_scans_are_false_positives():
    r = evaluate(gt_of([(0, 1, 1.0, 0.0)], n_frames=10), tracks_of([(0, 5, 1.0, 0.0), (9, 6, 2.0, 2.0)]))
    assert r["frames"] == 10 and r["false_positives"] == 1 and r["mota"] == 0.0
    assert r["ospa_m"] == pytest.approx(0.1)  # c = 1 in one frame of ten


def test_ospa_edge_cases():
    assert ospa(np.zeros((0, 2)), np.zeros((0, 2)), 1.0, 2.0) == 0.0
    assert ospa(np.zeros((1, 2)), np.zeros((0, 2)), 2.5, 1.0) == 2.5
    # order 2: sqrt((0.3² + 0.4²... ) one pair at 0.5 m and one unmatched (c = 1): sqrt((0.25 + 1)/2)
    assert ospa(np.array([[0, 0], [5, 5]]), np.array([[0.3, 0.4]]), 1.0, 2.0) == pytest.approx(np.sqrt(1.25 / 2))


def test_cli_scores_the_annotated_recording_against_its_own_ground_truth(tmp_path, moving_bag):
    gt = read_bag_ground_truth(moving_bag)
    f = tmp_path / "tracks.csv"
    f.write_text("scan_index,track_id,x,y\n" + "".join(
        f"{k},{p},{x},{y}\n" for k, p, x, y in zip(gt.scan_index, gt.person_id, gt.x, gt.y)))
    proc = run_cli("evaluate", str(f), "--ground-truth", str(moving_bag), "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 0, proc.stderr
    assert "MOTA                 100.0 %" in proc.stdout
    r = json.loads((tmp_path / "r.json").read_text())
    assert r["frames"] == 873 and r["ground_truth"] == 153 and r["matches"] == 153 and r["idf1"] == 1.0


def test_cli_scores_against_a_ground_truth_csv(tmp_path):
    (tmp_path / "gt.csv").write_text("scan_index,person_id,x,y\n0,1,1.0,0.0\n1,1,1.0,0.0\n")
    (tmp_path / "t.csv").write_text("scan_index,stamp,track_id,x,y,target\n0,0.0,4,1.2,0.0,0\n")
    proc = run_cli("evaluate", str(tmp_path / "t.csv"), "--ground-truth", str(tmp_path / "gt.csv"))
    assert proc.returncode == 0, proc.stderr
    assert "MOTA                 50.0 %" in proc.stdout and "MOTP                 0.200 m" in proc.stdout
    proc = run_cli("evaluate", str(tmp_path / "t.csv"), "--ground-truth", str(tmp_path / "gt.csv"),
                   "--bearing-window", "-80", "12")
    assert proc.returncode == 0 and "bearing -80°..12° only" in proc.stdout, proc.stderr


@pytest.mark.parametrize("tracks,args,words", [
    (None, [], "does not exist"),
    ("", [], "empty"),
    ("scan_index,x,y\n1,2,3\n", [], "track_id"),
    ("scan_index,track_id,x,y\n0,1,a,2\n", [], "line 2"),
    ("scan_index,track_id,x,y\n0,1,1,2\n", ["--threshold", "-1"], "--threshold"),
    ("scan_index,track_id,x,y\n0,1,1,2\n", ["--protocol", "other"], "invalid choice"),
    ("scan_index,track_id,x,y\n0,1,1,2\n", ["--bearing-window", "12", "-80"], "--bearing-window"),
    ("scan_index,track_id,x,y\n0,1,1,2\n", ["--bearing-window", "-200", "12"], "--bearing-window"),
])
def test_cli_bad_inputs(tmp_path, tracks, args, words):
    (tmp_path / "gt.csv").write_text("scan_index,person_id,x,y\n0,1,1.0,0.0\n")
    t = tmp_path / "t.csv"
    if tracks is not None:
        t.write_text(tracks)
    proc = run_cli("evaluate", str(t), "--ground-truth", str(tmp_path / "gt.csv"), *args,
                   "--json", str(tmp_path / "out.json"))
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and words in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "out.json").exists()


def test_bench_prints_one_row_per_recording_topic_and_scene(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    proc = run_cli("simulate", "crossing", "--output", str(data / "cross.bag"), "--format", "ros1", "--duration", "4")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("bench", "--quick", "--data", str(data))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[1].split()[:4] == ["input", "scans", "MOTA", "%"]
    rec = next(ln for ln in lines if ln.startswith("cross.bag /scan"))
    assert rec.split()[2] != "n/a" and float(rec.split()[2]) >= 0  # tracks per minute: two people crossing
    for scene in ("crossing", "stop_and_go", "occlusion", "following", "corridor", "crowd"):
        row = next(ln for ln in lines if ln.startswith(f"simulated {scene} "))
        assert float(row.split()[-4]) > 0  # scans per second
    assert "Joint Leg Tracker MOTA 10.2 %" in lines[-1]
    assert run_cli("bench", "--data", str(tmp_path / "nope")).returncode == 2


def test_bench_only_runs_the_inputs_named(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    proc = run_cli("simulate", "crossing", "--output", str(data / "cross.bag"), "--format", "ros1", "--duration", "4")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("bench", "--quick", "--data", str(data), "--only", "cross.bag", "stop_and")
    assert proc.returncode == 0, proc.stderr
    rows = [ln.split()[0:2] for ln in proc.stdout.splitlines()[2:-1]]
    assert rows == [["cross.bag", "/scan"], ["simulated", "stop_and_go"]]
    proc = run_cli("bench", "--quick", "--data", str(data), "--only", "nowhere")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and "--only nowhere" in proc.stderr
