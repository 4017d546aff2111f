"""Speed of one scan match: each scan of a real recording matched onto the previous one.

Usage::

    python benchmarks/bench_alignment.py [BAG] [--repeat N]

Scans are read, de-skewed and prepared as references beforehand; only
:func:`people_tracker.detection.icp.match` is timed (768 beams on the annotated recording), with the
odometry's relative motion as the prior. Prints p50/p99 milliseconds per match.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from people_tracker.detection.deskew import deskew
from people_tracker.detection.icp import ReferenceScan, match
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.recording import Recording

DEFAULT_BAG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT_BAG))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    if not Path(args.bag).exists():
        print(f"bench_alignment: recording '{args.bag}' not found (the real recordings live in ../shared/data)",
              file=sys.stderr)
        return 2
    cfg = load_config()
    icp = cfg.alignment.params().icp
    with Recording(args.bag, None, cfg.odometry) as rec:
        data = [(deskew(r.scan, r.pose, r.pose_last_beam).valid_points, r.pose) for r in rec.scans()]
    pairs = [(ReferenceScan(a[0], icp), b[0], a[1].between(b[1])) for a, b in zip(data[:-1], data[1:])]
    times = []
    ok = 0
    for _ in range(args.repeat):
        for ref, cur, prior in pairs:
            t0 = time.perf_counter()
            ok += match(cur, ref, prior, icp).ok
            times.append(time.perf_counter() - t0)
    ms = np.array(times) * 1e3
    print(f"scan matching: {Path(args.bag).name}, {len(pairs)} pairs of {len(data[0][0])}+ readings, "
          f"{args.repeat} passes: p50 {np.percentile(ms, 50):.2f} ms, p99 {np.percentile(ms, 99):.2f} ms, "
          f"{1e3 / ms.mean():.0f} matches/s, {100 * ok / len(times):.0f} % trusted")
    return 0


if __name__ == "__main__":
    sys.exit(main())
