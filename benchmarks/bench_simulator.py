"""Simulator speed: ray casting alone and whole simulation steps of the crowd scene.

Usage::

    python benchmarks/bench_simulator.py [--scans N]

Prints, per case, scans per second and p50/p99 milliseconds per scan:

* ray casting one 768-beam scan against 100 wall segments and 50 people (100 legs);
* a full step of the crowd scene (people's gait, ray casting, noise, visibility truth)
  with 30 and with 50 people.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from people_tracker.models.raycast import cast_rays
from people_tracker.models.scenario import build_simulation, load_scenario


def _report(name: str, times_s: list[float]) -> None:
    ms = np.array(times_s) * 1e3
    print(f"{name:<48} {1e3 / ms.mean():>9.0f} {np.percentile(ms, 50):>8.3f} {np.percentile(ms, 99):>8.3f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scans", type=int, default=300)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    print(f"{'case':<48} {'scans/s':>9} {'p50 ms':>8} {'p99 ms':>8}")

    n = 768
    ang = -math.radians(135) + np.arange(n) * math.radians(270) / (n - 1)
    origins = np.zeros((n, 2))
    dirs = np.column_stack([np.cos(ang), np.sin(ang)])
    a = rng.uniform(-15, 15, (100, 2))
    segments = np.stack([a, a + rng.uniform(-3, 3, (100, 2))], axis=1)
    times = []
    for _ in range(args.scans):
        circles = np.column_stack([rng.uniform(-10, 10, (100, 2)), np.full(100, 0.07)])
        t0 = time.perf_counter()
        cast_rays(origins, dirs, segments, circles, 30.0)
        times.append(time.perf_counter() - t0)
    _report("ray cast: 768 beams, 100 segments, 100 legs", times)

    for people in (30, 50):
        sim, _ = build_simulation(load_scenario("crowd"), crowd_count=people)
        times = []
        for _ in range(args.scans):
            t0 = time.perf_counter()
            sim.step()
            times.append(time.perf_counter() - t0)
        _report(f"crowd scene step: {people} people, {sim.laser.n_beams} beams", times)
    return 0


if __name__ == "__main__":
    sys.exit(main())
