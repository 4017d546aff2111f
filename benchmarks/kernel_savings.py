"""What each compiled part saves: the tracker's step with it switched off, side by side.

Usage::

    python benchmarks/kernel_savings.py [--passes 15] [--scans 300] [--crowd-scans 100]

This machine's speed drifts by tens of percent between runs minutes apart, so timings from
separate runs cannot show a saving of a few percent. Here every variant runs in this one
process, on this process's first allowed core, in turn: pass 1 of each, then pass 2 of
each, and so on, each pass a fresh tracker over the same scans (read or rendered first);
the fastest pass of each is kept. Variants:

- ``compiled``: everything compiled (the default when numba is installed);
- ``without the grid search``: the nearest neighbours from pykdtree instead;
- ``without the static support kernel``: static support in numpy;
- ``without the hull kernel``: the objects' hull centroids and boxes from shapely;
- ``numpy only``: every kernel off (``PEOPLE_TRACKER_COMPILED=0``).

Inputs: the annotated recording (``general_tracking_moving_1.bag``, its first ``--scans``
scans) and the simulated crowd of 50 (``--crowd-scans`` scans). Per input, milliseconds a
scan for each variant and its cost against ``compiled``; last, whether every variant
reported the same tracks (ids, positions, velocities, confidences, bit for bit), as it must.
"""

from __future__ import annotations

import argparse
import sys
import time
import types
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pipeline import DATA, _one_core, crowd_steps, recording_steps  # noqa: E402

from people_tracker.detection import kdtree, objects  # noqa: E402
from people_tracker.models import compiled  # noqa: E402
from people_tracker.tracker import static_support  # noqa: E402
from people_tracker.tracker.config import load_config  # noqa: E402
from people_tracker.tracker.people_tracker import PeopleTracker, warm_up_kernels  # noqa: E402

_ALL_BACKENDS = kdtree.BACKENDS


_OFF = types.SimpleNamespace(on=False)


def _set(grid: bool, support: bool, hull: bool, kernels: bool) -> None:
    kdtree.BACKENDS = _ALL_BACKENDS if grid else kdtree.LIBRARIES
    static_support.compiled = compiled if support else _OFF
    objects.compiled = compiled if hull else _OFF
    compiled.on = kernels


VARIANTS = {
    "compiled": (True, True, True, True),
    "without the grid search": (False, True, True, True),
    "without the static support kernel": (True, False, True, True),
    "without the hull kernel": (True, True, False, True),
    "numpy only": (False, False, False, False),
}


def _pass(config, items) -> tuple[float, list]:
    tracker = PeopleTracker.from_config(config)
    t0 = time.perf_counter()
    out = [[(t.track_id, t.x, t.y, t.vx, t.vy, t.confidence) for t in tracker.step(*item)] for item in items]
    return time.perf_counter() - t0, out


def compare(name: str, config, items, passes: int) -> bool:
    best = {v: float("inf") for v in VARIANTS}
    outputs = {}
    for _ in range(passes):
        for variant, switches in VARIANTS.items():
            _set(*switches)
            seconds, outputs[variant] = _pass(config, items)
            best[variant] = min(best[variant], seconds)
    _set(True, True, True, True)
    base = best["compiled"]
    print(f"{name}: {len(items)} scans, the fastest of {passes} passes")
    for variant in VARIANTS:
        extra = "" if variant == "compiled" else f"   {1e3 * (best[variant] - base) / len(items):+.3f} ms a scan"
        print(f"  {variant:<36} {1e3 * best[variant] / len(items):7.3f} ms a scan{extra}")
    return all(out == outputs["compiled"] for out in outputs.values())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--passes", type=int, default=15, help="passes of each variant (default 15)")
    ap.add_argument("--scans", type=int, default=300, help="scans of the recording (default 300)")
    ap.add_argument("--crowd-scans", type=int, default=100, help="scans of the crowd of 50 (default 100)")
    args = ap.parse_args(argv)
    if not compiled.ENABLED:
        print("the compiled kernels are off (numba is not installed, or PEOPLE_TRACKER_COMPILED=0): nothing to compare")
        return 0
    _one_core()
    warm_up_kernels()
    config = load_config()
    same = []
    bag = DATA / "general_tracking_moving_1.bag"
    if bag.exists():
        same.append(compare(bag.name, config, recording_steps(bag, config)[:args.scans], args.passes))
    else:
        print(f"({bag} not found: the real recording is left out)")
    same.append(compare("crowd of 50", config, crowd_steps(50, args.crowd_scans), args.passes))
    print("every variant reported the same tracks:", "yes" if all(same) else "NO")
    return 0 if all(same) else 1


if __name__ == "__main__":
    sys.exit(main())
