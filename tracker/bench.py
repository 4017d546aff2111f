"""``people-tracker bench``: one table of accuracy and speed on every recording and scene.

For each recording in the data folder (every LaserScan topic of it) and each simulated
scenario, the whole pipeline runs (read, de-skew, match, detect, pair, track) and the
table gives:

* accuracy where ground truth exists: CLEAR MOT by Leigh et al.'s protocol (0.75 m) and
  IDF1, through the same code as ``people-tracker evaluate``; for recordings without
  annotations, the confirmed tracks per minute and how many of them were reported for 2 s
  or more (on ``negative_2.bag`` nobody is there, so every one is false);
* speed: scans per second and p50/p99 milliseconds per scan (reading and tracking for a
  recording; tracking only for a simulated scene, whose rendering is not timed), and the
  process's peak resident memory so far.
"""

from __future__ import annotations

import platform
import resource
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from people_tracker.tracker.config import Config
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.evaluation import TrackRows, evaluate
from people_tracker.tracker.io.bag import LASER_SCAN, open_bag, topics_of_type
from people_tracker.tracker.io.ground_truth import GroundTruth, read_bag_ground_truth
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.io.simulated import SimulatedSource
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame
from people_tracker.tracker.scan_checks import ScanChecker

LASTING_S = 2.0  # a false person reported this long is one a user would act on
LEIGH_WINDOW_DEG = (-80.0, 12.0)  # the bearings Leigh et al. scored on the moving-robot recordings
SCENES = ("crossing", "stop_and_go", "occlusion", "following", "corridor", "crowd")
PUBLISHED = ("Published (Leigh et al., ICRA 2015, moving robot, pooled with a second bag): Joint Leg Tracker "
             "MOTA 10.2 %, MOTP 0.15 m, 2 id switches, 480 misses, 97 false positives; ROS leg_detector "
             "MOTA -22.5 %. Runtime on an Intel Core i7: 24 Hz average, 11 Hz worst case.")


@dataclass
class Row:
    name: str
    scans: int
    seconds: list[float]
    result: dict | None = None
    tracks_per_min: float | None = None
    lasting: int | None = None  # confirmed tracks reported over 2 s or more (first to last stamp)


def _run(source, config: Config, timed_read: bool, limit: int | None):
    """Run the pipeline over ``source``; rows of (scan_index, track_id, x, y) and per-scan times."""
    tracker = PeopleTracker.from_config(config)
    checker = ScanChecker(config.scan_checks.stamp_jump_periods, config.scan_checks.beam_count_confirm)
    rows, times, ids = [], [], set()
    seen: dict[int, list[float]] = {}  # track id -> first and last stamp it was reported
    first = last = None
    t_prev = time.perf_counter()
    for n, record in enumerate(source.scans()):
        if limit is not None and n >= limit:
            break
        t0 = t_prev if timed_read else time.perf_counter()
        verdict = checker.check(record.scan, record.problem)
        if verdict.use:
            if verdict.restart:
                tracker.reset()
            tracks = tracker.step(record.scan, record.pose, record.pose_last_beam)
            for t, (x, y) in zip(tracks, tracks_in_sensor_frame(tracks, tracker.last.pose)):
                rows.append((record.index, t.track_id, x, y))
                ids.add(t.track_id)
                seen.setdefault(t.track_id, [record.scan.stamp, record.scan.stamp])[1] = record.scan.stamp
            first = record.scan.stamp if first is None else first
            last = record.scan.stamp
        t_prev = time.perf_counter()
        times.append(t_prev - t0)
    span = (last - first) if first is not None and last is not None else 0.0
    lasting = sum(b - a >= LASTING_S for a, b in seen.values())
    return rows, times, ids, span, lasting


def bench_recording(path: Path, topic: str, config: Config, limit: int | None) -> list[Row]:
    """The recording's row; for an annotated one, also its score in Leigh et al.'s bearing window."""
    with Recording(path, topic, config.odometry) as rec:
        rows, times, ids, span, lasting = _run(rec, config, timed_read=True, limit=limit)
    row = Row(f"{path.name} {topic}", len(times), times, lasting=lasting)
    gt = read_bag_ground_truth(path, topic, required=False)
    if gt is not None:
        if limit is not None:
            keep = gt.scan_index < limit
            gt = GroundTruth(min(gt.n_frames, limit), gt.scan_index[keep], gt.person_id[keep], gt.x[keep], gt.y[keep])
        row.result = evaluate(gt, TrackRows.of(rows))
        lo, hi = LEIGH_WINDOW_DEG
        window = Row(f"  same, bearings {lo:g}..{hi:g} deg (Leigh's protocol)", len(times), [],
                     evaluate(gt, TrackRows.of(rows), bearing_window_deg=LEIGH_WINDOW_DEG))
        return [row, window]
    row.tracks_per_min = len(ids) / (span / 60.0) if span > 0 else float("nan")
    return [row]


def scene_ground_truth(truths) -> tuple[GroundTruth, GroundTruth]:
    """A simulated scene's visible people and its hidden ones (there, fewer than 3 points)."""
    def gt(which: bool) -> GroundTruth:
        g = np.array([(i, p, x, y) for i, tr in enumerate(truths)
                      for p, (x, y) in zip(tr.person_id[tr.visible == which], tr.torso_sensor[tr.visible == which])],
                     dtype=float).reshape(-1, 4)
        return GroundTruth(len(truths), g[:, 0].astype(np.int64), g[:, 1].astype(np.int64), g[:, 2], g[:, 3])
    return gt(True), gt(False)


def bench_scene(name: str, config: Config, duration: float | None) -> Row:
    """A simulated scene's row: tracks on hidden people are ignored (MOTChallenge's rule)."""
    source = SimulatedSource(name, duration=duration)
    rows, times, ids, span, _ = _run(source, config, timed_read=False, limit=None)
    gt, hidden = scene_ground_truth(source.truths)
    return Row(f"simulated {name}", len(times), times, evaluate(gt, TrackRows.of(rows), hidden=hidden))


def recordings(data: Path) -> list[tuple[Path, str]]:
    """Every (recording, LaserScan topic) under ``data``."""
    out = []
    for path in sorted(list(data.rglob("*.bag")) + list(data.rglob("*.mcap"))):
        try:
            reader = open_bag(path)
        except InputError:
            continue
        try:
            out += [(path, t) for t in topics_of_type(reader, LASER_SCAN)]
        finally:
            reader.close()
    return out


def format_row(row: Row) -> str:
    ms = np.array(row.seconds) * 1e3
    speed = (f"{1e3 / ms.mean():>7.0f} {np.percentile(ms, 50):>7.2f} {np.percentile(ms, 99):>7.2f} "
             f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:>6.0f}") if len(ms) else ""
    def num(v: float, width: int, fmt: str) -> str:
        return f"{'n/a':>{width}}" if v != v else f"{v:>{width}{fmt}}"

    if row.result is not None:
        r = row.result
        acc = (f"{num(100 * r['mota'], 8, '.1f')} {num(r['motp_m'], 6, '.3f')} {r['id_switches']:>5} {r['misses']:>6} "
               f"{r['false_positives']:>6} {num(100 * r['idf1'], 6, '.1f')} {'':>8}")
    else:
        acc = f"{'':>8} {'':>6} {'':>5} {'':>6} {'':>6} {'':>6} {row.tracks_per_min:>8.1f} {row.lasting:>5}"
        return f"{row.name:<48} {row.scans:>5} {acc} {speed}"
    acc += f" {'':>5}"
    return f"{row.name:<48} {row.scans:>5} {acc} {speed}"


HEADER = (f"{'input':<48} {'scans':>5} {'MOTA %':>8} {'MOTP m':>6} {'IDsw':>5} {'misses':>6} {'FP':>6} "
          f"{'IDF1 %':>6} {'trk/min':>8} {'>=2s':>5} {'scans/s':>7} {'p50 ms':>7} {'p99 ms':>7} {'MiB':>6}")


def machine() -> str:
    import os
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, one core used"


def run_bench(config: Config, data: Path | None, quick: bool, out, only: list[str] | None = None) -> None:
    """Print the table to ``out`` (a text stream), one row as soon as it is measured.
    ``only``: just the inputs whose name (``FILE TOPIC``, ``simulated SCENE``) contains one of
    these texts; :class:`InputError` when none does."""
    limit = 200 if quick else None
    duration = 6.0 if quick else None

    def wanted(name: str) -> bool:
        return not only or any(t in name for t in only)

    found = recordings(data) if data is not None and data.is_dir() else None
    chosen = [(p, t) for p, t in found or [] if wanted(f"{p.name} {t}")]
    scenes = [n for n in SCENES if wanted(f"simulated {n}")]
    if only and not chosen and not scenes:
        raise InputError(f"--only {' '.join(only)}: no recording or simulated scene has that in its name")
    print(f"people-tracker bench on {machine()}" + (" (quick: 200 scans, 6 s scenes)" if quick else ""), file=out)
    print(HEADER, file=out, flush=True)
    if found is None:
        print(f"(no recordings: data folder {data} not found)", file=out)
    for path, topic in chosen:
        for row in bench_recording(path, topic, config, limit):
            print(format_row(row), file=out, flush=True)
    for name in scenes:
        print(format_row(bench_scene(name, config, duration)), file=out, flush=True)
    print(PUBLISHED, file=out)
