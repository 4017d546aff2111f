"""Leg-shaped segments found by shape alone (standing people)."""

import numpy as np

from people_tracker.detection.legs import free_standing_legs
from people_tracker.models.scenario import build_simulation

LASER = {"fov_deg": 270, "resolution_deg": 0.35, "rate_hz": 10, "range_max": 20, "noise_std": 0.0}


def _legs_in(pillars, **kw):
    sim, _ = build_simulation({"duration_s": 1, "laser": LASER,
                               "world": {"room": [-1, -6, 5, 6], "pillars": pillars}})
    scan = sim.step().scan
    args = dict(k_segment=12.0, segment_floor_m=0.06, min_points=3, min_size_m=0.04, max_size_m=0.18,
                edge_jump_m=0.3, max_range_m=6.0)
    return free_standing_legs(scan, **{**args, **kw})


def _near(found, xy, tol=0.08):
    return len(found) and np.hypot(*(found - xy).T).min() < tol


def test_free_standing_leg_sized_cylinders_are_legs_and_nothing_else_is():
    pillars = [[2.0, -0.5, 0.06],    # a leg in the open
               [2.0, -0.2, 0.06],    # its partner
               [4.90, 2.0, 0.06],    # leg-sized but against the wall (x = 5): no depth jump
               [2.0, 2.0, 0.01],     # a thin post: chord under 4 cm
               [2.5, -3.0, 0.30]]    # a pillar: chord over 18 cm
    found = _legs_in(pillars)
    # the centre of the readings lies on the near side of the cylinder
    assert _near(found, [1.96, -0.49]) and _near(found, [1.96, -0.2])
    assert len(found) == 2, found


def test_legs_beyond_the_range_limit_are_not_judged():
    found = _legs_in([[4.0, 0.0, 0.06]], max_range_m=3.0)
    assert len(found) == 0
    assert len(_legs_in([[4.0, 0.0, 0.06]], max_range_m=6.0)) == 1


def test_a_scan_with_no_valid_reading_has_no_legs():
    sim, _ = build_simulation({"duration_s": 1, "laser": {**LASER, "range_max": 0.5}, "world": {"room": [-9, -9, 9, 9]}})
    scan = sim.step().scan
    assert scan.n_valid == 0
    assert free_standing_legs(scan, 12.0, 0.06, 3, 0.04, 0.18, 0.3, 6.0).shape == (0, 2)
