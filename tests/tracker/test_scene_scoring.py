"""The scene-scoring helpers of ``benchmarks/track_evidence.py``: which ids each person was given,
when a person's id changed, and when someone visible went untracked."""

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from track_evidence import SceneRun, id_changes, ids_per_person, untracked_spells  # noqa: E402


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


def test_spells_in_which_someone_visible_had_no_track():
    run = _run()
    assert untracked_spells(run, min_s=0.0) == ["  person 1 untracked 0.2-0.2 s (1 visible scans)"]
    assert untracked_spells(run, min_s=0.1) == []  # shorter than asked
    run.rows = run.rows[run.rows[:, 0] >= 3]  # nothing on them in scans 0-2 ...
    run.truths[1].visible = np.array([False])  # ... hidden in scan 1: two spells
    assert untracked_spells(run, min_s=0.0) == ["  person 1 untracked 0.0-0.0 s (1 visible scans)",
                                                "  person 1 untracked 0.2-0.2 s (1 visible scans)"]
    run.truths[1].visible = np.array([True])
    assert untracked_spells(run, min_s=0.2) == ["  person 1 untracked 0.0-0.2 s (3 visible scans)"]
    run.rows = run.rows[:0]  # never tracked: the spell runs to the end
    assert untracked_spells(run, min_s=0.0) == ["  person 1 untracked 0.0-0.4 s (5 visible scans)"]
