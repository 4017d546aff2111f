"""Why the followed person's track changes, over all tracks (Leigh et al.'s id switches).

Usage::

    python benchmarks/person_switches.py [--scene follow_outdoor] [--laser wide] [--seed 1] [--duration S]

Runs the default tracker, without ``--follow``, on one simulated following run and keeps,
scan by scan, the reported track on the followed person as CLEAR MOT does: the one matched
before while it is still reported and within 0.75 m of them (sensor frame), else the
nearest reported track within 0.75 m. Each time that track changes (an id switch of the
following protocol) it prints the time, how long the person had no track, their range and
bearing from the sensor, the nearest other person, the new track's age, and what became of
the old track: deleted (by which rule of ``TrackState.end_reason``: its evidence of absence alone
fell below ``existence.delete`` (its place seen through, no motion while it walks); its
existence did; its position's uncertainty grew past ``tracks.max_position_std_m``; or
another rule: a duplicate of someone standing, someone who set off), alive but not
reported, or alive and how far from the person (it slid onto someone or something else).
A count by what became of the old track closes the output. The development seeds of the
following work are 1 and 2 (``benchmarks/following.py``).
"""

from __future__ import annotations

import math
import sys
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from following_losses import NEAR_M, one_run_arguments  # noqa: E402

from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.io.simulated import SimulatedSource  # noqa: E402
from people_tracker.tracker.people_tracker import PeopleTracker  # noqa: E402


# TrackState.end_reason's rules, as the output names them
ENDED = {"absence": "deleted: evidence of absence alone", "existence": "deleted: existence below existence.delete",
         "tentative": "deleted: tentative too long", "uncertainty": "deleted: position uncertainty",
         None: "deleted: a duplicate, or set off"}
SLID = "alive, on someone or something else"


def switches(scene: str, laser: str, seed: int, duration: float | None) -> list[tuple]:
    source = SimulatedSource(scene, seed=seed, duration=duration, laser=laser)
    tracker = PeopleTracker.from_config(load_config())
    person = source.sim.target_id
    current, current_end, last_seen, t0 = None, None, None, None  # current_end: why it was deleted
    out = []
    for record in source.scans():
        tracker.step(record.scan, record.pose, record.pose_last_beam)
        stamp = record.scan.stamp
        t0 = stamp if t0 is None else t0
        alive = any(t is current for t in tracker._tracks)
        if current is not None and not alive and current_end is None:
            current_end = ENDED[current.end_reason()]  # its state as the step that ended it left it
        truth = source.truths[record.index]
        k = int(np.flatnonzero(truth.person_id == person)[0])
        if not truth.visible[k]:
            continue
        inv = tracker.last.pose.inverse()
        where = truth.torso_sensor[k]

        def dist(t) -> float:
            return float(np.hypot(*(inv.transform_points(t.position[None])[0] - where)))

        if current is not None and current.reported and alive and dist(current) <= NEAR_M:
            on = current
        else:
            near = [(d, t) for d, t in ((dist(t), t) for t in tracker._tracks if t.reported) if d <= NEAR_M]
            on = min(near, key=lambda dt: dt[0])[1] if near else None
        if on is None:
            continue
        if current is not None and on is not current:
            off_m = math.nan  # how far from the person the old track is, when it slid off them
            if current_end is not None:
                what = current_end
            elif not current.reported:
                what = "alive, not reported"
            else:
                what, off_m = SLID, dist(current)
            others = [float(np.hypot(*(truth.torso_world[j] - truth.torso_world[k])))
                      for j in range(len(truth.person_id)) if j != k]
            out.append((stamp - t0, stamp - last_seen, float(np.hypot(*where)),
                        math.degrees(math.atan2(where[1], where[0])), min(others, default=math.inf),
                        stamp - on.born, what, off_m))
        if on is not current:
            current_end = None
        current, last_seen = on, stamp
    return out


def main(argv=None) -> int:
    args = one_run_arguments(__doc__, "follow_outdoor", 1, argv)
    rows = switches(args.scene, args.laser, args.seed, args.duration)
    print(f"{args.scene}, laser {args.laser}, seed {args.seed}: {len(rows)} changes of the track on the person")
    print(f"{'time s':>7} {'gap s':>6} {'range m':>8} {'bearing':>8} {'other m':>8} {'new age s':>10}  old track")
    for s, gap, rng, brg, other, age, what, off_m in rows:
        near = f"{other:8.1f}" if math.isfinite(other) else f"{'-':>8}"
        old = f"alive, {off_m:.1f} m from the person" if what == SLID else what
        print(f"{s:7.1f} {gap:6.1f} {rng:8.1f} {brg:+7.0f}° {near} {age:10.1f}  {old}")
    counts = Counter(row[6] for row in rows)
    print("by what became of the old track: " + "; ".join(f"{n} {what}" for what, n in counts.most_common()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
