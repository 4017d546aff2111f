"""The detector's stages one by one, on hand-made inputs."""

import math
from contextlib import nullcontext

import numpy as np
import pytest

from people_tracker.detection.closest import closest_point_static
from people_tracker.detection.detector import DetectorParams, MovingObjectDetector, combine, label_pair
from people_tracker.detection.kdtree import BACKENDS, PointTree
from people_tracker.detection.labels import INVALID, MOVING, OCCLUDED, OUT_OF_VIEW, STATIC
from people_tracker.detection.objects import describe, describe_all, recovered_name
from people_tracker.detection.recover import join, recover_moving
from people_tracker.detection.scan_lines import bin_to_beams, scan_line_labels
from people_tracker.detection.segments import Segment, split_runs
from people_tracker.detection.thresholds import range_threshold
from people_tracker.models import compiled
from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan


def test_threshold_grows_with_range_and_resolution_and_has_a_floor():
    thr = range_threshold(np.array([0.1, 2.0, 4.0]), math.radians(0.5), k=4.0, floor=0.02)
    assert thr[0] == 0.02
    assert thr[2] == pytest.approx(2 * thr[1]) and thr[1] == pytest.approx(4 * math.tan(math.radians(0.25)) * 2)


@pytest.mark.parametrize("backend", BACKENDS)
def test_closest_points_are_static_both_ways(backend):
    c = np.array([[1.0, 0.0], [2.0, 0.0], [5.0, 5.0]])
    p = np.array([[1.01, 0.0], [2.2, 0.0]])
    # both scans in one frame here: each tree queried with the other scan's points
    sc, sp = closest_point_static(PointTree(c, backend), p, np.full(2, 0.05), PointTree(p, backend), c, np.full(3, 0.05))
    assert sc.tolist() == [True, False, False] and sp.tolist() == [True, False]


@pytest.mark.parametrize("inc", [math.radians(1), -math.radians(1)])
def test_binning_to_beams_follows_the_scan_direction(inc):
    amin = -math.pi / 2 if inc > 0 else math.pi / 2
    pts = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, -1.0], [-1.0, 0.0]])
    idx = bin_to_beams(pts, amin, inc, 181)
    straight, left, right = (90, 180, 0) if inc > 0 else (90, 0, 180)
    assert idx.tolist() == [straight, left, right, -1]


def test_algorithm1_nearer_is_moving_farther_is_occluded_and_unseen_is_out_of_view():
    beam_c = np.array([10, 11, 12, 50])
    range_c = np.array([2.0, 5.0, 3.0, 4.0])
    beam_p = np.array([10, 11, 12])
    range_p = np.array([4.0, 3.0, 3.0])
    lc, lp = scan_line_labels(beam_c, range_c, beam_p, range_p, 100, window=1)
    assert lc.tolist() == [MOVING, OCCLUDED, OCCLUDED, OUT_OF_VIEW]
    # O_P behind M_C; M_P in front of O_C; equal ranges pair nothing
    assert lp.tolist() == [OCCLUDED, MOVING, OUT_OF_VIEW]


def test_algorithm1_falls_back_to_static_previous_readings_on_the_line_of_sight():
    # no B_P at all (everything previous was static): an object in front of the wall is moving
    lc, _ = scan_line_labels(np.array([5, 6]), np.array([2.0, 9.0]), np.zeros(0, int), np.zeros(0), 20, 1,
                             beam_all=np.array([5, 6]), range_all=np.array([8.0, 8.0]))
    assert lc.tolist() == [MOVING, OCCLUDED]


def test_segments_split_on_label_change_and_on_gaps():
    labels = np.array([STATIC, STATIC, MOVING, MOVING, MOVING, STATIC])
    pts = np.array([[0, 0], [0, 0.05], [0, 0.1], [0, 0.15], [0, 0.5], [0, 0.55]], dtype=float)
    runs = split_runs(labels, pts, np.full(6, 0.1))
    assert [(r.start, r.stop, r.label) for r in runs] == [(0, 2, STATIC), (2, 4, MOVING), (4, 5, MOVING), (5, 6, STATIC)]


def test_join_absorbs_close_neighbours_once_and_respects_the_size_limit():
    pts = np.column_stack([np.zeros(10), np.arange(10) * 0.05])
    thr = np.full(10, 0.08)
    runs = [Segment(0, 3, STATIC, (STATIC,)), Segment(3, 6, MOVING, (MOVING,)), Segment(6, 10, OCCLUDED, (OCCLUDED,))]
    assert join(runs, MOVING, STATIC, pts, thr, max_extent=5.0)
    assert [(r.start, r.stop, r.label) for r in runs] == [(0, 6, MOVING), (6, 10, OCCLUDED)]
    assert not join(runs, MOVING, STATIC, pts, thr, max_extent=5.0)
    runs2 = [Segment(0, 3, MOVING, (MOVING,)), Segment(3, 10, STATIC, (STATIC,))]
    assert not join(runs2, MOVING, STATIC, pts, thr, max_extent=0.2)  # would be 0.45 m long


def test_algorithm3_replaces_only_under_the_single_object_condition():
    pts = np.column_stack([np.zeros(12), np.arange(12) * 0.05])
    thr = np.full(12, 0.01)  # nothing joins
    one_o = [Segment(0, 6, STATIC, (STATIC,)), Segment(6, 10, OCCLUDED, (OCCLUDED,))]
    need = np.full(12, 3)  # readings an object needs (thresholds.readings_needed)
    assert [(r.start, r.stop) for r in recover_moving(one_o, pts, thr, need - 1, need, 1.0, 1)] == [(6, 10)]
    two_o = [Segment(0, 4, OCCLUDED, (OCCLUDED,)), Segment(4, 6, STATIC, (STATIC,)), Segment(6, 10, OCCLUDED, (OCCLUDED,))]
    assert recover_moving(two_o, pts, thr, need - 1, need, 1.0, 1) == []


def test_describe_gives_hull_centroid_and_a_rectangle_with_width_below_length():
    ang = np.linspace(-np.pi / 2, np.pi / 2, 9)
    pts = np.column_stack([2.0 - 0.1 * np.cos(ang), 0.1 * np.sin(ang)])  # the near half of a leg
    o = describe(7, np.arange(20, 29), pts, (MOVING, STATIC))
    assert o.first_beam == 20 and o.last_beam == 28 and o.n_points == 9 and o.recovered_from == "M+A"
    assert o.width <= o.length and o.length == pytest.approx(0.2, abs=1e-6) and o.width == pytest.approx(0.1, abs=1e-6)
    assert 1.9 < o.x < 1.96 and abs(o.y) < 1e-9
    line = describe(8, np.arange(3), np.array([[1.0, 0], [1.0, 0.1], [1.0, 0.2]]), (OCCLUDED,))
    assert line.width == 0.0 and line.length == pytest.approx(0.2) and line.recovered_from == "O"


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("kernels", [True, False])
def test_describe_is_quiet_and_finite_on_an_object_nanometres_across(kernels):
    """Readings of 1e-209 m (a driver whose range_min is 0): GEOS's rectangle divides by a
    side that underflows; the box is still a point-sized one and nothing is printed."""
    pts = np.array([[4.55e-209, 6.83e-210], [6.32e-6, 7.75e-6], [1.11e-218, 1.52e-218],
                    [-4.24e-39, 1.10e-38], [-5.03e-13, 8.64e-13]])
    with (nullcontext() if kernels else compiled.numpy_only()):
        o = describe_all(0, [np.arange(5)], [pts], [(MOVING,)])[0]
    assert all(np.isfinite([o.x, o.y, o.width, o.length]))
    assert o.width <= o.length < 2e-5 and 0 <= o.x < 1e-5


def test_recovered_names():
    assert recovered_name((MOVING,)) == "M" and recovered_name((OCCLUDED, MOVING, STATIC)) == "M+A+O"


def test_combining_comparisons_prefers_motion():
    a = np.array([INVALID, STATIC, STATIC, OUT_OF_VIEW, STATIC])
    b = np.array([INVALID, MOVING, STATIC, OUT_OF_VIEW, OCCLUDED])
    assert combine([a, b]).tolist() == [INVALID, MOVING, STATIC, OUT_OF_VIEW, OCCLUDED]


def _wall_scan(stamp, blob_at=None, n=181):
    ang = np.radians(np.linspace(-90, 90, n))
    r = np.full(n, 5.0) / np.maximum(np.cos(ang), 0.2)  # a wall at x = 5 (clipped at the sides)
    if blob_at is not None:
        r[blob_at - 3: blob_at + 4] = 2.0
    return Scan(r, ang[0], ang[1] - ang[0], 0.05, 30.0, stamp=stamp)


def test_a_moving_sensor_uses_the_pose_and_a_still_wall_stays_static():
    # the sensor moves 0.5 m towards the wall between scans: without the pose the wall looks moving
    s0 = _wall_scan(0.0)
    ang = s0.angles
    r1 = np.full(181, 4.5) / np.maximum(np.cos(ang), 0.2 * 5.0 / 4.5)
    s1 = Scan(r1, s0.angle_min, s0.angle_increment, 0.05, 30.0, stamp=0.1)
    params = DetectorParams(compare_dt_s=(0.1,))
    with_pose = label_pair(s1, s0, Pose2D(0.5, 0, 0).between(Pose2D(0, 0, 0)), params)
    assert (with_pose[40:140] == STATIC).all()
    without = label_pair(s1, s0, Pose2D(), params)
    assert (without[40:140] == MOVING).mean() > 0.9


def test_detector_finds_an_object_that_appears_and_keeps_history_by_time():
    det = MovingObjectDetector(DetectorParams(compare_dt_s=(0.1,)))
    assert det.detect(_wall_scan(0.0)).objects == []
    d = det.detect(_wall_scan(0.1, blob_at=90))
    assert len(d.objects) == 1 and d.objects[0].first_beam == 87 and d.objects[0].last_beam == 93
    assert d.objects[0].x == pytest.approx(2.0, abs=0.05) and d.compared_dt_s == pytest.approx((0.1,))
    det.reset()
    assert det.detect(_wall_scan(0.2, blob_at=90)).compared_dt_s == ()



def test_lookbacks_take_the_nearest_kept_scan_oldest_first_each_once():
    """``_lookback``: per lookback, of the kept scans at least half that long ago (with a
    pose when asked), the one nearest ``stamp - lookback``, the oldest of equally near
    ones; a scan chosen once. Checked against the plain loop over the history on random
    ones, and on one by hand (stamps in eighths of a second: exact in binary)."""
    def reference(history, stamp, lookbacks, need_pose):
        out = []
        for lookback in lookbacks:
            best = None
            for past in history:
                age = stamp - past.scan.stamp
                if age >= 0.5 * lookback and (past.pose is not None or not need_pose) and (
                        best is None or abs(age - lookback) < abs(stamp - best.scan.stamp - lookback)):
                    best = past
            if best is not None and all(best is not o for o in out):
                out.append(best)
        return out

    det = MovingObjectDetector(DetectorParams(compare_dt_s=(0.125,)))
    for k, t in enumerate((0.0, 0.125, 0.25, 0.375, 0.625, 0.875, 1.0)):
        det.detect(_wall_scan(t), Pose2D() if k != 5 else None)
    stamps = [p.scan.stamp for p in det._lookback(1.0, (0.25, 0.5, 0.625), need_pose=False)]
    assert stamps == [0.625, 0.375]  # 0.25: 0.125 s and 0.375 s ago tie, the older; 0.5 too; 0.625: taken
    assert [p.scan.stamp for p in det._lookback(1.0, (0.125,), need_pose=False)] == [0.875]
    assert [p.scan.stamp for p in det._lookback(1.0, (0.125,), need_pose=True)] == [0.625]  # 0.875 has no pose
    assert det._lookback(1.0, (5.0,), need_pose=False) == []
    rng = np.random.default_rng(5)
    for _ in range(20):
        det = MovingObjectDetector(DetectorParams(compare_dt_s=(0.1,)))
        t = 0.0
        for _ in range(rng.integers(1, 40)):
            t += float(rng.choice([0.05, 0.1, 0.1, 0.2]))
            det.detect(_wall_scan(t), Pose2D() if rng.random() < 0.8 else None)
        for need_pose in (False, True):
            lookbacks = tuple(rng.uniform(0.05, 2.0, size=3))
            got = det._lookback(t + 0.1, lookbacks, need_pose)
            want = reference(det._history, t + 0.1, lookbacks, need_pose)
            assert len(got) == len(want) and all(a is b for a, b in zip(got, want))
    det.reset()
    assert det._lookback(1.0, (0.25,), need_pose=False) == []


def test_free_space_sees_through_empty_places_only():
    from people_tracker.detection.free_space import seen_through
    ranges = np.array([5.0, np.inf, np.nan, 2.0, 2.0, 0.0])
    scan = Scan(ranges, -0.25, 0.1, 0.05, 10.0, stamp=0.0)  # beams at -0.25 … 0.25 rad
    pose = Pose2D(1.0, 0.0, 0.0)  # the sensor 1 m along x in the world
    ang = scan.angles
    pts = np.column_stack([1.0 + 3.0 * np.cos(ang), 3.0 * np.sin(ang)])  # 3 m out along each beam
    moving = np.array([False, False, False, True, False, False])
    free = seen_through(pts, scan, pose, 0.3, moving)
    # beyond (5 m), no return (inf), lost (nan: unknown), blocked by a moving reading,
    # blocked by a static one, lost (0: unknown)
    assert free.tolist() == [True, True, False, True, False, False]
    behind = seen_through(np.array([[-5.0, 0.0]]), scan, pose, 0.3)  # outside the field of view
    assert behind.tolist() == [False]


def test_a_flickering_post_is_static_clutter_but_a_walker_is_not():
    """A thin post that returns a reading only now and then looks newly arrived each time it
    does; the static memory remembers its place from ~0.9-1.5 s earlier and drops it. A blob
    that moves 8 beams (~28 cm at 2 m) a scan is never where it was that long ago and is kept."""
    params = DetectorParams(compare_dt_s=(0.1,))
    post = MovingObjectDetector(params)
    seen_post = []
    for k in range(25):
        visible = k >= 3 and k % 3 == 0  # the post's beams return a reading one scan in three
        d = post.detect(_wall_scan(0.1 * k, blob_at=90 if visible else None))
        if visible:
            seen_post.append(len(d.objects))
    assert seen_post[0] == 1  # first sighting: nothing to remember
    assert seen_post[-5:] == [0] * 5  # once the memory reaches back to a sighting it has it
    walker = MovingObjectDetector(params)
    seen_walker = [len(walker.detect(_wall_scan(0.1 * k, blob_at=20 + 8 * k)).objects) for k in range(19)]
    assert seen_walker[1:] == [1] * 18
    off = MovingObjectDetector(DetectorParams(compare_dt_s=(0.1,), static_memory_k=0.0))
    counts = [len(off.detect(_wall_scan(0.1 * k, blob_at=90 if k >= 3 and k % 3 == 0 else None)).objects)
              for k in range(25)]
    assert counts[-1] == 1  # with the memory off the paper's detector flags it every time


def test_static_memory_keeps_objects_near_a_tracked_person():
    params = DetectorParams(compare_dt_s=(0.1,))
    det = MovingObjectDetector(params)
    for k in range(24):
        det.detect(_wall_scan(0.1 * k, blob_at=90 if k % 3 == 0 else None))
    person = np.array([[2.0, 0.3]])  # 0.3 m from the blob, sensor frame
    assert len(det.detect(_wall_scan(2.4, blob_at=90), people=person).objects) == 1


def test_a_post_a_walker_uncovers_is_not_moving_beside_them():
    """A walker at 2.6 m passes in front of a post at 3 m (a wall at 5 m behind both, a
    0.25 deg laser). As they step off its beams the post's readings lie farther than the
    walker's a scan before: occluded readings, a free-standing object, as a walker moving
    away is. The static memory saw the post there a second before; beside the walker's
    track (0.44 m) it is still dropped, while the walker (moving readings) is kept."""
    n = 721
    ang = np.radians(np.linspace(-90, 90, n))

    def scan(k):
        r = np.full(n, 5.0) / np.maximum(np.cos(ang), 0.2)
        r[400:408] = 3.0  # the post, 0.1 m across
        c = 240 + 12 * k  # the walker, 0.26 m across, 1.4 m/s
        r[c - 11:c + 12] = 2.6
        return Scan(r, ang[0], ang[1] - ang[0], 0.05, 30.0, stamp=0.1 * k), c

    def last_objects(with_people):
        det = MovingObjectDetector(DetectorParams(compare_dt_s=(0.1,)))
        for k in range(16):  # the last scan uncovers the post (the walker on beams 409-431)
            s, c = scan(k)
            walker = 2.6 * np.array([[math.cos(ang[c]), math.sin(ang[c])]])
            found = det.detect(s, people=walker if with_people else None).objects
        return found, walker

    post = 3.0 * np.array([math.cos(ang[404]), math.sin(ang[404])])
    for with_people in (False, True):
        found, walker = last_objects(with_people)
        assert np.hypot(*(walker[0] - post)) < DetectorParams().static_memory_keep_m
        assert [o.recovered_from for o in found] == ["M+A"]  # the walker only
        assert np.hypot(found[0].x - walker[0, 0], found[0].y - walker[0, 1]) < 0.15


def test_beside_a_person_only_what_stood_still_is_remembered():
    """Beside a tracked person, an object of occluded readings is dropped only where the
    scans a second before saw something still: where someone else walked through then
    (moving readings), it is kept; where a post stood, it is dropped. Away from people,
    anything seen there counts, as before."""
    n = 721
    ang = np.radians(np.linspace(-90, 90, n))

    def scan(k, walker=None, post=False):
        r = np.full(n, 5.0) / np.maximum(np.cos(ang), 0.2)
        if post:
            r[400:408] = 3.0
        if walker is not None:
            r[walker - 11:walker + 12] = 3.0
        return Scan(r, ang[0], ang[1] - ang[0], 0.05, 30.0, stamp=0.1 * k)

    span = [(400, 408)]  # every reading is valid: valid index = beam
    person = 3.0 * np.array([[math.cos(ang[440]), math.sin(ang[440])]])  # 0.5 m from the object
    for post in (False, True):
        det = MovingObjectDetector(DetectorParams())  # compared 0.15 and 0.45 s back
        for k in range(15):  # a walker (1.6 m/s) crosses beams 400-408 at k = 6, 0.9 s before the last scan
            det.detect(scan(k, walker=404 + 12 * (k - 6), post=post), Pose2D())
        now = scan(15, post=True)
        now_pts, now_r = now.valid_points, now.ranges[now.valid_index]

        def keep(**kw):
            return bool(det._static_memory(now, Pose2D(), span, now_pts, now_r, **kw)[0])

        assert keep(people=person, moving=[False]) is not post
        assert keep(people=person, moving=[True])  # moving readings beside a person: kept
        assert not keep(people=None)  # away from people whatever was there counts


def test_no_return_counts_as_seen_through_only_when_asked():
    ang = np.radians(np.linspace(-90, 90, 181))
    far = Scan(np.full(181, np.inf), ang[0], ang[1] - ang[0], 0.05, 10.0, stamp=0.0)  # nothing in range
    r = np.full(181, np.inf)
    r[88:93] = 2.0
    now = Scan(r, ang[0], ang[1] - ang[0], 0.05, 10.0, stamp=0.1)
    off = label_pair(now, far, Pose2D(), DetectorParams())
    assert (off[88:93] == OUT_OF_VIEW).all()
    on = label_pair(now, far, Pose2D(), DetectorParams(no_return_free_m=5.0))
    assert (on[88:93] == MOVING).all()
    short = label_pair(now, far, Pose2D(), DetectorParams(no_return_free_m=1.5))  # trusted only to 1.5 m
    assert (short[88:93] == OCCLUDED).all()


def test_only_no_return_runs_that_open_onto_free_space_count_as_seen_through():
    # a wall 2 m away with two patches that return nothing: a narrow one (3 beams, 1.5 deg:
    # a dropout at 3 m is 8 cm wide) and a wide dark one (20 beams) with the wall on both
    # sides; beyond the wall's end, nothing in range (an open field)
    ang = np.radians(np.linspace(-90, 90, 361))
    r = np.full(361, 2.0)
    r[100:103] = np.inf
    r[150:170] = np.inf
    r[250:] = np.inf
    before = Scan(r, ang[0], ang[1] - ang[0], 0.05, 10.0, stamp=0.0)
    open_ = before.open_no_return(3.0)
    assert not open_[100:103].any()  # narrower than a leg at 3 m: a dropout
    assert not open_[150:170].any()  # the wall returns on both sides: a dark patch of it
    assert open_[250:].all()  # a line of sight into the open (no reading beyond it)
    assert before.open_no_return(0.0)[150:170].all()  # trusted nowhere: the mask does not matter
    clockwise = Scan(r, ang[-1], ang[0] - ang[1], 0.05, 10.0, stamp=0.0)  # the same beams, swept the other way
    assert (clockwise.open_no_return(3.0) == open_).all()
    # something now on the dark patch is not seen arriving; someone stepping into the open is
    now = r.copy()
    now[155:165] = 1.5
    now[280:290] = 1.5
    labels = label_pair(Scan(now, ang[0], ang[1] - ang[0], 0.05, 10.0, stamp=0.1), before, Pose2D(),
                        DetectorParams(no_return_free_m=3.0))
    assert not (labels[155:165] == MOVING).any()
    assert (labels[280:290] == MOVING).all()


def test_deskew_keeps_no_return_beams():
    from people_tracker.detection.deskew import deskew
    r = np.full(181, 4.0)
    r[100:120] = np.inf
    ang = np.radians(np.linspace(-90, 90, 181))
    s = Scan(r, ang[0], ang[1] - ang[0], 0.05, 10.0, stamp=0.0, time_increment=1e-4)
    out = deskew(s, Pose2D(), Pose2D(0.02, 0.0, 0.0))
    assert np.isposinf(out.ranges[102:118]).all() and out.no_return[102:118].all()
    assert not out.no_return[:90].any()
