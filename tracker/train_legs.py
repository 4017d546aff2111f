"""Fit the leg model to labelled recordings: ``people-tracker train-legs``.

Positives are candidates (:func:`people_tracker.detection.leg_features.leg_candidates`) matched to a
labelled leg: each label in a ``geometry_msgs/PoseArray`` topic (Leigh et al.'s
``/leg_cluster_positions``, sensor frame) takes the nearest candidate within
``match_radius_m``, one each. Without labels, a box on the floor (``--box``, sensor frame)
where only people's legs appeared makes every candidate inside it a positive, as Leigh et
al.'s extraction does. Negatives are every candidate of recordings where nobody is.
Candidates of a labelled scan that match no label are left out (they may be people
outside the labelled area).

Labelled legs are recorded in one place (Leigh et al.'s stand beyond a doorway), so what
surrounds them is the same in every example, and a model learns the place with the legs:
trained on them alone it found 2 % of the same legs moved into another room, and no
simulated ones. Each labelled scan's legs are therefore also pasted, with their real
readings, into two empty rooms of the negative recordings (:func:`transplant`), where the
room lies behind them.

Recorded legs come from a few people in one place; ``--simulated`` scans of randomised
furnished rooms with people (:func:`simulated_rooms`, every leg known, so every other
candidate is a negative) show the model other leg sizes, rooms and lasers. The
calibration map is fitted on the recorded examples alone, so the share of legs it learns
is the recordings'.

Every scan is also used at every 2nd and every 3rd beam (each offset), so the model learns
what a leg looks like to coarser lasers and needs no retraining for them. The ensemble
(scikit-learn's ``GradientBoostingClassifier``) is calibrated with an isotonic map fitted
to out-of-fold scores, the folds grouped by recording and topic, so no recording is scored
by a model that saw it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from people_tracker.detection.leg_features import FEATURES, leg_candidates
from people_tracker.models.leg_model import LegModel
from people_tracker.models.scan import Scan
from people_tracker.tracker.errors import InputError, require

LABEL_TOPIC = "/leg_cluster_positions"
POSE_ARRAY = "geometry_msgs/msg/PoseArray"
DECIMATIONS = ((1, 0), (2, 0), (2, 1), (3, 0), (3, 1), (3, 2))  # (every k-th beam, from beam)
SIMULATED_RESOLUTIONS_DEG = (0.25, 0.35, 0.5, 0.75)  # the simulated rooms' lasers, degrees between beams
BLOCKS = 5  # each recording is cut into this many stretches of time; a fold leaves whole stretches out


@dataclass(frozen=True, eq=False)
class LabelledScan:
    """A scan and the legs labelled in it (sensor frame, metres, shape (m, 2)), or the box
    (x0, y0, x1, y1) inside which every candidate is a leg. ``complete``: every leg of the
    scan is labelled (a simulated one), so the other candidates are not legs."""

    scan: Scan
    legs: np.ndarray | None = None
    box: tuple[float, float, float, float] | None = None
    complete: bool = False


def decimate(scan: Scan, every: int, offset: int = 0) -> Scan:
    """The scan a laser with ``every`` times the angular step would have given (its beams
    ``offset``, ``offset + every``, ...)."""
    if every == 1:
        return scan
    return Scan(scan.ranges[offset::every], scan.angle_min + offset * scan.angle_increment,
                scan.angle_increment * every, scan.range_min, scan.range_max, scan.stamp, scan.frame_id,
                scan.time_increment * every)


def _odometry_none():
    from people_tracker.tracker.config import load_config

    return dataclasses.replace(load_config().odometry, source="none")


def read_scans(path: str | Path, topic: str | None = None) -> list[tuple[int, Scan]]:
    """Every usable scan of a LaserScan topic with its bag time (ns)."""
    from people_tracker.tracker.io.recording import Recording

    with Recording(path, topic, _odometry_none()) as rec:
        return [(r.bag_time, r.scan) for r in rec.scans() if r.problem is None and r.scan.n_valid]


def laser_topics(path: str | Path) -> list[str]:
    from people_tracker.tracker.io.bag import LASER_SCAN, open_bag, topics_of_type

    reader = open_bag(path)
    try:
        return topics_of_type(reader, LASER_SCAN)
    finally:
        reader.close()


def read_labelled(path: str | Path, topic: str | None = None, label_topic: str = LABEL_TOPIC,
                  box: tuple[float, float, float, float] | None = None) -> list[LabelledScan]:
    """The scans of a recording with their labelled legs (each label message goes to the
    scan nearest in bag time), or with ``box`` when there are no labels."""
    from people_tracker.tracker.io.bag import connections_of, open_bag, select_topic

    scans = read_scans(path, topic)
    if box is not None:
        return [LabelledScan(s, box=box) for _, s in scans]
    reader = open_bag(path)
    try:
        name = select_topic(reader, label_topic, POSE_ARRAY, "PoseArray", "--label-topic")
        labels = []
        for conn, t, raw in reader.messages(connections_of(reader, name)):
            msg = reader.deserialize(raw, conn.msgtype)
            labels.append((t, np.array([(p.position.x, p.position.y) for p in msg.poses], dtype=float).reshape(-1, 2)))
    finally:
        reader.close()
    if not scans:
        return []
    times = np.array([t for t, _ in scans])
    out: dict[int, list[np.ndarray]] = {}
    for t, xy in labels:
        out.setdefault(int(np.argmin(np.abs(times - t))), []).append(xy)
    return [LabelledScan(scans[k][1], np.vstack(v)) for k, v in sorted(out.items())]


def match(candidates_xy: np.ndarray, legs: np.ndarray, radius_m: float) -> tuple[np.ndarray, np.ndarray]:
    """One-to-one matching of labelled legs to candidates within ``radius_m``: a mask of the
    candidates matched, and for each leg whether it was."""
    hit_c = np.zeros(len(candidates_xy), dtype=bool)
    hit_l = np.zeros(len(legs), dtype=bool)
    if len(candidates_xy) and len(legs):
        d = np.hypot(legs[:, None, 0] - candidates_xy[None, :, 0], legs[:, None, 1] - candidates_xy[None, :, 1])
        rows, cols = linear_sum_assignment(np.where(d <= radius_m, d, 1e6))
        ok = d[rows, cols] <= radius_m
        hit_l[rows[ok]] = True
        hit_c[cols[ok]] = True
    return hit_c, hit_l


def transplant(item: LabelledScan, room: Scan, rng: np.random.Generator, match_radius_m: float = 0.15,
               clearance_m: float = 0.3, tries: int = 30) -> LabelledScan | None:
    """The labelled legs of ``item`` (the readings of the candidates matched to its labels)
    pasted into ``room``, an empty scan of a laser with the same beams: turned about the
    sensor by a whole number of beams, at their own ranges, to a place where the room's
    readings lie at least ``clearance_m`` behind them (a person stands in front of what is
    behind them). None where the lasers differ or no such place was found.

    Recordings of labelled legs are made in one place (Leigh et al.'s: beyond a doorway),
    so what surrounds their legs is the same in every example; pasted into many rooms, the
    legs keep their real shape and lose that sameness."""
    scan = item.scan
    if (item.legs is None or not len(item.legs) or room.n_beams != scan.n_beams
            or abs(room.angle_increment - scan.angle_increment) > 1e-9):
        return None
    c = leg_candidates(scan)
    hit, _ = match(c.xy, item.legs, match_radius_m)
    if not hit.any():
        return None
    beams = np.concatenate([np.arange(a, b + 1) for a, b in zip(c.first_beam[hit], c.last_beam[hit])])
    beams = beams[scan.valid[beams]]
    r = scan.ranges[beams]
    n = scan.n_beams
    for _ in range(tries):
        shift = int(rng.integers(-beams.min(), n - beams.max()))
        target = beams + shift
        behind = room.ranges[target]
        free = room.no_return[target] | ~room.valid[target] | (behind > r + clearance_m)
        if free.all():
            ranges = np.array(room.ranges)
            ranges[target] = r
            turn = shift * scan.angle_increment
            c_, s_ = np.cos(turn), np.sin(turn)
            legs = item.legs @ np.array([[c_, s_], [-s_, c_]])  # each label turned by the same angle
            return LabelledScan(Scan(ranges, room.angle_min, room.angle_increment, room.range_min, room.range_max,
                                     room.stamp, room.frame_id, room.time_increment), legs)
    return None


def transplanted(labelled: list[list[LabelledScan]], rooms: list[list[Scan]], per_scan: int = 2,
                 seed: int = 0) -> list[list[LabelledScan]]:
    """Each labelled scan's legs pasted into ``per_scan`` empty rooms drawn at random (see
    :func:`transplant`), one list per recording; scans whose legs fit no room are left out."""
    rng = np.random.default_rng(seed)
    pool = [s for recording in rooms for s in recording]
    out = []
    for recording in labelled:
        moved = []
        for item in recording:
            for _ in range(per_scan if pool else 0):
                t = transplant(item, pool[int(rng.integers(len(pool)))], rng)
                if t is not None:
                    moved.append(t)
        out.append(moved)
    return out


def people_among_furniture(laser, world, furniture: np.ndarray, rng: np.random.Generator, count: int,
                           range_m: tuple[float, float], bearing_rad: float, clearance_m: tuple[float, float],
                           max_stride_m: float, leg_radius_m: tuple[float, float]) -> tuple[Scan, np.ndarray]:
    """One scan of ``count`` people placed at random among ``furniture`` (rows x, y, radius)
    in ``world``, seen by ``laser`` from the origin, and the centres of the legs it shows
    two readings or more of (sensor frame, m).

    Each person stands ``range_m`` away within ``bearing_rad`` of straight ahead, at least
    ``clearance_m`` (from furniture, from other people) clear, standing or mid-stride (up
    to ``max_stride_m``), legs 10-30 cm apart of a radius in ``leg_radius_m``."""
    import math

    from people_tracker.models.pose import Pose2D

    people: list[np.ndarray] = []
    for _ in range(count):
        for _ in range(50):  # a free place
            r, a = rng.uniform(*range_m), rng.uniform(-bearing_rad, bearing_rad)
            c = np.array([r * math.cos(a), r * math.sin(a)])
            if (np.hypot(*(furniture[:, :2] - c).T).min() > clearance_m[0]
                    and all(np.hypot(*(c - q)) > clearance_m[1] for q in people)):
                people.append(c)
                break
    legs = []
    for c in people:
        heading, stride, spacing = rng.uniform(-math.pi, math.pi), rng.uniform(0, max_stride_m), rng.uniform(0.1, 0.3)
        radius = rng.uniform(*leg_radius_m)
        along = np.array([math.cos(heading), math.sin(heading)])
        across = np.array([-along[1], along[0]])
        legs += [(*(c + s * stride * along + s * spacing * across), radius) for s in (-0.5, 0.5)]
    legs = np.array(legs).reshape(-1, 3)
    scan, hit = laser.render(0.0, Pose2D(), world.segments, np.vstack([world.circles, furniture, legs]), rng)
    first = len(world.segments) + len(world.circles) + len(furniture)
    seen = np.bincount(hit[scan.valid & (hit >= first)] - first, minlength=len(legs))
    return scan, legs[seen >= 2, :2]


def simulated_rooms(n_scans: int, seed: int = 100, resolutions_deg=SIMULATED_RESOLUTIONS_DEG) -> list[LabelledScan]:
    """Scans of randomised furnished rooms with people, every leg labelled.

    A new room every 10 scans: walls 6-14 by 5-12 m, two to eight tables and chairs whose
    legs are 1.2-3.5 cm in radius, a 270-degree laser of one of ``resolutions_deg`` with
    0.5-2 cm of noise; in each scan one to six people 0.7-6 m away, standing or mid-stride,
    legs 4.5-8.5 cm in radius and 10-30 cm apart. A leg is labelled when two or more
    readings fall on it. Recorded legs come from a few people in one place; these show
    the model other leg sizes, other rooms and other lasers."""
    import math

    from people_tracker.models.laser import LaserModel
    from people_tracker.models.world import build_world

    rng = np.random.default_rng(seed)
    out = []
    world = furniture = laser = None
    for k in range(n_scans):
        if k % 10 == 0:
            w, h = rng.uniform(6, 14), rng.uniform(5, 12)
            x0, y0 = -rng.uniform(1, 3), -h / 2
            world = build_world({"room": [x0, y0, x0 + w, y0 + h]})
            legs_ = []
            for _ in range(rng.integers(2, 9)):
                cx, cy = rng.uniform(x0 + 0.5, x0 + w - 0.5), rng.uniform(y0 + 0.5, y0 + h - 0.5)
                ww, dd, r = rng.uniform(0.35, 1.6), rng.uniform(0.35, 1.0), rng.uniform(0.012, 0.035)
                legs_ += [(cx + sx * ww / 2, cy + sy * dd / 2, r) for sx in (-1, 1) for sy in (-1, 1)]
            furniture = np.array(legs_)
            laser = LaserModel(fov=math.radians(270), resolution=math.radians(float(rng.choice(resolutions_deg))),
                               range_max=20.0, noise_std=rng.uniform(0.005, 0.02))
        scan, legs = people_among_furniture(laser, world, furniture, rng, int(rng.integers(1, 7)), (0.7, 6.0), 2.2,
                                            (0.5, 0.6), 0.4, (0.045, 0.085))
        out.append(LabelledScan(scan, legs, complete=True))
    return out


def dataset(labelled: list[list[LabelledScan]], negatives: list[list[Scan]], match_radius_m: float = 0.15,
            decimations=DECIMATIONS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Features, labels (1 leg, 0 not) and group of every candidate used for training, each
    scan at each decimation. The group is a stretch of one recording (``BLOCKS`` per
    recording and topic, in time order): calibration folds leave whole stretches out, so
    no scan is scored by a model that saw the scans just before and after it."""
    xs, ys, gs = [], [], []
    for g, recording in enumerate(labelled):
        for k, item in enumerate(recording):
            group = g * BLOCKS + k * BLOCKS // len(recording)
            for every, offset in decimations:
                c = leg_candidates(decimate(item.scan, every, offset))
                if item.box is not None:
                    x0, y0, x1, y1 = item.box
                    pos = (c.xy[:, 0] > x0) & (c.xy[:, 0] < x1) & (c.xy[:, 1] > y0) & (c.xy[:, 1] < y1)
                    keep = pos
                else:
                    pos, _ = match(c.xy, item.legs, match_radius_m)
                    keep = np.ones(len(c), dtype=bool) if item.complete else pos
                xs.append(c.features[keep])
                ys.append(pos[keep].astype(float))
                gs.append(np.full(int(keep.sum()), group))
    for g, recording in enumerate(negatives, start=len(labelled)):
        for k, scan in enumerate(recording):
            group = g * BLOCKS + k * BLOCKS // len(recording)
            for every, offset in decimations:
                c = leg_candidates(decimate(scan, every, offset))
                xs.append(c.features)
                ys.append(np.zeros(len(c)))
                gs.append(np.full(len(c), group))
    if not xs:
        return np.zeros((0, len(FEATURES))), np.zeros(0), np.zeros(0, dtype=np.int64)
    return np.vstack(xs), np.concatenate(ys), np.concatenate(gs)


def training_set(positives: list[list[LabelledScan]], negatives: list[list[Scan]], simulated: int = 600,
                 resolutions_deg=SIMULATED_RESOLUTIONS_DEG) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """What ``people-tracker train-legs`` fits on: the labelled recordings' candidates, their
    legs pasted into two empty rooms each, the empty rooms' candidates and ``simulated``
    scans of simulated rooms (lasers of ``resolutions_deg``), every scan at every
    decimation. Returns features, labels, groups (the simulated and pasted ones in groups
    of their own), the mask of recorded examples (the calibration's) and how many pasted
    scans there are (a scan whose legs fit no room is left out)."""
    moved = transplanted(positives, negatives, per_scan=2)
    x, y, groups = dataset(positives, negatives)
    xm, ym, gm = dataset(moved, [])
    xs, ys, gs = dataset([simulated_rooms(simulated, resolutions_deg=tuple(resolutions_deg))] if simulated else [], [])
    gs = gs + (int(groups.max(initial=0)) + 1) * BLOCKS
    recorded = np.concatenate([np.ones(len(y), dtype=bool), np.zeros(len(ym) + len(ys), dtype=bool)])
    return (np.vstack([x, xm, xs]), np.concatenate([y, ym, ys]), np.concatenate([groups, gm, gs]), recorded,
            sum(map(len, moved)))


def _export(clf) -> tuple[np.ndarray, ...]:
    """The fitted ensemble's trees as arrays of one shape, leaves their own children.

    Reads scikit-learn's ``HistGradientBoostingClassifier`` predictors (the ``[train]``
    extra pins the versions this layout is known for; a test checks that the exported
    model scores exactly as scikit-learn does)."""
    trees = [pred[0].nodes for pred in clf._predictors]
    n_nodes = max(len(t) for t in trees)
    shape = (len(trees), n_nodes)
    feature = np.zeros(shape, dtype=np.int64)
    threshold = np.full(shape, np.inf)
    left = np.tile(np.arange(n_nodes), (len(trees), 1))
    right = left.copy()
    value = np.zeros(shape)
    depth = 0
    for i, t in enumerate(trees):
        m = len(t)
        split = ~t["is_leaf"].astype(bool)
        feature[i, :m] = np.where(split, t["feature_idx"], 0)
        threshold[i, :m] = np.where(split, t["num_threshold"], np.inf)
        left[i, :m] = np.where(split, t["left"], np.arange(m))
        right[i, :m] = np.where(split, t["right"], np.arange(m))
        value[i, :m] = np.where(split, 0.0, t["value"])
        depth = max(depth, int(t["depth"].max()))
    return feature, threshold, left, right, value, depth


def fit(x: np.ndarray, y: np.ndarray, groups: np.ndarray, n_trees: int = 200, depth: int = 4,
        learning_rate: float = 0.1, seed: int = 0, meta: dict | None = None,
        calibrate_on: np.ndarray | None = None) -> LegModel:
    """Fit the ensemble and its calibration (isotonic, on out-of-fold scores grouped by
    recording); needs scikit-learn (the ``[train]`` extra).

    ``calibrate_on`` (a mask) picks the examples the calibration map is fitted to: the
    recorded ones, not the pasted copies, so the share of legs it learns is the recordings'."""
    require("sklearn", "train", "training the leg model")
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.isotonic import IsotonicRegression
    from sklearn.model_selection import GroupKFold

    if len(np.unique(y)) < 2:
        raise InputError("training the leg model needs both legs and non-legs: check the positive and negative "
                         "recordings (and --box)")

    def model():
        return HistGradientBoostingClassifier(max_iter=n_trees, max_depth=depth, learning_rate=learning_rate,
                                              early_stopping=False, random_state=seed)

    raw = np.zeros(len(y))
    n_groups = len(np.unique(groups))
    folded = n_groups >= 2
    if folded:
        for train, test in GroupKFold(n_splits=min(5, n_groups)).split(x, y, groups):
            if len(np.unique(y[train])) < 2:
                folded = False
                break
            raw[test] = model().fit(x[train], y[train]).decision_function(x[test])
    clf = model().fit(x, y)
    if not folded:
        raw = clf.decision_function(x)
    cal = np.ones(len(y), dtype=bool) if calibrate_on is None else calibrate_on
    iso = IsotonicRegression(out_of_bounds="clip", y_min=0.0, y_max=1.0).fit(raw[cal], y[cal])
    calib_raw, calib_p = np.asarray(iso.X_thresholds_, float), np.asarray(iso.y_thresholds_, float)
    if len(calib_raw) < 2:
        calib_raw, calib_p = np.array([-1.0, 1.0]), np.repeat(calib_p[:1], 2)
    feature, threshold, left, right, value, tree_depth = _export(clf)
    info = {"features": list(FEATURES), "n_trees": n_trees, "depth": depth, "learning_rate": learning_rate,
            "positives": int(y.sum()), "negatives": int(len(y) - y.sum()),
            "calibration": ("isotonic on out-of-fold scores" if folded else "isotonic on in-sample scores")
            + (", recorded examples only" if calibrate_on is not None else ""),
            **(meta or {})}
    return LegModel(FEATURES, feature, threshold, left, right, value, tree_depth,
                    float(np.ravel(clf._baseline_prediction)[0]), calib_raw, calib_p, info)


def leg_scores(model: LegModel, scan: Scan, every: int = 1, raw: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Candidate positions (sensor frame, m, shape (k, 2)) and their probabilities of being a
    leg (``raw``: the ensemble's log-odds), with every ``every``-th beam of the scan kept."""
    c = leg_candidates(decimate(scan, every))
    return c.xy, (model.log_odds if raw else model.probability)(c.features)


def recall_at_false_rates(model: LegModel, labelled: list[LabelledScan], empty: list[Scan],
                          false_per_scan=(0.2, 0.5, 1.0), match_radius_m: float = 0.15,
                          every: int = 1, raw: bool = False) -> list[dict]:
    """Leg detection scored per labelled leg: found when a candidate at or above the
    threshold lies within ``match_radius_m`` of it (one candidate per leg). The threshold
    for each rate is the score above which the ``empty`` scans (nobody there) hold that
    many candidates per scan. ``every`` > 1 drops beams from every scan first. ``raw``:
    rank by the ensemble's log-odds instead of the calibrated probability (whose map is a
    staircase, so models that rank alike can differ by a step)."""
    lowest, highest = (-np.inf, np.inf) if raw else (0.0, 1.0)
    empty_scores = np.concatenate([leg_scores(model, s, every, raw)[1] for s in empty] or [np.zeros(0)])
    found = [(leg_scores(model, item.scan, every, raw), item.legs) for item in labelled]
    n_legs = sum(len(legs) for _, legs in found)
    ranked = np.sort(empty_scores)[::-1]
    out = []
    for rate in false_per_scan:
        k = int(round(rate * len(empty)))
        # past the last empty-room candidate every score passes; no false legs allowed, none does
        threshold = float(np.nextafter(ranked[k - 1], highest)) if 0 < k <= len(ranked) else (lowest if k else highest)
        hits = 0
        for (xy, p), legs in found:
            hits += int(match(xy[p >= threshold], legs, match_radius_m)[1].sum())
        out.append({"false_per_scan": rate, "threshold": threshold, "recall": hits / max(n_legs, 1),
                    "legs": n_legs, "false": int((empty_scores >= threshold).sum()) / max(len(empty), 1)})
    return out
