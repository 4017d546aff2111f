"""Write recordings with rosbags in every supported format and read them back identically."""

import math

import numpy as np
import pytest

from people_tracker.models.pose import wrap_angle
from tests_helpers import bagmaker
from people_tracker.tracker.config import config_from_dict
from people_tracker.tracker.io.recording import Recording


def _read(path, source="auto", topic=None):
    with Recording(path, topic, config_from_dict({"odometry": {"source": source}}).odometry) as rec:
        return rec, list(rec.scans())


@pytest.mark.parametrize("fmt,name", [("mcap", "bag2"), ("sqlite3", "bag2"), ("ros1", "bag.bag")])
def test_scans_read_back_identically(tmp_path, fmt, name):
    written = bagmaker.write_bag(tmp_path / name, fmt)
    rec, records = _read(tmp_path / name)
    assert rec.topic == "/scan" and rec.scan_count == len(written) and rec.laser_frame == "laser"
    assert len(records) == len(written)
    for r, s in zip(records, written):
        got = r.scan
        np.testing.assert_array_equal(got.ranges, s.ranges.astype(np.float32))  # LaserScan stores float32
        np.testing.assert_array_equal(got.valid, s.valid)
        assert got.stamp == pytest.approx(s.stamp, abs=1e-9)
        for attr in ("angle_min", "angle_increment", "range_min", "range_max", "time_increment"):
            assert getattr(got, attr) == pytest.approx(getattr(s, attr), rel=1e-6)


def test_ros2_mcap_and_ros1_read_back_the_same(tmp_path):
    bagmaker.write_bag(tmp_path / "b2", "mcap")
    bagmaker.write_bag(tmp_path / "b1.bag", "ros1")
    _, a = _read(tmp_path / "b2")
    _, b = _read(tmp_path / "b1.bag")
    mcap_file = next((tmp_path / "b2").glob("*.mcap"))
    _, c = _read(mcap_file)  # a bare .mcap file, without metadata.yaml
    _, d = _read(tmp_path / "b2" / "metadata.yaml")  # the folder's metadata, as ros2 bag info takes it
    assert len(a) == len(b) == len(c) == len(d)
    for x, y, z, w in zip(a, b, c, d):
        np.testing.assert_array_equal(x.scan.ranges, w.scan.ranges)
        np.testing.assert_array_equal(x.scan.ranges, y.scan.ranges)
        np.testing.assert_array_equal(x.scan.ranges, z.scan.ranges)
        assert x.scan.stamp == y.scan.stamp == z.scan.stamp
        assert (x.pose.x, x.pose.y, x.pose.yaw) == pytest.approx((y.pose.x, y.pose.y, y.pose.yaw), abs=1e-9)
        assert (x.pose.x, x.pose.y, x.pose.yaw) == pytest.approx((z.pose.x, z.pose.y, z.pose.yaw), abs=1e-9)


@pytest.mark.parametrize("source", ["auto", "odom", "tf"])
@pytest.mark.parametrize("fmt,name", [("mcap", "bag2"), ("ros1", "bag.bag")])
def test_sensor_pose_is_robot_pose_composed_with_the_mount(tmp_path, source, fmt, name):
    bagmaker.write_bag(tmp_path / name, fmt)
    rec, records = _read(tmp_path / name, source)
    assert rec.fixed_frame == "odom"
    assert rec.odometry.startswith("/odom" if source in ("auto", "odom") else "/tf")
    for r in records:
        truth = bagmaker.robot_pose(r.scan.stamp) @ bagmaker.MOUNT
        # 50 Hz linear interpolation of an arc: sub-millimetre
        assert math.hypot(r.pose.x - truth.x, r.pose.y - truth.y) < 1e-3
        assert abs(wrap_angle(r.pose.yaw - truth.yaw)) < 1e-3


def test_no_odometry_gives_no_pose(tmp_path):
    bagmaker.write_bag(tmp_path / "b", "mcap", odom=False, tf=False)
    rec, records = _read(tmp_path / "b")
    assert rec.fixed_frame is None and rec.odometry == "none"
    assert all(r.pose is None for r in records)


def test_memory_stays_bounded_while_streaming(tmp_path):
    """The odometry buffer holds a bounded window, not the whole recording."""
    bagmaker.write_bag(tmp_path / "b", "mcap", n_scans=300)
    with Recording(tmp_path / "b") as rec:
        sizes = []
        for r in rec.scans():
            sizes.append(len(rec.pose_source._series))
    assert max(sizes) < 60  # 0.5 s margin + one scan period at 50 Hz, not 300 scans' worth (1500)
