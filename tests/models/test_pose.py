import math

import numpy as np
import pytest

from people_tracker.models.pose import Pose2D, interpolate_pose, wrap_angle, yaw_from_quaternion


def test_compose_inverse_is_identity_and_matches_matrices():
    a = Pose2D(1.0, -2.0, 0.7)
    b = Pose2D(0.3, 0.4, -2.9)
    ab = a @ b
    np.testing.assert_allclose(ab.as_matrix(), a.as_matrix() @ b.as_matrix(), atol=1e-12)
    ident = a @ a.inverse()
    assert abs(ident.x) < 1e-12 and abs(ident.y) < 1e-12 and abs(ident.yaw) < 1e-12
    rel = a.between(ab)
    assert (rel.x, rel.y) == pytest.approx((b.x, b.y)) and rel.yaw == pytest.approx(b.yaw)


def test_transform_points_matches_matrix():
    p = Pose2D(0.5, 1.5, 2.0)
    pts = np.array([[1.0, 0.0], [0.0, 2.0], [-3.0, 1.0]])
    homog = np.c_[pts, np.ones(3)] @ p.as_matrix().T
    np.testing.assert_allclose(p.transform_points(pts), homog[:, :2], atol=1e-12)


def test_interpolation_takes_the_short_way_round():
    p0, p1 = Pose2D(0, 0, math.pi - 0.1), Pose2D(2, 4, -math.pi + 0.1)
    mid = interpolate_pose(p0, p1, 0.5)
    assert (mid.x, mid.y) == pytest.approx((1.0, 2.0))
    assert abs(wrap_angle(mid.yaw - math.pi)) < 1e-12


def test_yaw_from_quaternion():
    for yaw in (-3.0, -1.0, 0.0, 0.5, 3.1):
        assert yaw_from_quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)) == pytest.approx(yaw)


def test_transform_points_gives_the_same_bits_compiled_and_in_numpy():
    from people_tracker.models import compiled
    rng = np.random.default_rng(3)
    for n in (0, 1, 7, 900):
        p, pts = Pose2D(*rng.normal(size=3) * 5), rng.normal(size=(n, 2)) * 10
        fast = p.transform_points(pts)
        with compiled.numpy_only():
            ref = p.transform_points(pts)
        assert fast.shape == ref.shape == (n, 2) and np.array_equal(fast, ref)
    # one point as a 1-D array, and integer input
    np.testing.assert_allclose(Pose2D(1.0, 2.0, math.pi / 2).transform_points(np.array([1, 0])), [1.0, 3.0], atol=1e-12)
