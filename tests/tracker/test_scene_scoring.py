"""The scene-scoring helpers of ``benchmarks/track_evidence.py``: which ids each person was given,
and when a person's id changed."""

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from track_evidence import SceneRun, id_changes, ids_per_person  # noqa: E402


def _run():
    """Person 1 stands at (1, 0) for five scans, 0.1 s apart. Track 7 is on them in scans 0
    and 1; nothing is reported in scan 2; from scan 3 on, track 9 is on them, and in scan 3
    track 7 is still reported, 1 m beside them."""
    truths = [SimpleNamespace(person_id=np.array([1]), torso_sensor=np.array([[1.0, 0.0]]),
                              visible=np.array([True])) for _ in range(5)]
    rows = np.array([[0, 7, 1.0, 0.0, 0.9], [1, 7, 1.05, 0.0, 0.9],
                     [3, 9, 1.0, 0.02, 0.9], [3, 7, 1.0, 1.0, 0.9], [4, 9, 1.0, 0.0, 0.9]])
    return SceneRun("test", None, np.arange(5) * 0.1, rows, truths)


def test_a_persons_ids_and_where_they_changed():
    run = _run()
    assert ids_per_person(run) == {1: {7, 9}}  # track 7 beside them in scan 3 is not paired with them
    assert id_changes(run) == ["  person 1 at 0.3 s: id 7 -> 9 (7 theirs 0.2 s before; still reported, 1.00 m from them)"]


def test_a_person_who_keeps_their_id_has_no_change():
    run = _run()
    run.rows[:, 1] = 7
    run.rows = run.rows[[0, 1, 2, 4]]  # one track on them throughout
    assert ids_per_person(run) == {1: {7}} and id_changes(run) == []
