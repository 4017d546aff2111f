"""Where a scan's time goes: the tracker's step split into its stages.

Usage::

    python benchmarks/stage_times.py [--people 50] [--scans 300]

Times each stage of :meth:`PeopleTracker.step` (wall clock around each call, so the
figures include the stage's own Python) over the annotated recording
(``general_tracking_moving_1.bag``, its scans read first) and over a simulated crowd
(``--people`` walkers, ``--scans`` scans, rendered first), the second of two passes with a
fresh tracker each, on this process's first allowed core. Per input: milliseconds a scan
for the whole step, then per stage (mean over every scan, the detector's and the
aligner's largest parts indented under them), and the same for the slowest 1 % of scans:
which stages make the tail (``p99`` in ``bench_pipeline.py``). The wrappers cost a few
microseconds a call; ``bench_pipeline.py`` gives the rates without them.
"""

from __future__ import annotations

import argparse
import functools
import gc
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pipeline import DATA, _one_core, crowd_steps, recording_steps  # noqa: E402

from people_tracker.detection import align as align_mod  # noqa: E402
from people_tracker.detection import detector  # noqa: E402
from people_tracker.tracker import people_tracker as pt  # noqa: E402
from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.people_tracker import PeopleTracker, warm_up_kernels  # noqa: E402

TRACKER_STAGES = ("_candidates", "_receding", "_associate", "_recover", "_standing_candidates", "_update_standing",
                  "_support", "_weigh", "_remember_standing", "_reacquire_standing", "_initiate", "_initiate_standing",
                  "_delete", "_follow", "_unmatchable_legs")
DETECT, ALIGN = "detect: moving objects", "align: de-skew and scan matching"
# (module or class, attribute, label, the stage it is part of): the detector's and the aligner's parts
PARTS = ((detector, "label_pair", "detect: Algorithm 1 and the closest-point test", DETECT),
         (detector.MovingObjectDetector, "_static_memory", "detect: static memory (with carried objects)", DETECT),
         (detector, "describe_all", "detect: hull centroids and boxes", DETECT),
         (detector, "recover_from_bounds", "detect: Algorithms 2 and 3", DETECT),
         (align_mod, "match", "align: scan matching (ICP)", ALIGN),
         (align_mod, "deskew", "align: de-skew", ALIGN))

_spent: Counter = Counter()


def _timed(owner, name: str, label: str) -> None:
    """Replace ``owner.name`` by a wrapper adding its wall time to ``_spent[label]``."""
    f = getattr(owner, name)

    @functools.wraps(f)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return f(*args, **kwargs)
        finally:
            _spent[label] += time.perf_counter() - t0

    setattr(owner, name, wrapper)


def instrument(tracker: PeopleTracker) -> None:
    """Wrap the step's stages (once per process: the wrappers go on the classes)."""
    _timed(type(tracker.aligner), "align", ALIGN)
    _timed(type(tracker.detector), "detect", DETECT)
    _timed(type(tracker.leg_model), "probability", "leg model")
    _timed(pt, "leg_candidates", "leg candidates and features")
    for name in TRACKER_STAGES:
        _timed(PeopleTracker, name, name.strip("_").replace("_", " "))
    for owner, name, label, _ in PARTS:
        _timed(owner, name, label)


def run(name: str, items: list, config) -> None:
    """Two passes over ``items`` (scan, pose, pose of the last beam); print the second."""
    for _ in range(2):
        tracker = PeopleTracker.from_config(config)
        per_scan = []
        for scan, pose, last in items:
            _spent.clear()
            t0 = time.perf_counter()
            tracker.step(scan, pose, last)
            per_scan.append((time.perf_counter() - t0, dict(_spent)))
    total = np.array([t for t, _ in per_scan])
    p99 = np.percentile(total, 99)
    slowest = [k for k, t in enumerate(total) if t >= p99]
    labels = {k for _, s in per_scan for k in s}
    mean = {k: np.mean([s.get(k, 0.0) for _, s in per_scan]) for k in labels}
    tail = {k: np.mean([per_scan[i][1].get(k, 0.0) for i in slowest]) for k in labels}
    print(f"{name}: {len(items)} scans, step {1e3 * total.mean():.2f} ms a scan (p50 {1e3 * np.median(total):.2f}, "
          f"p99 {1e3 * p99:.2f}); the slowest 1 % ({len(slowest)} scans) {1e3 * total[slowest].mean():.2f}")
    print(f"  {'stage':<52} {'ms/scan':>8} {'slowest 1 %':>12}")
    parts = {label: parent for _, _, label, parent in PARTS}
    top = [k for k in labels if k not in parts]
    for k in sorted(top, key=lambda k: -mean[k]):
        print(f"  {k:<52} {1e3 * mean[k]:>8.3f} {1e3 * tail[k]:>12.3f}")
        for part in sorted(p for p in labels if parts.get(p) == k):
            print(f"    {part:<50} {1e3 * mean[part]:>8.3f} {1e3 * tail[part]:>12.3f}")
    rest = total.mean() - sum(mean[k] for k in top)
    print(f"  {'the rest (predict, update, report, the step itself)':<52} {1e3 * rest:>8.3f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--people", type=int, default=50, help="crowd walkers (default 50)")
    ap.add_argument("--scans", type=int, default=300, help="crowd scans (default 300)")
    args = ap.parse_args(argv)
    _one_core()
    warm_up_kernels()
    gc.freeze()  # as people-tracker run and the ROS 2 node do after start-up
    config = load_config()
    instrument(PeopleTracker.from_config(config))
    bag = DATA / "general_tracking_moving_1.bag"
    if bag.exists():
        run(bag.name, recording_steps(bag, config), config)
    else:
        print(f"({bag} not found: the real recording is left out)")
    run(f"crowd of {args.people}", crowd_steps(args.people, args.scans), config)
    return 0


if __name__ == "__main__":
    sys.exit(main())
