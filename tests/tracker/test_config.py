import re
from importlib import resources

import pytest

from people_tracker.tracker.config import Config, config_from_dict, dump_config, load_config
from people_tracker.tracker.errors import InputError


def test_defaults_load_into_frozen_dataclasses():
    cfg = load_config()
    assert isinstance(cfg, Config) and cfg.odometry.source == "auto"
    with pytest.raises(Exception):
        cfg.odometry.source = "tf"


def test_default_yaml_ships_with_the_package_and_every_tunable_has_a_unit_comment():
    text = resources.files("people_tracker.configs").joinpath("default.yaml").read_text()
    leaves = [ln for ln in text.splitlines() if re.match(r"^\s+\w+:\s*\S", ln)]
    assert leaves, "no tunables found"
    for line in leaves:
        assert "#" in line and len(line.split("#", 1)[1].strip()) > 5, f"no unit/explanation: {line!r}"


def test_override_file_changes_only_its_keys(tmp_path):
    f = tmp_path / "c.yaml"
    f.write_text("odometry:\n  max_wait_s: 2\n")
    cfg = load_config(f)
    assert cfg.odometry.max_wait_s == 2.0 and cfg.odometry.source == "auto"
    assert "max_wait_s: 2.0" in dump_config(cfg)


@pytest.mark.parametrize("override,key", [
    ({"odometry": {"bogus": 1}}, "odometry.bogus"),
    ({"nonsense": {}}, "nonsense"),
    ({"odometry": {"max_wait_s": -1}}, "odometry.max_wait_s"),
    ({"odometry": {"max_interpolation_gap_s": 0}}, "odometry.max_interpolation_gap_s"),
    ({"odometry": {"source": "gps"}}, "odometry.source"),
    ({"odometry": {"max_wait_s": "soon"}}, "odometry.max_wait_s"),
    ({"scan_checks": {"beam_count_confirm": 2.5}}, "scan_checks.beam_count_confirm"),
    ({"scan_checks": {"stamp_jump_periods": float("nan")}}, "scan_checks.stamp_jump_periods"),
    ({"odometry": 3}, "odometry"),
])
def test_bad_values_name_the_key(override, key):
    with pytest.raises(InputError) as err:
        config_from_dict(override)
    assert f"'{key}'" in str(err.value)


@pytest.mark.parametrize("text,words", [("", "empty"), ("odometry: [1, 2\n", "not valid YAML"), ("- 1\n- 2\n", "mapping")])
def test_bad_files(tmp_path, text, words):
    f = tmp_path / "c.yaml"
    f.write_text(text)
    with pytest.raises(InputError, match=words):
        load_config(f)


def test_missing_file():
    with pytest.raises(InputError, match="does not exist"):
        load_config("/no/such/config.yaml")


@pytest.mark.parametrize("override, words", [
    ({"pairing": {"min_leg_size_m": 0.5}}, "'pairing.min_leg_size_m' (0.5) must not exceed 'pairing.max_leg_size_m'"),
    ({"standing": {"min_leg_separation_m": 0.9}}, "'standing.min_leg_separation_m'"),
    ({"alignment": {"min_correspondence_m": 0.9}}, "'alignment.min_correspondence_m'"),
    ({"existence": {"keep": 0.9}}, "'existence.keep' (0.9) must not exceed 'existence.confirm' (0.7)"),
])
def test_every_minimum_is_at_most_its_maximum(override, words):
    from people_tracker.tracker.config import config_from_dict
    from people_tracker.tracker.errors import InputError
    with pytest.raises(InputError, match=re.escape(words)):
        config_from_dict(override)


def test_a_scripts_bad_configuration_is_one_line_and_exit_2(tmp_path, capsys):
    from people_tracker.tracker.config import load_config_or_exit
    bad = tmp_path / "bad.yaml"
    bad.write_text("tracks:\n  same_person_after_s: -1\n")
    for source in (str(bad), "no_such_configuration"):
        with pytest.raises(SystemExit) as stop:
            load_config_or_exit(source, "script")
        assert stop.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("script: ") and err.count("\n") == 1, err
    assert load_config_or_exit("outdoors", "script") == load_config("outdoors")


def _benchmark(script: str, *args: str):
    """Run ``benchmarks/SCRIPT ARGS`` as a user would; the finished process."""
    import subprocess
    import sys
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "benchmarks" / script
    return subprocess.run([sys.executable, str(path), *args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("script", ["following.py", "track_evidence.py", "follow_closed_loop.py"])
def test_the_benchmarks_refuse_a_bad_configuration_in_one_line(tmp_path, script):
    bad = tmp_path / "bad.yaml"
    bad.write_text("tracks:\n  same_person_after_s: -1\n")
    proc = _benchmark(script, "--config", str(bad))
    assert proc.returncode == 2 and proc.stdout == "", proc
    assert proc.stderr.count("\n") == 1 and "same_person_after_s" in proc.stderr, proc.stderr


def test_track_evidence_refuses_a_laser_step_out_of_range_in_one_line():
    proc = _benchmark("track_evidence.py", "--resolution", "10")
    assert proc.returncode == 2 and proc.stdout == "", proc
    assert proc.stderr.count("\n") == 1 and "--resolution" in proc.stderr, proc.stderr


@pytest.mark.parametrize("scene, laser", [("crossing", None), ("follow_outdoor", "long_cw")])
def test_a_simulated_scene_runs_on_another_laser_step(scene, laser):
    import math
    from people_tracker.tracker.io.simulated import SimulatedSource
    own = next(iter(SimulatedSource(scene, duration=0.5, laser=laser).scans())).scan
    coarse = next(iter(SimulatedSource(scene, duration=0.5, laser=laser, resolution_deg=1.0).scans())).scan
    assert math.isclose(coarse.resolution, math.radians(1.0), rel_tol=1e-9)
    assert own.resolution < coarse.resolution
    # the same field of view, fewer beams
    fov_own, fov_coarse = (s.resolution * (len(s.ranges) - 1) for s in (own, coarse))
    assert abs(fov_own - fov_coarse) < math.radians(1.0) and len(coarse.ranges) < len(own.ranges)
