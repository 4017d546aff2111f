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
