"""Speed of the whole pipeline: read, de-skew, detect, pair, track.

Usage::

    python benchmarks/bench_pipeline.py [BAG] [--people 50] [--repeat N]

On the real recording, each scan's time covers reading it (with its poses) from the bag
and the tracker's step; on the crowd scene (scaled to ``--people``) the simulator's
rendering is left out and only the tracker's step is timed. Prints scans per second,
p50/p99 milliseconds per scan and the peak resident memory, on one core.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.people_tracker import PeopleTracker

DEFAULT_BAG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"


def _row(name: str, seconds: list[float], extra: str = "") -> None:
    ms = np.array(seconds) * 1e3
    print(f"{name:<44} {1e3 / ms.mean():>8.0f} {np.percentile(ms, 50):>8.2f} {np.percentile(ms, 99):>8.2f}  {extra}")


def bench_recording(path: Path, config) -> tuple[list[float], float]:
    tracker = PeopleTracker.from_config(config)
    times, people = [], 0
    with Recording(path, None, config.odometry) as rec:
        t_last = time.perf_counter()
        for r in rec.scans():
            if r.scan is not None:
                people += len(tracker.step(r.scan, r.pose, r.pose_last_beam))
            now = time.perf_counter()
            times.append(now - t_last)
            t_last = now
    return times, people / max(len(times), 1)


def bench_crowd(people: int, config, scans: int) -> tuple[list[float], float]:
    sim, n = build_simulation(load_scenario("crowd"), crowd_count=people)
    tracker = PeopleTracker.from_config(config)
    times, reported = [], 0
    for _ in range(min(n, scans)):
        st = sim.step()
        t0 = time.perf_counter()
        reported += len(tracker.step(st.scan, st.odom_pose, st.odom_pose_last_beam))
        times.append(time.perf_counter() - t0)
    return times, reported / max(len(times), 1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT_BAG))
    ap.add_argument("--people", type=int, default=50)
    ap.add_argument("--scans", type=int, default=300, help="crowd scans to time")
    args = ap.parse_args(argv)
    config = load_config()
    print(f"{'pipeline':<44} {'scans/s':>8} {'p50 ms':>8} {'p99 ms':>8}  tracks/scan")
    if Path(args.bag).exists():
        times, per = bench_recording(Path(args.bag), config)
        _row(f"{Path(args.bag).name} (read+track)", times, f"{per:.2f}")
    else:
        print(f"{Path(args.bag).name}: not found (the real recordings live in ../shared/data)")
    times, per = bench_crowd(args.people, config, args.scans)
    _row(f"crowd scene, {args.people} people (track only)", times, f"{per:.2f}")
    print(f"peak resident memory: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
