"""The nearest-neighbour search gives the same answers from the compiled grid and either library."""

import os
import subprocess
import sys
from itertools import islice

import numpy as np
import pytest

from people_tracker.detection import kdtree
from people_tracker.detection.kdtree import PointTree
from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.recording import Recording
from people_tracker.tracker.people_tracker import PeopleTracker

needs_both = pytest.mark.skipif(len(kdtree.BACKENDS) < 2,
                                reason="neither pykdtree nor numba is installed: only scipy's tree to compare")
needs_grid = pytest.mark.skipif("grid" not in kdtree.BACKENDS, reason="numba is not installed (the [fast] extra): no grid")


def test_an_empty_tree_finds_nothing():
    d, i = PointTree(np.zeros((0, 2))).query(np.array([[1.0, 2.0]]), 5.0)
    assert d.tolist() == [np.inf] and i.tolist() == [0]


def test_the_bound_is_exclusive_and_a_miss_points_past_the_end():
    for backend in kdtree.BACKENDS:
        tree = PointTree(np.array([[0.0, 0.0], [1.0, 0.0]]), backend)
        d, i = tree.query(np.array([[0.5, 0.0], [0.9, 0.0]]), 0.5)
        assert d[0] == np.inf and i[0] == 2 and d[1] == pytest.approx(0.1) and i[1] == 1


def test_an_uninstalled_backend_is_one_clear_error():
    with pytest.raises(ValueError, match="not installed"):
        PointTree(np.zeros((3, 2)), "flann")


def _scans(bag, n):
    cfg = load_config()
    with Recording(bag, None, cfg.odometry) as rec:
        return cfg, [(r.scan, r.pose, r.pose_last_beam) for r in islice(rec.scans(), n) if r.scan is not None]


def _agree(ref, query, bounds=(0.02, 0.05, 0.3, 1.0, np.inf)):
    """Every installed backend gives scipy's distances and indices, bit for bit."""
    for bound in bounds:
        slow = PointTree(ref, "scipy").query(query, bound)
        for backend in kdtree.BACKENDS:
            fast = PointTree(ref, backend).query(query, bound)
            np.testing.assert_array_equal(fast[0], slow[0], err_msg=f"{backend}, bound {bound}")
            np.testing.assert_array_equal(fast[1], slow[1], err_msg=f"{backend}, bound {bound}")


@needs_both
def test_every_backend_agrees_on_real_scans(moving_bag):
    _, scans = _scans(moving_bag, 60)
    rng = np.random.default_rng(3)
    for (a, _, _), (b, _, _) in zip(scans, scans[5:]):
        _agree(a.valid_points, b.valid_points + 0.01)
        _agree(a.valid_points, b.valid_points + rng.normal(0.0, 0.1, b.valid_points.shape))


@needs_grid
def test_the_grid_agrees_where_its_cells_are_odd():
    rng = np.random.default_rng(4)
    far = rng.uniform(-500.0, 500.0, size=(300, 2))  # a wide extent: cells grow past 0.1 m
    line = np.column_stack([np.linspace(0.0, 30.0, 400), np.full(400, 2.0)])  # one row of cells
    one = np.array([[1.0, -1.0]])
    same = np.repeat(one, 5, axis=0)  # every point in one place: ties go to the lowest index
    queries = np.vstack([rng.uniform(-50.0, 50.0, size=(200, 2)), [[1e6, -1e6], [1.0, -1.0]]])  # in, far out
    for ref in (far, line, one, same):
        _agree(ref, queries)
    d, i = PointTree(same, "grid").query(np.array([[1.0, -1.0], [np.nan, 0.0], [0.0, np.inf]]), 1.0)
    assert d.tolist() == [0.0, np.inf, np.inf] and i.tolist() == [0, 5, 5]  # nothing is near no place


def _within_agrees(ref, query, radius):
    """``within`` answers what ``query`` and a comparison answer, on every backend, with a
    strict and an inclusive bound."""
    for backend in kdtree.BACKENDS:
        tree = PointTree(ref, backend)
        d, _ = tree.query(query, float(radius.max()))
        np.testing.assert_array_equal(tree.within(query, radius), d < radius, err_msg=backend)
        np.testing.assert_array_equal(tree.within(query, radius, inclusive=True), d <= radius, err_msg=backend)


def test_within_a_radius_is_the_nearest_distance_compared(moving_bag):
    _, scans = _scans(moving_bag, 40)
    rng = np.random.default_rng(6)
    hits = 0
    for (a, _, _), (b, _, _) in zip(scans, scans[3:]):
        q = b.valid_points + rng.normal(0.0, 0.05, b.valid_points.shape)
        radius = rng.uniform(0.0, 0.15, len(q))
        _within_agrees(a.valid_points, q, radius)
        hits += int(PointTree(a.valid_points).within(q, radius).sum())
    assert hits > 1000
    # on the radius exactly, the largest radius (the search's bound) included; nowhere; and
    # a tree of one place many times
    ref = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]])
    q = np.array([[0.5, 0.0], [1.25, 0.0], [3.0, 0.0], [1.0, 0.1]])
    _within_agrees(ref, q, np.array([0.5, 0.25, 1.0, 0.1]))
    _within_agrees(ref, q, np.array([0.5, 0.5, 1.0, 0.1]))
    _within_agrees(ref, q, np.array([0.5, 0.5, 0.5, 0.1]))
    assert PointTree(ref).within(q, np.array([0.5, 0.5, 0.5, 0.1]), inclusive=True).tolist() == \
        [False, True, False, True]  # 0.5 away at the search's bound 0.5: not found, as the search
    assert PointTree(ref).within(np.array([[np.nan, 0.0]]), np.array([1.0])).tolist() == [False]
    assert PointTree(np.zeros((0, 2))).within(q, np.full(4, 1.0)).tolist() == [False] * 4


@needs_both
def test_the_tracker_reports_the_same_people_with_every_backend(moving_bag, monkeypatch):
    cfg, scans = _scans(moving_bag, 300)
    runs, every = [], kdtree.BACKENDS
    for k in range(len(every)):  # the default first, then without it, and so on
        monkeypatch.setattr(kdtree, "BACKENDS", every[k:])
        tracker = PeopleTracker.from_config(cfg)
        runs.append([[(t.track_id, t.x, t.y, t.status) for t in tracker.step(*s)] for s in scans])
    assert sum(map(len, runs[0])) > 50  # people were reported: the comparison means something
    assert all(run == runs[0] for run in runs[1:])


_THREADS = """
import os, numpy as np
from people_tracker.detection.kdtree import BACKENDS, PointTree
tree = PointTree(np.random.default_rng(0).uniform(size=(500, 2)), "pykdtree")
before = len(os.listdir("/proc/self/task"))
for _ in range(200):
    tree.query(np.random.default_rng(1).uniform(size=(300, 2)), 0.1)
print("pykdtree" in BACKENDS, before, len(os.listdir("/proc/self/task")), os.environ.get("OMP_NUM_THREADS"))
"""


@pytest.mark.skipif(not os.path.isdir("/proc/self/task") or "pykdtree" not in kdtree.BACKENDS,
                    reason="needs Linux's /proc and pykdtree")
@pytest.mark.parametrize("omp", [None, "2"])
def test_queries_start_no_threads_and_leave_the_environment_alone(omp, tmp_path):
    # OpenMP workers would spin between queries, keeping a second core busy
    env = {k: v for k, v in os.environ.items() if k != "OMP_NUM_THREADS"}
    if omp:
        env["OMP_NUM_THREADS"] = omp
    # away from the checkout, whose people_tracker/ folder would shadow the installed package
    out = subprocess.run([sys.executable, "-c", _THREADS], env=env, capture_output=True, text=True, check=True,
                         cwd=tmp_path)
    backend, before, after, left = out.stdout.split()
    assert backend == "True" and after == before and left == str(omp)
