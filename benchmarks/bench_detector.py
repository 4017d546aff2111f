"""Speed of the detector alone on a real recording (default: 768 beams, default configuration).

Usage::

    python benchmarks/bench_detector.py [BAG] [--topic T] [--config FILE] [--repeat N]

Scans and poses are read into memory first, so only ``MovingObjectDetector.detect`` is
timed: scans per second and p50/p99 milliseconds per scan, one core.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from people_tracker.detection.detector import MovingObjectDetector
from people_tracker.tracker.config import load_config_or_exit
from people_tracker.tracker.io.recording import Recording

DEFAULT_BAG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT_BAG))
    ap.add_argument("--topic")
    ap.add_argument("--config")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    if not Path(args.bag).exists():
        print(f"bench_detector: recording '{args.bag}' not found (the real recordings live in ../shared/data)",
              file=sys.stderr)
        return 2
    config = load_config_or_exit(args.config, "bench_detector")
    with Recording(args.bag, args.topic, config.odometry) as rec:
        data = [(r.scan, r.pose) for r in rec.scans() if r.scan is not None]
    times = []
    objects = 0
    for _ in range(args.repeat):
        det = MovingObjectDetector(config.detector.params())
        for scan, pose in data:
            t0 = time.perf_counter()
            objects += len(det.detect(scan, pose).objects)
            times.append(time.perf_counter() - t0)
    ms = np.array(times) * 1e3
    print(f"detector benchmark: {Path(args.bag).name}, {len(data)} scans of {data[0][0].n_beams} beams, "
          f"Δt {list(config.detector.compare_dt_s)} s, {args.repeat} passes")
    print(f"scans/s {1e3 / ms.mean():.0f}   p50 {np.percentile(ms, 50):.3f} ms   p99 {np.percentile(ms, 99):.3f} ms   "
          f"objects/scan {objects / len(times):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
