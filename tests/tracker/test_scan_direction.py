"""One scene, a clockwise and a counter-clockwise laser: the same people, whichever way it sweeps.

Every shipped scene whose sensor moves is rendered twice, identical but for the laser's
beam order, noise-free so that both see the same world (the range noise would be drawn
in another order), with the people held still during each sweep (else the two lasers would
see each walker at another time). With the robot held still the two scans are exact mirrors and every
detection and track must agree to the micrometre. Moving, the two lasers fire each beam
from another place on the robot's path, so a leg is crossed by other rays: after de-skew
the hull centroids agree to a centimetre at the median, and objects at the edge of the
size threshold (2 or 3 readings, the count a width of detector.min_object_width_m takes at
that range) may be found by one laser only.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from people_tracker.models.scenario import build_simulation, load_scenario, scenario_names
from people_tracker.tracker.config import load_config
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame

MOVING_SCENES = [n for n in scenario_names() if any(k in (load_scenario(n).get("robot") or {})
                                                     for k in ("drive", "waypoints", "follow"))]


def _run(name: str, clockwise: bool, still: bool):
    spec = copy.deepcopy(load_scenario(name))
    spec["laser"] = {**spec.get("laser", {}), "clockwise": clockwise, "noise_std": 0.0, "dropout": 0.0, "spurious": 0.0}
    spec["duration_s"] = min(float(spec.get("duration_s", 20)), 40.0)  # the long following scenes: their first 40 s
    if still:
        spec["robot"] = {k: v for k, v in spec["robot"].items() if k not in ("drive", "waypoints", "follow")}
    sim, n = build_simulation(spec)
    sim.people_walk_in_sweep = False  # else the two lasers see each walker at other times
    tracker = PeopleTracker.from_config(load_config())
    tracker._seen_after_stamp = lambda xy, scan, world: np.zeros(len(xy))  # nor reported back along the sweep
    detections, tracks = [], []
    for _ in range(n):
        st = sim.step()
        last = st.odom_pose_last_beam @ sim.mount if st.odom_pose_last_beam is not None else None
        found = tracker.step(st.scan, st.odom_pose @ sim.mount, last)
        detections.append(np.array([(o.x, o.y) for o in tracker.last.detection.objects]).reshape(-1, 2))
        tracks.append(tracks_in_sensor_frame(found, tracker.last.pose))
    return detections, tracks


def _pair_up(a_scans, b_scans, gate_m=0.1):
    """Per scan, the one-to-one pairing of the two runs' positions within ``gate_m``: the
    distances of the pairs, and how many positions of either run found no partner."""
    dist, unpaired, total = [], 0, 0
    for a, b in zip(a_scans, b_scans):
        total += len(a) + len(b)
        if len(a) and len(b):
            d = np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])
            r, c = linear_sum_assignment(np.minimum(d, 10.0))
            ok = d[r, c] < gate_m
            dist.extend(d[r, c][ok])
            unpaired += len(a) + len(b) - 2 * int(ok.sum())
        else:
            unpaired += len(a) + len(b)
    return np.array(dist), unpaired / max(total, 1)


def test_the_moving_scenes_are_found():
    assert {"corridor", "following", "room_drive"} <= set(MOVING_SCENES)


@pytest.mark.parametrize("name", MOVING_SCENES)
def test_still_sensor_gives_the_same_detections_and_tracks_either_way(name):
    ccw, cw = _run(name, False, still=True), _run(name, True, still=True)
    for a, b in ((ccw[0], cw[0]), (ccw[1], cw[1])):
        assert [len(x) for x in a] == [len(x) for x in b]
        dist, unpaired = _pair_up(a, b)
        assert unpaired == 0 and (len(dist) == 0 or dist.max() < 1e-6)


@pytest.mark.parametrize("name", MOVING_SCENES)
def test_moving_sensor_gives_the_same_detections_and_tracks_either_way(name):
    ccw, cw = _run(name, False, still=False), _run(name, True, still=False)
    dist, unpaired = _pair_up(ccw[0], cw[0])
    # unpaired measured on room_drive: 9.7 % with a fixed 3-reading size rule, 10.1 % with the
    # width rule (4 more one-laser objects, all beyond 6 m where 2 readings now suffice)
    assert len(dist) > 100 and np.median(dist) < 0.01 and unpaired <= 0.12, (np.median(dist), unpaired)
    # tracks carry the same sampling differences through the leg model's scores (a standing
    # leg scored just above its threshold in one direction, just below in the other, so a
    # start a few scans earlier or later) and the filter: measured 1.0 cm median on
    # room_drive, 17.5 % of track-scans unpaired on corridor. In a crowd (follow_indoor_crowd:
    # 32 %) such a difference decides which of two tracks takes a passer-by's legs, and the
    # tracks part for good: only the detections are compared there.
    if "crowd" in load_scenario(name):
        return
    dist, unpaired = _pair_up(ccw[1], cw[1])
    assert len(dist) > 100 and np.median(dist) < 0.015 and unpaired <= 0.20, (np.median(dist), unpaired)
