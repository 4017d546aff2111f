"""Scan matching and alignment on simulated moving-robot scenes with known poses."""

import math
import sys
from dataclasses import replace
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


def _blind(scan, stamp):
    """The scan a laser with nothing in range gives at ``stamp``."""
    return replace(scan, ranges=np.full(scan.n_beams, np.inf), stamp=stamp)


@pytest.mark.parametrize("fade_s", [0.0, 0.5])
def test_without_anything_to_match_the_predicted_motion_fades_to_rest(fade_s):
    """Without odometry and with nothing in range, the sensor's motion is not observed: the
    last matched motion goes on (fade_s 0) or fades to rest with the time constant fade_s."""
    from people_tracker.detection.align import AlignParams, ScanAligner

    world = build_world({"room": [-4, -3, 6, 5], "boxes": [[1, 2, 2, 3]], "pillars": [[3, -1, 0.3]]})
    laser = LaserModel()
    aligner = ScanAligner(AlignParams(fade_s=fade_s))
    dt, speed = 0.1, 1.0  # s, m/s
    for k in range(4):  # matched: 1 m/s along x
        scan, _ = laser.render(k * dt, Pose2D(speed * k * dt, 0.0, 0.0), world.segments, world.circles, None)
        scan = replace(scan, time_increment=0.0)  # rendered from one pose: no skew
        pose = aligner.align(scan).pose
    assert pose.x == pytest.approx(3 * dt * speed, abs=0.01)
    steps = []
    for k in range(4, 10):  # nothing in range
        before = pose
        pose = aligner.align(_blind(scan, k * dt)).pose
        steps.append(before.between(pose).x)
    expected = speed * dt * np.exp(-dt / fade_s * np.arange(6)) if fade_s else np.full(6, speed * dt)
    assert steps == pytest.approx(expected, abs=0.01 * speed * dt)


def test_the_scan_matchers_step_is_the_least_squares_step_in_the_constrained_directions():
    """The written-out eigen-decomposition of the matcher's step against numpy's (LAPACK):
    the same step (to 1e-9), conditioning and degenerate directions, on random normal
    equations, corridors (one direction unconstrained) among them."""
    from people_tracker.detection.icp import _solve_step
    solve = getattr(_solve_step, "py_func", _solve_step)  # the Python code itself
    rng = np.random.default_rng(4)
    kinds = set()
    for k in range(2000):
        A = rng.normal(size=(int(rng.integers(3, 80)), 3)) * rng.uniform(0.01, 10, 3)
        if k % 3 == 0:
            A[:, 0] = A[:, 1] * rng.uniform(0.5, 2) + rng.normal(0, 1e-4, len(A))
        H, g, rng_m, ratio = A.T @ A, A.T @ rng.normal(0, 0.05, len(A)), float(rng.uniform(0.2, 9)), 0.06
        d = np.array([1.0, 1.0, 1.0 / max(rng_m, 1.0)])
        w, V = np.linalg.eigh(H * np.outer(d, d))
        good = w > ratio * w[-1]
        if np.any(np.abs(w[:, None] - ratio * w[-1]) < 1e-6 * w[-1]):
            continue  # on the threshold: either answer is right
        expected = d * -(V[:, good] @ ((V[:, good].T @ (d * g)) / w[good]))
        dx, dy, dth, cond, degenerate = solve(*H[np.triu_indices(3)], *g, rng_m, ratio)
        np.testing.assert_allclose([dx, dy, dth], expected, rtol=1e-9, atol=1e-12 * np.abs(expected).max())
        assert cond == pytest.approx(w[0] / w[-1], rel=1e-9, abs=1e-15)
        assert degenerate == (not good.all())
        kinds.add(degenerate)
    assert kinds == {True, False}
