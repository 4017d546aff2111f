"""The following scenes hold what they promise, measured on the simulator's truth.

``follow_outdoor`` and ``follow_indoor_crowd`` run for 10 minutes with each of their three
lasers; from the truth of every scan: the followed person turns sharply, stops, walks
beside the robot, leaves its view for 1-3 s, and passers-by cross between them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from people_tracker.models.scenario import build_simulation, load_scenario

LASERS = {  # name: fov (deg), resolution (deg), rate (Hz), range (m), clockwise
    "narrow": (86, 0.35, 10.0, 5.6, False),
    "wide": (270, 0.33, 7.5, 11.0, False),
    "long_cw": (270, 0.5, 12.5, 29.0, True),
}


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) index runs where ``mask`` holds."""
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def _crosses(a0, b0, a1, b1, p0, p1) -> bool:
    """Whether a point moving p0 -> p1 crosses the segment a-b (which moved a0-b0 -> a1-b1)."""
    def side(a, b, p):
        return np.sign((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]))

    u = b1 - a1
    along = float(np.dot(p1 - a1, u) / max(float(np.dot(u, u)), 1e-9))
    return side(a0, b0, p0) != side(a1, b1, p1) and 0.0 <= along <= 1.0


def scene_properties(name: str, laser: str) -> dict:
    """What the followed person does in one run of the scene, from the truth."""
    sim, n = build_simulation(load_scenario(name), laser=laser)
    target = next(w for w in sim.walkers if w.person_id == sim.target_id)
    dt = sim.laser.period
    pos, sensor, visible, bearing, rng = [], [], [], [], []
    others = []
    for _ in range(n):
        tr = sim.step().truth
        k = int(np.flatnonzero(tr.person_id == sim.target_id)[0])
        pos.append(tr.torso_world[k])
        sensor.append((tr.sensor_pose.x, tr.sensor_pose.y))
        visible.append(bool(tr.visible[k]))
        x, y = tr.torso_sensor[k]
        bearing.append(math.atan2(y, x))
        rng.append(math.hypot(x, y))
        others.append({int(p): tr.torso_world[j] for j, p in enumerate(tr.person_id) if p != sim.target_id})
    pos, sensor, visible = np.array(pos), np.array(sensor), np.array(visible)
    bearing, rng = np.array(bearing), np.array(rng)
    speed = np.r_[0.0, np.hypot(*np.diff(pos, axis=0).T)] / dt
    # heading each second while walking; a sharp turn: it changes by 90 degrees or more within 4 s
    step = int(round(1.0 / dt))
    idx = np.arange(0, n - step, step)
    moved = pos[idx + step] - pos[idx]
    walking = np.hypot(*moved.T) > 0.3
    heading = np.arctan2(moved[:, 1], moved[:, 0])
    turns, busy_until = 0, -1
    for j in np.flatnonzero(walking):
        if j <= busy_until:
            continue
        later = [k for k in range(j + 1, min(j + 5, len(idx))) if walking[k]
                 and abs((heading[k] - heading[j] + math.pi) % (2 * math.pi) - math.pi) >= math.radians(89)]
        if later:
            turns, busy_until = turns + 1, later[0] + 4
    crossed, near = set(), set()
    for i in range(1, n):
        for pid, q in others[i].items():
            if np.hypot(*(q - pos[i])) < 0.5:
                near.add(pid)
            q0 = others[i - 1].get(pid)
            if q0 is not None and _crosses(sensor[i - 1], pos[i - 1], sensor[i], pos[i], q0, q):
                crossed.add(pid)
    same_build = {w.person_id for w in sim.walkers if w is not target
                  and (w.body.leg_radius, w.body.leg_spacing) == (target.body.leg_radius, target.body.leg_spacing)}
    minutes = n * dt / 60.0
    return {
        "laser": sim.laser, "minutes": minutes, "odometry": sim.has_odometry,
        "sharp_turns": turns,
        "stops_3_10s": sum(3.0 <= (b - a) * dt <= 10.5 for a, b in _runs(speed < 0.05)),
        "beside_s": float(np.sum((np.abs(np.abs(bearing) - math.pi / 2) < math.radians(30)) & (rng < 2.5)
                                 & (speed > 0.3)) * dt),
        "out_of_view_1_3s": sum(1.0 <= (b - a) * dt <= 3.0 for a, b in _runs(~visible)),
        "crossings_per_min": len(crossed) / minutes,
        "same_build_within_half_metre_per_min": len(near & same_build) / minutes,
    }


@pytest.fixture(scope="module", params=[(s, laser) for s in ("follow_outdoor", "follow_indoor_crowd") for laser in LASERS],
                ids=lambda p: f"{p[0]}-{p[1]}")
def scene(request):
    name, laser = request.param
    return name, laser, scene_properties(name, laser)


def test_the_scene_runs_ten_minutes_with_the_laser_asked_for(scene):
    name, laser, p = scene
    fov, res, rate, rmax, clockwise = LASERS[laser]
    m = p["laser"]
    assert p["minutes"] == pytest.approx(10.0)
    assert (math.degrees(m.fov), math.degrees(m.resolution), m.rate_hz, m.range_max) == \
        pytest.approx((fov, res, rate, rmax))
    assert m.clockwise == clockwise
    assert m.dropout == pytest.approx(0.01)
    if name == "follow_outdoor":  # no odometry, sunlight
        assert not p["odometry"] and m.spurious == pytest.approx(0.005)
    else:
        assert p["odometry"]


def test_the_person_turns_stops_walks_beside_and_leaves_the_view(scene):
    name, laser, p = scene
    assert p["sharp_turns"] >= 6, p
    assert p["stops_3_10s"] >= 4, p
    assert p["beside_s"] >= 5.0, p
    assert p["out_of_view_1_3s"] >= 2, p


def test_passers_by_cross_between_the_robot_and_the_person(scene):
    name, laser, p = scene
    assert p["crossings_per_min"] >= 3.0, p
    if name == "follow_indoor_crowd":  # people of their build pass within 0.5 m
        assert p["same_build_within_half_metre_per_min"] >= 3.0, p
