"""How well the detector alone finds annotated people in a real recording.

Usage::

    python benchmarks/detector_accuracy.py [BAG] [--topic T] [--config FILE] [--far 1.0]

For every scan of the annotated recording: the share of ground-truth people with a
detected moving object within 0.3 m and within 0.5 m (hull centroids, sensor frame), and
the number of detections per scan farther than ``--far`` metres from every annotated
person. On a recording without annotations (``negative_2.bag``: nobody is there) every
detection counts as far. Scans are prepared as the pipeline does (de-skew, then scan
matching unless ``--no-matching``; odometry where the recording has it).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from dataclasses import replace

from people_tracker.detection.align import ScanAligner
from people_tracker.detection.detector import MovingObjectDetector
from people_tracker.tracker.config import load_config
from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.ground_truth import read_bag_ground_truth
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.scan_checks import ScanChecker

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh"


def detector_figures(bag: Path, topic: str | None, config, far: float, annotated: bool,
                     matching: bool = True) -> dict:
    gt = read_bag_ground_truth(bag, topic) if annotated else None
    gt_by_scan: dict[int, np.ndarray] = {}
    if gt is not None:
        for k in np.unique(gt.scan_index):
            sel = gt.scan_index == k
            gt_by_scan[int(k)] = np.column_stack([gt.x[sel], gt.y[sel]])
    det = MovingObjectDetector(config.detector.params())
    aligner = ScanAligner(replace(config.alignment.params(), enabled=matching))
    checker = ScanChecker(config.scan_checks.stamp_jump_periods, config.scan_checks.beam_count_confirm)
    near3 = near5 = n_gt = n_det = n_far = scans = 0
    with Recording(bag, topic, config.odometry) as rec:
        for r in rec.scans():
            v = checker.check(r.scan, r.problem)
            if not v.use:
                continue
            if v.restart:
                det.reset()
                aligner.reset()
            aligned = aligner.align(r.scan, r.pose, r.pose_last_beam)
            objs = det.detect(aligned.scan, aligned.pose).objects
            scans += 1
            xy = np.array([(o.x, o.y) for o in objs]).reshape(-1, 2)
            people = gt_by_scan.get(r.index, np.zeros((0, 2)))
            n_det += len(xy)
            if len(people) and len(xy):
                d = np.hypot(people[:, None, 0] - xy[None, :, 0], people[:, None, 1] - xy[None, :, 1])
                near3 += int((d.min(axis=1) <= 0.3).sum())
                near5 += int((d.min(axis=1) <= 0.5).sum())
                n_far += int((d.min(axis=0) > far).sum())
            else:
                n_far += len(xy)
            n_gt += len(people)
    return {"scans": scans, "gt_people": n_gt, "within_0.3m": near3 / n_gt if n_gt else float("nan"),
            "within_0.5m": near5 / n_gt if n_gt else float("nan"), "detections_per_scan": n_det / max(scans, 1),
            "far_per_scan": n_far / max(scans, 1)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bags", nargs="*", help="default: the annotated recording and negative_2.bag's /left_scan")
    ap.add_argument("--topic")
    ap.add_argument("--config")
    ap.add_argument("--far", type=float, default=1.0, help="metres from every annotated person (1.0)")
    ap.add_argument("--no-matching", action="store_true", help="odometry (or nothing) alone, no scan matching")
    args = ap.parse_args(argv)
    try:
        config = load_config(args.config)
        runs = [(Path(b), args.topic, True) for b in args.bags] or [
            (DATA / "general_tracking_moving_1.bag", None, True), (DATA / "negative_2.bag", "/left_scan", False)]
        print(f"{'recording':<34} {'scans':>5} {'people':>6} {'<=0.3 m':>8} {'<=0.5 m':>8} {'det/scan':>9} "
              f"{'far/scan':>9}")
        for bag, topic, annotated in runs:
            if not bag.exists():
                print(f"{bag.name:<34} not found (the real recordings live in ../shared/data)")
                continue
            f = detector_figures(bag, topic, config, args.far, annotated, not args.no_matching)
            pct = lambda v: "n/a" if v != v else f"{100 * v:.1f} %"  # noqa: E731
            print(f"{bag.name + (' ' + topic if topic else ''):<34} {f['scans']:>5} {f['gt_people']:>6} "
                  f"{pct(f['within_0.3m']):>8} {pct(f['within_0.5m']):>8} {f['detections_per_scan']:>9.2f} "
                  f"{f['far_per_scan']:>9.2f}")
    except InputError as exc:
        print(f"detector_accuracy: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
