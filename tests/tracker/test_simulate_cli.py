"""people-tracker simulate: a ROS 2 MCAP bag and its ground truth, deterministic, readable."""

import hashlib

import numpy as np
import pytest

from people_tracker.models.scenario import build_simulation, load_scenario
from tests_helpers import run_cli
from people_tracker.tracker.io.ground_truth import read_gt_csv
from people_tracker.tracker.io.recording import Recording


def _digest(folder):
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def test_same_seed_same_bytes_and_other_seed_other_bytes(tmp_path):
    # the bag's name is written inside it, so the runs share a name in different folders
    for run, extra in (("1", []), ("2", []), ("3", ["--seed", "99"])):
        (tmp_path / run).mkdir()
        proc = run_cli("simulate", "occlusion", "--output", str(tmp_path / run / "bag"), "--duration", "3", *extra)
        assert proc.returncode == 0, proc.stderr
    assert _digest(tmp_path / "1" / "bag") == _digest(tmp_path / "2" / "bag")
    assert (tmp_path / "1" / "bag.gt.csv").read_bytes() == (tmp_path / "2" / "bag.gt.csv").read_bytes()
    assert _digest(tmp_path / "1" / "bag") != _digest(tmp_path / "3" / "bag")


def test_simulated_bag_reads_back_through_the_normal_reader(tmp_path):
    out = tmp_path / "cross"
    proc = run_cli("simulate", "crossing", "--output", str(out), "--duration", "4")
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.suffix for p in out.iterdir()) == [".mcap", ".yaml"]
    sim, n = build_simulation({**load_scenario("crossing"), "duration_s": 4})
    steps = [sim.step() for _ in range(n)]
    with Recording(out) as rec:
        records = list(rec.scans())
        assert rec.fixed_frame == "odom" and rec.odometry.startswith("/odom")
    assert len(records) == n == 40
    for r, s in zip(records, steps):
        np.testing.assert_array_equal(r.scan.ranges, s.scan.ranges)
        assert r.scan.stamp == pytest.approx(s.scan.stamp, abs=1e-9)
        assert (r.pose.x, r.pose.y) == pytest.approx((s.truth.sensor_pose.x, s.truth.sensor_pose.y), abs=1e-6)
    gt = read_gt_csv(f"{out}.gt.csv")
    expected = sum(int(s.truth.visible.sum()) for s in steps)
    assert len(gt) == expected > 0
    first = steps[0].truth
    i = list(gt.scan_index).index(0)
    j = list(first.person_id).index(gt.person_id[i])
    assert (gt.x[i], gt.y[i]) == pytest.approx(tuple(first.torso_sensor[j]), abs=1e-4)


def test_moving_robot_scene_poses_follow_the_drifting_odometry(tmp_path):
    out = tmp_path / "corr.bag"
    proc = run_cli("simulate", "corridor", "--output", str(out), "--duration", "5", "--format", "ros1")
    assert proc.returncode == 0, proc.stderr
    with Recording(out) as rec:
        records = list(rec.scans())
    assert len(records) == 50 and all(r.pose is not None for r in records)
    travelled = records[-1].pose.x - records[0].pose.x
    assert travelled == pytest.approx(0.8 * 4.9, rel=0.2)  # 0.8 m/s with 5 % drift


def test_simulate_bad_inputs(tmp_path):
    for args, words in ((["nope", "--output", str(tmp_path / "x")], "no scenario 'nope'"),
                        (["crossing", "--output", str(tmp_path / "no" / "x")], "does not exist"),
                        (["crossing", "--output", str(tmp_path / "x"), "--people", "-1"], "--people")):
        proc = run_cli("simulate", *args)
        assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and words in proc.stderr
    (tmp_path / "bad.yaml").write_text("laser: {fov_deg: 500}\n")
    proc = run_cli("simulate", str(tmp_path / "bad.yaml"), "--output", str(tmp_path / "y"))
    assert proc.returncode == 2 and "laser.fov_deg" in proc.stderr
    assert not (tmp_path / "y").exists() and not (tmp_path / "y.gt.csv").exists()
    (tmp_path / "exists").mkdir()
    proc = run_cli("simulate", "crossing", "--output", str(tmp_path / "exists"))
    assert proc.returncode == 2 and "exists already" in proc.stderr


def test_run_without_input_runs_the_built_in_scene():
    proc = run_cli("run")
    assert proc.returncode == 0, proc.stderr
    assert "built-in scene 'crossing'" in proc.stdout and "200 read, 200 used" in proc.stdout


def test_following_scene_without_odometry_names_its_target_and_scores_the_following(tmp_path):
    out = tmp_path / "outdoor"
    proc = run_cli("simulate", "follow_outdoor", "--laser", "narrow", "--output", str(out), "--duration", "20")
    assert proc.returncode == 0, proc.stderr
    assert "/odom" not in proc.stdout
    gt = read_gt_csv(f"{out}.gt.csv")
    assert gt.target is not None and set(gt.person_id[gt.target == 1].tolist()) == {1}
    with Recording(out) as rec:
        assert rec.fixed_frame is None  # no odometry in the recording
        first = next(rec.scans()).scan
    assert first.n_beams == 247 and abs(first.angle_increment - np.radians(0.35)) < 1e-4  # 86 deg at 0.35 deg
    tracks = tmp_path / "tracks.csv"
    proc = run_cli("run", str(out), "--follow", "auto", "--tracks", str(tracks))
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("evaluate", str(tracks), "--ground-truth", f"{out}.gt.csv", "--protocol", "following")
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    for line in ("followed person", "first lock", "target on the person", "target elsewhere", "target changes"):
        assert line in proc.stdout, proc.stdout
    # the ground truth names the person; another id must exist in it
    proc = run_cli("evaluate", str(tracks), "--ground-truth", f"{out}.gt.csv", "--protocol", "following",
                   "--target-person", "999")
    assert proc.returncode == 2 and "999 is not in the ground truth" in proc.stderr


def test_unknown_laser_and_a_target_person_without_following_are_one_line_errors(tmp_path):
    proc = run_cli("simulate", "follow_outdoor", "--laser", "nope", "--output", str(tmp_path / "x"))
    assert proc.returncode == 2 and "no laser 'nope'" in proc.stderr and "narrow" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not (tmp_path / "x").exists()
    gt = tmp_path / "gt.csv"
    gt.write_text("scan_index,person_id,x,y\n0,1,1.0,0.0\n")
    tr = tmp_path / "t.csv"
    tr.write_text("scan_index,track_id,x,y\n0,1,1.0,0.0\n")
    proc = run_cli("evaluate", str(tr), "--ground-truth", str(gt), "--target-person", "1")
    assert proc.returncode == 2 and "--protocol following" in proc.stderr
