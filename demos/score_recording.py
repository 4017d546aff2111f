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
import time
from pathlib import Path

import numpy as np

from tracker.config import load_config
from tracker.evaluation import TrackRows, evaluate
from tracker.io.ground_truth import GroundTruth, read_bag_ground_truth
from tracker.io.recording import Recording
from tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame
from tracker.scan_checks import ScanChecker

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"
PUBLISHED = {"mota": 0.102, "motp_m": 0.15, "id_switches": 2, "misses": 480, "false_positives": 97, "matches": 163}


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
    config = load_config()
    tracker = PeopleTracker.from_config(config)
    checker = ScanChecker(config.scan_checks.stamp_jump_periods, config.scan_checks.beam_count_confirm)
    limit = 300 if args.short else None
    rows = []
    t0 = time.perf_counter()
    with Recording(path, None, config.odometry) as rec:
        for r in rec.scans():
            if limit is not None and r.index >= limit:
                break
            v = checker.check(r.scan, r.problem)
            if not v.use:
                continue
            if v.restart:
                tracker.reset()
            tracks = tracker.step(r.scan, r.pose, r.pose_last_beam)
            rows += [(r.index, t.track_id, x, y) for t, (x, y) in zip(tracks, tracks_in_sensor_frame(tracks, tracker.last.pose))]
    elapsed = time.perf_counter() - t0
    gt = read_bag_ground_truth(path)
    if limit is not None:
        keep = gt.scan_index < limit
        gt = GroundTruth(min(gt.n_frames, limit), gt.scan_index[keep], gt.person_id[keep], gt.x[keep], gt.y[keep])
    a = np.array(rows, dtype=float).reshape(-1, 4)
    res = evaluate(gt, TrackRows(a[:, 0].astype(np.int64), a[:, 1].astype(np.int64), a[:, 2], a[:, 3]))
    print(f"score_recording: {path.name}, {res['frames']} scans in {elapsed:.1f} s "
          f"({res['frames'] / elapsed:.0f} scans/s), Leigh et al.'s protocol (0.75 m)")
    print(f"{'':<18} {'people-tracker':>15} {'Joint Leg Tracker (published)':>31}")
    for key, label, fmt in (("mota", "MOTA", "{:.1%}"), ("motp_m", "MOTP (m)", "{:.3f}"),
                            ("id_switches", "id switches", "{}"), ("misses", "misses", "{}"),
                            ("false_positives", "false positives", "{}"), ("matches", "matches", "{}")):
        print(f"{label:<18} {fmt.format(res[key]):>15} {fmt.format(PUBLISHED[key]):>31}")
    print(f"ground-truth people {res['ground_truth']} (the published figures pool this recording with a "
          f"second one we do not have: 643 people)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
