"""Where person candidates sit relative to the person, by kind: a leg pair, a lone leg, a blob.

For every person candidate of every scan (the tracker's default configuration) that lies
within 0.6 m of a visible simulated person walking faster than 0.5 m/s, the offset from
that person's torso is split two ways: along the line of sight (radial: negative is nearer
the laser than the person) and along the person's walking direction (negative: behind
them). The radial offset is also given by how closely the person walks along the line of
sight (|cos| of the angle between their walking direction and the beam: 0 across it, 1
straight towards or away from the laser), since a person walking along the beam shows the
laser one leg in front of the other.

This is the measurement behind the position error of the following scenes
(docs/following.md, "Where the candidates sit"); it changes nothing in the tracker.

Usage::

    python benchmarks/candidate_offsets.py [--scene NAME_OR_YAML --laser LASER --duration S]

With ``--scene``, that scene alone (a shipped name or a scenario YAML file).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from people_tracker.models.pose import Pose2D
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.simulated import SimulatedSource
from people_tracker.tracker.people_tracker import PeopleTracker

SCENES = (("crossing", None, None), ("crowd", None, None), ("follow_outdoor", "wide", 120.0),
          ("follow_indoor_crowd", "wide", 120.0))
NEAR_M = 0.6  # m: a candidate farther than this from every visible person is nobody's
MIN_SPEED_MPS = 0.5  # walking people only: a standing person has no walking direction
COS_BINS = ((0.0, 0.5), (0.5, 0.87), (0.87, 1.0))


def offsets(scene: str, laser: str | None, duration: float | None) -> list[tuple[str, float, float, float]]:
    """(kind, radial offset m, along-walk offset m, |cos(walk, beam)|) of every candidate near a walker."""
    source = SimulatedSource(scene, laser=laser, duration=duration)
    tracker = PeopleTracker.from_config(load_config())
    previous: dict[int, tuple[np.ndarray, float]] = {}
    out = []
    for record in source.scans():
        tracker.step(record.scan, record.pose, record.pose_last_beam)
        truth = source.truths[record.index]
        turn = Pose2D(0.0, 0.0, -truth.sensor_pose.yaw)  # world directions into the sensor frame
        walk = {}  # person id -> velocity in the sensor frame, m/s
        for pid, xy in zip(truth.person_id.tolist(), truth.torso_world):
            if pid in previous and truth.stamp > previous[pid][1]:
                walk[pid] = turn.transform_points((xy - previous[pid][0])[None] / (truth.stamp - previous[pid][1]))[0]
            previous[pid] = (xy.copy(), truth.stamp)
        seen = truth.visible
        if not seen.any() or not tracker.last.candidates:
            continue
        people, ids = truth.torso_sensor[seen], truth.person_id[seen].tolist()
        world_to_sensor = tracker.last.pose.inverse()
        for c in tracker.last.candidates:
            q = world_to_sensor.transform_points(np.array([[c.x, c.y]]))[0]
            d = np.hypot(*(people - q).T)
            j = int(np.argmin(d))
            v = walk.get(ids[j])
            if d[j] > NEAR_M or v is None or np.hypot(*v) < MIN_SPEED_MPS:
                continue
            beam = people[j] / np.hypot(*people[j])
            heading = v / np.hypot(*v)
            off = q - people[j]
            out.append((c.kind, float(off @ beam), float(off @ heading), float(abs(beam @ heading))))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", help="one scene (a shipped name or a scenario YAML file) instead of the four")
    ap.add_argument("--laser", help="with --scene: the laser (default: the scene's)")
    ap.add_argument("--duration", type=float, help="with --scene: seconds (default: the scene's)")
    args = ap.parse_args(argv)
    scenes = SCENES if args.scene is None else ((args.scene, args.laser, args.duration),)
    print(f"{'scene':<44} {'kind':<5} {'cands':>6} {'radial m':>9} {'sd m':>6} {'along m':>8}   "
          f"radial m by |cos(walk, beam)| {' / '.join(f'{a:g}-{b:g}' for a, b in COS_BINS)}")
    for scene, laser, duration in scenes:
        rows = offsets(scene, laser, duration)
        kinds = np.array([r[0] for r in rows], dtype=object)
        values = np.array([r[1:] for r in rows]).reshape(-1, 3)
        label = scene + (f" ({laser}, {duration:g} s)" if laser and duration else f" ({laser})" if laser else "")
        for kind in ("pair", "leg", "blob"):
            m = kinds == kind
            if m.sum() < 10:
                continue
            radial, along, cos = values[m].T
            by_cos = []
            for a, b in COS_BINS:
                sel = (cos >= a) & (cos < b) if b < 1.0 else (cos >= a)
                by_cos.append(f"{radial[sel].mean():+.3f} ({sel.sum()})" if sel.sum() >= 10 else "-")
            print(f"{label:<44} {kind:<5} {m.sum():>6} {radial.mean():>+9.3f} {radial.std():>6.3f} "
                  f"{along.mean():>+8.3f}   {' / '.join(by_cos)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
