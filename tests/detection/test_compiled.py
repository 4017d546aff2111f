"""The compiled kernels (numba, the [fast] extra) give what their numpy twins give, to the bit.

Each kernel stands in for numpy code that stays the reference; here both run on the same
scans (simulated lasers of every kind the pipeline meets, and the real recordings) and
their outputs are compared byte for byte, negative zeros included, so the tracker's every
figure is the same whichever is installed. One exception: the sides of an object's box,
which shapely takes from corners GEOS intersects in double-double precision and the kernel
from the same calipers' distances, agree to 1e-12 m (the centroids to the bit).
"""

import logging
from pathlib import Path

import numpy as np
import pytest

from people_tracker.detection.deskew import deskew_with_source
from people_tracker.detection.leg_features import leg_candidates
from people_tracker.models import compiled
from people_tracker.models.compiled import beam_of
from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import beam_index
from people_tracker.models.scenario import build_simulation, load_scenario

pytestmark = pytest.mark.skipif(not compiled.ENABLED, reason="numba is not installed (the [fast] extra) "
                                "or PEOPLE_TRACKER_COMPILED=0: only the numpy path runs")

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "leigh"

LASERS = {  # every kind of laser: narrow and wide, clockwise, a full turn; lost readings as nan and as 0
    "narrow": {"fov_deg": 86, "resolution_deg": 0.35, "rate_hz": 10, "range_max": 5.6, "dropout": 0.01},
    "clockwise": {"fov_deg": 270, "resolution_deg": 0.5, "rate_hz": 12.5, "range_max": 29, "clockwise": True,
                  "dropout": 0.02, "dropout_value": "zero", "spurious": 0.005},
    "full_turn": {"fov_deg": 360, "resolution_deg": 1.0, "rate_hz": 10, "range_max": 12, "dropout": 0.02},
}


def _simulated(laser: dict, seconds: float = 6.0):
    spec = {**load_scenario("crowd"), "duration_s": seconds, "laser": {**load_scenario("crowd")["laser"], **laser}}
    sim, n = build_simulation(spec, crowd_count=12)
    return [sim.step().scan for _ in range(n)]


def _real(name: str, topic: str | None = None, limit: int = 300):
    path = DATA / name
    if not path.exists():
        pytest.skip(f"{path} not found: the real recordings live in ../shared/data")
    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.io.recording import Recording
    with Recording(path, topic, load_config().odometry) as rec:
        return [r.scan for r, _ in zip(rec.scans(), range(limit)) if r.scan is not None]


def _same(a, b, what: str) -> None:
    for field in ("first_beam", "last_beam", "start", "stop", "xy", "features"):
        x, y = getattr(a, field), getattr(b, field)
        assert x.dtype == y.dtype and x.shape == y.shape, f"{what}: {field} {x.dtype}{x.shape} vs {y.dtype}{y.shape}"
        assert x.tobytes() == y.tobytes(), f"{what}: {field} differs by up to {np.nanmax(np.abs(x - y))}"


def _agree(scans, what: str) -> int:
    found = 0
    for i, scan in enumerate(scans):
        fast = leg_candidates(scan)
        with compiled.numpy_only():
            ref = leg_candidates(scan)
        _same(fast, ref, f"{what} scan {i}")
        found += len(fast)
    return found


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_leg_features_agree_on_simulated_lasers(laser):
    assert _agree(_simulated(LASERS[laser]), laser) > 100


@pytest.mark.parametrize("name, topic", [("general_tracking_moving_1.bag", None),
                                         ("negative_2.bag", "/rear_scan"),
                                         ("training/positive_4_extracted.bag", None)])
def test_leg_features_agree_on_real_recordings(name, topic):
    assert _agree(_real(name, topic), name) > 100


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_deskew_agrees_on_simulated_lasers(laser):
    rng = np.random.default_rng(7)
    for scan in _simulated(LASERS[laser], seconds=2.0):
        first = Pose2D(*rng.uniform(-2, 2, 2), rng.uniform(-3, 3))
        last = first @ Pose2D(*rng.normal(0, 0.08, 2), rng.normal(0, 0.1))  # up to ~2 m/s and 6 rad/s a sweep
        fast, src = deskew_with_source(scan, first, last)
        with compiled.numpy_only():
            ref, ref_src = deskew_with_source(scan, first, last)
        assert src.tobytes() == ref_src.tobytes()
        assert fast.ranges.tobytes() == ref.ranges.tobytes() and fast.bearings.tobytes() == ref.bearings.tobytes()
        assert fast.angle_increment == ref.angle_increment
        # the scan the loop's arrays were handed to is what the constructor makes
        for name in ("angle_min", "range_min", "range_max", "stamp", "frame_id", "time_increment"):
            assert getattr(fast, name) == getattr(ref, name), name
        assert not fast.ranges.flags.writeable and not fast.bearings.flags.writeable
        # the properties the loop filled in are what the scan would compute
        seeded = {"valid", "valid_index", "no_return"} | ({"points", "valid_points"} if compiled.trig_is_numpys else set())
        assert seeded <= set(vars(fast))
        for name in seeded:
            assert getattr(fast, name).tobytes() == getattr(ref, name).tobytes(), name
            assert not getattr(fast, name).flags.writeable, name


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_leg_scores_and_line_normals_agree_on_simulated_lasers(laser):
    from people_tracker.detection.icp import line_normals
    from people_tracker.models.leg_model import load_leg_model
    model = load_leg_model()
    for scan in _simulated(LASERS[laser], seconds=2.0):
        feats = leg_candidates(scan).features
        fast, normals = model.log_odds(feats), line_normals(scan.valid_points, 0.2)
        with compiled.numpy_only():
            assert fast.tobytes() == model.log_odds(feats).tobytes()
            assert normals.tobytes() == line_normals(scan.valid_points, 0.2).tobytes()


def _places_around(laser: str, rng):
    """Each simulated scan of ``laser`` with a random sensor pose and 60 places around it
    (world frame; in view and not, near and far)."""
    for scan in _simulated(LASERS[laser], seconds=2.0):
        pose = Pose2D(*rng.uniform(-1, 1, 2), rng.uniform(-3, 3))
        yield scan, pose, pose.transform_points(rng.uniform(-8, 8, (60, 2)))


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_seen_through_agrees_on_simulated_lasers(laser):
    from people_tracker.detection.free_space import seen_through
    rng = np.random.default_rng(12)
    seen = 0
    for scan, pose, places in _places_around(laser, rng):
        moving = rng.random(scan.n_beams) < 0.3
        for margin, reach, mask in ((0.1, np.inf, None), (0.3, 3.0, moving), (0.0, 0.0, moving)):
            fast = seen_through(places, scan, pose, margin, mask, reach)
            with compiled.numpy_only():
                ref = seen_through(places, scan, pose, margin, mask, reach)
            assert fast.dtype == ref.dtype and fast.tobytes() == ref.tobytes()
            seen += int(ref.sum())
    assert seen > 100


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_place_visibility_agrees_on_simulated_lasers(laser):
    from people_tracker.detection.free_space import place_visibility
    codes = set()
    for scan, pose, places in _places_around(laser, np.random.default_rng(11)):
        for radius, reach in ((0.25, np.inf), (0.4, 3.0), (0.1, 0.0)):
            fast = place_visibility(places, scan, pose, radius, reach)
            with compiled.numpy_only():
                assert fast.tobytes() == place_visibility(places, scan, pose, radius, reach).tobytes()
            codes |= set(fast.tolist())
    assert codes == {0, 1, 2, 3}  # every outcome was compared


@pytest.mark.parametrize("laser", sorted(LASERS))
def test_static_support_agrees_on_simulated_lasers(laser):
    from people_tracker.tracker.static_support import static_support
    rng = np.random.default_rng(12)
    supported = 0
    for scan in _simulated(LASERS[laser], seconds=2.0):
        pose = Pose2D(*rng.uniform(-1, 1, 2), rng.uniform(-3, 3))
        pts = scan.valid_points
        near = pts[rng.integers(0, len(pts), 30)] + rng.normal(0.0, 0.2, (30, 2))  # beside readings, and not
        predictions = pose.transform_points(np.vstack([near, rng.uniform(-8, 8, (10, 2))]))
        masks = rng.random((2, scan.n_beams)) < np.array([[0.2], [0.7]])
        for explained, needed, leg_radius, width in ((None, None, 0.0, 0.0), (masks[0], None, 0.1, 0.15),
                                                     (None, masks[1], 0.06, 0.3), (masks[0], masks[1], 0.1, 0.0)):
            args = (predictions, pose, scan, 2.5, 0.1, 0.3, 0.8, 3, leg_radius, explained, needed)
            fast = static_support(*args, min_width_m=width)  # widths: counts of 3 near, 2 farther
            with compiled.numpy_only():
                ref = static_support(*args, min_width_m=width)
            assert [None if f is None else f.tobytes() for f in fast] == \
                [None if r is None else r.tobytes() for r in ref]
            supported += sum(f is not None for f in fast)
    assert supported > 100  # places were supported: the comparison means something


def _clouds(rng, n: int) -> list[np.ndarray]:
    """Point sets of every shape an object can take: leg arcs, blobs, straight and nearly
    straight lines, one point repeated, points on a 0.1 m grid (ties in x, y and area),
    slivers, single points and pairs."""
    out = []
    for k in range(n):
        m = int(rng.integers(1, 30))
        kind = k % 7
        if kind == 0:  # a leg's near side, as a laser sees it
            th = rng.uniform(-1.2, 1.2, m) + np.pi
            p = rng.uniform(0.5, 8, 2) + 0.06 * np.c_[np.cos(th), np.sin(th)] + rng.normal(0, 0.005, (m, 2))
        elif kind == 1:
            p = rng.normal(0, 0.05, (m, 2)) + rng.uniform(-6, 6, 2)
        elif kind == 2:  # on a line, up to rounding
            t = rng.uniform(0, 1, m)
            p = np.c_[t, 2 * t + 1]
        elif kind == 3:
            p = np.repeat(rng.uniform(-3, 3, (1, 2)), m, axis=0)
        elif kind == 4:
            p = rng.uniform(0, 1, (m, 2)).round(1)
        elif kind == 5:  # three readings nearly in a row: a sliver
            p = np.array([[0.0, 0.0], [1.0, 2.0], [0.5, 1.0 + rng.normal(0, 1e-12)]]) * 0.1 + rng.uniform(0, 5, 2)
        else:
            p = rng.uniform(-5, 5, (int(rng.integers(1, 3)), 2))
        out.append(p)
    return out


def test_hull_centroids_and_boxes_agree_with_shapely():
    from people_tracker.detection.objects import describe_all
    rng = np.random.default_rng(5)
    clouds = _clouds(rng, 3500)
    beams = [np.arange(len(c)) for c in clouds]
    fast = describe_all(0, beams, clouds, [(1,)] * len(clouds))
    with compiled.numpy_only():
        ref = describe_all(0, beams, clouds, [(1,)] * len(clouds))
    xy = np.array([(o.x, o.y) for o in fast]), np.array([(o.x, o.y) for o in ref])
    assert xy[0].tobytes() == xy[1].tobytes(), f"centroids differ by up to {np.abs(xy[0] - xy[1]).max()}"
    sides = np.array([(o.width, o.length) for o in fast]), np.array([(o.width, o.length) for o in ref])
    np.testing.assert_allclose(sides[0], sides[1], rtol=0, atol=1e-12)
    assert (sides[1][:, 0] > 0).sum() > 1000 and (sides[1][:, 0] == 0).sum() > 500  # boxes, lines and points


def test_near_any_agrees_with_the_distance_matrix():
    from people_tracker.models.pose import near_any
    rng = np.random.default_rng(8)
    near = 0
    for k in range(3000):
        a, b = rng.uniform(-5, 5, (int(rng.integers(0, 50)), 2)), rng.uniform(-5, 5, (int(rng.integers(0, 8)), 2))
        m = min(len(a), len(b))
        a[:m] = b[:m] + rng.normal(0, 0.3, (m, 2))
        radius = 0.5 if k % 4 == 0 else float(rng.uniform(0, 1))
        if k % 4 == 0 and m:
            a[0] = b[0] + [0.3, 0.4]  # on the radius: not near (strictly closer only)
        if k % 7 == 0 and m:
            a[-1, 0] = np.nan  # a lost reading: near nothing
        if k % 17 == 0 and m:
            b[-1, 1] = np.nan  # a person nowhere: numpy finds nobody near (the numpy path answers)
        fast = near_any(a, b, radius)
        with compiled.numpy_only():
            ref = near_any(a, b, radius)
        assert fast.tobytes() == ref.tobytes(), k
        near += int(fast.sum())
    assert near > 1000


def test_group_means_and_chords_agree():
    """The moving objects' means and end-to-end chords (the leg centres' input), and the
    static memory's object means: the compiled sums down the rows are numpy's."""
    from people_tracker.detection.segments import means_and_chords
    rng = np.random.default_rng(12)
    for k in range(500):
        groups = [rng.normal(size=(int(rng.integers(1, 300)), 2)) * rng.uniform(0.01, 30) + rng.uniform(-20, 20, 2)
                  for _ in range(int(rng.integers(1, 40)))]
        fast = means_and_chords(groups)
        with compiled.numpy_only():
            ref = means_and_chords(groups)
        assert fast[0].tobytes() == ref[0].tobytes() and fast[1].tobytes() == ref[1].tobytes(), k
    assert [a.shape for a in means_and_chords([])] == [(0, 2), (0,)]


def test_best_leg_within_a_radius_agrees():
    from people_tracker.models.pose import best_within
    rng = np.random.default_rng(10)
    found = 0
    for k in range(3000):
        places = rng.uniform(0, 3, (int(rng.integers(0, 20)), 2))
        legs = rng.uniform(0, 3, (int(rng.integers(0, 30)), 2))
        scores = rng.random(len(legs)).round(2)  # ties among the best
        radius = 0.5 if k % 3 == 0 else float(rng.uniform(0, 1))
        if k % 3 == 0 and len(places) and len(legs):
            places[0] = legs[0] + [0.3, 0.4]  # on the radius: within it
        if k % 11 == 0 and len(places):
            places[-1, 1] = np.nan  # nowhere: nothing within reach
        if k % 13 == 0 and len(scores):
            scores[0] = np.nan  # the numpy path answers
        fast = best_within(places, legs, scores, radius)
        with compiled.numpy_only():
            ref = best_within(places, legs, scores, radius)
        assert fast.tobytes() == ref.tobytes(), k
        found += int(np.isfinite(fast).sum())
    assert found > 5000


def test_stance_partners_agree():
    """Lone moving legs choosing standing partners: the compiled loop and the numpy code
    make the same choices, with several legs wanting the same partner, ties in distance and
    partners that must lie behind the leg as seen from the sensor."""
    from people_tracker.tracker.people_tracker import _stance_kernel, _stance_partner_choice
    rng = np.random.default_rng(9)
    paired = 0
    for k in range(2000):
        n_still, n_legs, n_tracks = int(rng.integers(1, 12)), int(rng.integers(1, 10)), int(rng.integers(1, 5))
        s_xy = rng.uniform(0, 2, (n_still, 2)).round(2 if k % 3 == 0 else 8)  # rounded: equal distances
        xy = rng.uniform(0, 2, (n_legs + 3, 2)).round(2 if k % 3 == 0 else 8)
        s_own = rng.integers(-1, n_tracks, n_still)
        leg = rng.permutation(len(xy))[:n_legs].astype(np.int64)
        walker_at = rng.integers(-2, n_tracks, n_legs)
        walker_xy = xy[leg] + rng.normal(0, 0.3, (n_legs, 2))
        behind = np.where(rng.random(n_still) < 0.5, -np.inf, 0.08)
        args = (s_xy, s_own, xy, leg, walker_at, walker_xy, 0.1, 0.9, behind, *rng.uniform(-1, 3, 2))
        fast, ref = _stance_kernel(*args), _stance_partner_choice(*args)
        assert fast[0].tobytes() == ref[0].tobytes() and fast[1].tobytes() == ref[1].tobytes(), k
        paired += int((fast[0] >= 0).sum())
    assert paired > 1000


def test_bearing_to_beam_agrees_with_beam_index():
    rng = np.random.default_rng(3)
    for n, inc in ((768, np.radians(0.35)), (811, -np.radians(1 / 3)), (1440, np.radians(0.25)),
                   (360, np.radians(1.0)), (541, -np.radians(0.5))):
        for amin in (-np.pi, -0.5 * n * abs(inc), 0.3, 0.9 * np.pi):
            amin = -amin if inc < 0 else amin
            grid = amin + inc * np.arange(-3, n + 3)  # every beam, the edges, and half-way between
            bearing = np.concatenate([rng.uniform(-7, 7, 500), grid, grid + 0.5 * inc])
            got = np.array([beam_of(b, amin, inc, n) for b in bearing])
            assert np.array_equal(got, beam_index(bearing, amin, inc, n)), (n, inc, amin)


def test_numpy_only_switches_the_kernels_off_and_back():
    assert compiled.on
    with compiled.numpy_only():
        assert not compiled.on
    assert compiled.on


def _trace(steps) -> tuple[list[bytes], list[np.ndarray]]:
    """What the tracker gives, scan by scan, as bytes: labels, leg features, objects, the
    world pose, candidates and reported tracks; and apart, the objects' box sides (m)."""
    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.people_tracker import PeopleTracker
    tracker, out, sides = PeopleTracker.from_config(load_config()), [], []
    for scan, pose, pose_last in steps:
        tracks = tracker.step(scan, pose, pose_last)
        last = tracker.last
        out.append(b"".join([
            last.detection.labels.tobytes(), last.legs.features.tobytes(), last.leg_scores.tobytes(),
            np.array([(o.x, o.y) for o in last.detection.objects]).tobytes(),
            np.array([last.pose.x, last.pose.y, last.pose.yaw]).tobytes(),
            np.array([(c.x, c.y) for c in [*last.candidates, *last.standing]]).tobytes(),
            np.array([(t.track_id, t.x, t.y, t.vx, t.vy, t.confidence) for t in tracks]).tobytes()]))
        sides.append(np.array([(o.width, o.length) for o in last.detection.objects]).reshape(-1, 2))
    return out, sides


def _tracker_agrees(steps, what: str) -> None:
    fast, fast_sides = _trace(steps)
    with compiled.numpy_only():
        ref, ref_sides = _trace(steps)
    first = next((i for i, (a, b) in enumerate(zip(fast, ref)) if a != b), None)
    assert first is None, f"{what}: the tracker's outputs differ from scan {first} on"
    for i, (a, b) in enumerate(zip(fast_sides, ref_sides)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12, err_msg=f"{what}: box sides, scan {i}")


@pytest.mark.parametrize("scene, laser", [("crowd", None), ("follow_outdoor", "long_cw")])
def test_the_tracker_gives_the_same_with_and_without_kernels_on_simulated_scenes(scene, laser):
    spec = {**load_scenario(scene), "duration_s": 20.0}
    sim, n = build_simulation(spec, laser=laser) if laser else build_simulation(spec)
    steps = []
    for _ in range(n):
        st = sim.step()
        steps.append((st.scan, st.odom_pose @ sim.mount if sim.has_odometry else None, None))
    _tracker_agrees(steps, scene)


def test_the_tracker_gives_the_same_with_and_without_kernels_on_the_real_recording():
    path = DATA / "general_tracking_moving_1.bag"
    if not path.exists():
        pytest.skip(f"{path} not found: the real recordings live in ../shared/data")
    from people_tracker.tracker.config import load_config
    from people_tracker.tracker.io.recording import Recording
    with Recording(path, None, load_config().odometry) as rec:
        steps = [(r.scan, r.pose, r.pose_last_beam) for r, _ in zip(rec.scans(), range(400)) if r.scan is not None]
    _tracker_agrees(steps, path.name)


def test_the_warm_up_reaches_every_kernel(tmp_path):
    """What a live node runs before its first scan loads every kernel: none is left to
    compile (or load) on a scan. In a fresh interpreter, so nothing else loaded them, and
    with an empty cache, so every kernel is compiled and :func:`compiled.uncompiled` (the
    command line's first-run note) counts them all before and none after."""
    import os
    import subprocess
    import sys
    code = ("from people_tracker.tracker.people_tracker import warm_up_kernels\n"
            "from people_tracker.models import compiled\n"
            "before = compiled.uncompiled()\n"
            "warm_up_kernels()\n"
            "print(len(compiled.KERNELS), before, compiled.uncompiled(), "
            "[k.py_func.__qualname__ for k in compiled.KERNELS if not k.signatures])\n")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=env).stdout.split(" ", 3)
    assert int(out[0]) >= 8 and out[3].strip() == "[]", out
    assert int(out[1]) == int(out[0]) and int(out[2]) == 0, out


def test_the_command_line_says_when_it_compiles(monkeypatch, caplog):
    from people_tracker.tracker.cli import note_first_compile
    log = logging.getLogger("test")
    monkeypatch.setattr(compiled, "uncompiled", lambda: 0)
    with caplog.at_level(logging.WARNING):
        note_first_compile(log, terminal=True)
    assert not caplog.records  # compiled before: nothing to say
    monkeypatch.setattr(compiled, "uncompiled", lambda: 3)
    with caplog.at_level(logging.WARNING):
        note_first_compile(log, terminal=False)
    assert not caplog.records  # stderr read by a script: no notes
    with caplog.at_level(logging.WARNING):
        note_first_compile(log, terminal=True)
    assert len(caplog.records) == 1 and "compiling" in caplog.records[0].getMessage()


def test_track_filter_steps_agree():
    """The track filter's predict and update (the state and its covariance) to the bit, over
    long runs of random steps, steps of zero and tiny measurement noise included."""
    from people_tracker.models.motion import constant_velocity_Q, cv_predict, position_update
    rng = np.random.default_rng(14)
    for k in range(300):
        x = rng.normal(0, [5, 1.5, 5, 1.5])
        A = rng.normal(size=(4, 4)) * 10.0 ** rng.uniform(-3, 0.5, 4)
        P = A @ A.T + np.diag(10.0 ** rng.uniform(-6, 0, 4))
        for step in range(20):
            dt = float(rng.choice([0.0, 0.0133, 0.0667, 0.1, 0.45, 2.0]))
            Q = constant_velocity_Q(dt, float(rng.uniform(0.1, 4.0)))
            fast = cv_predict(x, P, dt, Q)
            with compiled.numpy_only():
                ref = cv_predict(x, P, dt, Q)
            assert all(a.tobytes() == b.tobytes() for a, b in zip(fast, ref)), f"predict {k}.{step}"
            x, P = ref
            z = x[::2] + rng.normal(0, 0.3, 2)
            c = rng.uniform(-0.5, 0.5) * 1e-3
            R = np.array([[rng.uniform(1e-6, 0.05), c], [c, rng.uniform(1e-6, 0.05)]])
            fast = position_update(x, P, z, R)
            with compiled.numpy_only():
                ref = position_update(x, P, z, R)
            assert all(a.tobytes() == b.tobytes() for a, b in zip(fast, ref)), f"update {k}.{step}"
            x, P = ref


def test_the_scan_matchers_step_is_the_same_compiled_and_in_python():
    """The Gauss-Newton step of one ICP iteration (a 3x3 eigen-decomposition written out):
    the same bits from the compiled helper as from Python, degenerate scenes included."""
    from people_tracker.detection.icp import _solve_step
    rng = np.random.default_rng(15)
    degenerate = 0
    for k in range(3000):
        A = rng.normal(size=(int(rng.integers(3, 60)), 3)) * rng.uniform(0.01, 10, 3)
        if k % 3 == 0:
            A[:, 0] = A[:, 1] * rng.uniform(0.5, 2)  # a corridor: one direction unconstrained
        if k % 17 == 0:
            A[:, 2] = 0.0  # nothing constrains the rotation
        H = A.T @ A
        g = A.T @ rng.normal(0, 0.05, len(A))
        args = (H[0, 0], H[0, 1], H[0, 2], H[1, 1], H[1, 2], H[2, 2], *g, float(rng.uniform(0.5, 8)), 0.06)
        fast, ref = _solve_step(*args), _solve_step.py_func(*args)
        assert np.array(fast).tobytes() == np.array(ref).tobytes(), k
        degenerate += ref[4]
    assert 500 < degenerate < 3000


def test_run_bounds_agree():
    """The segments' boundaries (by gaps, and by gaps and labels), lost readings' nan
    thresholds, ties on the threshold and single readings included."""
    from people_tracker.detection.segments import run_bounds
    rng = np.random.default_rng(16)
    cuts = 0
    for k in range(2000):
        n = int(rng.integers(1, 200))
        pts = np.cumsum(rng.normal(0, 0.05, (n, 2)), axis=0)
        gap = rng.uniform(0.01, 0.1, n)
        if k % 5 == 0 and n > 1:
            gap[1] = np.hypot(*(pts[1] - pts[0]))  # a step exactly on its threshold: a cut
        if k % 7 == 0:
            gap[rng.integers(0, n)] = np.nan
        labels = rng.integers(0, 3, n).astype(np.int8)
        for lab in (None, labels):
            fast = run_bounds(pts, gap, lab)
            with compiled.numpy_only():
                ref = run_bounds(pts, gap, lab)
            assert fast.dtype == ref.dtype and fast.tobytes() == ref.tobytes(), k
            cuts += len(fast) - 2
    assert cuts > 10000


def test_the_detectors_lookbacks_agree():
    """The kept scans the static memory and the free-space tests look back to: the same
    choice compiled as in numpy, ties (the oldest of equally near ones), scans without a
    pose and lookbacks longer than the history included."""
    from collections import deque

    from people_tracker.detection.detector import MovingObjectDetector
    rng = np.random.default_rng(17)
    chosen = 0
    for k in range(3000):
        det = MovingObjectDetector()
        n = int(rng.integers(1, 50))
        stamps = np.sort(rng.uniform(0, 3, n)).round(1 if k % 2 else 6)  # rounded: ties
        det._history = deque(object() for _ in range(n))
        det._stamps, det._posed = stamps, rng.random(n) < 0.8
        stamp = float(stamps[-1] + rng.uniform(0, 0.2))
        lookbacks = tuple(rng.uniform(0.05, 4.0, int(rng.integers(1, 4))).round(1))
        for need_pose in (False, True):
            fast = det._lookback(stamp, lookbacks, need_pose)
            with compiled.numpy_only():
                ref = det._lookback(stamp, lookbacks, need_pose)
            assert [id(o) for o in fast] == [id(o) for o in ref], k
            chosen += len(ref)
    assert chosen > 5000


def test_recovering_objects_agrees():
    """Algorithms 2 and 3 (joins by the closest pair of ends first, the extent limit, the
    noise seeds, the single-object case) compiled and on Segment lists, over random
    labellings of random scans; ties of gaps and lost readings' nan thresholds included."""
    from people_tracker.detection.recover import recover_from_bounds
    from people_tracker.detection.segments import run_bounds
    rng = np.random.default_rng(18)
    joined = moving = single = 0
    for k in range(3000):
        n = int(rng.integers(0, 150))
        pts = np.cumsum(rng.normal(0, 0.04, (n, 2)), axis=0)
        if k % 4 == 0 and n:
            pts = pts.round(2)  # equal gaps: the first in beam order wins
        gap = rng.uniform(0.02, 0.12, n)
        if k % 7 == 0 and n:
            gap[rng.integers(0, n)] = np.nan
        labels = rng.choice([1, 2, 3, 4], n, p=[0.5, 0.1, 0.3, 0.1] if k % 3 else [0.6, 0.0, 0.3, 0.1]).astype(np.int8)
        bounds = run_bounds(pts, gap, labels) if n else np.zeros(1, np.int64)
        need = rng.integers(1, 5, n).astype(np.int64)  # readings an object needs, per reading (thresholds.readings_needed)
        seed_need = rng.integers(1, 4, n).astype(np.int64)
        args = (bounds, labels, pts, gap, seed_need, need, float(rng.uniform(0.3, 2)),
                int(rng.integers(0, 3)))
        fast = recover_from_bounds(*args)
        with compiled.numpy_only():
            ref = recover_from_bounds(*args)
        assert fast == ref, k
        joined += sum(len(s.sets) > 1 for s in ref)
        moving += any(s.label == 2 for s in ref)
        single += any(s.label == 3 for s in ref)
    assert joined > 1000 and moving > 500 and single > 100, (joined, moving, single)


def test_combining_the_comparisons_agrees():
    from people_tracker.detection.detector import combine
    rng = np.random.default_rng(19)
    for k in range(500):
        n = int(rng.integers(0, 800))
        pairs = [rng.integers(0, 5, n).astype(np.int8) for _ in range(int(rng.integers(1, 4)))]
        pairs[1:] = [np.where(pairs[0] == 0, 0, p).astype(np.int8) for p in pairs[1:]]  # invalid in every pair alike
        fast = combine(pairs)
        with compiled.numpy_only():
            ref = combine(pairs)
        assert fast.dtype == ref.dtype and fast.tobytes() == ref.tobytes(), k


def test_the_nearest_earlier_scans_agree():
    """The scans each comparison's Δt picks (the first of equally near ones), as np.argmin."""
    from collections import deque

    from people_tracker.detection.detector import DetectorParams, MovingObjectDetector
    rng = np.random.default_rng(20)
    for k in range(2000):
        n = int(rng.integers(1, 40))
        det = MovingObjectDetector(DetectorParams(compare_dt_s=tuple(rng.uniform(0.02, 1.0, int(rng.integers(1, 4))))))
        det._history = deque(object() for _ in range(n))
        det._stamps = np.sort(rng.uniform(0, 2, n)).round(1 if k % 2 else 6)  # rounded: ties
        stamp = float(det._stamps[-1] + rng.uniform(0, 0.2))
        fast = det._earlier(stamp)
        with compiled.numpy_only():
            ref = det._earlier(stamp)
        assert [id(o) for o in fast] == [id(o) for o in ref], k


def test_the_static_memorys_span_helpers_agree():
    """The readings of a run of objects, each object's share of flagged readings, and the
    occluded runs isolated_occluded keeps: compiled and in numpy."""
    from people_tracker.detection.detector import _share_per_span, _span_readings
    from people_tracker.detection.labels import OCCLUDED
    from people_tracker.detection.recover import isolated_from_bounds, isolated_occluded
    from people_tracker.detection.segments import Segment, run_bounds
    rng = np.random.default_rng(21)
    kept = 0
    for k in range(2000):
        sizes = rng.integers(1, 30, int(rng.integers(1, 8)))
        starts = np.cumsum(np.r_[0, sizes[:-1]]) + rng.integers(0, 3, len(sizes)).cumsum()
        flags = rng.random(int(sizes.sum())) < rng.uniform(0, 1)
        fast = (_span_readings(starts, sizes), _share_per_span(flags, sizes))
        with compiled.numpy_only():
            idx, share = _span_readings(starts, sizes), _share_per_span(flags, sizes)
        assert fast[0].tobytes() == idx.tobytes() and fast[1].tobytes() == share.tobytes(), k
        n = int(rng.integers(2, 120))
        pts = np.cumsum(rng.normal(0, 0.05, (n, 2)), axis=0) + [2.0, 0.0]
        ranges = np.hypot(pts[:, 0], pts[:, 1]) + np.where(rng.random(n) < 0.3, rng.uniform(0, 1, n), 0.0)
        gap = rng.uniform(0.02, 0.12, n)
        labels = rng.choice([1, 2, 3, 4], n, p=[0.3, 0.2, 0.4, 0.1]).astype(np.int8)
        bounds = run_bounds(pts, gap, labels)
        need, extent = rng.integers(1, 5, n).astype(np.int64), float(rng.uniform(0.1, 1.0))
        fast = isolated_from_bounds(bounds, labels, pts, ranges, gap, need, extent)
        with compiled.numpy_only():
            assert isolated_from_bounds(bounds, labels, pts, ranges, gap, need, extent) == fast, k
        big = [Segment(int(s), int(e), OCCLUDED, (OCCLUDED,)) for s, e in zip(bounds[:-1], bounds[1:])
               if labels[s] == OCCLUDED and e - s >= max(need[s], need[e - 1])]
        ref = isolated_occluded(big, pts, ranges, gap, need, extent)
        assert fast == ref, k
        kept += len(ref)
    assert kept > 300


def test_distances_leg_centres_and_touching_agree():
    from people_tracker.detection.leg_features import LegCandidates
    from people_tracker.models.pose import pairwise_distances
    from people_tracker.tracker.pairing import leg_centres
    rng = np.random.default_rng(22)
    touched = 0
    for k in range(1000):
        a, b = rng.normal(0, 5, (int(rng.integers(0, 20)), 2)), rng.normal(0, 5, (int(rng.integers(0, 20)), 2))
        widths = np.abs(rng.normal(0, 0.2, len(a)))
        if k % 5 == 0 and len(a):
            a[0, 1], widths[-1] = np.nan, np.nan
        if k % 7 == 0 and len(a):
            a[-1] = 0.0  # at the sensor: the direction's floor
        n_beams = int(rng.integers(1, 100))
        first = np.sort(rng.integers(0, n_beams, 6))
        last = np.minimum(first + rng.integers(0, 5, 6), n_beams - 1)
        legs = LegCandidates(first, last, first, last + 1, np.zeros((6, 2)), np.zeros((6, 1)))
        mask = rng.random(n_beams) < 0.05
        fast = (pairwise_distances(a, b), leg_centres(a, widths, 0.08), legs.touching(mask))
        with compiled.numpy_only():
            ref = (pairwise_distances(a, b), leg_centres(a, widths, 0.08), legs.touching(mask))
        for f, r in zip(fast, ref):
            assert f.shape == r.shape and f.tobytes() == r.tobytes(), k
        touched += int(ref[2].sum())
    assert touched > 200


def _cache_paths(tmp_path: Path, **env: str) -> list[str]:
    """Where a fresh process keeps every kernel's cache, and numba's CACHE_DIR after the
    import (last line), with the environment ``env`` and without NUMBA_CACHE_DIR otherwise."""
    import os
    import subprocess
    import sys
    clean = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    code = ("import numba, people_tracker.tracker.people_tracker, people_tracker.detection.icp\n"
            "from people_tracker.models import compiled\n"
            "print('\\n'.join(k._cache.cache_path for k in compiled.KERNELS))\n"
            "print(repr(numba.config.CACHE_DIR))\n")
    out = subprocess.run([sys.executable, "-c", code], env={**clean, **env}, cwd=tmp_path,
                         capture_output=True, text=True, check=True).stdout.splitlines()
    assert len(out) > 10, out
    return out


def test_kernels_are_cached_in_the_users_cache_folder_not_beside_the_modules(tmp_path):
    """Files numba writes beside the installed modules outlive ``pip uninstall``, and their
    folder turns people_tracker into a namespace package over a later editable install."""
    *paths, config_after = _cache_paths(tmp_path, XDG_CACHE_HOME=str(tmp_path / "xdg"))
    package = Path(compiled.__file__).resolve().parents[1]
    for p in paths:
        assert Path(p).is_relative_to(tmp_path / "xdg" / "people-tracker" / "numba"), p
        assert not Path(p).is_relative_to(package), p
    assert config_after == "''", "numba's own cache setting is left as it was"


def test_numba_cache_dir_set_by_the_user_wins(tmp_path):
    *paths, config_after = _cache_paths(tmp_path, XDG_CACHE_HOME=str(tmp_path / "xdg"),
                                        NUMBA_CACHE_DIR=str(tmp_path / "mine"))
    assert all(Path(p).is_relative_to(tmp_path / "mine") for p in paths), paths[:3]
    assert config_after == repr(str(tmp_path / "mine"))
