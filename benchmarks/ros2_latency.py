"""The live node's latency on a real recording: ``people-tracker replay`` feeds it the
scans and odometry of ``general_tracking_moving_1.bag`` at each rate, the node is stopped
with Ctrl-C (SIGINT) and its own summary line is printed: scans tracked, scans dropped,
and the latency from the scan callback's entry to ``people`` published (p50, p99), which
includes waiting for the odometry that covers the scan's sweep.

Needs the ``[ros2]`` extra. Usage::

    python benchmarks/ros2_latency.py [--rates 1 4] [--data DIR]
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def command() -> list[str]:
    exe = shutil.which("people-tracker", path=str(Path(sys.executable).parent)) or shutil.which("people-tracker")
    return [exe] if exe else [sys.executable, "-m", "people_tracker"]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rates", type=float, nargs="+", default=[1.0, 4.0])
    ap.add_argument("--data", type=Path, default=Path(os.environ.get("PEOPLE_TRACKER_DATA", REPO.parent / "shared" / "data")))
    args = ap.parse_args(argv)
    bag = args.data / "leigh" / "general_tracking_moving_1.bag"
    if not bag.exists():
        print(f"ros2_latency: {bag} not found", file=sys.stderr)
        return 2
    env = {**os.environ, "ROS_DOMAIN_ID": str(60 + os.getpid() % 30), "PYTHONUNBUFFERED": "1"}
    for rate in args.rates:
        node = subprocess.Popen(command() + ["-q", "ros2", "--mount", "0.850326", "0.235214", "42.1014"], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        node.stdout.readline()  # the node runs
        played = subprocess.run(command() + ["replay", str(bag), "--rate", f"{rate:g}"], env=env,
                                capture_output=True, text=True)
        time.sleep(1.5)
        node.send_signal(signal.SIGINT)
        out, _ = node.communicate(timeout=30)
        last = played.stdout.strip().splitlines()[-1] if played.stdout.strip() else played.stderr.strip()
        print(f"--rate {rate:g}: {last}")
        print("  " + out.strip().splitlines()[-1].replace("people-tracker ros2: ", "node: "))
    return 0


if __name__ == "__main__":
    sys.exit(main())
