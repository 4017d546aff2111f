"""How well the leg model finds legs on data it was not fitted on.

Usage::

    python benchmarks/leg_accuracy.py [--model MODEL.npz] [--frames N]

Held out from the shipped model's fitting (Leigh et al.'s recordings, see
``../shared/data/README.md``): the labelled legs of ``positive_4_extracted.bag`` and the empty
rooms of ``negative_2.bag`` ``/rear_scan``. A labelled leg is found when a candidate scored
at or above the threshold lies within 0.15 m of it; the threshold is where the empty-room
scans of that laser hold 0.2, 0.5 or 1.0 candidates per scan at or above it (recall at a
fixed false rate). Printed:

1. recall at those rates, on the full scans and with every 2nd and every 3rd beam dropped
   (0.70° and 1.05°), the threshold set again on the empty scans treated the same way; and
   with the held-out legs pasted into the held-out rooms (their labelled legs all stand
   beyond one doorway; see ``tracker/train_legs.py``);
2. calibration on the held-out candidates (the labelled legs' candidates and every
   empty-room candidate): per tenth of the score, how many, their mean score and the
   share that are legs; and the Brier score;
3. simulated lasers at 0.25°, 0.5° and 1° (270°, 1 cm noise): people standing and walking
   1-5 m away among chair and table legs of 1.5-3 cm radius, walls and boxes; recall of
   the legs that show two readings or more, at the full-resolution real threshold for
   0.5 false legs per scan, and the false legs per scan there;
4. the people of the annotated hallway recording (``general_tracking_moving_1.bag``: another
   robot, another place, never used in fitting the model): the share of annotated
   person-scans with a leg candidate at or above that threshold within 0.3 m of the
   person, by range, and the widths of the candidates nearest them against the fitted
   legs' (its people show narrower legs).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from people_tracker.models.laser import LaserModel
from people_tracker.models.leg_model import load_leg_model
from people_tracker.models.world import build_world
from people_tracker.tracker import train_legs as T

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "leigh"
RATES = (0.2, 0.5, 1.0)


def calibration(model, labelled, empty, bins: int = 10) -> tuple[list[tuple], float]:
    """Rows (low, high, count, mean score, share of legs) and the Brier score."""
    scores, truth = [], []
    for item in labelled:
        xy, p = T.leg_scores(model, item.scan)
        hit, _ = T.match(xy, item.legs, 0.15)
        scores.append(p[hit])
        truth.append(np.ones(int(hit.sum())))
    for scan in empty:
        scores.append(T.leg_scores(model, scan)[1])
        truth.append(np.zeros(len(scores[-1])))
    s, t = np.concatenate(scores), np.concatenate(truth)
    rows = []
    for k in range(bins):
        lo, hi = k / bins, (k + 1) / bins
        sel = (s >= lo) & ((s < hi) if k < bins - 1 else (s <= hi))
        rows.append((lo, hi, int(sel.sum()), float(s[sel].mean()) if sel.any() else math.nan,
                     float(t[sel].mean()) if sel.any() else math.nan))
    return rows, float(np.mean((s - t) ** 2))


def simulated_frames(resolution_deg: float, frames: int, seed: int = 1):
    """Scans of a furnished room with people, and each scan's visible legs (sensor frame)."""
    rng = np.random.default_rng(seed)
    world = build_world({"room": [-6, -6, 8, 6], "boxes": [[3, 3, 4.2, 3.8], [-3, -5, -1.5, -4.2]],
                         "pillars": [[5, -2, 0.2]]})
    furniture = []
    for cx, cy, w, d, r in ((2.5, -1.5, 1.2, 0.7, 0.025), (-2.0, 2.0, 1.0, 1.0, 0.03), (4.0, 1.0, 0.45, 0.45, 0.015),
                            (1.5, 2.5, 0.45, 0.45, 0.018), (-1.0, -2.5, 0.45, 0.45, 0.02), (5.5, 3.5, 1.6, 0.8, 0.03)):
        furniture += [(cx + sx * w / 2, cy + sy * d / 2, r) for sx in (-1, 1) for sy in (-1, 1)]
    furniture = np.array(furniture)
    laser = LaserModel(fov=math.radians(270), resolution=math.radians(resolution_deg), rate_hz=10.0,
                       range_max=20.0, noise_std=0.01)
    return [T.people_among_furniture(laser, world, furniture, rng, int(rng.integers(3, 8)), (1.0, 5.0), 2.0,
                                     (0.6, 0.7), 0.35, (0.05, 0.08)) for _ in range(frames)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", help="a model file (default: the shipped one)")
    ap.add_argument("--frames", type=int, default=150, help="simulated scans per laser (%(default)s)")
    args = ap.parse_args(argv)
    if not DATA.is_dir():
        print(f"leg_accuracy: {DATA} not found", file=sys.stderr)
        return 2
    model = load_leg_model(args.model)
    labelled = T.read_labelled(DATA / "training" / "positive_4_extracted.bag")
    empty = [s for _, s in T.read_scans(DATA / "negative_2.bag", "/rear_scan")]
    print(f"held out: positive_4_extracted.bag ({len(labelled)} scans, {sum(len(i.legs) for i in labelled)} labelled "
          f"legs) and negative_2.bag /rear_scan ({len(empty)} empty scans)")
    print("recall at a fixed number of false legs per empty scan")
    print("beams              " + "".join(f"  {r:.1f}/scan (thr)" for r in RATES))
    full = None
    for every, name in ((1, "all (0.35 deg)"), (2, "every 2nd (0.70)"), (3, "every 3rd (1.05)")):
        rows = T.recall_at_false_rates(model, labelled, empty, RATES, every=every)
        full = rows if full is None else full
        print(f"{name:<19}" + "".join(f"  {r['recall']:6.3f} ({r['threshold']:.3f})" for r in rows))
    moved = T.transplanted([labelled], [empty], per_scan=1, seed=11)[0]
    rows = T.recall_at_false_rates(model, moved, empty, RATES)
    print(f"{'legs in the rooms':<19}" + "".join(f"  {r['recall']:6.3f} ({r['threshold']:.3f})" for r in rows)
          + f"  ({len(moved)} scans)")
    rows, brier = calibration(model, labelled, empty)
    print("calibration on the held-out candidates (legs matched to labels, every empty-room candidate)")
    print("score       count  mean score  share of legs")
    for lo, hi, n, mean, share in rows:
        flag = "" if n < 50 or abs(mean - share) <= 0.1 else "  (off by more than 0.1)"
        print(f"{lo:.1f}-{hi:.1f}  {n:8d}  {mean:10.3f}  {share:13.3f}{flag}")
    print(f"Brier score {brier:.4f}")
    threshold = next(r["threshold"] for r in full if r["false_per_scan"] == 0.5)
    print(f"simulated lasers (270 deg, {args.frames} scans each), threshold {threshold:.3f} "
          "(0.5 false legs per real empty scan at full resolution)")
    print("resolution  legs  recall  false legs/scan")
    for res in (0.25, 0.5, 1.0):
        frames = simulated_frames(res, args.frames)
        found = total = false = 0
        for scan, legs in frames:
            xy, p = T.leg_scores(model, scan)
            keep = p >= threshold
            hit_c, hit_l = T.match(xy[keep], legs, 0.15)
            found += int(hit_l.sum())
            total += len(legs)
            false += int((~hit_c).sum())
        print(f"{res:5.2f} deg  {total:5d}  {found / max(total, 1):6.3f}  {false / len(frames):15.2f}")
    hallway(model, threshold)
    return 0


def hallway(model, threshold: float, near_m: float = 0.3) -> None:
    """Print part 4 of the module docstring."""
    from collections import defaultdict

    from people_tracker.detection.leg_features import FEATURES, leg_candidates
    from people_tracker.tracker.io.ground_truth import read_bag_ground_truth

    bag = DATA / "general_tracking_moving_1.bag"
    gt = read_bag_ground_truth(bag)
    people = defaultdict(list)
    for k, x, y in zip(gt.scan_index, gt.x, gt.y):
        people[int(k)].append((x, y))
    width = FEATURES.index("width_m")
    edges = np.array([0.0, 2.0, 4.0])  # m: range bands from each edge to the next (the last one open)
    bands = tuple(zip(edges, [*edges[1:], 8.0]))
    found, total, widths = np.zeros(len(bands)), np.zeros(len(bands)), []
    for i, (_, scan) in enumerate(T.read_scans(bag)):
        if i not in people:
            continue
        c = leg_candidates(scan)
        p = model.probability(c.features)
        for q in people[i]:
            d = np.hypot(*(c.xy - np.array(q)).T) if len(c) else np.zeros(0)
            b = int(np.searchsorted(edges, math.hypot(*q), side="right")) - 1
            total[b] += 1
            found[b] += bool(((d <= near_m) & (p >= threshold)).any())
            if len(d) and d.min() <= near_m:
                widths.append(c.features[int(np.argmin(d)), width])
    fitted = []
    for k in (1, 2, 3):
        for item in T.read_labelled(DATA / "training" / f"positive_{k}_extracted.bag"):
            c = leg_candidates(item.scan)
            fitted += list(c.features[T.match(c.xy, item.legs, 0.15)[0], width])
    print(f"people of the annotated hallway recording (never fitted on), threshold {threshold:.3f}: "
          f"{found.sum() / max(total.sum(), 1):.3f} of {int(total.sum())} annotated person-scans have a leg "
          f"within {near_m} m")
    print("  by range " + ", ".join(f"{lo:g}-{hi:g} m {f / max(n, 1):.3f} of {int(n)}"
                                    for (lo, hi), f, n in zip(bands, found, total)))
    w, v = np.percentile(widths, [10, 50, 90]), np.percentile(fitted, [10, 50, 90])
    print(f"  width of the candidate nearest each person p10/p50/p90 {w[0]:.3f}/{w[1]:.3f}/{w[2]:.3f} m, "
          f"of the fitted legs {v[0]:.3f}/{v[1]:.3f}/{v[2]:.3f} m")


if __name__ == "__main__":
    sys.exit(main())
