"""Score the tracker on the annotated real recording, next to the published figures.

Runs the whole pipeline on ``general_tracking_moving_1.bag`` (a moving robot in a
university hallway, hand-labelled people) and prints the evaluation table of Leigh et
al.'s protocol (CLEAR MOT at 0.75 m) beside the published Joint Leg Tracker figures.

    python demos/score_recording.py [BAG] [--short]

``--short`` scores the first 300 scans only (for CI).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from people_tracker.tracker.bench import bench_recording
from people_tracker.tracker.config import load_config

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"
PUBLISHED = {"mota": 0.102, "motp_m": 0.15, "id_switches": 2, "misses": 480, "false_positives": 97, "matches": 163,
             "ground_truth": 643}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bag", nargs="?", default=str(DEFAULT))
    ap.add_argument("--short", action="store_true", help="the first 300 scans only")
    args = ap.parse_args(argv)
    path = Path(args.bag)
    if not path.exists():
        print(f"score_recording: '{path}' not found (the annotated recording lives in ../shared/data/leigh/)",
              file=sys.stderr)
        return 2
    row, window = bench_recording(path, None, load_config(), 300 if args.short else None)
    elapsed = sum(row.seconds)
    print(f"score_recording: {path.name}, {row.result['frames']} scans in {elapsed:.1f} s "
          f"({row.scans / elapsed:.0f} scans/s), Leigh et al.'s protocol (0.75 m)")
    print(f"{'':<18} {'all bearings':>15} {'-80..12 deg':>12} {'Joint Leg Tracker (published, -80..12 deg)':>44}")
    for key, label, fmt in (("mota", "MOTA", "{:.1%}"), ("motp_m", "MOTP (m)", "{:.3f}"),
                            ("id_switches", "id switches", "{}"), ("misses", "misses", "{}"),
                            ("false_positives", "false positives", "{}"), ("matches", "matches", "{}"),
                            ("ground_truth", "ground truth", "{}")):
        print(f"{label:<18} {fmt.format(row.result[key]):>15} {fmt.format(window.result[key]):>12} "
              f"{fmt.format(PUBLISHED[key]):>44}")
    print("Leigh et al. scored only people and tracks at sensor bearings -80..12 deg, the part of the view "
          "they annotated; their figures pool this recording with a second one we do not have.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
