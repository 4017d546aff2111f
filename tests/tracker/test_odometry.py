import math

import pytest

from people_tracker.models.pose import Pose2D
from people_tracker.tracker.io.odometry import PoseSeries, TfTree, compose_chain


def series(**kw):
    s = PoseSeries(max_gap_s=kw.get("gap", 0.5), max_extrapolation_s=kw.get("extrap", 0.1))
    for t, x in kw.get("samples", [(0.0, 0.0), (0.1, 1.0), (0.2, 2.0)]):
        s.add(t, Pose2D(x, 0.0, 0.0))
    return s


def test_interpolates_between_samples():
    assert series().at(0.15).x == pytest.approx(1.5)
    assert series().at(0.1).x == pytest.approx(1.0)


def test_extrapolates_only_within_the_limit():
    s = series()
    assert s.at(0.25).x == pytest.approx(2.5)
    assert s.at(0.35) is None
    assert s.at(-0.05).x == pytest.approx(0.0)
    assert s.at(-0.5) is None


def test_gap_wider_than_the_limit_is_not_bridged():
    s = series(samples=[(0.0, 0.0), (1.0, 1.0)])
    assert s.at(0.5) is None


def test_a_transform_that_never_moved_holds_for_earlier_stamps():
    s = series(samples=[(1.0, 3.0), (1.1, 3.0), (1.2, 3.0)])
    assert s.at(0.2).x == 3.0
    moving = series(samples=[(1.0, 3.0), (1.1, 3.1)])
    assert moving.at(0.2) is None


def test_out_of_order_samples_are_dropped_and_prune_keeps_one_older():
    s = series(samples=[(0.0, 0.0), (0.1, 1.0), (0.05, 9.0), (0.2, 2.0), (0.3, 3.0)])
    assert len(s) == 4
    s.prune(0.25)
    assert len(s) == 2 and s.at(0.25).x == pytest.approx(2.5)


def test_lazy_decoding_decodes_only_what_a_query_needs():
    decoded = []

    def decode(raw):
        decoded.append(raw)
        return Pose2D(float(raw), 0.0, 0.0)

    s = PoseSeries(0.5, 0.1, decode)
    for i in range(100):
        s.add(i * 0.01, i)
    assert s.at(0.505).x == pytest.approx(50.5)
    assert sorted(decoded) == [50, 51]


def test_tf_tree_chain_with_and_without_leading_slash():
    tree = TfTree()
    tree.add("/odom", "/base_link", Pose2D(1.0, 2.0, math.pi / 2), 0.0, static=False)
    tree.add("base_link", "laser", Pose2D(0.5, 0.0, 0.0), 0.0, static=True)
    chain = tree.chain("laser")
    assert [e.child for e in chain] == ["laser", "base_link"] and tree.root("laser") == "odom"
    p = compose_chain(chain)
    assert (p.x, p.y, p.yaw) == pytest.approx((1.0, 2.5, math.pi / 2))


def _odometry_poses_both_ways(path):
    """(read in place, fully deserialized) pose.pose of every nav_msgs/Odometry message."""
    from people_tracker.tracker.io.bag import ODOMETRY, open_bag, peek_odometry_pose

    reader = open_bag(path)
    try:
        conns = [c for c in reader.connections if c.msgtype == ODOMETRY]
        assert conns, "the recording has odometry"
        out = []
        for conn, _, raw in reader.messages(connections=conns):
            p = reader.deserialize(raw, conn.msgtype).pose.pose
            full = (p.position.x, p.position.y, p.position.z,
                    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w)
            out.append((peek_odometry_pose(raw, not reader.is2), full))
        return out
    finally:
        reader.close()


@pytest.mark.parametrize("fmt", ["mcap", "sqlite3", "ros1"])
def test_odometry_pose_read_in_place_is_the_deserialized_one(tmp_path, fmt):
    from tests_helpers import simulated_corridor

    pairs = _odometry_poses_both_ways(simulated_corridor(tmp_path, fmt))
    assert len(pairs) > 10 and len({full for _, full in pairs}) > 10  # the robot drives: poses differ
    assert all(fast == full for fast, full in pairs)


def test_odometry_pose_read_in_place_on_the_real_recording(moving_bag):
    pairs = _odometry_poses_both_ways(moving_bag)
    assert len(pairs) == 11561 and all(fast == full for fast, full in pairs)


def test_odometry_pose_of_bytes_too_short_is_none_not_garbage(moving_bag):
    from people_tracker.tracker.io.bag import peek_odometry_pose

    raw = bytes(_first_odometry_raw(moving_bag))
    assert peek_odometry_pose(raw, True) is not None
    for cut in (0, 3, 11, 20, len(raw) - 700):
        assert peek_odometry_pose(raw[:cut], True) is None
    assert peek_odometry_pose(b"\x00\x01", False) is None


def _first_odometry_raw(path):
    from people_tracker.tracker.io.bag import ODOMETRY, open_bag

    reader = open_bag(path)
    try:
        conns = [c for c in reader.connections if c.msgtype == ODOMETRY]
        return next(raw for _, _, raw in reader.messages(connections=conns))
    finally:
        reader.close()
