"""Scenes keep their promises over any duration (checked from the walkers' own paths,
without rendering)."""

from __future__ import annotations

import numpy as np

from people_tracker.models.scenario import build_simulation, load_scenario


def test_a_long_crowd_keeps_wandering_to_the_end():
    spec = {**load_scenario("crowd"), "duration_s": 1200}
    sim, _ = build_simulation(spec)
    moved = [np.hypot(*(w.torso(1180.0) - w.torso(1120.0))) > 1.0 for w in sim.walkers]
    assert np.mean(moved) > 0.8  # in the last minute of 20, nearly everyone is on the move
    short, _ = build_simulation(load_scenario("crowd"))  # a 30 s crowd is the same as it always was
    assert [len(w.waypoints) for w in short.walkers] == [8] * 30
