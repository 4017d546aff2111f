"""The readers on the real recordings in ../shared/data."""

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from scipy.spatial.transform import Rotation

from people_tracker.models.pose import wrap_angle
from people_tracker.tracker.config import config_from_dict
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.ground_truth import read_bag_ground_truth
from people_tracker.tracker.io.recording import Recording


def _records(path, topic=None, source="auto"):
    cfg = config_from_dict({"odometry": {"source": source}}).odometry
    with Recording(path, topic, cfg) as rec:
        return rec, list(rec.scans())


def test_annotated_bag_gives_873_scans_of_768_beams_with_poses(moving_bag):
    rec, records = _records(moving_bag)
    assert rec.topic == "/scan" and rec.laser_frame == "left_laser" and rec.scan_count == 873
    assert [r.index for r in records] == list(range(873))
    assert all(r.scan is not None and r.scan.n_beams == 768 for r in records)
    assert all(r.pose is not None for r in records)
    assert rec.fixed_frame == "odom" and rec.odometry.startswith("/odom")
    s = records[0].scan
    assert s.angle_min == pytest.approx(-2.3562, abs=1e-4) and s.angle_increment == pytest.approx(0.006136, abs=1e-6)
    assert s.range_max == pytest.approx(11.0) and s.time_increment == pytest.approx(6.51e-5, rel=1e-3)
    # real ranges hold nan/inf/0: the mask must drop them
    assert all(np.isfinite(r.scan.ranges[r.scan.valid]).all() for r in records)
    assert sum(r.scan.n_valid < r.scan.n_beams for r in records) > 0


def _independent_laser_poses(path, stamps):
    """/odom ∘ static mount, composed with 3D rotation matrices and numpy interpolation."""
    t, pos, quat, mount = [], [], [], None
    with AnyReader([path]) as r:
        odom = [c for c in r.connections if c.topic == "/odom"]
        for c, _, raw in r.messages(connections=odom):
            m = r.deserialize(raw, c.msgtype)
            t.append(m.header.stamp.sec + m.header.stamp.nanosec * 1e-9)
            p, q = m.pose.pose.position, m.pose.pose.orientation
            pos.append((p.x, p.y, p.z))
            quat.append((q.x, q.y, q.z, q.w))
        tf = [c for c in r.connections if c.topic == "/tf"]
        for c, _, raw in r.messages(connections=tf):
            for tr in r.deserialize(raw, c.msgtype).transforms:
                if tr.header.frame_id.strip("/") == "base_link" and tr.child_frame_id.strip("/") == "left_laser":
                    a, b = tr.transform.translation, tr.transform.rotation
                    mount = np.eye(4)
                    mount[:3, :3] = Rotation.from_quat([b.x, b.y, b.z, b.w]).as_matrix()
                    mount[:3, 3] = [a.x, a.y, a.z]
                    break
            if mount is not None:
                break
    t, pos = np.array(t), np.array(pos)
    yaw = np.unwrap(Rotation.from_quat(quat).as_euler("xyz")[:, 2])
    out = []
    for s in stamps:
        base = np.eye(4)
        base[:3, :3] = Rotation.from_euler("z", np.interp(s, t, yaw)).as_matrix()
        base[:3, 3] = [np.interp(s, t, pos[:, 0]), np.interp(s, t, pos[:, 1]), 0.0]
        laser = base @ mount
        out.append((laser[0, 3], laser[1, 3], np.arctan2(laser[1, 0], laser[0, 0])))
    return np.array(out), mount


def _assert_poses_close(records, expected):
    got = np.array([(r.pose.x, r.pose.y, r.pose.yaw) for r in records])
    pos_err = np.hypot(*(got[:, :2] - expected[:, :2]).T)
    yaw_err = np.abs(wrap_angle(got[:, 2] - expected[:, 2]))
    assert pos_err.max() < 1e-3, f"position error up to {pos_err.max():.4f} m"
    assert yaw_err.max() < 1e-3, f"heading error up to {yaw_err.max():.4f} rad"


def test_laser_pose_equals_independent_odom_and_mount_composition(moving_bag):
    _, records = _records(moving_bag)
    expected, mount = _independent_laser_poses(moving_bag, [r.scan.stamp for r in records])
    # the mount of the README: x 0.850, y 0.235, yaw ≈ 42°
    assert mount[0, 3] == pytest.approx(0.850, abs=2e-3) and mount[1, 3] == pytest.approx(0.235, abs=2e-3)
    assert np.degrees(np.arctan2(mount[1, 0], mount[0, 0])) == pytest.approx(42.0, abs=1.0)
    _assert_poses_close(records, expected)


def test_tf_path_gives_the_same_poses_as_the_odometry_topic(moving_bag):
    rec_tf, via_tf = _records(moving_bag, source="tf")
    _, via_odom = _records(moving_bag, source="odom")
    assert rec_tf.odometry.startswith("/tf") and rec_tf.fixed_frame == "odom"
    # the fixed joints on /tf are stamped 0.5 s ahead: even the first scans get a pose
    assert all(r.pose is not None for r in via_tf)
    # /tf's odom → base_link and /odom are published separately, never with the same stamp,
    # so the two interpolations differ a little while the robot accelerates
    a = np.array([(r.pose.x, r.pose.y, r.pose.yaw) for r in via_tf])
    b = np.array([(r.pose.x, r.pose.y, r.pose.yaw) for r in via_odom])
    pos_err = np.hypot(*(a[:, :2] - b[:, :2]).T)
    yaw_err = np.abs(wrap_angle(a[:, 2] - b[:, 2]))
    assert np.median(pos_err) < 1e-4 and pos_err.max() < 5e-3
    assert np.median(yaw_err) < 1e-4 and yaw_err.max() < 2e-3


def test_recording_without_odometry_is_normal(negative_bag):
    _, records = _records(negative_bag, topic="/right_scan")
    assert len(records) == 434 and all(r.pose is None and r.scan is not None for r in records)


def test_several_laser_topics_and_none_chosen_is_an_error_listing_them(negative_bag):
    with pytest.raises(InputError) as err:
        Recording(negative_bag)
    msg = str(err.value)
    assert "several LaserScan topics" in msg and all(t in msg for t in ("/left_scan", "/right_scan", "/rear_scan"))
    for name in ("left_scan", "/rear_scan"):  # with or without the leading slash
        with Recording(negative_bag, name) as rec:
            assert rec.scan_count == 435


def test_ground_truth_of_the_annotated_bag(moving_bag):
    gt = read_bag_ground_truth(moving_bag)
    assert gt.n_frames == 873 and len(gt) == 153
    assert len(np.unique(gt.person_id)) == 12
    assert np.bincount(gt.scan_index).max() <= 2
    # people stand at a median 2.8 m from the laser (README)
    assert np.median(np.hypot(gt.x, gt.y)) == pytest.approx(2.8, abs=0.3)
    # each message is stamped midway between the scan it annotates and the next scan
    with AnyReader([moving_bag]) as r:
        scan_t = np.array([t for c, t, _ in r.messages(connections=[c for c in r.connections if c.topic == "/scan"])])
        gt_t = np.array([t for c, t, _ in r.messages(
            connections=[c for c in r.connections if c.topic == "/ground_truth_people_tracks"])])
    k = np.sort(gt.scan_index)
    assert k.shape == gt_t.shape
    frac = (np.sort(gt_t) - scan_t[k]) / (scan_t[k + 1] - scan_t[k])
    assert ((frac >= 0) & (frac < 1)).all()
    assert np.median(np.abs(frac - 0.5)) < 0.2


def test_flat_surfaces_start_no_false_people_in_the_empty_rooms(negative_bag):
    """negative_2.bag's left laser (nobody there; a laser this rule was chosen on): walls at a
    grazing angle labelled moving are flat, and with the rule none becomes a person
    candidate, and fewer false people last 2 s than without it."""
    from people_tracker.tracker.pairing import PairingParams
    from people_tracker.tracker.people_tracker import PeopleTracker

    rule = PairingParams()  # the shipped rule defines what is flat, on and off alike

    def run(depth_m):
        cfg = config_from_dict({"pairing": {"flat_max_depth_m": depth_m}})
        tracker = PeopleTracker.from_config(cfg)
        seen, flat_used = {}, 0
        with Recording(negative_bag, "/left_scan", cfg.odometry) as rec:
            for r in rec.scans():
                for t in tracker.step(r.scan, r.pose, r.pose_last_beam):
                    seen.setdefault(t.track_id, [r.scan.stamp, r.scan.stamp])[1] = r.scan.stamp
                flat = {o.object_id for o in tracker.last.detection.objects
                        if o.length >= rule.flat_min_length_m and o.width < rule.flat_max_depth_m}
                flat_used += sum(bool(flat & set(c.object_ids)) for c in tracker.last.candidates)
        return sum(b - a >= 2.0 for a, b in seen.values()), flat_used

    lasting_on, flat_on = run(rule.flat_max_depth_m)
    lasting_off, flat_off = run(0.0)
    assert flat_on == 0 and flat_off > 0
    assert lasting_on < lasting_off
