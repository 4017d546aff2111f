"""Scan matching accuracy: on simulated moving-robot scenes against the true poses, and on
the annotated recording against its odometry.

Usage::

    python benchmarks/alignment_accuracy.py [--real BAG]

Simulated (``room_drive``: 1 m/s and turns in place at 45°/s among furniture and five
walking people; ``corridor``: a long featureless corridor): for every pair of consecutive
scans, the error of the estimated relative motion against the truth, median and p95, with
noisy odometry as the prior (5 % of distance, 2° per turned radian) and with no odometry
at all. In the corridor the error along the corridor is given separately, with how often
that direction was found unconstrained and kept at the prior.

Real: the difference between the matched and the odometry relative motion per scan pair.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from people_tracker.detection.align import AlignParams, ScanAligner
from people_tracker.models.scenario import build_simulation, load_scenario
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.recording import Recording

DEFAULT_BAG = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh" / "general_tracking_moving_1.bag"


def plain_corridor() -> dict:
    """The corridor scene without its furniture: two bare walls, nothing along them."""
    spec = load_scenario("corridor")
    return {**spec, "world": {"walls": spec["world"]["walls"]}}


def simulated_errors(scenario: str | dict, use_odometry: bool, params: AlignParams | None = None,
                     duration=None) -> dict:
    """Per scan pair: translation error (m), rotation error (rad), error along x of the world
    (the corridor's axis), and whether the match was trusted / degenerate."""
    spec = load_scenario(scenario) if isinstance(scenario, str) else scenario
    if duration is not None:
        spec = {**spec, "duration_s": duration}
    sim, n = build_simulation(spec)
    aligner = ScanAligner(params or load_config().alignment.params())
    prev_truth = prev_est = None
    rows = []
    for _ in range(n):
        st = sim.step()
        odom = st.odom_pose @ sim.mount if use_odometry else None
        last = st.odom_pose_last_beam @ sim.mount if use_odometry else None
        people = st.truth.torso_world  # the tracker would pass its people; here the truth
        a = aligner.align(st.scan, odom, last, people)
        truth = st.truth.sensor_pose
        if prev_truth is not None:
            true_rel = prev_truth.between(truth)
            est_rel = prev_est.between(a.pose)
            err = true_rel.between(est_rel)
            # error of the motion along the world x axis (the corridor's axis)
            along = abs((prev_truth @ est_rel).x - truth.x)
            m = a.match
            rows.append((math.hypot(err.x, err.y), abs(err.yaw), along,
                         bool(m is not None and m.ok), bool(m is not None and m.degenerate)))
        prev_truth, prev_est = truth, a.pose
    r = np.array(rows, dtype=float)
    return {"pairs": len(r), "t50": np.median(r[:, 0]), "t95": np.percentile(r[:, 0], 95),
            "r50": math.degrees(np.median(r[:, 1])), "r95": math.degrees(np.percentile(r[:, 1], 95)),
            "along50": np.median(r[:, 2]), "along95": np.percentile(r[:, 2], 95),
            "ok": r[:, 3].mean(), "degenerate": r[:, 4].mean()}


def moving_readings_far_from_people(path: Path, matching: bool, far: float = 1.0) -> float:
    """Readings labelled moving (M) per scan that lie farther than ``far`` metres from every
    annotated person: static surfaces that misalignment made look moving."""
    from dataclasses import replace

    from people_tracker.detection.detector import MovingObjectDetector
    from people_tracker.detection.labels import MOVING
    from people_tracker.tracker.io.ground_truth import read_bag_ground_truth

    cfg = load_config()
    gt = read_bag_ground_truth(path)
    aligner = ScanAligner(replace(cfg.alignment.params(), enabled=matching))
    det = MovingObjectDetector(cfg.detector.params())
    count = scans = 0
    with Recording(path, None, cfg.odometry) as rec:
        for rcd in rec.scans():
            a = aligner.align(rcd.scan, rcd.pose, rcd.pose_last_beam)
            labels = det.detect(a.scan, a.pose).labels
            pts = a.scan.points[labels == MOVING]
            sel = gt.scan_index == rcd.index
            people = np.column_stack([gt.x[sel], gt.y[sel]])
            if len(people) and len(pts):
                d = np.hypot(pts[:, None, 0] - people[None, :, 0], pts[:, None, 1] - people[None, :, 1]).min(axis=1)
                count += int((d > far).sum())
            else:
                count += len(pts)
            scans += 1
    return count / max(scans, 1)


def real_differences(path: Path) -> dict:
    cfg = load_config()
    aligner = ScanAligner(cfg.alignment.params())
    prev_odom = prev_est = None
    rows, ok = [], []
    with Recording(path, None, cfg.odometry) as rec:
        for rcd in rec.scans():
            a = aligner.align(rcd.scan, rcd.pose, rcd.pose_last_beam)
            if prev_odom is not None:
                d = prev_odom.between(rcd.pose).between(prev_est.between(a.pose))
                rows.append((math.hypot(d.x, d.y), abs(d.yaw)))
                ok.append(a.match.ok)
            prev_odom, prev_est = rcd.pose, a.pose
    r = np.array(rows)
    return {"pairs": len(r), "t50": np.median(r[:, 0]), "t95": np.percentile(r[:, 0], 95),
            "r50": math.degrees(np.median(r[:, 1])), "r95": math.degrees(np.percentile(r[:, 1], 95)),
            "ok": float(np.mean(ok))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--real", default=str(DEFAULT_BAG))
    args = ap.parse_args(argv)
    print(f"{'scene':<34} {'prior':<10} {'pairs':>5} {'trans p50/p95 (cm)':>19} {'rot p50/p95 (deg)':>18} "
          f"{'along-x p50/p95 (cm)':>21} {'trusted':>8} {'degenerate':>10}")
    for name, scene in (("room_drive", "room_drive"), ("corridor (with furniture)", "corridor"),
                        ("corridor, bare walls", plain_corridor())):
        for use in (True, False):
            e = simulated_errors(scene, use)
            print(f"{name:<34} {'odometry' if use else 'none':<10} {e['pairs']:>5} "
                  f"{100 * e['t50']:>9.2f}/{100 * e['t95']:<9.2f} {e['r50']:>8.3f}/{e['r95']:<9.3f} "
                  f"{100 * e['along50']:>10.2f}/{100 * e['along95']:<10.2f} {100 * e['ok']:>7.0f}% {100 * e['degenerate']:>9.0f}%")
    if Path(args.real).exists():
        d = real_differences(Path(args.real))
        print(f"\n{Path(args.real).name}: matched vs odometry relative motion per scan pair ({d['pairs']} pairs): "
              f"translation p50 {100 * d['t50']:.2f} cm, p95 {100 * d['t95']:.2f} cm; rotation p50 {d['r50']:.3f}°, "
              f"p95 {d['r95']:.3f}°; {100 * d['ok']:.0f}% of matches trusted")
        for matching in (False, True):
            v = moving_readings_far_from_people(Path(args.real), matching)
            print(f"readings labelled moving farther than 1 m from every annotated person, per scan, "
                  f"{'with' if matching else 'without'} scan matching: {v:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
