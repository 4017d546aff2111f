"""Where identities go wrong in a simulated scene: tracks that hop from one person to another.

Runs the default tracker over a simulated scene (as ``track_evidence.py`` does) and follows
each reported track through the people it lies on (the nearest person within 0.5 m, world
frame). A *hop* is a track on one person in one scan and on another the next time it is on
anyone: one id carried from a person to someone else, which is where the crowd's id switches
come from. Prints the number of tracks and hops, how many hops came while the person the
track left was hidden (fewer than 3 readings), how many left the track on the new person
for a second or more (the others flicker: a track between two people standing close lies
within 0.5 m of both), which update brought the track onto the new person (a moving
candidate through association, static support, a standing leg pair, or none: the
prediction alone), and the tracks that hopped most, each with
the people it lay on and the scans.

Usage::

    python benchmarks/track_hops.py                          # crowd, 30 s
    python benchmarks/track_hops.py --scene waiting_room --seed 21
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from track_evidence import NEAR_M, SceneRun, nearest_person  # noqa: E402

from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.io.simulated import SimulatedSource  # noqa: E402
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame  # noqa: E402

LASTING_S = 1.0  # a hop after which the track stays this long on the new person is no flicker


class _NotingTracker(PeopleTracker):
    """The default tracker, noting after each scan how each track was updated."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.how: list[dict[int, str]] = []  # per scan: track id -> how it was updated

    def _support(self, scan, world, matched) -> None:
        before = {t.track_id: t.last_update for t in self._tracks}
        super()._support(scan, world, matched)
        self._supported = {t.track_id for t in self._tracks if t.last_update != before.get(t.track_id)}

    def step(self, scan, *args, **kwargs):
        self._supported = set()
        out = super().step(scan, *args, **kwargs)
        how = {}
        for t in self._tracks:
            if t.last_moving_update == t.stamp:
                how[t.track_id] = "a moving candidate"
            elif t.track_id in self._supported:
                how[t.track_id] = "static support"
            elif t.last_update == t.stamp:
                how[t.track_id] = "a standing leg pair"
        self.how.append(how)
        return out


def _run(scene: str, seed: int | None, duration: float | None):
    """``track_evidence.run_scene`` with the noting tracker."""
    source = SimulatedSource(scene, seed=seed, duration=duration)
    tracker = _NotingTracker.from_config(load_config())
    rows, stamps = [], []
    for record in source.scans():
        tracks = tracker.step(record.scan, record.pose, record.pose_last_beam)
        for t, (x, y) in zip(tracks, tracks_in_sensor_frame(tracks, tracker.last.pose)):
            rows.append((record.index, t.track_id, x, y, t.confidence))
        stamps.append(record.scan.stamp)
    run = SceneRun(scene, seed, np.array(stamps), np.array(rows, dtype=float).reshape(-1, 5), source.truths)
    return run, tracker.how


def hops(scene: str, seed: int | None, duration: float | None, show: int) -> None:
    run, how = _run(scene, seed, duration)
    dist, who = nearest_person(run)
    scan, track = run.rows[:, 0].astype(np.int64), run.rows[:, 1].astype(np.int64)
    on: dict[int, list[tuple[int, int]]] = defaultdict(list)  # track -> [(scan, person)]
    for k, t, p, d in zip(scan, track, who, dist):
        if d <= NEAR_M:
            on[int(t)].append((int(k), int(p)))
    visible = [dict(zip(tr.person_id.tolist(), tr.visible.tolist())) for tr in run.truths]
    n_hops, hidden, lasting, per_track = 0, 0, 0, {}
    carried: Counter = Counter()  # how the track came onto the new person
    for t, seq in on.items():
        runs = []  # [person, first scan, last scan]
        for k, p in seq:
            if runs and runs[-1][0] == p:
                runs[-1][2] = k
            else:
                runs.append([p, k, k])
        for (p0, _, k0), (_, k1, k2) in zip(runs, runs[1:]):
            n_hops += 1
            hidden += not visible[k1].get(p0, False)
            lasting += run.stamps[k2] - run.stamps[k1] >= LASTING_S
            # the last update at or before the first scan on the new person
            carried[next((how[k][t] for k in range(k1, k0, -1) if t in how[k]), "prediction alone")] += 1
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
    print("  the update that brought the track onto the new person: " +
          ", ".join(f"{kind} {n}" for kind, n in carried.most_common()))
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
