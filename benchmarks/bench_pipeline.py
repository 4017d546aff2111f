"""Speed of the whole pipeline: read, de-skew, detect, pair, track.

Usage::

    python benchmarks/bench_pipeline.py [BAG] [--people 10 50 100] [--hour]

Its parts, each on one core (the process pins itself to its first allowed CPU). The first
line says whether the compiled kernels run (numba, the ``[fast]`` extra; see
``models/compiled.py``); when they do, the real recording and the crowd of 50 are also
timed with the numpy code alone (in-process, and the recording as a whole program with
``PEOPLE_TRACKER_COMPILED=0``), each run in turn with its twin, so the kernels' share shows:

* **in-process**: on the real recording each scan's time covers reading it (with its
  poses) from the bag and the tracker's step; on the crowd scene (one row per ``--people``)
  the simulator's rendering is left out and only the tracker's step is timed. Scans per
  second, p50/p99 milliseconds per scan, of the fastest of three runs.
* **whole program**: ``people-tracker run BAG --tracks t.csv`` as a user runs it, on a long
  and a short recording of the same laser; the marginal rate ``(n1 - n2) / (t1 - t2)``
  leaves the start-up (imports, opening the bag) out. The real pair is
  general_tracking_moving_1.bag (873 scans) and training/positive_2.bag (243 scans, same
  laser); the simulated pair is ``follow_outdoor`` with its 86°, 0.35° laser (245 beams),
  150 s and 30 s, written to a temporary folder. Best of three runs each.
* **start-up**: ``people-tracker --help`` and ``--version`` as a user types them (the console
  script beside this Python), median and fastest of 15 runs, beside ``python -c pass``: an
  interpreter start with nothing of ours (with the ``[ros2]`` extra installed, the ROS
  wheels' ``.pth`` hook re-executes every Python start once to set the library path).
* ``--hour``: resident memory after 1, 15 and 60 minutes of a simulated crowd (30 people):
  it grows while the place memory fills (``existence.place_memory_s``), then stays flat.

Peak resident memory of the benchmark process closes the output.
"""

from __future__ import annotations

import argparse
import gc
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.people_tracker import PeopleTracker

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh"
DEFAULT_BAG = DATA / "general_tracking_moving_1.bag"
SHORT_BAG = DATA / "training" / "positive_2.bag"  # the same laser, 243 scans


def _row(name: str, seconds: list[float], extra: str = "") -> None:
    ms = np.array(seconds) * 1e3
    print(f"{name:<44} {1e3 / ms.mean():>8.0f} {np.percentile(ms, 50):>8.2f} {np.percentile(ms, 99):>8.2f}  {extra}")


def recording_steps(path: Path, config) -> list[tuple]:
    """Every usable scan of a recording with its poses, read first: the arguments of
    :meth:`PeopleTracker.step`, so a timing leaves the reading out."""
    with Recording(path, None, config.odometry) as rec:
        return [(r.scan, r.pose, r.pose_last_beam) for r in rec.scans() if r.scan is not None]


def crowd_steps(people: int, scans: int) -> list[tuple]:
    """The first ``scans`` scans of the crowd scene with ``people`` walkers, rendered first,
    as :meth:`PeopleTracker.step`'s arguments."""
    sim, n = build_simulation(load_scenario("crowd"), crowd_count=people)
    return [(st.scan, st.odom_pose, st.odom_pose_last_beam) for st in (sim.step() for _ in range(min(n, scans)))]


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


def run_program(bag: Path, out: Path, env: dict | None = None) -> tuple[int, float]:
    """Scans read and the wall time (s) of one ``people-tracker run BAG --tracks`` on this core."""
    cmd = [sys.executable, "-m", "people_tracker", "run", str(bag), "--tracks", str(out)]
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=True, env=env)
    seconds = time.perf_counter() - t0
    m = re.search(r"scans: (\d+) read", done.stderr + done.stdout)
    return (int(m.group(1)) if m else 0), seconds


def _marginal(name: str, long: Path, short: Path, out: Path, numpy_too: bool = False) -> None:
    """The marginal rate's line, and with ``numpy_too`` (and the kernels on) a second one
    with ``PEOPLE_TRACKER_COMPILED=0``, their runs taken in turn."""
    envs = [None] + ([{**os.environ, "PEOPLE_TRACKER_COMPILED": "0"}] if numpy_too and compiled.ENABLED else [])
    best = [[(0, float("inf")), (0, float("inf"))] for _ in envs]
    for _ in range(3):
        for k, env in enumerate(envs):
            for j, bag in enumerate((long, short)):
                n, t = run_program(bag, out, env=env)
                best[k][j] = (n, min(t, best[k][j][1]))
    for k, ((n1, t1), (n2, t2)) in enumerate(best):
        rate = (n1 - n2) / (t1 - t2) if t1 > t2 else float("nan")
        label = name if k == 0 else "  the same, numpy only"
        print(f"{label:<44} {rate:>8.0f}   ({n1} scans in {t1:.2f} s, {n2} in {t2:.2f} s)")


def bench_whole_program() -> None:
    print(f"{'whole program: people-tracker run BAG --tracks t.csv':<44} {'scans/s':>8}   marginal: (n1 - n2) / (t1 - t2)")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "t.csv"
        if DEFAULT_BAG.exists() and SHORT_BAG.exists():
            _marginal("moving_1.bag (873) - positive_2.bag (243)", DEFAULT_BAG, SHORT_BAG, out, numpy_too=True)
        else:
            print("real recordings: not found (they live in ../shared/data)")
        bags = []
        for seconds in (150, 30):
            bag = Path(tmp) / f"follow_{seconds}"
            subprocess.run([sys.executable, "-m", "people_tracker", "-q", "simulate", "follow_outdoor", "--laser", "narrow",
                            "--duration", str(seconds), "--output", str(bag)], check=True, capture_output=True)
            bags.append(bag)
        _marginal("follow_outdoor 86 deg, 245 beams (150 s - 30 s)", bags[0], bags[1], out)


def bench_startup(runs: int = 15) -> None:
    """Median and fastest wall time of ``people-tracker --help`` / ``--version``, ms."""
    import shutil

    script = Path(sys.executable).with_name("people-tracker")
    script = str(script) if script.exists() else shutil.which("people-tracker")
    cmds = [("python -c pass (no people-tracker code)", [sys.executable, "-c", "pass"])]
    if script:
        cmds += [("people-tracker --help", [script, "--help"]), ("people-tracker --version", [script, "--version"])]
    else:
        print("start-up: the people-tracker console script is not installed beside this Python")
    for name, cmd in cmds:
        times = []
        for _ in range(runs):
            t0 = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=True)
            times.append(1e3 * (time.perf_counter() - t0))
        print(f"start-up: {name:<40} median {np.median(times):5.0f} ms, fastest {min(times):5.0f} ms")


def _rss_mib() -> float:
    """Resident memory of this process now, MiB (Linux; nan elsewhere)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return float("nan")


def bench_hour(config) -> None:
    sim, n = build_simulation({**load_scenario("crowd"), "duration_s": 3600.0})
    tracker = PeopleTracker.from_config(config)
    marks = {60.0: None, 900.0: None}  # s into the hour: resident memory then, MiB
    start = None
    t0 = time.perf_counter()
    for _ in range(n):
        st = sim.step()
        tracker.step(st.scan, st.odom_pose, st.odom_pose_last_beam)
        start = st.scan.stamp if start is None else start
        for at in marks:
            if marks[at] is None and st.scan.stamp - start >= at:
                marks[at] = _rss_mib()
    print(f"one hour of the crowd (30 people, {n} scans, {time.perf_counter() - t0:.0f} s): resident memory "
          f"{marks[60.0]:.0f} MiB after 1 min, {marks[900.0]:.0f} MiB after 15 min (the place memory holds "
          f"{config.existence.place_memory_s / 60:g} min of scans), {_rss_mib():.0f} MiB at 60 min")


def _best_both(run, repeat: int = 3, numpy_too: bool = True):
    """The fastest of ``repeat`` runs with the compiled kernels (a shared machine only ever
    slows a run down, so the fastest is the nearest to the code's own cost) and, when they
    are on and ``numpy_too``, of as many with the numpy code alone, the runs taken in turn
    so that a machine slowing down meanwhile weighs on both alike. Each is (per-scan times,
    the run's other figure as text), or None."""
    fast, slow = [], []
    for _ in range(repeat):
        fast.append(run())
        if compiled.ENABLED and numpy_too:
            with compiled.numpy_only():
                slow.append(run())
    def fastest(runs):
        times, other = min(runs, key=lambda run: sum(run[0]))
        return times, f"{other:.2f}"

    return fastest(fast), (fastest(slow) if slow else None)


def _one_core() -> None:
    """Pin every thread of this process (numpy's BLAS threads too) and its children to one
    core, as ``taskset -c CPU`` would (Linux; elsewhere nothing is pinned)."""
    if not hasattr(os, "sched_setaffinity"):
        return
    cpu = {min(os.sched_getaffinity(0))}
    tasks = Path("/proc/self/task")
    for tid in ([int(t) for t in os.listdir(tasks)] if tasks.exists() else [0]):
        try:
            os.sched_setaffinity(tid, cpu)
        except OSError:
            pass


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT_BAG))
    ap.add_argument("--people", type=int, nargs="+", default=[10, 50, 100])
    ap.add_argument("--scans", type=int, default=300, help="crowd scans to time")
    ap.add_argument("--hour", action="store_true", help="also the memory over a one-hour crowd (about 10 minutes)")
    args = ap.parse_args(argv)
    _one_core()
    config = load_config()
    gc.freeze()  # as people-tracker run and the ROS 2 node do after start-up
    print("compiled kernels: " + (f"on (numba {compiled.numba_version()})" if compiled.ENABLED else
                                  "off, numpy only (install the [fast] extra, or PEOPLE_TRACKER_COMPILED is 0)"))
    print(f"{'pipeline':<44} {'scans/s':>8} {'p50 ms':>8} {'p99 ms':>8}  tracks/scan")
    if Path(args.bag).exists():
        fast, slow = _best_both(lambda: bench_recording(Path(args.bag), config))
        _row(f"{Path(args.bag).name} (read+track)", *fast)
        if slow:
            _row("  the same, numpy only", *slow)
    else:
        print(f"{Path(args.bag).name}: not found (the real recordings live in ../shared/data)")
    for people in args.people:
        fast, slow = _best_both(lambda: bench_crowd(people, config, args.scans), numpy_too=people == 50)
        _row(f"crowd scene, {people} people (track only)", *fast)
        if slow:
            _row("  the same, numpy only", *slow)
    bench_whole_program()
    bench_startup()
    if args.hour:
        bench_hour(config)
    print(f"peak resident memory: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
