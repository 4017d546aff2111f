"""The command line as users meet it: bad inputs give one line and exit 2, never a traceback."""

import shutil

import pytest

from tests_helpers import assert_one_line_error, bagmaker, run_cli
from conftest import data_file


@pytest.fixture
def good_bag(small_bag):
    return small_bag


def test_missing_input(tmp_path):
    assert_one_line_error(run_cli("run", str(tmp_path / "nope.bag")), "does not exist")


def test_empty_input(tmp_path):
    (tmp_path / "empty.bag").write_bytes(b"")
    assert_one_line_error(run_cli("run", str(tmp_path / "empty.bag")), "is empty")


@pytest.mark.parametrize("name", ["junk.bag", "junk.mcap"])
def test_corrupt_input(tmp_path, name):
    (tmp_path / name).write_bytes(b"\x00garbage" * 1000)
    assert_one_line_error(run_cli("run", str(tmp_path / name)), "cannot be read")


def test_truncated_real_recording(tmp_path):
    """Cut short, a bag is read as far as it goes, with one warning; with no message left
    in it, it is one line and status 2."""
    src = data_file("leigh/positive_1.bag")
    (tmp_path / "cut.bag").write_bytes(src.read_bytes()[: 300_000])
    proc = run_cli("run", str(tmp_path / "cut.bag"))
    assert proc.returncode == 0 and "92 read, 92 used" in proc.stdout, proc.stderr
    assert proc.stderr.startswith("people-tracker: warning: input") and proc.stderr.count("\n") == 1, proc.stderr
    assert "has its index cut off (a recording cut short?)" in proc.stderr
    (tmp_path / "head.bag").write_bytes(src.read_bytes()[: 5000])
    assert_one_line_error(run_cli("run", str(tmp_path / "head.bag")), "head.bag")


def test_not_a_recording(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    assert_one_line_error(run_cli("run", str(tmp_path / "notes.txt")), "not a ROS 1 .bag")
    assert_one_line_error(run_cli("run", str(tmp_path)), "no metadata.yaml")


def test_no_laser_scan_topic(tmp_path):
    from people_tracker.tracker.io.bag_writer import BagWriter
    from people_tracker.models.pose import Pose2D
    with BagWriter(tmp_path / "odom_only", "mcap") as w:
        w.write_odometry("/odom", 1.0, "odom", "base_link", Pose2D())
    assert_one_line_error(run_cli("run", str(tmp_path / "odom_only")), "no LaserScan topic", "/odom")


def test_several_topics_and_none_chosen(negative_bag):
    assert_one_line_error(run_cli("run", str(negative_bag)), "/left_scan", "/rear_scan", "/right_scan", "--topic")


def test_wrong_topic(good_bag):
    assert_one_line_error(run_cli("run", str(good_bag), "--topic", "/laser"), "no topic '/laser'", "/scan")
    assert_one_line_error(run_cli("run", str(good_bag), "--topic", "/odom"), "not a LaserScan topic")


@pytest.mark.parametrize("text,words", [
    ("odometry:\n  speed: 3\n", "'odometry.speed'"),
    ("odometry:\n  max_wait_s: -2\n", "'odometry.max_wait_s'"),
    ("odometry: [\n", "not valid YAML"),
    ("", "empty"),
])
def test_bad_config(tmp_path, good_bag, text, words):
    (tmp_path / "c.yaml").write_text(text)
    assert_one_line_error(run_cli("run", str(good_bag), "--config", str(tmp_path / "c.yaml")), words)


def test_missing_config(tmp_path, good_bag):
    assert_one_line_error(run_cli("run", str(good_bag), "--config", str(tmp_path / "no.yaml")), "does not exist")


def test_bad_usage():
    assert_one_line_error(run_cli("dance"), "invalid choice")
    assert_one_line_error(run_cli("run", "--bogus"), "unrecognized arguments")


def test_run_on_a_good_recording_summarises_it(good_bag):
    proc = run_cli("run", str(good_bag))
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    assert "10 read, 10 used, 0 skipped" in proc.stdout and "fixed frame odom" in proc.stdout


def test_bad_scans_inside_a_good_recording_warn_once_each_and_keep_their_index(tmp_path):
    import numpy as np
    scans = [bagmaker.make_scan(i) for i in range(12)]
    scans[3] = bagmaker.make_scan(3, ranges=np.full(360, np.nan))  # all invalid
    scans[6] = bagmaker.make_scan(6, stamp=scans[4].stamp)  # stamp goes backwards
    scans[8] = bagmaker.make_scan(8, n=180)  # changed beam count
    scans[10] = bagmaker.make_scan(10, stamp=scans[9].stamp + 5.0)  # a jump
    scans[11] = bagmaker.make_scan(11, stamp=scans[10].stamp + 0.1)
    bagmaker.write_bag(tmp_path / "bad", "mcap", scans=scans)
    proc = run_cli("run", str(tmp_path / "bad"))
    assert proc.returncode == 0, proc.stderr
    warnings = proc.stderr.strip().splitlines()
    assert len(warnings) == 4 and all(w.startswith("people-tracker: warning: scan ") for w in warnings)
    for idx, words in ((3, "invalid"), (6, "goes back"), (8, "180 beams"), (10, "jumps")):
        assert any(w.startswith(f"people-tracker: warning: scan {idx} ") and words in w for w in warnings), warnings
    assert "12 read, 9 used, 3 skipped, 1 history restarts" in proc.stdout


def test_repeated_warnings_are_grouped_and_v_shows_them_all(tmp_path):
    import numpy as np
    scans = [bagmaker.make_scan(i, ranges=np.full(360, np.nan) if i % 2 else None) for i in range(40)]
    bagmaker.write_bag(tmp_path / "half", "mcap", scans=scans)
    proc = run_cli("run", str(tmp_path / "half"))
    warnings = proc.stderr.strip().splitlines()
    assert proc.returncode == 0 and len(warnings) == 4, warnings  # three, then the count of the rest
    assert warnings[-1].startswith("people-tracker: warning: ... and 17 more like this: scan 1 ")
    every = run_cli("run", str(tmp_path / "half"), "-v").stderr.strip().splitlines()
    assert len(every) == 20 and not any("more like this" in w for w in every)
    assert run_cli("run", str(tmp_path / "half"), "-q").stderr == ""


def test_version_and_options_after_the_subcommand():
    from importlib.metadata import version

    from people_tracker import __version__
    assert run_cli("--version").stdout.strip() == f"people-tracker {__version__}"
    assert __version__ == version("people-tracker")  # the package's version is the installed one's
    proc = run_cli("simulate", "--help")
    for name in ("crossing", "crowd", "room_drive", "case5_lateral"):
        assert f"  {name} " in proc.stdout
    assert "Two people cross" in proc.stdout



def test_console_script_is_installed_beside_the_interpreter():
    import sys
    from pathlib import Path
    exe = shutil.which("people-tracker", path=str(Path(sys.executable).parent))
    assert exe is not None, "pip install did not put people-tracker next to python"
    proc = run_cli("--help")
    assert proc.returncode == 0 and "run" in proc.stdout and "evaluate" in proc.stdout and "simulate" in proc.stdout


def test_run_writes_the_detections_contract_and_the_resolved_config(tmp_path):
    import csv
    out = tmp_path / "det.csv"
    proc = run_cli("run", "--detections", str(out))  # the built-in crossing scene
    assert proc.returncode == 0, proc.stderr
    assert "V_min = Δd_c/Δt for Δt 0.15 s" in proc.stdout and "at 3 m" in proc.stdout
    rows = list(csv.DictReader(out.open()))
    assert list(rows[0].keys()) == ["scan_index", "stamp", "object_id", "first_beam", "last_beam", "n_points",
                                    "x", "y", "width", "length", "recovered_from"]
    assert len(rows) > 100
    for r in rows:
        assert float(r["width"]) <= float(r["length"])
        assert int(r["first_beam"]) <= int(r["last_beam"]) < 772
        assert r["recovered_from"] in ("M", "M+A", "M+O", "M+A+O", "O")
    assert "compare_dt_s" in (tmp_path / "det.csv.config.yaml").read_text()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]


def test_unwritable_detections_path_fails_before_any_work(tmp_path, good_bag):
    proc = run_cli("run", str(good_bag), "--detections", str(tmp_path / "missing" / "d.csv"))
    assert_one_line_error(proc, "does not exist")


def test_a_failed_run_leaves_no_output(tmp_path):
    out = tmp_path / "d.csv"
    (tmp_path / "bad.bag").write_bytes(b"#ROSBAG V2.0\n" + b"\x00" * 500)
    proc = run_cli("run", str(tmp_path / "bad.bag"), "--detections", str(out))
    assert proc.returncode == 2 and not out.exists() and list(tmp_path.iterdir()) == [tmp_path / "bad.bag"]


def test_help_and_version_import_nothing_heavy(tmp_path):
    # the start-up of --help and --version: no numpy, no logging, no package metadata and no
    # shipped files (the scenario list is read only for `simulate --help`); run away from the
    # checkout so that the installed package is the one measured
    import subprocess
    import sys

    code = ("import sys; before = set(sys.modules)\n"
            "from people_tracker.tracker.cli import main\n"
            "try:\n    main([sys.argv[1]])\nexcept SystemExit:\n    pass\n"
            "print(' '.join(sorted(set(sys.modules) - before)))")
    for flag in ("--help", "--version"):
        out = subprocess.run([sys.executable, "-c", code, flag], capture_output=True, text=True, check=True,
                             cwd=tmp_path).stdout
        loaded = set(out.strip().splitlines()[-1].split())
        heavy = {"numpy", "logging", "importlib.metadata", "importlib.resources", "people_tracker.configs", "yaml"}
        assert not heavy & loaded, (flag, heavy & loaded)


def test_a_source_checkout_imports_whole_from_its_root():
    # `python -c`/`-m people_tracker` in the checkout's root takes people_tracker/ from the
    # checkout, shadowing the installed copy; its subpackages (tracker/, models/, ... beside it)
    # must come with it. A development install's finder would map them anyway, so it is removed.
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    code = ("import sys\n"
            "sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in repr(f).lower()\n"
            "                    and 'editable' not in type(f).__module__.lower()]\n"
            "import people_tracker.tracker.cli as cli, people_tracker.models.pose as pose\n"
            "print(cli.__file__); print(pose.__file__)\n"
            "cli.main(['--version'])")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=root)
    assert proc.returncode == 0, proc.stderr
    cli_file, pose_file, version = proc.stdout.splitlines()[:3]
    assert Path(cli_file) == root / "tracker" / "cli.py" and Path(pose_file) == root / "models" / "pose.py"
    assert version.startswith("people-tracker ")


def test_a_ros2_queue_below_one_scan_is_refused_before_ros_starts():
    proc = run_cli("ros2", "--queue", "0")
    assert_one_line_error(proc, "--queue")
