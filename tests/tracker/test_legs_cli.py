"""The leg model as users meet it: --legs, train-legs, and legs.model in a configuration."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from conftest import data_file
from tests_helpers import run_cli


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_legs_csv_holds_every_scored_candidate(tmp_path):
    bag = data_file("leigh/training/positive_4_extracted.bag")
    proc = run_cli("run", str(bag), "--legs", "legs.csv", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    rows = _rows(tmp_path / "legs.csv")
    assert list(rows[0]) == ["scan_index", "stamp", "x", "y", "score"]
    scores = np.array([float(r["score"]) for r in rows])
    assert (scores >= 0.01).all() and (scores <= 1.0).all()
    scans = {int(r["scan_index"]) for r in rows}
    assert len(scans) > 250  # nearly every one of the 295 scans has a person's legs
    assert (tmp_path / "legs.csv.config.yaml").exists()
    # the labelled legs (held out from the shipped model's fitting) are there, scored high:
    # most have a row scored 0.5 or more within 0.15 m, in the scan of the same stamp
    from people_tracker.tracker.train_legs import read_labelled
    high: dict[str, list] = {}
    for r in rows:
        if float(r["score"]) >= 0.5:
            high.setdefault(r["stamp"], []).append((float(r["x"]), float(r["y"])))
    found = total = 0
    for item in read_labelled(bag):
        xy = np.array(high.get(f"{item.scan.stamp:.6f}", []), dtype=float).reshape(-1, 2)
        for leg in item.legs:
            total += 1
            found += bool(len(xy)) and np.hypot(*(xy - leg).T).min() <= 0.15
    assert total == 415 and found / total > 0.6, found / total


def test_train_legs_fits_a_model_that_run_can_use(tmp_path):
    pytest.importorskip("sklearn", reason="scikit-learn is the [train] extra")
    pos = data_file("leigh/training/positive_2_extracted.bag")
    neg = data_file("leigh/negative_2.bag")
    proc = run_cli("train-legs", "--positive", str(pos), "--negative", f"{neg}:/left_scan", "--output", "mine.npz", "--simulated", "50",
                   "--trees", "30", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "wrote mine.npz" in proc.stdout and "legs" in proc.stdout
    from people_tracker.models.leg_model import load_leg_model
    model = load_leg_model(tmp_path / "mine.npz")
    assert len(model.feature) == 30 and model.meta["trained_on"][0].endswith("positive_2_extracted.bag")
    (tmp_path / "mine.yaml").write_text("legs: {model: mine.npz}\n")
    proc = run_cli("run", str(data_file("leigh/training/positive_4_extracted.bag")), "--config", "mine.yaml",
                   "--legs", "legs.csv", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert len(_rows(tmp_path / "legs.csv")) > 100


def test_train_legs_with_a_box_instead_of_labels(tmp_path):
    pytest.importorskip("sklearn", reason="scikit-learn is the [train] extra")
    pos = data_file("leigh/training/positive_2.bag")  # the raw recording: no labels
    neg = data_file("leigh/negative_2.bag")
    proc = run_cli("train-legs", "--positive", str(pos), "--negative", f"{neg}:/rear_scan", "--box", "0.5", "-0.7",
                   "5.0", "0.25", "--output", "boxed.npz", "--trees", "20", "--simulated", "0", "--depth", "6",
                   cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    from people_tracker.models.leg_model import load_leg_model
    assert load_leg_model(tmp_path / "boxed.npz").depth == 6


@pytest.mark.parametrize("args, words", [
    (["--box", "1", "0", "0", "1"], "--box needs X0 < X1"),
    (["--trees", "3"], "--trees must be between"),
    (["--depth", "0"], "--depth must be between"),
    (["--simulated-resolutions", "0.5", "-1"], "--simulated-resolutions takes"),
])
def test_train_legs_bad_arguments_are_one_line(tmp_path, args, words):
    pytest.importorskip("sklearn", reason="scikit-learn is the [train] extra")
    pos = data_file("leigh/training/positive_2_extracted.bag")
    proc = run_cli("train-legs", "--positive", str(pos), "--negative", str(pos), "--output", "m.npz", *args,
                   cwd=tmp_path)
    assert proc.returncode == 2 and words in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_a_bad_legs_model_in_the_configuration_is_one_line(tmp_path):
    (tmp_path / "c.yaml").write_text("legs: {model: nowhere.npz}\n")
    proc = run_cli("run", "--config", "c.yaml", cwd=tmp_path)
    assert proc.returncode == 2 and "legs.model" in proc.stderr and "does not exist" in proc.stderr


def test_train_legs_defaults_are_the_fitting_code_s():
    # the parser is built without importing the training code (start-up time), so its
    # defaults are written out twice; they must stay the same
    import inspect

    from people_tracker.tracker import train_legs
    from people_tracker.tracker.cli import _build_parser

    args = _build_parser().parse_args(["train-legs", "--positive", "p.bag", "--negative", "n.bag", "--output", "m.npz"])
    assert tuple(args.simulated_resolutions) == train_legs.SIMULATED_RESOLUTIONS_DEG
    assert args.depth == inspect.signature(train_legs.fit).parameters["depth"].default
    assert args.trees == inspect.signature(train_legs.fit).parameters["n_trees"].default
