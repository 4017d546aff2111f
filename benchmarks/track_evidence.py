"""Tracks that live on evidence: the figures of the track-existence work, on simulated scenes.

For each scene and seed the default tracker runs over the simulated scans (in-process, as
``people-tracker bench`` does) and the script prints:

* CLEAR MOT (0.75 m) and IDF1 against the visible people, through ``evaluate``, with tracks
  on people who are there but hidden ignored (MOTChallenge's rule, as ``people-tracker
  bench`` scores scenes), and ``strict``: MOTA counting those tracks as false positives;
* per minute: the mean number of visible people and of reported people (``count`` column:
  reported / visible, the target is within 10 %);
* ``ids/person``: the most distinct track ids any one person was given while they were in
  the scene (people and tracks paired one to one in each scan, within 0.5 m: someone else's
  track passing close by is not theirs), the target is 1; ``people>1``: how many people had
  more than one;
* ``false>=2s``: reported tracks that spent 2 s or more in a row farther than 0.75 m from
  every person in the scene (furniture, ghosts);

and, pooled over every scene run, the calibration table of ``confidence``: of the reported
track-scans whose confidence falls in a 0.1-wide bin, the share within 0.5 m of a person.

Usage::

    python benchmarks/track_evidence.py --jobs 2                 # every figure (about 10 min on 2 cores)
    python benchmarks/track_evidence.py --scenes waiting_room --seeds 21
    python benchmarks/track_evidence.py --scenes crowd --duration 1200
    python benchmarks/track_evidence.py --config mine.yaml       # score another configuration
    python benchmarks/track_evidence.py --scenes waiting_room --seeds 22 --id-changes   # where ids change
    python benchmarks/track_evidence.py --scenes waiting_room --seeds 70 --untracked    # who went untracked, when
    python benchmarks/track_evidence.py --scenes crossing stop_and_go --resolution 1.0  # on a 1° laser
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from people_tracker.models.pose import pairwise_distances
from people_tracker.tracker.association import associate
from people_tracker.tracker.config import load_config, load_config_or_exit
from people_tracker.tracker.evaluation import TrackRows, evaluate
from people_tracker.tracker.bench import scene_ground_truth
from people_tracker.tracker.io.simulated import SimulatedSource
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame

NEAR_M = 0.5  # a reported track this close to a person is that person (calibration, ids)
FALSE_M = 0.75  # farther than this from everyone is a false person (the evaluation's threshold)
LASTING_S = 2.0


@dataclass
class SceneRun:
    name: str
    seed: int | None
    stamps: np.ndarray  # (n,) s
    rows: np.ndarray  # (m, 5): scan index, track id, x, y (sensor frame, m), confidence
    truths: list  # the simulator's Truth per scan


def run_scene(name: str, seed: int | None, duration: float | None, people: int | None = None,
              config=None, resolution_deg: float | None = None) -> SceneRun:
    """One scene run by the tracker of ``config`` (default: the shipped one); ``resolution_deg``
    replaces the scene laser's angular step (degrees)."""
    source = SimulatedSource(name, seed=seed, duration=duration, people=people, resolution_deg=resolution_deg)
    tracker = PeopleTracker.from_config(config if config is not None else load_config())
    rows, stamps = [], []
    for record in source.scans():
        tracks = tracker.step(record.scan, record.pose, record.pose_last_beam)
        stamps.append(record.scan.stamp)
        for t, (x, y) in zip(tracks, tracks_in_sensor_frame(tracks, tracker.last.pose)):
            rows.append((record.index, t.track_id, x, y, t.confidence))
    return SceneRun(name, seed, np.array(stamps), np.array(rows, dtype=float).reshape(-1, 5), source.truths)


def _scans_with_people(run: SceneRun):
    """Each scan with reported rows and people in the scene: (indices of its rows, its Truth)."""
    scan = run.rows[:, 0].astype(np.int64)
    for k in np.unique(scan):
        if len(run.truths[k].person_id):
            yield np.flatnonzero(scan == k), run.truths[k]


def nearest_person(run: SceneRun) -> tuple[np.ndarray, np.ndarray]:
    """For each reported row: the distance to the nearest person in the scene (m) and their id.
    In the sensor frame, as ``evaluate`` scores: the tracker's world frame may drift from the
    simulator's (scan matching), which says nothing of where the tracks are."""
    dist = np.full(len(run.rows), np.inf)
    who = np.full(len(run.rows), -1, dtype=np.int64)
    for sel, tr in _scans_with_people(run):
        d = pairwise_distances(run.rows[sel, 2:4], tr.torso_sensor)
        j = d.argmin(axis=1)
        dist[sel] = d[np.arange(len(sel)), j]
        who[sel] = tr.person_id[j]
    return dist, who


def ids_per_person(run: SceneRun) -> dict[int, set[int]]:
    """The track ids each person was given: in every scan, people and reported tracks are
    paired one to one (the pairing of least total distance, pairs within ``NEAR_M`` only), so
    a track is one person's at a time, as in CLEAR MOT's matching; someone else's track
    passing close by is not an id of theirs."""
    ids: dict[int, set[int]] = {}
    for _, _, person, track in _pairs(run):
        ids.setdefault(person, set()).add(track)
    return ids


def _pairs(run: SceneRun):
    """(scan index, the scan's rows, person id, track id) for each person and reported track
    paired in a scan (see :func:`ids_per_person`)."""
    for sel, tr in _scans_with_people(run):
        for i, j in associate(pairwise_distances(tr.torso_sensor, run.rows[sel, 2:4]), NEAR_M, "gnn"):
            yield int(run.rows[sel[0], 0]), sel, int(tr.person_id[i]), int(run.rows[sel[j], 1])


def id_changes(run: SceneRun) -> list[str]:
    """One line per change of a person's track id (paired as in :func:`ids_per_person`): when
    (s from the first scan), from which id to which, how long before the old id was last
    theirs, and whether the old track was still reported then (and how far from them, m)."""
    last: dict[int, tuple[int, float]] = {}
    out = []
    for k, sel, person, track in _pairs(run):
        t = float(run.stamps[k] - run.stamps[0])
        if person in last and last[person][0] != track:
            old, since = last[person]
            rows = run.rows[sel]
            here = rows[rows[:, 1] == old]
            tr = run.truths[k]
            at = tr.torso_sensor[tr.person_id == person][0]
            where = (f"still reported, {np.hypot(*(here[0, 2:4] - at)):.2f} m from them" if len(here)
                     else "not reported")
            out.append(f"  person {person} at {t:.1f} s: id {old} -> {track} ({old} theirs {t - since:.1f} s "
                       f"before; {where})")
        last[person] = (track, t)
    return out


def untracked_spells(run: SceneRun, min_s: float = LASTING_S) -> list[str]:
    """One line per spell of at least ``min_s`` seconds in which a person was visible and
    paired with no reported track (as in :func:`ids_per_person`): who, from when to when
    (s from the first scan) and how many of their visible scans it held. A spell ends when
    they are tracked again or hidden."""
    paired: dict[int, set[int]] = {}
    for k, _, person, _ in _pairs(run):
        paired.setdefault(k, set()).add(person)
    open_: dict[int, list] = {}  # person -> [first scan index, last scan index, scans]
    spells = []
    for k, tr in enumerate(run.truths):
        missed = {int(p) for p, v in zip(tr.person_id, tr.visible) if v} - paired.get(k, set())
        for person in list(open_):
            if person not in missed:
                spells.append((person, *open_.pop(person)))
        for person in missed:
            if person in open_:
                open_[person][1:] = [k, open_[person][2] + 1]
            else:
                open_[person] = [k, k, 1]
    spells += [(person, *v) for person, v in open_.items()]
    t = run.stamps - run.stamps[0]
    return [f"  person {person} untracked {t[a]:.1f}-{t[b]:.1f} s ({n} visible scans)"
            for person, a, b, n in sorted(spells, key=lambda s: s[1]) if t[b] - t[a] >= min_s]


def scene_figures(run: SceneRun, id_change_lines: bool = False, untracked_lines: bool = False) -> dict:
    """The figures of one run; with ``id_change_lines`` / ``untracked_lines`` also the lines of
    :func:`id_changes` / :func:`untracked_spells` (empty lists otherwise)."""
    r = run.rows
    gt, hidden = scene_ground_truth(run.truths)  # the visible people and the hidden ones
    rows = TrackRows(r[:, 0].astype(np.int64), r[:, 1].astype(np.int64), r[:, 2], r[:, 3])
    result = evaluate(gt, rows, hidden=hidden)
    strict = evaluate(gt, rows)
    dist, _ = nearest_person(run)
    # reported / visible people per minute
    minute = ((run.stamps - run.stamps[0]) // 60.0).astype(int)
    visible = np.array([int(tr.visible.sum()) for tr in run.truths])
    reported = np.bincount(r[:, 0].astype(np.int64), minlength=len(run.truths))
    ratios = []
    for m in np.unique(minute):
        v, p = visible[minute == m].mean(), reported[minute == m].mean()
        ratios.append((v, p))
    near = dist <= NEAR_M
    ids = ids_per_person(run)
    # false people reported for LASTING_S in a row
    false_ids = 0
    far = dist > FALSE_M
    for t in np.unique(r[:, 1]):
        sel = np.flatnonzero(r[:, 1] == t)
        run_start, best = None, 0.0
        for k, f in zip(r[sel, 0].astype(np.int64), far[sel]):
            if f:
                run_start = run.stamps[k] if run_start is None else run_start
                best = max(best, run.stamps[k] - run_start)
            else:
                run_start = None
        false_ids += best >= LASTING_S
    return {"result": result, "strict": strict, "minutes": ratios, "ids_per_person": max((len(s) for s in ids.values()), default=0),
            "people_with_more_ids": sum(len(s) > 1 for s in ids.values()), "false_lasting": false_ids,
            "confidence": r[:, 4], "near": near, "id_changes": id_changes(run) if id_change_lines else [],
            "untracked": untracked_spells(run) if untracked_lines else []}


def calibration_table(confidence: np.ndarray, near: np.ndarray, min_samples: int = 100) -> list[str]:
    lines = [f"{'confidence':>12} {'track-scans':>11} {'mean conf':>9} {'near a person':>13} {'|diff|':>6}"]
    edges = np.linspace(0.0, 1.0, 11)
    worst = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (confidence >= lo) & ((confidence < hi) if hi < 1.0 else (confidence <= hi))
        n = int(sel.sum())
        if n == 0:
            continue
        mean_c, share = float(confidence[sel].mean()), float(near[sel].mean())
        counted = n >= min_samples
        if counted:
            worst = max(worst, abs(share - mean_c))
        lines.append(f"  {lo:.1f}-{hi:.1f}   {n:>11} {mean_c:>9.3f} {share:>13.3f} {abs(share - mean_c):>6.3f}"
                     + ("" if counted else "  (fewer than %d: not counted)" % min_samples))
    lines.append(f"largest |share near a person - mean confidence| over bins with >= {min_samples} track-scans: "
                 f"{worst:.3f} (target <= 0.1)")
    return lines


def _figures(job: tuple) -> dict:
    """One scene run's figures (a worker process's job): (scene, seed, duration, config path,
    whether to list id changes, whether to list untracked spells, the laser's angular step
    in degrees or None for the scene's own)."""
    name, seed, duration, config_path, id_change_lines, untracked_lines, resolution_deg = job
    run = run_scene(name, seed, duration, config=load_config(config_path), resolution_deg=resolution_deg)
    return {**scene_figures(run, id_change_lines, untracked_lines), "scans": len(run.truths)}


def _print_run(name: str, seed: int | None, duration: float | None, f: dict) -> None:
    r = f["result"]
    per_min = " ".join(f"{p:.1f}/{v:.1f}" for v, p in f["minutes"])
    label = name if duration is None else f"{name} {duration:g}s"
    print(f"{label:<22} {seed if seed is not None else '-':>4} {f['scans']:>6} {100 * r['mota']:>7.1f} "
          f"{100 * f['strict']['mota']:>7.1f} "
          f"{100 * r['idf1']:>7.1f} {r['id_switches']:>5} {r['false_positives']:>6} {r['misses']:>7} "
          f"{f['ids_per_person']:>10} {f['people_with_more_ids']:>8} {f['false_lasting']:>9}  {per_min}", flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["waiting_room", "crowd", "crossing", "stop_and_go", "occlusion",
                                                     "following", "corridor"])
    ap.add_argument("--seeds", nargs="+", type=int, default=None,
                    help="seeds for waiting_room (default 21 22 23); other scenes use their own")
    ap.add_argument("--duration", type=float, default=None, help="override every scene's duration, s")
    ap.add_argument("--long-crowd", type=float, default=1200.0,
                    help="also run crowd this long (s) when crowd is listed; 0 skips it")
    ap.add_argument("--config", help="a configuration to score instead of the default (a YAML file or a shipped name)")
    ap.add_argument("--jobs", type=int, default=1, help="scene runs at once (each on one core)")
    ap.add_argument("--id-changes", action="store_true",
                    help="under each run, every change of a person's track id: when, from which id to which, "
                         "and whether the old track was still reported")
    ap.add_argument("--untracked", action="store_true",
                    help=f"under each run, every spell of {LASTING_S:g} s or more in which someone visible had no "
                         "track: who, when, and how many of their visible scans")
    ap.add_argument("--resolution", type=float, default=None, metavar="DEG",
                    help="run every scene with its laser's angular step set to this many degrees (the same field "
                         "of view, rate and range): how the figures hold on a coarser or finer laser")
    args = ap.parse_args(argv)
    if args.resolution is not None and not 0.05 <= args.resolution <= 5.0:
        print(f"track_evidence: --resolution must lie in 0.05..5 degrees, not {args.resolution:g}", file=sys.stderr)
        return 2
    load_config_or_exit(args.config, "track_evidence")  # a bad configuration stops here, before any run
    runs = []
    print(f"{'scene':<22} {'seed':>4} {'scans':>6} {'MOTA %':>7} {'strict':>7} {'IDF1 %':>7} {'IDsw':>5} {'FP':>6} {'misses':>7} "
          f"{'ids/person':>10} {'people>1':>8} {'false>=2s':>9}  reported/visible per minute")
    jobs = []
    for name in args.scenes:
        if name == "waiting_room":
            jobs += [(name, s, args.duration) for s in (args.seeds or [21, 22, 23])]
        else:
            jobs.append((name, None, args.duration))
        if name == "crowd" and args.long_crowd > 0 and args.duration is None:
            jobs.append((name, None, args.long_crowd))
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        figures = pool.map(_figures, [(name, seed, duration, args.config, args.id_changes, args.untracked,
                                       args.resolution)
                                      for name, seed, duration in jobs])
        for (name, seed, duration), f in zip(jobs, figures):
            runs.append(f)
            _print_run(name, seed, duration, f)
            if args.id_changes and f["id_changes"]:
                print("\n".join(f["id_changes"]), flush=True)
            if args.untracked and f["untracked"]:
                print("\n".join(f["untracked"]), flush=True)
    conf = np.concatenate([f["confidence"] for f in runs]) if runs else np.zeros(0)
    near = np.concatenate([f["near"] for f in runs]) if runs else np.zeros(0, dtype=bool)
    print("\ncalibration of confidence over every run above (share of reported track-scans within "
          f"{NEAR_M} m of a person):")
    print("\n".join(calibration_table(conf, near)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
