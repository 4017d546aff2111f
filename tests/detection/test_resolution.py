"""The detector's minimum sizes are widths in metres, not counts of readings: a coarser laser
keeps the same objects (detector.min_object_width_m, min_seed_width_m)."""

import math

import numpy as np
import pytest

from people_tracker.detection.detector import DetectorParams, MovingObjectDetector
from people_tracker.detection.thresholds import enough_readings, readings_needed
from people_tracker.models.scenario import build_simulation, load_scenario


def test_readings_needed_is_what_a_width_shows_between_the_bounds():
    ranges = np.array([1.0, 4.0, 8.0, 30.0])
    # 0.33° (5.8 mm a metre): 0.15 m shows 25, 6, 3 and 0 readings there; at most 3, at least 2
    assert readings_needed(ranges, math.radians(0.33), 0.15, 3).tolist() == [3, 3, 3, 2]
    # 1° (17.5 mm a metre): 8, 2, 1, 0
    assert readings_needed(ranges, math.radians(1.0), 0.15, 3).tolist() == [3, 2, 2, 2]
    assert readings_needed(ranges, math.radians(1.0), 0.1, 2, least=1).tolist() == [2, 1, 1, 1]
    assert readings_needed(ranges, math.radians(1.0), 0.0, 3).tolist() == [3, 3, 3, 3]  # 0: the plain count
    assert readings_needed(ranges, math.radians(1.0), 0.15, 1).tolist() == [1, 1, 1, 1]  # never above the most
    assert readings_needed(np.array([0.0, np.inf]), math.radians(1.0), 0.15, 3).tolist() == [3, 2]


def test_a_run_needs_what_its_nearer_end_asks_whichever_way_the_beams_count():
    need = np.array([3, 3, 2, 2, 2])
    assert not enough_readings(need, 1, 3)  # 2 readings, its nearer end asks 3
    assert enough_readings(need, 2, 4)
    assert enough_readings(need[::-1], 1, 3) == enough_readings(need, 2, 4)


def _walkers_found(resolution_deg: float, params: DetectorParams) -> float:
    """Of the scans in which a walker of the crossing scene shows two readings or more, the
    share in which a detected object covers one of them."""
    spec = load_scenario("crossing")
    spec = {**spec, "laser": {**spec["laser"], "resolution_deg": resolution_deg}, "duration_s": 12}
    sim, n = build_simulation(spec)
    det = MovingObjectDetector(params)
    seen = found = 0
    for i in range(n):
        step = sim.step()
        cover = {b for o in det.detect(step.scan).objects for b in o.beams.tolist()}
        if i < 5:
            continue
        for pid in (1, 2):
            on = set(np.flatnonzero((step.truth.beam_person == pid) & step.scan.valid).tolist())
            if len(on) >= 2:
                seen += 1
                found += bool(on & cover)
    return found / seen


@pytest.mark.parametrize("resolution_deg", [0.5, 1.0])
def test_walkers_3_m_away_are_found_on_a_coarse_laser(resolution_deg):
    """Two people walk 3 m in front of the laser (the crossing scene; at 1° a leg there shows
    two readings). The widths find them in most scans; the paper's plain counts (3 readings,
    2 for a seed) lose most of them at 1°."""
    found = _walkers_found(resolution_deg, DetectorParams())
    counted = _walkers_found(resolution_deg, DetectorParams(min_object_width_m=0.0, min_seed_width_m=0.0))
    assert found >= 0.8, found
    assert found > counted
    if resolution_deg == 1.0:
        assert counted < 0.6, counted
