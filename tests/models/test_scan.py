import numpy as np
import pytest

from people_tracker.models.scan import Scan


def make(ranges, inc=0.1, amin=-0.5, rmin=0.1, rmax=10.0):
    return Scan(np.asarray(ranges, dtype=float), amin, inc, rmin, rmax, stamp=1.0, frame_id="/laser")


def test_validity_mask_rejects_nan_inf_zero_and_limits():
    s = make([1.0, np.nan, np.inf, 0.0, 0.1, 10.0, 9.99, -np.inf, 0.11])
    assert s.valid.tolist() == [True, False, False, False, False, False, True, False, True]
    assert s.n_valid == 3
    assert np.isnan(s.points[1]).all() and np.isfinite(s.points[0]).all()
    assert s.valid_points.shape == (3, 2)


def test_angles_points_and_frame_name():
    s = make([1.0, 2.0, 3.0], inc=np.pi / 2, amin=-np.pi / 2)
    np.testing.assert_allclose(s.angles, [-np.pi / 2, 0.0, np.pi / 2])
    np.testing.assert_allclose(s.points, [[0, -1], [2, 0], [0, 3]], atol=1e-12)
    assert s.frame_id == "laser" and s.angle_max == pytest.approx(np.pi / 2)


def test_negative_increment_gives_the_same_points_as_its_reversed_twin():
    rng = np.random.default_rng(3)
    n = 181
    ranges = rng.uniform(0.5, 8.0, n)
    ranges[[5, 17, 90]] = [np.nan, np.inf, 0.0]
    ccw = make(ranges, inc=np.radians(1.0), amin=-np.pi / 2)
    cw = make(ranges[::-1], inc=-np.radians(1.0), amin=np.pi / 2)
    np.testing.assert_allclose(cw.points[::-1], ccw.points, atol=1e-12, equal_nan=True)
    np.testing.assert_array_equal(cw.valid[::-1], ccw.valid)
    # as sets of points, irrespective of order
    a = ccw.valid_points[np.lexsort(ccw.valid_points.T)]
    b = cw.valid_points[np.lexsort(cw.valid_points.T)]
    np.testing.assert_allclose(a, b, atol=1e-12)


def test_scan_keeps_a_private_read_only_copy():
    src = np.array([1.0, 2.0, 3.0])
    s = make(src)
    src[0] = 99.0
    assert s.ranges[0] == 1.0
    with pytest.raises(ValueError):
        s.ranges[0] = 5.0


@pytest.mark.parametrize("inc", [0.0, np.nan, np.inf])
def test_degenerate_increment_is_refused(inc):
    with pytest.raises(ValueError):
        make([1.0, 2.0], inc=inc)


def test_beam_times_follow_time_increment():
    s = Scan(np.ones(4), 0.0, 0.1, 0.0, 5.0, stamp=2.0, time_increment=0.01)
    np.testing.assert_allclose(s.beam_times, [0.0, 0.01, 0.02, 0.03])
