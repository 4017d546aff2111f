"""Leg candidates, their shape features and the leg model's probabilities."""

import math

import numpy as np
import pytest

from people_tracker.detection.leg_features import FEATURES, leg_candidates
from people_tracker.models.leg_model import LegModelError, load_leg_model
from people_tracker.models.scenario import build_simulation

LASER = {"fov_deg": 270, "resolution_deg": 0.35, "rate_hz": 10, "range_max": 20, "noise_std": 0.0}
PILLARS = [[2.0, -0.5, 0.06],    # a leg in the open
           [2.0, -0.2, 0.06],    # its partner
           [4.90, 2.0, 0.06],    # leg-sized but against the wall (x = 5)
           [2.0, 2.0, 0.01],     # a thin post
           [2.5, -3.0, 0.30],    # a pillar
           [3.0, 1.0, 0.025],    # two table legs
           [3.0, 1.6, 0.025]]


def _scan(pillars=PILLARS, **laser):
    sim, _ = build_simulation({"duration_s": 1, "laser": {**LASER, **laser},
                               "world": {"room": [-1, -6, 5, 6], "pillars": pillars}})
    return sim.step().scan


def _near(xy, target, tol=0.08):
    return np.hypot(*(xy - target).T) < tol


def test_free_standing_legs_score_high_and_furniture_low():
    c = leg_candidates(_scan())
    p = load_leg_model().probability(c.features)
    assert c.features.shape == (len(c), len(FEATURES)) and np.isfinite(c.features).all()
    legs = _near(c.xy, [1.96, -0.49]) | _near(c.xy, [1.96, -0.2])  # readings' mean: the near side
    assert legs.sum() == 2 and (p[legs] > 0.5).all()
    assert (p[~legs] < 0.1).all()  # table legs, the post, the pillar, the leg against the wall


def test_features_do_not_depend_on_the_beam_order():
    a, b = leg_candidates(_scan()), leg_candidates(_scan(clockwise=True))
    order_a, order_b = np.lexsort(a.xy.T), np.lexsort(b.xy.T)
    np.testing.assert_allclose(a.xy[order_a], b.xy[order_b], atol=1e-9)
    np.testing.assert_allclose(a.features[order_a], b.features[order_b], atol=1e-9)


def test_features_with_lost_readings_do_not_depend_on_the_beam_order():
    """Where the reading beside a candidate is lost and both its neighbours are real, the
    nearer is taken, whichever way the laser sweeps (a clockwise laser took the other one
    and scored a leg 0.31 that a counter-clockwise one scored 0.80)."""
    import dataclasses

    scan = _scan()
    ranges = scan.ranges.copy()
    ranges[1::3] = np.nan  # every third reading lost
    ccw = dataclasses.replace(scan, ranges=ranges)
    cw = dataclasses.replace(scan, ranges=ranges[::-1].copy(), angle_increment=-scan.angle_increment,
                             angle_min=scan.angle_min + (scan.n_beams - 1) * scan.angle_increment)
    a, b = leg_candidates(ccw), leg_candidates(cw)
    order_a, order_b = np.lexsort(a.xy.T), np.lexsort(b.xy.T)
    assert len(a) >= 2
    np.testing.assert_allclose(a.xy[order_a], b.xy[order_b], atol=1e-9)
    np.testing.assert_allclose(a.features[order_a], b.features[order_b], atol=1e-9)


@pytest.mark.parametrize("resolution_deg", [0.25, 0.5, 1.0])
def test_a_leg_is_found_at_other_resolutions(resolution_deg):
    c = leg_candidates(_scan(resolution_deg=resolution_deg))
    p = load_leg_model().probability(c.features)
    near = _near(c.xy, [1.96, -0.49], 0.1) | _near(c.xy, [1.96, -0.2], 0.1)
    assert near.sum() == 2 and (p[near] > 0.2).all(), p[near]


def test_a_scan_with_no_valid_reading_has_no_candidates():
    scan = _scan(range_max=0.5)
    assert scan.n_valid == 0
    c = leg_candidates(scan)
    assert len(c) == 0 and c.features.shape == (0, len(FEATURES))
    assert load_leg_model().probability(c.features).shape == (0,)


def test_the_shipped_model_is_a_calibrated_probability():
    m = load_leg_model()
    assert m.feature_names == FEATURES
    assert (np.diff(m.calib_raw) >= 0).all() and (np.diff(m.calib_p) >= -1e-12).all()
    assert 0.0 <= m.calib_p.min() and m.calib_p.max() <= 1.0
    assert "trained_on" in m.meta and any("positive_1" in t for t in m.meta["trained_on"])


def test_bad_model_files_are_named(tmp_path):
    with pytest.raises(LegModelError, match="does not exist"):
        load_leg_model(tmp_path / "none.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a model")
    with pytest.raises(LegModelError, match="cannot be read"):
        load_leg_model(tmp_path / "junk.npz")


def test_the_numpy_ensemble_scores_exactly_as_scikit_learn():
    pytest.importorskip("sklearn", reason="scikit-learn is the [train] extra")
    from sklearn.ensemble import HistGradientBoostingClassifier

    from people_tracker.tracker.train_legs import fit

    rng = np.random.default_rng(0)
    x = rng.normal(size=(3000, len(FEATURES)))
    y = (x[:, 0] + np.sin(3 * x[:, 1]) + 0.5 * x[:, 2] * x[:, 3] > 0.3).astype(float)
    groups = np.arange(len(y)) % 5
    model = fit(x, y, groups, n_trees=40, depth=3)
    clf = HistGradientBoostingClassifier(max_iter=40, max_depth=3, learning_rate=0.1, early_stopping=False,
                                         random_state=0).fit(x, y)
    np.testing.assert_allclose(model.log_odds(x), clf.decision_function(x), atol=1e-9)
    p = model.probability(x)
    assert ((p > 0.5) == (y == 1)).mean() > 0.9 and p.min() >= 0 and p.max() <= 1
    assert math.isfinite(model.init)
