"""Where the tracks sit along the line of sight: leg centres against the readings' hull centroid.

A laser sees the near half of a round leg, so a leg's readings lie in front of its centre,
and a person's torso is behind their legs' front surfaces. For every reported track within
0.75 m of a visible person (the nearest one), the radial offset is the track's distance
from the laser minus the person's (negative: nearer than the person). The script prints its
mean and spread and the MOTP, with the leg centres stepped back along the beam (the
default) and with the paper's hull centroid (``pairing.max_leg_radius_m: 0``), on the
annotated recording (if ``../shared/data`` is there) and on simulated scenes.

Usage::

    python benchmarks/radial_bias.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from people_tracker.tracker.bench import _run, scene_ground_truth
from people_tracker.tracker.config import config_from_dict
from people_tracker.tracker.evaluation import TrackRows, evaluate
from people_tracker.tracker.io.ground_truth import read_bag_ground_truth
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.io.simulated import SimulatedSource

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "leigh"
RECORDING = DATA / "general_tracking_moving_1.bag"
SCENES = (("crossing", None, None), ("following", None, None), ("follow_indoor_crowd", "wide", 120.0),
          ("follow_outdoor", "wide", 120.0))
VARIANTS = (("leg centres", None), ("hull centroid", {"pairing": {"max_leg_radius_m": 0.0}}))


def radial_offsets(gt, tracks, threshold: float = 0.75) -> np.ndarray:
    """For each ground-truth row with a track within ``threshold``: track range minus person range, m."""
    out = []
    for k, x, y in zip(gt.scan_index, gt.x, gt.y):
        sel = np.flatnonzero(tracks.scan_index == k)
        if not len(sel):
            continue
        d = np.hypot(tracks.x[sel] - x, tracks.y[sel] - y)
        j = sel[int(np.argmin(d))]
        if d.min() <= threshold:
            out.append(np.hypot(tracks.x[j], tracks.y[j]) - np.hypot(x, y))
    return np.array(out)


def line(name: str, variant: str, offsets: np.ndarray, motp: float) -> str:
    return (f"{name:<44} {variant:<14} {len(offsets):>6} {np.mean(offsets):>+9.3f} {np.std(offsets):>7.3f} "
            f"{motp:>7.3f}")


def main() -> int:
    print(f"{'input':<44} {'position':<14} {'pairs':>6} {'mean m':>9} {'sd m':>7} {'MOTP m':>7}")
    for variant, overrides in VARIANTS:
        config = config_from_dict(overrides)
        if RECORDING.exists():
            with Recording(RECORDING, "/scan", config.odometry) as rec:
                rows = _run(rec, config, timed_read=False, limit=None)[0]
            gt, tracks = read_bag_ground_truth(RECORDING, "/scan"), TrackRows.of(rows)
            print(line(RECORDING.name, variant, radial_offsets(gt, tracks), evaluate(gt, tracks)["motp_m"]), flush=True)
        for name, laser, duration in SCENES:
            source = SimulatedSource(name, laser=laser, duration=duration)
            rows = _run(source, config, timed_read=False, limit=None)[0]
            gt, hidden = scene_ground_truth(source.truths)
            tracks = TrackRows.of(rows)
            label = f"simulated {name}" + (f" ({laser}, {duration:g} s)" if laser else "")
            print(line(label, variant, radial_offsets(gt, tracks), evaluate(gt, tracks, hidden=hidden)["motp_m"]),
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
