"""Scan matching and alignment on simulated moving-robot scenes with known poses."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from people_tracker.detection.icp import IcpParams, ReferenceScan, line_normals, match
from people_tracker.models.pose import Pose2D
from people_tracker.models.world import build_world
from people_tracker.models.laser import LaserModel

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from alignment_accuracy import plain_corridor, simulated_errors  # noqa: E402


def _room_scan(pose, noise=0.0, seed=0):
    world = build_world({"room": [-4, -3, 6, 5], "boxes": [[1, 2, 2, 3]], "pillars": [[3, -1, 0.3]]})
    laser = LaserModel(noise_std=noise)
    scan, _ = laser.render(0.0, pose, world.segments, world.circles, np.random.default_rng(seed) if noise else None)
    return scan.valid_points


def test_icp_recovers_a_known_motion():
    a, b = Pose2D(0, 0, 0), Pose2D(0.15, -0.08, math.radians(4))
    ref = ReferenceScan(_room_scan(a), IcpParams())
    res = match(_room_scan(b), ref, Pose2D(), IcpParams())
    truth = a.between(b)
    assert res.ok and not res.degenerate
    assert (res.pose.x, res.pose.y, res.pose.yaw) == pytest.approx((truth.x, truth.y, truth.yaw), abs=2e-3)
    assert res.rms_m < 0.01 and res.overlap > 0.7


def test_failure_keeps_the_prior_and_says_why():
    prior = Pose2D(0.1, 0.0, 0.0)
    res = match(np.zeros((5, 2)), ReferenceScan(_room_scan(Pose2D()), IcpParams()), prior, IcpParams())
    assert not res.ok and res.pose == prior and "too few" in res.reason


def test_excluded_readings_are_left_out():
    pts = _room_scan(Pose2D())
    ref = ReferenceScan(pts, IcpParams())
    exclude = np.ones(len(pts), dtype=bool)
    exclude[:10] = False
    res = match(pts, ref, Pose2D(), IcpParams(), exclude)
    assert not res.ok  # ten readings are too few to match


def test_normals_are_perpendicular_to_a_wall_and_missing_at_jumps():
    wall = np.column_stack([np.linspace(0, 1, 11), np.full(11, 2.0)])
    jump = np.vstack([wall, [[1.1, 4.0], [1.2, 4.0], [1.3, 4.0]]])
    n = line_normals(jump, 0.2)
    assert np.allclose(np.abs(n[2:9, 1]), 1.0) and np.isnan(n[9:, 0]).all() and np.isnan(n[:2, 0]).all()


@pytest.fixture(scope="module")
def room_with_odometry():
    return simulated_errors("room_drive", use_odometry=True)


@pytest.fixture(scope="module")
def room_without_odometry():
    return simulated_errors("room_drive", use_odometry=False)


def test_room_with_noisy_odometry_meets_the_targets(room_with_odometry):
    e = room_with_odometry  # driving at 1 m/s and turning at 45°/s; odometry 5 % and 2°/rad
    assert e["t95"] < 0.02 and e["r95"] < 0.2, e
    assert e["ok"] > 0.95


def test_room_without_odometry_meets_the_targets(room_without_odometry):
    e = room_without_odometry
    assert e["t95"] < 0.05 and e["r95"] < 0.5, e


def test_bare_corridor_is_found_degenerate_and_keeps_the_prior_along_it():
    with_odom = simulated_errors(plain_corridor(), use_odometry=True, duration=8)
    assert with_odom["degenerate"] > 0.9
    assert with_odom["along95"] < 0.02  # the odometry along the corridor, refined across it
    without = simulated_errors(plain_corridor(), use_odometry=False, duration=8)
    assert without["degenerate"] > 0.9
    assert without["r95"] < 0.1  # heading and the lateral position are still matched
