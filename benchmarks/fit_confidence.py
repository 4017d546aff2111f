"""Fit the calibration map of the reported ``confidence`` (``existence.confidence_raw`` and
``existence.confidence_calibrated`` in ``configs/default.yaml``).

The tracker runs with the identity map over simulated scenes whose seeds are *not* the
ones ``benchmarks/track_evidence.py`` reports on (the waiting room with seeds 1, 2 and 3,
five minutes of crowd with seeds 1 and 2, the other scenes with their seed + 100); every reported track-scan is
an example: its existence probability, and whether it lay within 0.5 m of a person. An
isotonic regression (scikit-learn, the ``[train]`` extra) maps one to the other; its
knots, thinned to at most 12, are printed as the two YAML lines to paste.

Usage::

    python benchmarks/fit_confidence.py
"""

from __future__ import annotations

import sys

import numpy as np

from track_evidence import nearest_person, run_scene, NEAR_M
from people_tracker.models.scenario import load_scenario
from people_tracker.tracker.config import config_from_dict

TRAIN = [("waiting_room", 1, None), ("waiting_room", 2, None), ("waiting_room", 3, None), ("crowd", 1, 300.0),
         ("crowd", 2, 300.0), ("crossing", None, None), ("stop_and_go", None, None), ("occlusion", None, None),
         ("following", None, None), ("corridor", None, None)]


def examples() -> tuple[np.ndarray, np.ndarray]:
    identity = config_from_dict({"existence": {"confidence_raw": [0.0, 1.0], "confidence_calibrated": [0.0, 1.0]}})
    raw, near = [], []
    for name, seed, duration in TRAIN:
        if seed is None:
            seed = int(load_scenario(name).get("seed", 0)) + 100
        run = run_scene(name, seed, duration, config=identity)
        dist, _ = nearest_person(run)
        raw.append(run.rows[:, 4])
        near.append(dist <= NEAR_M)
        print(f"{name} seed {seed}: {len(run.rows)} reported track-scans, {np.mean(near[-1]):.3f} near a person",
              flush=True)
    return np.concatenate(raw), np.concatenate(near)


def fit(raw: np.ndarray, near: np.ndarray, max_knots: int = 12) -> tuple[list[float], list[float]]:
    """The isotonic map's own steps (blocks of 100 examples or more), each at the mean of
    its block's raw values, thinned to ``max_knots`` by dropping the knots that change the
    map least."""
    from sklearn.isotonic import IsotonicRegression
    iso = IsotonicRegression(y_min=0.0, y_max=1.0, out_of_bounds="clip").fit(raw, near.astype(float))
    fitted = iso.predict(raw)
    xs, ys = [], []
    for y in np.unique(fitted):  # one knot per block of equal fitted value, where its examples lie
        sel = fitted == y
        if sel.sum() < 100:  # too few to say anything: the neighbours' line decides there
            continue
        xs.append(float(raw[sel].mean()))
        ys.append(float(y))
    order = np.argsort(xs)
    xs, ys = list(np.array(xs)[order]), list(np.array(ys)[order])
    while len(xs) > max_knots:
        # drop the inner knot that the line through its neighbours misses least
        err = [abs(ys[i] - np.interp(xs[i], [xs[i - 1], xs[i + 1]], [ys[i - 1], ys[i + 1]])) for i in range(1, len(xs) - 1)]
        k = 1 + int(np.argmin(err))
        del xs[k], ys[k]
    return [round(x, 3) for x in xs], [round(y, 3) for y in ys]


def main() -> int:
    raw, near = examples()
    xs, ys = fit(raw, near)
    # equal rounded x values would make the map ill-defined
    keep = [0] + [i for i in range(1, len(xs)) if xs[i] > xs[i - 1]]
    print(f"{len(raw)} examples, {near.mean():.3f} of them near a person")
    print(f"  confidence_raw: [{', '.join(f'{xs[i]:g}' for i in keep)}]")
    print(f"  confidence_calibrated: [{', '.join(f'{ys[i]:g}' for i in keep)}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
