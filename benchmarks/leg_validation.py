"""Design choices for the leg model, scored on its own training data only.

Usage::

    python benchmarks/leg_validation.py [--depth D] [--trees N] [--simulated N]
                                        [--simulated-resolutions DEG ...]

The shipped model's held-out data (``positive_4_extracted.bag``, ``negative_2.bag``
``/rear_scan``; ``benchmarks/leg_accuracy.py``) must not steer its design, so choices such
as the trees' depth or the simulated lasers' resolutions are made here: three folds, each
fitted as ``people-tracker train-legs`` fits (legs pasted into the empty rooms, simulated
rooms, every scan also at every 2nd and 3rd beam) on two of ``positive_{1,2,3}_extracted``
and one of ``/left_scan``, ``/right_scan``, and scored on the third recording with the
other laser's empty rooms. Printed per fold and on average: the share of labelled legs
with a candidate within 0.15 m at or above the threshold that leaves 0.5 candidates per
empty scan, at full resolution and with every 2nd and 3rd beam (the threshold set again
on the empty scans treated the same way). Candidates are ranked by the ensemble's raw
log-odds, not the calibrated probability: the calibration map is a staircase whose steps
make the recall jump by several points between models that rank alike.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from people_tracker.tracker import train_legs as T
from people_tracker.tracker.errors import InputError, require

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh"
FOLDS = ((3, "/left_scan", "/right_scan"), (2, "/right_scan", "/left_scan"), (1, "/left_scan", "/right_scan"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--depth", type=int, default=4, help="tree depth (%(default)s)")
    ap.add_argument("--trees", type=int, default=200, help="boosting rounds (%(default)s)")
    ap.add_argument("--simulated", type=int, default=600, help="simulated scans (%(default)s)")
    ap.add_argument("--simulated-resolutions", type=float, nargs="+", default=list(T.SIMULATED_RESOLUTIONS_DEG), metavar="DEG",
                    help="the simulated lasers' beam spacings (%(default)s)")
    args = ap.parse_args(argv)
    if not DATA.is_dir():
        print(f"leg_validation: {DATA} not found", file=sys.stderr)
        return 2
    try:
        require("sklearn", "train", "leg_validation.py")
    except InputError as exc:
        print(f"leg_validation: {exc}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    positives = {k: T.read_labelled(DATA / "training" / f"positive_{k}_extracted.bag") for k in (1, 2, 3)}
    rooms = {t: [s for _, s in T.read_scans(DATA / "negative_2.bag", t)] for t in ("/left_scan", "/right_scan")}
    print(f"depth {args.depth}, {args.trees} trees, {args.simulated} simulated scans at {args.simulated_resolutions} deg")
    print("fitted on                        scored on                        all    2nd    3rd")
    rows = []
    for held, fit_laser, score_laser in FOLDS:
        fit_on = [positives[k] for k in (1, 2, 3) if k != held]
        x, y, groups, recorded, _ = T.training_set(fit_on, [rooms[fit_laser]], args.simulated,
                                                   args.simulated_resolutions)
        model = T.fit(x, y, groups, n_trees=args.trees, depth=args.depth, calibrate_on=recorded)
        r = [T.recall_at_false_rates(model, positives[held], rooms[score_laser], (0.5,), every=every, raw=True)[0]["recall"]
             for every in (1, 2, 3)]
        rows.append(r)
        names = "+".join(f"p{k}" for k in (1, 2, 3) if k != held)
        print(f"{names + ' ' + fit_laser:<32} {f'p{held} ' + score_laser:<32} " + " ".join(f"{v:.3f}" for v in r))
    mean = np.mean(rows, axis=0)
    print(f"{'mean':<65} " + " ".join(f"{v:.3f}" for v in mean) + f"   ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
