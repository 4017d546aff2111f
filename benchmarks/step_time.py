"""The tracker's step time, with this machine's noise taken out: each scan's fastest of N passes.

Usage::

    python benchmarks/step_time.py [--passes 5] [--people 50] [--scans 300]

This machine's speed drifts by tens of percent within minutes (docs/results.md, "Speed"), so
a mean over one pass, or the fastest of several passes' means, moves by more than most
changes save. Here every scan is timed in each of ``--passes`` passes (a fresh tracker each,
the inputs read or rendered once, on this process's first allowed core, CPU time of this
thread) and each scan's fastest time is kept: a slow spell of the host then costs a scan
only if it hits that scan in every pass. Printed per input: the mean over scans of those
fastest times (ms a scan, the first three scans left out: kernels load there) and, for
comparison, each pass's own mean. Inputs: the annotated recording
(``general_tracking_moving_1.bag``, skipped when ``../shared/data`` is missing) and the
crowd scene with ``--people`` walkers (``--scans`` scans).

To compare two versions of the code, run it on each, in turn, more than once: for example
``git checkout REV -- detection models tracker``, run, ``git checkout HEAD -- detection
models tracker``, run.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pipeline import DEFAULT_BAG, _one_core, crowd_steps, recording_steps  # noqa: E402

from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.people_tracker import PeopleTracker  # noqa: E402

SKIP = 3  # the first scans load the compiled kernels


def fastest_per_scan(steps: list, config, passes: int) -> tuple[float, list[float]]:
    """Mean over scans of each scan's fastest step (ms), and each pass's mean (ms)."""
    times = np.empty((passes, len(steps)))
    for k in range(passes):
        tracker = PeopleTracker.from_config(config)
        for i, step in enumerate(steps):
            t0 = time.thread_time()
            tracker.step(*step)
            times[k, i] = time.thread_time() - t0
    kept = times[:, SKIP:] * 1e3
    return float(kept.min(axis=0).mean()), kept.mean(axis=1).tolist()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--passes", type=int, default=5)
    ap.add_argument("--people", type=int, default=50)
    ap.add_argument("--scans", type=int, default=300)
    args = ap.parse_args()
    _one_core()
    config = load_config()
    inputs = []
    if DEFAULT_BAG.exists():
        inputs.append((DEFAULT_BAG.name, recording_steps(DEFAULT_BAG, config)))
    else:
        print(f"(skipping the recording: {DEFAULT_BAG} not found)")
    inputs.append((f"crowd of {args.people}", crowd_steps(args.people, args.scans)))
    print(f"{'input':<32} {'scans':>6} {'ms/scan':>8}   (each scan's fastest of {args.passes} passes; each pass's mean)")
    for name, steps in inputs:
        best, means = fastest_per_scan(steps, config, args.passes)
        print(f"{name:<32} {len(steps):>6} {best:>8.3f}   ({' '.join(f'{m:.2f}' for m in means)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
