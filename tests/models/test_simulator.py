"""The simulator: geometry, gait, visibility, determinism, and the files it writes."""

import math

import numpy as np
import pytest

from people_tracker.models.laser import LaserModel
from people_tracker.models.person import PersonModel, Walker
from people_tracker.models.pose import Pose2D
from people_tracker.models.raycast import CircleMotion, cast_rays
from people_tracker.models.scenario import ScenarioError, build_simulation, load_scenario, scenario_names
from people_tracker.models.simulator import Simulation, visible_people
from people_tracker.models.world import build_world
from people_tracker.models.scan import Scan


def test_rendered_ranges_equal_the_analytic_ones():
    """Sensor at (1, 0.5) rotated 30° in a 8 m x 6 m room with a pillar: exact distances."""
    laser = LaserModel(fov=math.radians(360) - math.radians(1), resolution=math.radians(1), range_max=50,
                       noise_std=0.0)
    world = build_world({"room": [-3, -3, 5, 3], "pillars": [[3.0, 0.5, 0.4]]})
    pose = Pose2D(1.0, 0.5, math.radians(30))
    scan, hit = laser.render(0.0, pose, world.segments, world.circles, rng=None)
    heading = pose.yaw + scan.angles
    dx, dy = np.cos(heading), np.sin(heading)
    # walls: first positive crossing of x = -3, 5 and y = -3, 3
    with np.errstate(divide="ignore"):
        tx = np.where(dx > 0, (5 - pose.x) / dx, (-3 - pose.x) / dx)
        ty = np.where(dy > 0, (3 - pose.y) / dy, (-3 - pose.y) / dy)
    expected = np.minimum(np.abs(tx), np.abs(ty))
    # pillar at distance 2 m straight along world x: a ray hits it when its offset is < r
    fx, fy = pose.x - 3.0, pose.y - 0.5
    b = fx * dx + fy * dy
    disc = b * b - (fx * fx + fy * fy - 0.16)
    on = (disc >= 0) & (-b - np.sqrt(np.maximum(disc, 0)) > 0)
    expected[on] = (-b - np.sqrt(np.maximum(disc, 0)))[on]
    np.testing.assert_allclose(scan.ranges, expected, rtol=1e-6, atol=1e-5)  # float32 storage
    assert on.sum() >= 10 and (hit[on] == len(world.segments)).all()
    # the beam pointing exactly at the pillar centre sees its near face: 2 - 0.4 m
    i = int(np.argmin(np.abs(np.angle(np.exp(1j * (heading - 0.0))))))
    assert scan.ranges[i] == pytest.approx(1.6, abs=1e-3)


def test_ray_caster_reports_nothing_beyond_max_range():
    d, hit = cast_rays(np.zeros((2, 2)), np.array([[1.0, 0.0], [0.0, 1.0]]),
                       np.array([[[5.0, -1.0], [5.0, 1.0]]]), np.zeros((0, 3)), max_range=4.0)
    assert np.isinf(d).all() and (hit == -1).all()


def test_clockwise_laser_mirrors_the_beam_order():
    world = build_world({"room": [-3, -2, 6, 4]})
    a, _ = LaserModel(noise_std=0.0).render(0.0, Pose2D(), world.segments, world.circles)
    b, _ = LaserModel(noise_std=0.0, clockwise=True).render(0.0, Pose2D(), world.segments, world.circles)
    assert b.angle_increment < 0
    np.testing.assert_allclose(a.points, b.points[::-1], atol=1e-5)


def _walker(speed=1.0, **kw):
    return Walker(1, [[0, 0], [20, 0]], speed, body=PersonModel(0.06, 0.2, 0.6), **kw)


def test_stance_leg_stands_still_and_swing_leg_moves_at_twice_walking_speed():
    w = _walker(1.0)
    dt = 0.05
    # within one step (1.8 s … 2.4 s at 1 m/s and 0.6 m steps) the stance leg does not move
    t = np.arange(1.8, 2.38, dt)
    legs = np.array([w.legs(x) for x in t])
    stance_moves = np.hypot(*np.diff(legs[:, 0], axis=0).T)
    swing_speed = np.hypot(*np.diff(legs[:, 1], axis=0).T) / dt
    assert stance_moves.max() < 1e-9
    assert np.median(swing_speed) == pytest.approx(2.0, rel=0.05)
    # torso lies between the legs
    assert np.allclose(w.torso(2.3), [2.3, 0.0])


def test_cadence_follows_speed_and_pauses_stand_still_feet_together():
    fast, slow = _walker(1.5), _walker(0.5)
    # steps per second = speed / step length
    assert 1.5 / fast.body.step_length == pytest.approx(2.5) and 0.5 / slow.body.step_length == pytest.approx(0.833, abs=1e-3)
    w = Walker(1, [[0, 0], [3, 0], [6, 0]], 1.0, pauses={1: 3.0}, body=PersonModel(0.06, 0.2, 0.6))
    legs = np.array([w.legs(t) for t in np.arange(3.5, 5.5, 0.1)])
    assert np.ptp(legs, axis=0).max() < 1e-9  # nothing moves during the pause
    feet = legs[0]
    along = abs(feet[0, 0] - feet[1, 0])
    assert along < 1e-6 and abs(feet[0, 1] - feet[1, 1]) == pytest.approx(0.2)  # side by side


def test_stance_leg_readings_do_not_move_between_scans():
    laser = LaserModel(noise_std=0.0, rate_hz=10.0)
    w = Walker(7, [[3, -3], [3, 3]], 0.5, body=PersonModel(0.07, 0.2, 0.6))  # 1.2 s per step
    sim = Simulation(laser, build_world({"room": [-2, -6, 8, 6]}), [w], np.random.default_rng(0))
    steps = [sim.step() for _ in range(4)]  # t = 0 … 0.3 s: the same stance footprint
    stance = w.legs(0.0)[0]
    scans = [s.scan for s in steps]
    near = [np.flatnonzero(np.hypot(*(s.points - stance).T) < 0.08) for s in scans]
    assert len(near[0]) >= 3
    for s, idx in zip(scans[1:], near[1:]):
        np.testing.assert_array_equal(idx, near[0])
        np.testing.assert_allclose(s.ranges[idx], scans[0].ranges[idx], atol=1e-6)


def test_visibility_follows_leighs_rule():
    n = 40
    ranges = np.full(n, 3.0)
    ang = np.radians(0.5)
    scan = Scan(ranges, 0.0, ang, 0.05, 10.0, stamp=0.0)  # neighbours 2.6 cm apart
    owner = np.full(n, -1)
    owner[[0, 1, 2]] = 1  # three in a cluster: visible
    owner[[10, 11]] = 2  # two only: not visible
    owner[[20, 25, 30]] = 3  # three, but 13 cm apart or more: not visible (5 beams = 13.1 cm)
    owner[[35, 36, 37]] = 4
    ranges4 = ranges.copy()
    ranges4[36] = np.nan  # an invalid reading does not count
    assert visible_people(scan, owner) == {1, 4}
    assert visible_people(Scan(ranges4, 0.0, ang, 0.05, 10.0, stamp=0.0), owner) == {1}


def test_people_behind_a_wall_or_beyond_range_are_not_visible():
    laser = LaserModel(noise_std=0.0, range_max=8.0)
    world = build_world({"walls": [[2, -1, 2, 1]]})
    walkers = [Walker(1, [[4, 0], [4, 0.1]], 0.1), Walker(2, [[0, 12], [0.1, 12]], 0.1),
               Walker(3, [[0, 3], [0.1, 3]], 0.1)]
    truth = Simulation(laser, world, walkers, np.random.default_rng(1)).step().truth
    assert dict(zip(truth.person_id.tolist(), truth.visible.tolist())) == {1: False, 2: False, 3: True}


def test_every_shipped_scenario_builds_and_runs():
    names = scenario_names()
    for required in ("crossing", "case1_separated", "case2_partial", "case3_away", "case4_towards",
                     "case5_lateral", "following", "corridor", "occlusion", "stop_and_go", "crowd"):
        assert required in names
    for name in names:
        sim, n = build_simulation(load_scenario(name))
        assert n > 0
        step = sim.step()
        assert step.scan.n_valid > 0


def test_crowd_size_is_a_parameter():
    sim, _ = build_simulation(load_scenario("crowd"), crowd_count=50)
    assert len(sim.walkers) == 50


def test_following_robot_keeps_near_its_target():
    sim, n = build_simulation(load_scenario("following"))
    gaps = []
    for _ in range(n):
        tr = sim.step().truth
        i = list(tr.person_id).index(1)
        gaps.append(np.hypot(*(tr.torso_world[i] - (tr.robot_pose.x, tr.robot_pose.y))))
    assert np.median(gaps[50:]) < 2.5 and max(gaps) < 5.0


@pytest.mark.parametrize("bad,key", [
    ({"laser": {"fov": 90}}, "laser.fov"),
    ({"people": [{"path": [[0, 0], [1, 1]], "sped": 1}]}, "people[0].sped"),
    ({"people": [{"path": [[0, 0], [1, 1]], "speed": -1}]}, "people[0].speed"),
    ({"laser": {"rate_hz": 0}}, "laser.rate_hz"),
])
def test_bad_scenarios_name_the_key(tmp_path, bad, key):
    import yaml
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(bad))
    with pytest.raises(ScenarioError, match=key.replace("[", r"\[").replace("]", r"\]")):
        build_simulation(load_scenario(f))


@pytest.mark.parametrize("seed", range(6))
def test_culled_ray_caster_equals_the_dense_one(seed):
    from people_tracker.models.raycast import cast_rays_dense
    rng = np.random.default_rng(seed)
    n = 500
    clockwise = seed % 2 == 1
    fov = math.radians(360 - 0.5) if seed % 3 == 0 else math.radians(270)
    yaw0 = rng.uniform(-np.pi, np.pi)
    ang = yaw0 + (np.linspace(fov / 2, -fov / 2, n) if clockwise else np.linspace(-fov / 2, fov / 2, n))
    # a sensor moving 10 cm during the sweep
    origins = np.column_stack([np.linspace(0, 0.1, n), np.linspace(0, 0.03, n)]) + rng.uniform(-1, 1, 2)
    dirs = np.column_stack([np.cos(ang), np.sin(ang)])
    a = rng.uniform(-8, 8, (60, 2))
    segments = np.stack([a, a + rng.uniform(-4, 4, (60, 2))], axis=1)
    circles = np.column_stack([rng.uniform(-6, 6, (80, 2)), rng.uniform(0.03, 0.4, 80)])
    circles[0, :2] = origins[0] + [0.05, 0.0]  # the sensor inside a circle
    d1, h1 = cast_rays(origins, dirs, segments, circles, 12.0)
    d2, h2 = cast_rays_dense(origins, dirs, segments, circles, 12.0)
    np.testing.assert_allclose(d1, d2, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(h1[np.isfinite(d1)], h2[np.isfinite(d2)])
    # the circles walking on during the sweep (up to 3 m/s, 0.1 s, a turn at a middle knot)
    knots = circles[None, :, :2] + np.cumsum(rng.uniform(-0.15, 0.15, (3, 80, 2)), axis=0)
    motion = CircleMotion(np.linspace(0, 0.1, n), np.array([0.0, 0.04, 0.1]), knots)
    d1, h1 = cast_rays(origins, dirs, segments, circles, 12.0, motion)
    d2, h2 = cast_rays_dense(origins, dirs, segments, circles, 12.0, motion)
    np.testing.assert_allclose(d1, d2, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(h1[np.isfinite(d1)], h2[np.isfinite(d2)])
    assert (h1 >= len(segments)).sum() > 20 and not np.allclose(d1, cast_rays(origins, dirs, segments, circles, 12.0)[0])


@pytest.mark.parametrize("clockwise", [False, True])
def test_a_walker_is_seen_where_they_are_when_each_beam_fires(clockwise):
    """A scanner sweeps its beams over most of its period and people walk on meanwhile: each
    reading of a walker lies on a leg where that leg is at the beam's time, not at the
    stamp's (a still laser, a person crossing 2.5 m ahead of it at 1.5 m/s, seen mid-sweep)."""
    laser = LaserModel(fov=math.radians(270), resolution=math.radians(0.33), rate_hz=7.5, range_max=11,
                       noise_std=0.0, clockwise=clockwise)
    walker = Walker(1, [[2.5, -4], [2.5, 4]], 1.5, body=PersonModel(0.06, 0.2, 0.6))
    sim = Simulation(laser, build_world({}), [walker], np.random.default_rng(0), t0=0.0)
    for _ in range(20):
        step = sim.step()
    scan, truth = step.scan, step.truth
    t_scan = scan.stamp
    on = np.flatnonzero(truth.beam_person == 1)
    assert len(on) >= 10
    pts = scan.points[on]  # the laser stands at the origin of the world, facing x
    beam_t = t_scan + on * laser.time_increment
    gap_then = [np.hypot(*(walker.legs(t)[:, None, :] - p).transpose(2, 0, 1)).min() - 0.06
                for t, p in zip(beam_t, pts)]
    gap_stamp = np.hypot(*(walker.legs(t_scan)[:, None, :] - pts[None]).transpose(2, 0, 1)).min(axis=0) - 0.06
    assert np.abs(gap_then).max() < 0.03  # on the leg where it is when the beam fires
    assert np.abs(gap_stamp).max() > 0.05  # not where it was at the stamp
    np.testing.assert_allclose(truth.torso_world[0], walker.torso(t_scan))  # the truth: at the stamp
