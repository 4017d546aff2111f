"""Where identities go wrong in a simulated scene: tracks that hop from one person to another.

Runs the default tracker over a simulated scene (as ``track_evidence.py`` does) and follows
each reported track through the people it lies on (the nearest person within 0.5 m, world
frame). A *hop* is a track on one person in one scan and on another the next time it is on
anyone: one id carried from a person to someone else, which is where the crowd's id switches
come from. Prints the number of tracks and hops, how many hops came while the person the
track left was hidden (fewer than 3 readings), how many left the track on the new person
for a second or more (the others flicker: a track between two people standing close lies
within 0.5 m of both), and the tracks that hopped most, each with
the people it lay on and the scans.

Usage::

    python benchmarks/track_hops.py                          # crowd, 30 s
    python benchmarks/track_hops.py --scene waiting_room --seed 21
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from track_evidence import NEAR_M, nearest_person, run_scene  # noqa: E402

LASTING_S = 1.0  # a hop after which the track stays this long on the new person is no flicker


def hops(scene: str, seed: int | None, duration: float | None, show: int) -> None:
    run = run_scene(scene, seed, duration)
    dist, who = nearest_person(run)
    scan, track = run.rows[:, 0].astype(np.int64), run.rows[:, 1].astype(np.int64)
    on: dict[int, list[tuple[int, int]]] = defaultdict(list)  # track -> [(scan, person)]
    for k, t, p, d in zip(scan, track, who, dist):
        if d <= NEAR_M:
            on[int(t)].append((int(k), int(p)))
    visible = [dict(zip(tr.person_id.tolist(), tr.visible.tolist())) for tr in run.truths]
    n_hops, hidden, lasting, per_track = 0, 0, 0, {}
    for t, seq in on.items():
        runs = []  # [person, first scan, last scan]
        for k, p in seq:
            if runs and runs[-1][0] == p:
                runs[-1][2] = k
            else:
                runs.append([p, k, k])
        for (p0, _, _), (_, k1, k2) in zip(runs, runs[1:]):
            n_hops += 1
            hidden += not visible[k1].get(p0, False)
            lasting += run.stamps[k2] - run.stamps[k1] >= LASTING_S
        per_track[t] = runs
    ids = defaultdict(set)
    for t, seq in on.items():
        for _, p in seq:
            ids[p].add(t)
    label = scene if seed is None else f"{scene} seed {seed}"
    print(f"{label}: {len(run.truths)} scans, {len(on)} tracks on someone, {n_hops} hops from one person to "
          f"another ({hidden} while the person left was hidden, {lasting} staying on the new person "
          f"{LASTING_S:g} s or more); {sum(len(s) > 1 for s in ids.values())} of "
          f"{len(ids)} people were given more than one id")
    worst = sorted(per_track.items(), key=lambda kv: -len(kv[1]))[:show]
    for t, runs in worst:
        if len(runs) < 2:
            break
        print(f"  track {t}: " + " ".join(f"p{p}[{a}-{b}]" for p, a, b in runs[:12]) + (" ..." if len(runs) > 12 else ""))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="crowd")
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--duration", type=float, default=None, help="seconds (default: the scene's)")
    ap.add_argument("--show", type=int, default=3, help="how many of the tracks that hopped most to list")
    args = ap.parse_args(argv)
    hops(args.scene, args.seed, args.duration, args.show)
    return 0


if __name__ == "__main__":
    sys.exit(main())
