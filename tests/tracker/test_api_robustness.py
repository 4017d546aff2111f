"""The Python API never fails on what a robot's loop can hand it.

``PeopleTracker.step`` is driven with random scans (any beam count and increment, readings
that are nan, inf, 0, negative or huge), poses (non-finite ones included), and stamps that
repeat, go backwards or jump. The only exception allowed is the documented ``ValueError``
of a malformed :class:`Scan`, raised when the scan is built, never inside ``step``; nor may
numpy print a floating-point warning.
"""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from people_tracker import PeopleTracker, Pose2D, Scan, load_config

READINGS = st.one_of(st.floats(0.0, 30.0), st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -1.0, 1e12]))
ANY_FLOAT = st.one_of(st.floats(-50.0, 50.0), st.sampled_from([math.nan, math.inf, -math.inf]))


@st.composite
def scans(draw):
    n = draw(st.integers(0, 400))
    base = draw(st.lists(READINGS, min_size=min(n, 1), max_size=min(n, 1)))  # one value, or a wall of noise
    if n and draw(st.booleans()):
        ranges = np.full(n, base[0])
    else:
        ranges = np.asarray(draw(st.lists(READINGS, min_size=n, max_size=n)), dtype=float)
    increment = draw(st.one_of(st.floats(-0.1, 0.1, allow_subnormal=False).filter(lambda v: v != 0.0), st.sampled_from([1e-9, -3.0, 7.0])))
    range_min = draw(st.floats(0.0, 1.0))
    return dict(ranges=ranges, angle_min=draw(st.floats(-4.0, 4.0)), angle_increment=increment,
                range_min=range_min, range_max=range_min + draw(st.floats(0.0, 40.0)),
                time_increment=draw(st.sampled_from([0.0, 1e-5, 1e-4, -1e-4])))


@st.composite
def poses(draw):
    if draw(st.integers(0, 3)) == 0:
        return None
    return Pose2D(draw(ANY_FLOAT), draw(ANY_FLOAT), draw(ANY_FLOAT))


@st.composite
def steps(draw):
    """A run of scans: stamps advance by a period, repeat, go back or jump."""
    out, stamp = [], draw(st.floats(0.0, 1e9))
    for _ in range(draw(st.integers(1, 12))):
        stamp += draw(st.sampled_from([0.1, 0.1, 0.1, 0.0, -0.3, 50.0, 1e-6]))
        out.append((draw(scans()), stamp, draw(poses()), draw(poses())))
    return out


@pytest.mark.filterwarnings("error::RuntimeWarning")  # numpy's floating-point warnings reach a user's console
@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(steps(), st.sampled_from([None, "auto"]))
def test_step_never_raises_on_what_a_robot_can_send(run, follow):
    tracker = PeopleTracker.from_config(load_config(), follow=follow)
    logging.disable(logging.WARNING)  # the warnings are tested below; here only that nothing raises
    try:
        for fields, stamp, pose, pose_last in run:
            scan = Scan(stamp=stamp, **fields)
            tracks = tracker.step(scan, pose, pose_last)
            for t in tracks:
                assert math.isfinite(t.x) and math.isfinite(t.y) and 0.0 <= t.confidence <= 1.0
    finally:
        logging.disable(logging.NOTSET)


def test_a_non_finite_pose_counts_as_missing_with_one_warning(caplog):
    tracker = PeopleTracker.from_config(load_config())
    scan = Scan(np.full(360, 3.0), -math.pi / 2, math.pi / 359, 0.05, 20.0, stamp=10.0)
    with caplog.at_level(logging.WARNING):
        for k in range(5):
            tracker.step(Scan(scan.ranges, scan.angle_min, scan.angle_increment, 0.05, 20.0, stamp=10.0 + 0.1 * k),
                         Pose2D(math.nan, 0.0, 0.0))
    bad = [r for r in caplog.records if "pose" in r.getMessage()]
    assert len(bad) == 1 and "not finite" in bad[0].getMessage()
    assert tracker.last.pose.x == 0.0  # no pose: the first scan's frame is the world


def test_a_malformed_scan_is_a_value_error_when_built():
    import pytest

    for bad in (dict(angle_increment=0.0), dict(angle_increment=math.nan), dict(stamp=math.nan),
                dict(angle_min=math.inf), dict(range_max=math.nan), dict(ranges=np.zeros((2, 2)))):
        kwargs = dict(ranges=np.ones(10), angle_min=0.0, angle_increment=0.01, range_min=0.0, range_max=10.0,
                      stamp=0.0) | bad
        with pytest.raises(ValueError):
            Scan(**kwargs)
