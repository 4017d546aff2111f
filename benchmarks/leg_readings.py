"""How many readings a leg leaves at coarser beam spacings: the ceiling on leg recall there.

Usage::

    python benchmarks/leg_readings.py [--data DIR]

On the leg model's *training* recordings (``positive_{1,2,3}_extracted.bag``, so no figure
here is a look at the held-out data), every labelled leg is matched to a candidate segment
(:func:`people_tracker.detection.leg_features.leg_candidates`, within 0.15 m, as
``people-tracker train-legs`` matches them) with every beam, every 2nd and every 3rd
(0.35°, 0.70°, 1.05°). Prints the share of legs with a candidate at all (a segment needs
two readings) and how many readings the matched candidates have: a segment of two or three
readings has a width and surroundings but no shape (a circle through three points fits
exactly), so what the leg model can tell from it is bounded by the laser, not the model.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from people_tracker.detection.leg_features import leg_candidates
from people_tracker.tracker import train_legs as T


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", default=os.environ.get("PEOPLE_TRACKER_DATA", "../shared/data"),
                    help="folder of the real recordings (default: $PEOPLE_TRACKER_DATA, else ../shared/data)")
    args = ap.parse_args()
    folder = Path(args.data) / "leigh" / "training"
    bags = [folder / f"positive_{k}_extracted.bag" for k in (1, 2, 3)]
    if not all(b.exists() for b in bags):
        print(f"the training recordings are not in {folder}: nothing to measure", file=sys.stderr)
        return 2
    labelled = [item for b in bags for item in T.read_labelled(b)]
    print(f"training recordings: {len(labelled)} labelled scans, {sum(len(i.legs) for i in labelled)} legs")
    print("beams               with a candidate  readings p10/p50/p90   2 readings  3 or fewer  4 or fewer")
    for every, name in ((1, "all (0.35 deg)"), (2, "every 2nd (0.70)"), (3, "every 3rd (1.05)")):
        n, found = [], 0
        for item in labelled:
            c = leg_candidates(T.decimate(item.scan, every, 0))
            pos, _ = T.match(c.xy, item.legs, 0.15)
            found += int(pos.sum())
            n += (c.stop[pos] - c.start[pos]).tolist()
        n = np.array(n)
        p10, p50, p90 = np.percentile(n, [10, 50, 90])
        total = sum(len(i.legs) for i in labelled)
        spread = f"{p10:.0f}/{p50:.0f}/{p90:.0f}"
        print(f"{name:18s}  {found / total:16.3f}  {spread:>14s}{'':7s}{np.mean(n <= 2):10.2f}"
              f"  {np.mean(n <= 3):10.2f}  {np.mean(n <= 4):10.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
