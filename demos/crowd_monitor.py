"""Crowd monitoring: people count, occupancy per zone and flow across a line, against the truth.

A stationary sensor over a 14 m x 12 m hall with 30 people (or ``--people N``) wandering
and pausing. Every scan goes through the tracker; the demo turns its tracks into the
figures a monitoring display shows and scores each against the simulator's truth:

* people count over time (tracked, and really visible);
* occupancy per zone: the hall split into four zones, mean people in each;
* flow across the line x = 7 m: crossings left-to-right and right-to-left.

    python demos/crowd_monitor.py [--short] [--people 30] [--rrd demos/crowd_monitor.rrd]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.config import load_config
from people_tracker.tracker.people_tracker import PeopleTracker

LINE_X = 7.0  # m, the counting line (world frame)
ZONES = {"near left": (1, 7, 0, 6), "near right": (1, 7, -6, 0), "far left": (7, 14, 0, 6), "far right": (7, 14, -6, 0)}


def zone_counts(xy: np.ndarray) -> dict[str, int]:
    """People in each zone; ``xy`` (k, 2) world frame, metres."""
    return {z: int(((xy[:, 0] >= x0) & (xy[:, 0] < x1) & (xy[:, 1] >= y0) & (xy[:, 1] < y1)).sum())
            for z, (x0, x1, y0, y1) in ZONES.items()}


class LineCounter:
    """Counts crossings of x = LINE_X by identified objects (track ids or person ids)."""

    def __init__(self) -> None:
        self.side: dict[int, bool] = {}
        self.left_to_right = self.right_to_left = 0

    def update(self, ids, xs) -> None:
        for i, x in zip(ids, xs):
            right = x >= LINE_X
            if i in self.side and self.side[i] != right:
                if right:
                    self.left_to_right += 1
                else:
                    self.right_to_left += 1
            self.side[i] = right


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--short", action="store_true", help="10 s instead of 30 s (for CI)")
    ap.add_argument("--people", type=int, default=30)
    ap.add_argument("--rrd", default="crowd_monitor.rrd", help="rerun recording to save ('' for none)")
    args = ap.parse_args(argv)
    spec = load_scenario("crowd")
    if args.short:
        spec = {**spec, "duration_s": 10}
    sim, n = build_simulation(spec, crowd_count=args.people)
    tracker = PeopleTracker.from_config(load_config())
    sink = None
    if args.rrd:
        import rerun as rr

        from people_tracker.tracker.viz_rerun import RerunSink
        sink = RerunSink(args.rrd, name="crowd-monitor")
    counts, truth_counts, present_counts = [], [], []
    zones_tracked = {z: [] for z in ZONES}
    zones_truth = {z: [] for z in ZONES}
    flow_tracked, flow_truth = LineCounter(), LineCounter()
    t0 = time.perf_counter()
    for i in range(n):
        step = sim.step()
        t_step = time.perf_counter()
        tracks = tracker.step(step.scan, step.odom_pose @ sim.mount, step.odom_pose_last_beam @ sim.mount)
        latency = time.perf_counter() - t_step
        truth = step.truth
        # the sensor stands still at the world origin: world = the tracker's frame here
        xy = np.array([(t.x, t.y) for t in tracks]).reshape(-1, 2)
        truth_xy = truth.torso_world[truth.visible]
        counts.append(len(tracks))
        truth_counts.append(len(truth_xy))
        present_counts.append(len(truth.torso_world))
        for z, c in zone_counts(xy).items():
            zones_tracked[z].append(c)
        for z, c in zone_counts(truth_xy).items():
            zones_truth[z].append(c)
        flow_tracked.update([t.track_id for t in tracks], xy[:, 0])
        flow_truth.update(truth.person_id.tolist(), truth.torso_world[:, 0])
        if sink is not None:
            sink.scan(i, step.scan.stamp, tracker.last, latency, truth.torso_sensor[truth.visible])
            for z, c in zone_counts(xy).items():
                sink.rec.log(f"metrics/zones/{z.replace(' ', '_')}", rr.Scalars(float(c)))
    if sink is not None:
        sink.close()
    c, tc = np.array(counts), np.array(truth_counts)
    print(f"crowd_monitor: {n} scans ({n / sim.laser.rate_hz:.0f} s), {args.people} people in the hall, "
          f"in {time.perf_counter() - t0:.1f} s")
    print(f"people count: tracked mean {c.mean():.1f}, visible (truth) mean {tc.mean():.1f}, present (truth) "
          f"mean {np.mean(present_counts):.1f}; mean absolute error against visible {np.abs(c - tc).mean():.1f}")
    print("occupancy per zone (mean people, tracked / truth visible): " + "; ".join(
        f"{z} {np.mean(zones_tracked[z]):.1f} / {np.mean(zones_truth[z]):.1f}" for z in ZONES))
    print(f"flow across x = {LINE_X:g} m (left->right / right->left): tracked {flow_tracked.left_to_right} / "
          f"{flow_tracked.right_to_left}, truth {flow_truth.left_to_right} / {flow_truth.right_to_left}")
    if args.rrd:
        print(f"rerun recording: {args.rrd}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
