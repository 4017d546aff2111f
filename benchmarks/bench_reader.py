"""Reader throughput on a real recording: scans per second and per-scan latency.

Usage::

    python benchmarks/bench_reader.py [BAG] [--topic T] [--repeat N]

Reads every scan with its sensor pose, with each odometry source (``none``, the
Odometry topic + static mount, ``/tf``), and prints scans per second for the whole
read (opening included) and for streaming alone, the p50/p99 time per scan, and the
process's peak resident memory.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

from people_tracker.tracker.config import config_from_dict
from people_tracker.tracker.io.recording import Recording

DEFAULT_BAG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"


def measure(path: Path, topic: str | None, source: str) -> dict:
    cfg = config_from_dict({"odometry": {"source": source}}).odometry
    t0 = time.perf_counter()
    with Recording(path, topic, cfg) as rec:
        t_open = time.perf_counter()
        gaps = []
        last = t_open
        n = posed = 0
        for r in rec.scans():
            now = time.perf_counter()
            gaps.append(now - last)
            last = now
            n += 1
            posed += r.pose is not None
        t_end = time.perf_counter()
        odometry = rec.odometry
    gaps_ms = np.array(gaps) * 1e3
    return {
        "source": source, "odometry": odometry, "scans": n, "posed": posed,
        "total_sps": n / (t_end - t0), "stream_sps": n / (t_end - t_open), "open_s": t_open - t0,
        "p50_ms": float(np.percentile(gaps_ms, 50)), "p99_ms": float(np.percentile(gaps_ms, 99)),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT_BAG))
    ap.add_argument("--topic")
    ap.add_argument("--repeat", type=int, default=5, help="runs per source; the median run is shown")
    args = ap.parse_args(argv)
    path = Path(args.bag)
    if not path.exists():
        print(f"bench_reader: recording '{path}' not found (the real recordings live in ../shared/data)", file=sys.stderr)
        return 2
    print(f"reader benchmark: {path.name}, {args.repeat} runs per source (median run shown)")
    print(f"{'odometry':<8} {'scans':>5} {'posed':>5} {'scans/s total':>14} {'scans/s stream':>15} "
          f"{'open s':>7} {'p50 ms':>7} {'p99 ms':>7}")
    for source in ("none", "odom", "tf"):
        runs = [measure(path, args.topic, source) for _ in range(args.repeat)]
        med = sorted(runs, key=lambda r: r["total_sps"])[len(runs) // 2]
        print(f"{source:<8} {med['scans']:>5} {med['posed']:>5} {med['total_sps']:>14.0f} {med['stream_sps']:>15.0f} "
              f"{med['open_s']:>7.3f} {med['p50_ms']:>7.3f} {med['p99_ms']:>7.3f}")
        if source != "none":
            print(f"         via {med['odometry']}")
    print(f"peak resident memory: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
