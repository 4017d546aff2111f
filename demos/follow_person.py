"""Follow a person outdoors: a closed loop in the simulator, steered by the tracker's target.

The `follow_outdoor` scene: person 1 walks round a building and across an open field with a
few trees and posts, turning sharply, stopping, while passers-by cross between them and the
robot; sunlight adds spurious short readings. The robot has no odometry: each scan goes
through the tracker alone (`--follow auto` locks onto the person straight ahead), and the
robot's velocity command comes from where the tracker says the target is (while the person's
track coasts, unmarked, from its prediction; when the target is lost, from the person's place
relative to the robot averaged over the last 1.5 s, for up to 10 s: a robot that follows
someone keeps them at much the same place in front of it, so it drives on as it followed
them, and the re-lock finds them ahead). The tracker runs with the shipped `outdoors`
configuration (a line of sight into the open that returned nothing counts as seen through
to 3 m). The simulator's truth is used only to score the run, with `evaluate`'s following
protocol.

    python demos/follow_person.py [--laser narrow|wide|long_cw] [--seed N] [--short] [--rrd FILE] [--config NAME|FILE]

Prints the following distance (median, p95, max) and the following figures: the share of
the person's visible scans with the target on them after the first lock, the scans with the
target on someone or something else, target changes, the time to the first lock, and, over
all tracks, id switches, misses and MOTP.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from people_tracker.models.robot import Command
from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.bench import scene_ground_truth
from people_tracker.tracker.config import Config, load_config, load_config_or_exit
from people_tracker.tracker.evaluation import TrackRows, evaluate
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame

SCENE = "follow_outdoor"
FOLLOW_DISTANCE_M = 1.0
MAX_SPEED_MPS = 1.5
MAX_TURN_RADPS = 1.5
SEARCH_S = 10.0  # s: with the target lost, the robot drives on after where the person was lately, this long


def steer(target_base: np.ndarray | None) -> Command:
    """Velocity command towards a target given in the robot's base frame (metres)."""
    if target_base is None:
        return Command()  # no target: stop and wait
    x, y = target_base
    err = math.atan2(y, x)
    gap = math.hypot(x, y) - FOLLOW_DISTANCE_M
    v = float(np.clip(0.8 * gap, 0.0, MAX_SPEED_MPS)) * max(0.0, math.cos(err))
    return Command(v, float(np.clip(2.0 * err, -MAX_TURN_RADPS, MAX_TURN_RADPS)))


def run(laser: str = "wide", seed: int = 1, config: Config | None = None, short: bool = False,
        rrd: str = "") -> dict:
    """One closed-loop run: the robot steered by the tracker's target through ``follow_outdoor``.

    ``config``: the tracker's configuration (a loaded one; None: the shipped ``outdoors``);
    ``rrd``: a rerun recording to save ('' for none). Returns the scene's scan count and
    duration (s), the robot-to-person distances (m, one per scan the person exists), the
    following figures of ``evaluate`` (its result dict), the person's id, the selector's
    events and the wall time (s).
    """
    config = load_config("outdoors") if config is None else config
    spec = load_scenario(SCENE)
    # people walk round a robot whose path is worked out before the scene runs; this one is
    # steered live by the tracker, so its footprint is off and people may walk through it
    spec = {**spec, "robot": {**spec["robot"], "radius_m": 0.0}}
    if short:
        spec = {**spec, "duration_s": 60}
    sim, n = build_simulation(spec, seed=seed, laser=laser)
    sim.driver = None  # the robot moves only by the commands below
    person = sim.target_id
    tracker = PeopleTracker.from_config(config, follow="auto")
    sink = None
    if rrd:
        from people_tracker.tracker.viz_rerun import RerunSink
        sink = RerunSink(rrd, name="follow-person")
    command = Command()
    last_seen = None  # (stamp, world position) of the target when last reported
    gaps, rows, truths = [], [], []
    t0 = time.perf_counter()
    for i in range(n):
        step = sim.step(command)  # the scan at this time, then the robot moves with `command`
        t_step = time.perf_counter()
        tracks = tracker.step(step.scan)  # no odometry: the laser alone
        latency = time.perf_counter() - t_step
        truth = step.truth
        truths.append(truth)
        if sink is not None:
            sink.scan(i, step.scan.stamp, tracker.last, latency, truth.torso_sensor[truth.visible])
        xy = tracks_in_sensor_frame(tracks, tracker.last.pose)
        rows += [(i, t.track_id, x, y, int(t.target), step.scan.stamp) for t, (x, y) in zip(tracks, xy)]
        target = [k for k, t in enumerate(tracks) if t.target]
        if not target and tracker.selector.target is not None:
            # the person's own track coasts (reported, no longer marked as the target: where
            # they are is a guess): the robot drives on after its prediction meanwhile
            target = [k for k, t in enumerate(tracks) if t.track_id == tracker.selector.target]
        pose = tracker.last.pose  # the sensor in the tracker's world frame (from scan matching alone)
        if target:
            last_seen = (step.scan.stamp, np.array([tracks[target[0]].x, tracks[target[0]].y]))
            command = steer(sim.mount.transform_points(xy[target[0]][None, :])[0])
        elif last_seen is not None and step.scan.stamp - last_seen[0] <= SEARCH_S:
            # lost: drive on after where the person has been lately relative to the robot (the
            # selector's averaged place, sensor frame), or, with none, to where they were last
            # seen (world frame); then wait
            steady = tracker.selector.steady
            where = sim.mount.transform_points(
                steady[None, :] if steady is not None else pose.inverse().transform_points(last_seen[1][None, :]))[0]
            command = steer(where) if np.hypot(*where) > FOLLOW_DISTANCE_M else Command()
        else:
            command = Command()
        k = list(truth.person_id).index(person) if person in truth.person_id else None
        if k is not None:
            gaps.append(math.hypot(truth.torso_world[k, 0] - truth.robot_pose.x, truth.torso_world[k, 1] - truth.robot_pose.y))
    if sink is not None:
        sink.close()
    figures = evaluate(scene_ground_truth(truths)[0], TrackRows.of(rows), "following", target_person=person)
    return {"scans": n, "duration_s": n / sim.laser.rate_hz, "distances_m": np.array(gaps), "figures": figures,
            "person": person, "events": list(tracker.selector.events), "wall_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--laser", default="wide", choices=("narrow", "wide", "long_cw"),
                    help="86 deg 10 Hz 5.6 m; 270 deg 7.5 Hz 11 m; 270 deg 12.5 Hz 29 m clockwise (default: wide)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--short", action="store_true", help="60 s instead of the scene's 10 minutes (for CI)")
    ap.add_argument("--rrd", default="follow_person.rrd", help="rerun recording to save ('' for none)")
    ap.add_argument("--config", default="outdoors",
                    help="the tracker's configuration: a shipped name or a YAML file (default: outdoors)")
    args = ap.parse_args(argv)
    config = load_config_or_exit(args.config, "follow_person")
    out = run(args.laser, args.seed, config, short=args.short, rrd=args.rrd)
    r, g, person = out["figures"], out["distances_m"], out["person"]
    print(f"follow_person: {SCENE}, laser {args.laser}, seed {args.seed}: {out['scans']} scans "
          f"({out['duration_s']:.0f} s) in {out['wall_s']:.1f} s, no odometry")
    print(f"following distance to person {person}: median {np.median(g):.2f} m, p95 {np.percentile(g, 95):.2f} m, "
          f"max {g.max():.2f} m (the controller aims at {FOLLOW_DISTANCE_M} m)")
    lock = "never" if r["first_lock_scan"] is None else f"{r['first_lock_s']:.2f} s after they are first visible"
    print(f"target on person {person}: {100 * r['target_on_person']:.1f} % of their {r['target_person_scans']} visible "
          f"scans after the first lock; on someone or something else: {r['target_wrong_scans']} scans; "
          f"target changes: {r['target_changes']}; first lock: {lock}")
    print(f"over all tracks (Leigh et al.'s following figures): id switches {r['id_switches']}, misses {r['misses']}, "
          f"MOTP {r['motp_m']:.3f} m")
    print("tracker events: " + (", ".join(out["events"]) or "none"))
    if args.rrd:
        print(f"rerun recording: {args.rrd}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
