"""Scenes keep their promises over any duration (checked from the walkers' own paths,
without rendering)."""

from __future__ import annotations

import numpy as np
import pytest

from people_tracker.models.scenario import build_simulation, load_scenario


def test_a_long_crowd_keeps_wandering_to_the_end():
    spec = {**load_scenario("crowd"), "duration_s": 1200}
    sim, _ = build_simulation(spec)
    moved = [np.hypot(*(w.torso(1180.0) - w.torso(1120.0))) > 1.0 for w in sim.walkers]
    assert np.mean(moved) > 0.8  # in the last minute of 20, nearly everyone is on the move
    short, _ = build_simulation(load_scenario("crowd"))  # a 30 s crowd is the same as it always was
    assert [len(w.waypoints) for w in short.walkers] == [8] * 30


@pytest.mark.parametrize("seed", [21, 22, 23])
def test_the_waiting_room_keeps_its_promises(seed):
    sim, n_scans = build_simulation(load_scenario("waiting_room"), seed=seed)
    sensor = np.zeros(2)  # the laser stands at the origin, still
    assert sim.driver is None and n_scans == round(600 * sim.laser.rate_hz)
    assert np.degrees(sim.laser.fov) == pytest.approx(270)
    walkers = sim.walkers
    assert len(walkers) >= 10
    starts = [w.start_time for w in walkers]
    assert starts == sorted(starts) and len(set(starts)) == len(starts)  # one after another
    spots = []
    for w in walkers:
        stand = w.pauses[2]
        assert 120 <= stand <= 240
        # standing: the torso stays on the spot for the whole pause, feet side by side
        t0 = w.start_time + np.hypot(*np.diff(w.waypoints[:3], axis=0).T).sum() / float(np.asarray(w.speed).flat[0])
        for t in np.linspace(t0 + 0.5, t0 + stand - 0.5, 7):
            assert np.hypot(*(w.torso(t) - w.waypoints[2])) < 1e-6
            legs = w.legs(t)
            assert np.hypot(*(legs[0] - legs[1])) == pytest.approx(w.body.leg_spacing, abs=1e-6)
            assert np.allclose(legs.mean(axis=0), w.waypoints[2])
        assert 2.0 <= np.hypot(*(w.waypoints[2] - sensor)) <= 6.0
        assert w.exit_at_end and not w.present(w.end_time + 0.1)  # they walk out
        spots.append((w.waypoints[2], w.waypoints[1], t0, t0 + stand))
    # two of them stand face to face, 0.6-0.9 m apart, at the same time
    facing = 0
    for i, (a, a_pre, a0, a1) in enumerate(spots):
        for b, b_pre, b0, b1 in spots[i + 1:]:
            d = np.hypot(*(a - b))
            if 0.6 <= d <= 0.9 and max(a0, b0) + 60 < min(a1, b1):
                ua, ub = (a - a_pre) / np.hypot(*(a - a_pre)), (b - b_pre) / np.hypot(*(b - b_pre))
                facing += bool(np.dot(ua, b - a) > 0.99 * d and np.dot(ub, a - b) > 0.99 * d)
    assert facing >= 1
    # table and chair legs: pairs of human-leg-sized circles 0.2-0.5 m apart, 2-6 m out,
    # there from the first scan, where people also stand
    legs = sim.world.circles
    assert len(legs) >= 12 and len(legs) % 2 == 0
    assert ((legs[:, 2] >= 0.02) & (legs[:, 2] <= 0.06)).all()
    spacing = np.hypot(*(legs[0::2, :2] - legs[1::2, :2]).T)
    assert ((spacing >= 0.2) & (spacing <= 0.5)).all()
    r = np.hypot(*legs[:, :2].T)
    assert ((r >= 1.7) & (r <= 6.3)).all()
    standing_at = np.array([s[0] for s in spots])
    assert (np.hypot(*(legs[:, None, :2] - standing_at[None]).T).min(axis=0) < 3.0).mean() > 0.5


def _closest_pairs(walkers, times):
    """Seconds (at the step of ``times``) two present people spend closer than 0.30 m and
    0.40 m, torso to torso."""
    pos = np.stack([[w.torso(t) for t in times] for w in walkers])  # (people, times, 2)
    present = np.array([[w.present(t) for t in times] for w in walkers])
    dt = times[1] - times[0]
    below = {0.30: 0.0, 0.40: 0.0}
    for a in range(len(walkers)):
        d = np.hypot(*(pos[a + 1:] - pos[a]).transpose(2, 0, 1))
        d[~(present[a + 1:] & present[a])] = np.inf
        for gap in below:
            below[gap] += float((d < gap).sum()) * dt
    return below


@pytest.mark.parametrize("name, seconds", [("crowd", 30.0), ("follow_indoor_crowd", 120.0)])
def test_people_step_aside_rather_than_walk_through_each_other(name, seconds):
    spec = {**load_scenario(name), "duration_s": seconds}
    times = np.arange(0.0, seconds, 0.1)
    sim, _ = build_simulation(spec)
    apart = _closest_pairs(sim.walkers, times)
    through, _ = build_simulation({**spec, "keep_apart_m": 0})  # the same paths, nobody stepping aside
    close = _closest_pairs(through.walkers, times)
    assert close[0.30] > 5.0, close  # without it people overlap for seconds
    # with it hardly ever: a walker squeezed between several, or by the crowd's edge, may still be
    assert apart[0.30] < 0.1 * close[0.30] and apart[0.40] < 0.1 * close[0.40], (apart, close)
    if name == "follow_indoor_crowd":  # and never through the followed person (someone crossing
        # in the metre between them and the robot that follows them, which they walk round too,
        # may be squeezed to a little under 0.3 m for a moment)
        person = next(w for w in sim.walkers if w.person_id == sim.target_id)
        others = [w for w in sim.walkers if w is not person]
        assert all(np.hypot(*(w.torso(t) - person.torso(t))) >= 0.25
                   for w in others for t in times if w.present(t))
    # only a step aside: everyone stays within a metre of their path, in the crowd's area
    for w in sim.walkers:
        if w.detour is not None:
            assert np.hypot(*w.detour[1].T).max() <= 1.0 + 1e-9
    x0, y0, x1, y1 = spec["crowd"]["area"]
    crowd = [w for w in sim.walkers if w.detour is not None and not w.exit_at_end]
    assert crowd and all(x0 - 1e-9 <= w.torso(t)[0] <= x1 + 1e-9 and y0 - 1e-9 <= w.torso(t)[1] <= y1 + 1e-9
                         for w in crowd for t in times)


@pytest.mark.parametrize("seed", [21, 22])
def test_visitors_walk_round_those_standing_and_hold_their_place(seed):
    spec = load_scenario("waiting_room")
    times = np.arange(0.0, spec["duration_s"], 0.1)
    sim, _ = build_simulation(spec, seed=seed)
    through, _ = build_simulation({**spec, "keep_apart_m": 0}, seed=seed)
    close, apart = _closest_pairs(through.walkers, times), _closest_pairs(sim.walkers, times)
    assert close[0.40] > 1.0, close  # straight from the door to their spot and back, through others
    assert apart[0.30] == 0.0 and apart[0.40] < 0.1 * close[0.40], (apart, close)
    stepped = [w for w in sim.walkers if w.detour is not None]
    assert stepped  # someone made way
    for w in stepped:  # ... only while walking: standing, a visitor does not budge
        t, offsets = w.detour
        pos, _, _ = w.path_positions(t)
        still = np.hypot(*np.gradient(pos, t[1] - t[0], axis=0).T) < 0.05
        assert np.hypot(*np.diff(offsets, axis=0)[still[1:]].T).max(initial=0.0) == 0.0


def _seconds_at_obstacles(sim, times, within_m):
    """Seconds the crowd's torsos spend within ``within_m`` of a pillar's edge (m), and the
    deepest they go (negative: inside it)."""
    seconds, closest = 0.0, np.inf
    for w in sim.walkers:
        pos = np.array([w.torso(t) for t in times])
        for x, y, r in sim.world.circles:
            edge = np.hypot(pos[:, 0] - x, pos[:, 1] - y) - r
            seconds += float((edge < within_m).sum()) * (times[1] - times[0])
            closest = min(closest, float(edge.min()))
    return seconds, closest


def test_the_crowd_walks_round_the_pillars():
    spec = load_scenario("crowd")
    times = np.arange(0.0, spec["duration_s"], 0.1)
    sim, _ = build_simulation(spec)
    through, _ = build_simulation({**spec, "keep_apart_m": 0})
    before, deepest = _seconds_at_obstacles(through, times, 0.15)
    after, closest = _seconds_at_obstacles(sim, times, 0.15)
    assert before > 5.0 and deepest < 0.0, (before, deepest)  # the paths go through the pillars
    assert after < 0.1 * before and closest > 0.0, (after, closest)  # nobody walks into one now


def test_the_paths_worked_out_at_once_are_the_walkers_own():
    # keep_apart reads every walker's path for the whole scene at once (path_positions);
    # it must be where torso() puts them, pauses, turns and zero-length pieces included
    sim, _ = build_simulation({**load_scenario("follow_indoor_crowd"), "keep_apart_m": 0, "duration_s": 120})
    times = np.arange(-1.0, 121.0, 0.37)
    for w in sim.walkers:
        pos, _, present = w.path_positions(times)
        assert np.allclose(pos, [w.torso(t) for t in times], atol=1e-9)
        assert list(present) == [w.present(t) for t in times]


def _robot_clearance(spec: dict, laser: str) -> tuple[float, float]:
    """Seconds someone's torso spends within 0.4 m of the robot's base (inside its 0.3 m
    footprint, give or take a leg) while the scene runs, and the closest any comes (m)."""
    sim, n = build_simulation(spec, laser=laser)
    seconds, closest = 0.0, np.inf
    for _ in range(n):
        truth = sim.step().truth
        base = np.array([truth.robot_pose.x, truth.robot_pose.y])
        d = np.hypot(*(truth.torso_world - base).T)
        seconds += float((d < 0.4).sum()) * sim.laser.period
        closest = min(closest, float(d.min(initial=np.inf)))
    return seconds, closest


def test_people_walk_round_the_robot():
    # the robot drives after the person through the corridor's crowd; people make way for it
    # as for a pillar that moves (robot.radius_m), its path worked out before the scene runs
    spec = {**load_scenario("follow_indoor_crowd"), "duration_s": 90}
    through = {**spec, "robot": {**spec["robot"], "radius_m": 0.0}}
    before, deepest = _robot_clearance(through, "narrow")
    after, closest = _robot_clearance(spec, "narrow")
    assert before > 1.0 and deepest < 0.2, (before, deepest)  # without it they walk through the robot
    assert after == 0.0 and closest > 0.4, (after, closest)
