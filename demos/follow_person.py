"""Follow a person: a closed loop in the simulator, steered by the tracker's target.

The `following` scene: person 1 walks ahead of the robot, turns, pauses 4 s, turns again,
while two pedestrians cross. The robot sees only its laser and its (drifting) odometry;
each scan goes through the tracker (`--follow auto` picks the closest person ahead), and
the robot's velocity command comes from where the tracker says the target is. The
simulator's truth is used only to score the run.

    python demos/follow_person.py [--short] [--rrd demos/follow_person.rrd]

Prints the following distance (median, p95, max), how many scans the target was not
reported, and how often the tracker's target was on someone other than person 1.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from people_tracker.models.robot import Command
from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.config import load_config
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame

FOLLOW_DISTANCE_M = 1.2
MAX_SPEED_MPS = 1.2
MAX_TURN_RADPS = 1.5


def steer(target_base: np.ndarray | None) -> Command:
    """Velocity command towards a target given in the robot's base frame (metres)."""
    if target_base is None:
        return Command()  # no target: stop and wait
    x, y = target_base
    err = math.atan2(y, x)
    gap = math.hypot(x, y) - FOLLOW_DISTANCE_M
    v = float(np.clip(0.8 * gap, 0.0, MAX_SPEED_MPS)) * max(0.0, math.cos(err))
    return Command(v, float(np.clip(2.0 * err, -MAX_TURN_RADPS, MAX_TURN_RADPS)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--short", action="store_true", help="15 s instead of 40 s (for CI)")
    ap.add_argument("--rrd", default="follow_person.rrd", help="rerun recording to save ('' for none)")
    args = ap.parse_args(argv)
    spec = load_scenario("following")
    if args.short:
        spec = {**spec, "duration_s": 15}
    sim, n = build_simulation(spec)
    sim.driver = None  # the robot moves only by the commands below
    tracker = PeopleTracker.from_config(load_config(), follow="auto")
    sink = None
    if args.rrd:
        from people_tracker.tracker.viz_rerun import RerunSink
        sink = RerunSink(args.rrd, name="follow-person")
    command = Command()
    gaps, lost, wrong, target_ids = [], 0, 0, []
    t0 = time.perf_counter()
    for i in range(n):
        step = sim.step(command)  # the scan at this time, then the robot moves with `command`
        pose = step.odom_pose @ sim.mount
        t_step = time.perf_counter()
        tracks = tracker.step(step.scan, pose, step.odom_pose_last_beam @ sim.mount)
        latency = time.perf_counter() - t_step
        truth = step.truth
        if sink is not None:
            sink.scan(i, step.scan.stamp, tracker.last, latency, truth.torso_sensor[truth.visible])
        target = [t for t in tracks if t.target]
        if target:
            xy_sensor = tracks_in_sensor_frame(target, tracker.last.pose)[0]
            command = steer(sim.mount.transform_points(xy_sensor[None, :])[0])  # sensor -> base frame
            target_ids.append(target[0].track_id)
            # is the target on person 1? (truth: scoring only)
            world_xy = truth.sensor_pose.transform_points(xy_sensor[None, :])[0]
            d = np.hypot(*(truth.torso_world - world_xy).T)
            if truth.person_id[int(np.argmin(d))] != 1 or d.min() > 0.75:
                wrong += 1
        else:
            command = Command()
            lost += 1
        k = list(truth.person_id).index(1) if 1 in truth.person_id else None
        if k is not None:
            gaps.append(math.hypot(truth.torso_world[k, 0] - truth.robot_pose.x, truth.torso_world[k, 1] - truth.robot_pose.y))
    if sink is not None:
        sink.close()
    g = np.array(gaps)
    switches = sum(1 for a, b in zip(target_ids[:-1], target_ids[1:]) if a != b)
    print(f"follow_person: {n} scans ({n / sim.laser.rate_hz:.0f} s) in {time.perf_counter() - t0:.1f} s")
    print(f"following distance to person 1: median {np.median(g):.2f} m, p95 {np.percentile(g, 95):.2f} m, "
          f"max {g.max():.2f} m (the controller aims at {FOLLOW_DISTANCE_M} m)")
    print(f"target not reported: {lost} of {n} scans; target on someone else: {wrong} scans; "
          f"target id changes: {switches}; target ids: {sorted(set(target_ids))}")
    print("tracker events: " + (", ".join(tracker.selector.events) or "none"))
    if args.rrd:
        print(f"rerun recording: {args.rrd}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
