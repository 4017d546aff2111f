"""How the followed person's track leaves them: the last update it took before they had none.

Usage::

    python benchmarks/following_track_ends.py [--scene follow_indoor_crowd] [--laser wide] [--seed 2] [--duration S]

Runs the default tracker with ``--follow auto`` on one simulated following run. Each time
the person is visible and no reported track lies within 0.75 m of them (sensor frame), after
a scan where one did, the track that was on them is looked at: was it deleted, and what
was the last update it took before. Each update is sorted by the step that made it
(association of a moving candidate, the re-join of a sharp turn, a standing leg pair, static
support) and by where its measurement lay when it was made: within 0.5 m of the person, or
farther from them and within 0.5 m of someone else (the track was pulled onto them), or
neither. The development seeds of the following work are 1 and 2
(``benchmarks/following.py``).

The steps are told apart by wrapping the tracker's own methods in this process (the
tracker's answers are unchanged); a diagnostic, not a contract.
"""

from __future__ import annotations

import inspect
import sys
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from following_losses import NEAR_M, one_run_arguments  # noqa: E402
from people_tracker.tracker import people_tracker as P  # noqa: E402
from people_tracker.tracker import tracks as T  # noqa: E402
from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.io.simulated import SimulatedSource  # noqa: E402
from people_tracker.tracker.people_tracker import tracks_in_sensor_frame  # noqa: E402

ON_M = 0.5  # m: a measurement this close to a person was made of them
STEPS = {"associate": "a moving candidate (association)", "recover": "a moving candidate (re-join of a turn)",
         "_update_standing": "a standing leg pair", "_support": "static support"}


class _Traced:
    """Records every track update: (scan index, step, measurement in the world frame, m)."""

    def __init__(self) -> None:
        self.scan = -1
        self.recovered: set[int] = set()
        self.updates: dict[int, list] = defaultdict(list)  # id(TrackState) -> updates

    def install(self):
        """Wrap the tracker's methods; returns a function that puts them back."""
        update, recover = T.TrackState.update, P.PeopleTracker._recover
        traced = self

        def traced_update(track, z, R, moving):
            step = inspect.currentframe().f_back.f_code.co_name
            if step == "step":  # the matched candidates are applied in step()
                step = "recover" if id(track) in traced.recovered else "associate"
            traced.updates[id(track)].append((traced.scan, step, np.array(z, dtype=float)))
            return update(track, z, R, moving)

        def traced_recover(tracker, candidates, matched, *rest):
            out = recover(tracker, candidates, matched, *rest)
            traced.recovered = {id(tracker._tracks[ti]) for ti, _ in out}
            return out

        T.TrackState.update, P.PeopleTracker._recover = traced_update, traced_recover

        def uninstall() -> None:
            T.TrackState.update, P.PeopleTracker._recover = update, recover
        return uninstall


def classify(scene: str, laser: str, seed: int, duration: float | None) -> Counter:
    traced = _Traced()
    uninstall = traced.install()
    try:
        return _classify(traced, scene, laser, seed, duration)
    finally:
        uninstall()  # a second run in this process wraps the tracker's own methods, not these


def _classify(traced: _Traced, scene: str, laser: str, seed: int, duration: float | None) -> Counter:
    source = SimulatedSource(scene, seed=seed, duration=duration, laser=laser)
    tracker = P.PeopleTracker.from_config(load_config(), follow="auto")
    truths, poses, counts = [], [], Counter()
    on_person = None  # the TrackState on the person at the last scan, while they are visible
    for i, record in enumerate(source.scans()):
        traced.scan = i
        tracker.step(record.scan, record.pose, record.pose_last_beam)
        truth = source.truths[-1]
        truths.append(truth)
        poses.append(tracker.last.pose)
        k = list(truth.person_id).index(source.sim.target_id)
        if not truth.visible[k]:
            on_person = None
            continue
        reported = [t for t in tracker._tracks if t.reported]
        q = tracks_in_sensor_frame([t.report() for t in reported], tracker.last.pose)
        near = [(float(np.hypot(*(qt - truth.torso_sensor[k]))), id(t), t) for t, qt in zip(reported, q)]
        near = [n for n in near if n[0] <= NEAR_M]
        if near:
            on_person = min(near)[2]
            continue
        if on_person is None:
            continue
        track, on_person = on_person, None
        ended = "deleted" if not any(u is track for u in tracker._tracks) else "kept"
        if not traced.updates[id(track)]:
            counts[f"{ended}; never updated"] += 1
            continue
        j, step, z = traced.updates[id(track)][-1]
        then = truths[j]
        kk = list(then.person_id).index(source.sim.target_id)
        q = poses[j].inverse().transform_points(z[None])[0]
        from_person = float(np.hypot(*(q - then.torso_sensor[kk])))
        others = np.delete(then.torso_sensor, kk, axis=0)
        from_other = float(np.min(np.hypot(*(others - q).T))) if len(others) else np.inf
        where = ("of the person" if from_person <= ON_M else
                 "of someone else" if from_other <= ON_M else "of neither")
        counts[f"{ended}; last update: {STEPS.get(step, step)}, {where}"] += 1
    return counts


def main(argv=None) -> int:
    args = one_run_arguments(__doc__, "follow_indoor_crowd", 2, argv)
    counts = classify(args.scene, args.laser, args.seed, args.duration)
    total = sum(counts.values())
    print(f"{args.scene}, laser {args.laser}, seed {args.seed}: {total} times the visible person was left "
          f"with no reported track within {NEAR_M} m")
    for what, n in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])):
        print(f"{n:5d}  {what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
