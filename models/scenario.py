"""Scenarios: YAML descriptions of a simulated scene, turned into a :class:`Simulation`.

A scenario is a mapping with these sections (units in the names; angles in degrees in the
file, radians inside)::

    description: text
    duration_s: 20            # s
    seed: 1                   # the same seed gives the same scans, to the byte
    laser: {fov_deg, resolution_deg, rate_hz, range_min, range_max, noise_std,
            dropout, dropout_value (nan|zero), spurious, clockwise, frame_id, sweep_fraction}
    lasers: {name: {laser keys}, ...}   # other lasers the scene can run with (--laser NAME)
    world: {room: [x0, y0, x1, y1], walls: [[x0, y0, x1, y1]], boxes: [...], pillars: [[x, y, r]]}
    robot: {start: [x, y, yaw_deg], mount: [x, y, yaw_deg],
            drive: [[duration_s, v_mps, omega_degps], ...] | waypoints: [[x, y]], speed: m/s,
            odometry_noise: {trans: fraction, rot: rad per rad}, odometry: bool (default true),
            radius_m: 0.3 (its footprint round the base, which people walk round; 0: none),
            follow: {person, distance, max_speed, max_turn_degps, trail: bool,
                     hold: {at: [[x, y], ...], radius_m, seconds}, beside: {windows: [[t0, t1]], offset_m}}}
    people: [{id, path: [[x, y], ...], speed: m/s or list, start_s, pauses: {waypoint: s},
              exit: bool, round_radius: m (a round object instead of legs), laps: n}]
    passers: {person, per_minute, speed: [lo, hi], heading: across|oncoming, offset_m: [lo, hi], half_width_m,
              same_build: bool, start_s}   # or a list of such groups
    crowd: {count, area: [x0, y0, x1, y1], speed: [lo, hi], waypoints: n, pause_s: [lo, hi]}
    visitors: {count, door: [x, y], area: [x0, y0, x1, y1], range_m: [lo, hi], stand_s: [lo, hi],
               arrive_every_s: [lo, hi], speed: [lo, hi], face_to_face: pairs, distance_m: [lo, hi]}
    furniture: {count, area: [x0, y0, x1, y1], range_m: [lo, hi], radius_m: [lo, hi], spacing_m: [lo, hi]}
    keep_apart_m: 0.45        # m between torsos that crowd members, passers-by and visitors keep (0: none)

``visitors`` walk in from the door one after another, stand at a spot of their own in ``area``
(``range_m`` from the sensor) for ``stand_s`` and walk out; ``face_to_face`` pairs of them
stand ``distance_m`` apart facing each other. ``furniture`` is ``count`` pairs of round legs
(tables, chairs) in the same kind of place, there from the first scan. Both are drawn from
the seed.

``passers`` meet ``person`` (default: the followed one, else the first listed) ``per_minute`` times a minute on
average and leave: ``across`` ones cross their heading ``offset_m`` ahead of them (negative:
behind, between them and a robot that follows), from ``half_width_m`` on one side to as far on
the other; ``oncoming`` ones walk the other way and pass ``offset_m`` beside them (either side); ``same_build`` gives them the person's leg radius and spacing. A person's
``laps`` repeats their path (and its pauses) that many times. ``robot.follow`` drives after a
person with their true position (see :class:`~people_tracker.models.robot.FollowDriver`);
``odometry: false`` leaves odometry out of the recording.

Crowd members and passers-by step aside rather than walk through anyone: each keeps
``keep_apart_m`` between torsos from the people listed, the visitors and those of them drawn
before, and half of it from pillars, trees and furniture legs and from the edge of the
robot's footprint (``robot.radius_m`` round its base; the robot makes way for nobody)
(:func:`~people_tracker.models.keep_apart.keep_apart`; crowd members within their area).
Visitors do the same while they walk, for the people listed and every other visitor (whoever
walks past someone standing makes way), and hold their place while they stand.

Every key is checked: an unknown one is an error that names it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from people_tracker.configs import names_a_file, shipped_file, shipped_names

from people_tracker.models.keep_apart import GAP_M, keep_apart
from people_tracker.models.laser import LaserModel
from people_tracker.models.person import PersonModel, Walker
from people_tracker.models.pose import Pose2D
from people_tracker.models.robot import FollowDriver, ScriptedDriver, WaypointDriver, integrate
from people_tracker.models.simulator import Simulation
from people_tracker.models.world import World, build_world


class ScenarioError(ValueError):
    """A scenario that cannot be built; the message names the key."""


CROWD_AREA = [0, -5, 10, 5]  # m, world frame: where a crowd wanders unless told
#: m: the robot's footprint, a disc round its base (``robot.radius_m``), that people walk round
ROBOT_RADIUS_M = 0.3

_KEYS = {
    "": {"description", "duration_s", "seed", "laser", "lasers", "world", "robot", "people", "crowd", "visitors",
         "furniture", "passers", "keep_apart_m"},
    "laser": {"fov_deg", "resolution_deg", "rate_hz", "range_min", "range_max", "noise_std", "dropout",
              "dropout_value", "spurious", "clockwise", "frame_id", "sweep_fraction"},
    "world": {"room", "walls", "boxes", "pillars"},
    "robot": {"start", "mount", "drive", "waypoints", "speed", "max_turn_degps", "odometry_noise", "follow",
              "odometry", "radius_m"},
    "robot.follow": {"person", "distance", "max_speed", "max_turn_degps", "trail", "hold", "beside"},
    "robot.follow.hold": {"at", "radius_m", "seconds"},
    "robot.follow.beside": {"windows", "offset_m"},
    "robot.odometry_noise": {"trans", "rot"},
    "people[]": {"id", "path", "speed", "start_s", "pauses", "exit", "round_radius", "laps"},
    "passers": {"person", "per_minute", "speed", "offset_m", "half_width_m", "same_build", "start_s", "heading"},
    "crowd": {"count", "area", "speed", "waypoints", "pause_s", "pause_probability"},
    "visitors": {"count", "door", "area", "range_m", "stand_s", "arrive_every_s", "speed", "face_to_face",
                 "distance_m"},
    "furniture": {"count", "area", "range_m", "radius_m", "spacing_m"},
}


def scenario_names() -> list[str]:
    """Names of the scenarios shipped in ``configs/scenarios``."""
    return shipped_names("scenarios")


def load_scenario(name_or_path: str | Path) -> dict:
    """The scenario mapping for a shipped name, or for a YAML file when the argument ends in
    ``.yaml``/``.yml`` or holds a path separator (checked, not yet built)."""
    if names_a_file(name_or_path):
        p = Path(name_or_path)
        if not p.is_file():
            raise ScenarioError(f"scenario file '{name_or_path}' does not exist")
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ScenarioError(f"scenario file '{p}' cannot be read: {exc}") from None
        origin = f"scenario file '{p}'"
    else:
        f = shipped_file(str(name_or_path), "scenarios")
        if f is None:
            raise ScenarioError(f"no scenario '{name_or_path}' (shipped: {', '.join(scenario_names())}; "
                                f"a file needs .yaml or a path separator, e.g. ./{name_or_path}.yaml)")
        text, origin = f.read_text(encoding="utf-8"), f"scenario '{name_or_path}'"
    try:
        spec = yaml.safe_load(text)
    except yaml.YAMLError:
        raise ScenarioError(f"{origin} is not valid YAML") from None
    if not isinstance(spec, dict):
        raise ScenarioError(f"{origin} must be a mapping")
    _check_keys(spec)
    return spec


def _check_keys(spec: dict) -> None:
    def check(d, where):
        if not isinstance(d, dict):
            raise ScenarioError(f"scenario key '{where}' must be a mapping")
        for k in d:
            if k not in _KEYS[where]:
                name = f"{where}.{k}" if where else k
                raise ScenarioError(f"unknown scenario key '{name}'")
    check(spec, "")
    for sec in ("laser", "world", "robot", "crowd", "visitors", "furniture"):
        if sec in spec:
            check(spec[sec], sec)
    for group in _as_list(spec.get("passers")):
        check(group, "passers")
    if "lasers" in spec:
        if not isinstance(spec["lasers"], dict):
            raise ScenarioError("scenario key 'lasers' must be a mapping of names to lasers")
        for name, laser in spec["lasers"].items():
            if not isinstance(laser, dict):
                raise ScenarioError(f"scenario key 'lasers.{name}' must be a mapping")
            for k in laser:
                if k not in _KEYS["laser"]:
                    raise ScenarioError(f"unknown scenario key 'lasers.{name}.{k}'")
    for sub in ("odometry_noise", "follow"):
        if sub in (spec.get("robot") or {}):
            check(spec["robot"][sub], f"robot.{sub}")
    for sub in ("hold", "beside"):
        if sub in ((spec.get("robot") or {}).get("follow") or {}):
            check(spec["robot"]["follow"][sub], f"robot.follow.{sub}")
    for i, person in enumerate(spec.get("people", []) or []):
        if not isinstance(person, dict):
            raise ScenarioError(f"scenario key 'people[{i}]' must be a mapping")
        for k in person:
            if k not in _KEYS["people[]"]:
                raise ScenarioError(f"unknown scenario key 'people[{i}].{k}'")


def _num(d: dict, key: str, default, where: str, lo=None, hi=None, lo_open=False):
    v = d.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ScenarioError(f"scenario key '{where}{key}' must be a finite number, got {v!r}")
    if (lo is not None and (v < lo or (lo_open and v == lo))) or (hi is not None and v > hi):
        raise ScenarioError(f"scenario key '{where}{key}' is out of range: {v!r}")
    return float(v)


def _pose(v, where: str) -> Pose2D:
    try:
        x, y, yaw_deg = (float(a) for a in v)
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{where}' must be [x, y, yaw_deg]") from None
    return Pose2D(x, y, math.radians(yaw_deg))


def build_laser(spec: dict) -> LaserModel:
    w = "laser."
    dv = spec.get("dropout_value", "nan")
    if dv not in ("nan", "zero"):
        raise ScenarioError("scenario key 'laser.dropout_value' must be nan or zero")
    return LaserModel(
        fov=math.radians(_num(spec, "fov_deg", 270.0, w, 1.0, 360.0)),
        resolution=math.radians(_num(spec, "resolution_deg", 0.35, w, 0.01, 10.0)),
        rate_hz=_num(spec, "rate_hz", 10.0, w, 0.1, 1000.0),
        range_min=_num(spec, "range_min", 0.05, w, 0.0),
        range_max=_num(spec, "range_max", 20.0, w, 0.1, lo_open=True),
        noise_std=_num(spec, "noise_std", 0.01, w, 0.0, 1.0),
        dropout=_num(spec, "dropout", 0.0, w, 0.0, 1.0),
        dropout_value=float("nan") if dv == "nan" else 0.0,
        spurious=_num(spec, "spurious", 0.0, w, 0.0, 1.0),
        clockwise=bool(spec.get("clockwise", False)),
        frame_id=str(spec.get("frame_id", "laser")),
        sweep_fraction=_num(spec, "sweep_fraction", 0.75, w, 0.0, 1.0),
    )


def _walker(i: int, p: dict, rng: np.random.Generator) -> Walker:
    where = f"people[{i}]."
    if "path" not in p:
        raise ScenarioError(f"scenario key '{where}path' is missing")
    speed = p.get("speed", 1.0)
    speeds = speed if isinstance(speed, list) else [speed]
    for s in speeds:
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not (0 < s <= 5):
            raise ScenarioError(f"scenario key '{where}speed' must be in (0, 5] m/s, got {s!r}")
    path = np.asarray(p["path"], dtype=float)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) < 1:
        raise ScenarioError(f"scenario key '{where}path' must be a list of [x, y]")
    pauses = {int(k): float(v) for k, v in (p.get("pauses") or {}).items()}
    laps = int(_num(p, "laps", 1, where, 1, 1000))
    if laps > 1:  # the path again from its start, pauses and speeds with it
        pauses = {i + k * len(path): s for k in range(laps) for i, s in pauses.items()}
        if isinstance(speed, list):
            speed = ((speed + [speed[-1]]) * laps)[:-1]  # the leg back to the start at the last speed
        path = np.vstack([path] * laps)
    radius = p.get("round_radius")
    return Walker(int(p.get("id", i + 1)), path, speed, pauses, _num(p, "start_s", 0.0, where, 0.0),
                  bool(p.get("exit", False)), PersonModel.sample(rng, float(np.mean(speeds))),
                  None if radius is None else _num(p, "round_radius", 0.15, where, 0.01, 5.0))


def _crowd(spec: dict, first_id: int, rng: np.random.Generator, count: int | None, duration_s: float = 0.0,
           seed: int = 0) -> list[Walker]:
    """Crowd walkers wandering between random waypoints in ``area``, pausing now and then.

    Each walker gets ``waypoints`` points, and more until their walk lasts the whole
    ``duration_s`` (drawn from a generator of their own, so a short scene is unchanged):
    nobody stops for good at a last waypoint while the scene goes on.
    """
    w = "crowd."
    n = int(_num(spec, "count", 30, w, 0, 10000) if count is None else count)
    x0, y0, x1, y1 = _crowd_area(spec)
    lo, hi = (float(a) for a in spec.get("speed", [0.4, 1.4]))
    n_wp = int(_num(spec, "waypoints", 8, w, 2, 1000))
    p_lo, p_hi = (float(a) for a in spec.get("pause_s", [1.0, 4.0]))
    p_pause = _num(spec, "pause_probability", 0.2, w, 0.0, 1.0)
    out = []
    for k in range(n):
        path = np.column_stack([rng.uniform(x0, x1, n_wp), rng.uniform(y0, y1, n_wp)])
        speed = float(rng.uniform(lo, hi))
        pauses = {i: float(rng.uniform(p_lo, p_hi)) for i in range(1, n_wp - 1) if rng.random() < p_pause}
        more = np.random.default_rng((seed, k))
        points = list(path)
        walk_s = float(np.hypot(*np.diff(path, axis=0).T).sum()) / speed + sum(pauses.values())
        while walk_s < duration_s:
            nxt = np.array([more.uniform(x0, x1), more.uniform(y0, y1)])
            if more.random() < p_pause:  # a pause at the point reached before this one
                pauses[len(points) - 1] = float(more.uniform(p_lo, p_hi))
                walk_s += pauses[len(points) - 1]
            walk_s += float(np.hypot(*(nxt - points[-1]))) / speed
            points.append(nxt)
        out.append(Walker(first_id + k, np.array(points), speed, pauses, 0.0, False, PersonModel.sample(rng, speed)))
    return out


def _crowd_area(spec: dict) -> tuple[float, float, float, float]:
    """Where a crowd wanders, ``(x0, y0, x1, y1)``, m, world frame."""
    x0, y0, x1, y1 = (float(a) for a in spec.get("area", CROWD_AREA))
    return x0, y0, x1, y1


def _interval(d: dict, key: str, default: list[float], where: str, lo: float = 0.0) -> tuple[float, float]:
    v = d.get(key, default)
    try:
        a, b = (float(x) for x in v)
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{where}{key}' must be [lo, hi]") from None
    if not (math.isfinite(a) and math.isfinite(b) and lo <= a <= b):
        raise ScenarioError(f"scenario key '{where}{key}' must be [lo, hi] with {lo} <= lo <= hi, got {v!r}")
    return a, b


def _place(rng: np.random.Generator, area, range_m, sensor: np.ndarray, clear_of: list[tuple[np.ndarray, float]],
           tries: int = 500) -> np.ndarray | None:
    """A random point in ``area`` at ``range_m`` from ``sensor``, farther than r from each (p, r)."""
    x0, y0, x1, y1 = area
    for _ in range(tries):
        p = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
        if not range_m[0] <= np.hypot(*(p - sensor)) <= range_m[1]:
            continue
        if all(np.hypot(*(p - q)) > r for q, r in clear_of):
            return p
    return None


def _area(d: dict, where: str) -> tuple[float, float, float, float]:
    try:
        x0, y0, x1, y1 = (float(a) for a in d.get("area", [0, -5, 10, 5]))
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{where}area' must be [x0, y0, x1, y1]") from None
    if not (x0 < x1 and y0 < y1):
        raise ScenarioError(f"scenario key '{where}area' must have x0 < x1 and y0 < y1")
    return x0, y0, x1, y1


def _furniture(spec: dict, rng: np.random.Generator, sensor: np.ndarray) -> np.ndarray:
    """Pairs of round legs (x, y, r), shape (2·count, 3), metres."""
    w = "furniture."
    n = int(_num(spec, "count", 6, w, 0, 1000))
    area, range_m = _area(spec, w), _interval(spec, "range_m", [2.0, 6.0], w)
    r_lo, r_hi = _interval(spec, "radius_m", [0.02, 0.06], w)
    s_lo, s_hi = _interval(spec, "spacing_m", [0.2, 0.5], w)
    legs: list[tuple[float, float, float]] = []
    for _ in range(n):
        c = _place(rng, area, range_m, sensor, [(np.array(q[:2]), 0.8) for q in legs])
        if c is None:
            break
        a, spacing, r = rng.uniform(0, math.pi), rng.uniform(s_lo, s_hi), rng.uniform(r_lo, r_hi)
        half = 0.5 * spacing * np.array([math.cos(a), math.sin(a)])
        legs += [(*(c + half), r), (*(c - half), r)]
    return np.array(legs, dtype=float).reshape(-1, 3)


def _visitors(spec: dict, first_id: int, rng: np.random.Generator, sensor: np.ndarray,
              furniture: np.ndarray) -> list[Walker]:
    """People who walk in from the door one after another, stand a while at a spot and leave."""
    w = "visitors."
    n = int(_num(spec, "count", 10, w, 0, 1000))
    try:
        door = np.array([float(a) for a in spec.get("door", [0.0, 4.0])]).reshape(2)
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{w}door' must be [x, y]") from None
    area, range_m = _area(spec, w), _interval(spec, "range_m", [2.0, 6.0], w)
    stand, every = _interval(spec, "stand_s", [120.0, 240.0], w), _interval(spec, "arrive_every_s", [10.0, 40.0], w)
    v_lo, v_hi = _interval(spec, "speed", [0.6, 1.2], w, lo=0.1)
    d_lo, d_hi = _interval(spec, "distance_m", [0.6, 0.9], w)
    pairs = int(_num(spec, "face_to_face", 1, w, 0, n // 2))
    # the second and third arrival, the fifth and sixth, … stand face to face
    partner_of = {3 * k + 2: 3 * k + 1 for k in range(pairs)}
    furniture_clear = [(np.array(f[:2]), 0.6) for f in furniture]
    spots: list[tuple[np.ndarray, float, float]] = []  # where, from, until (s)
    out, t = [], float(rng.uniform(*every)) * 0.25
    for i in range(n):
        speed = float(rng.uniform(v_lo, v_hi))
        body = PersonModel.sample(rng, speed)
        stand_s = float(rng.uniform(*stand))
        spot = None
        if i in partner_of and partner_of[i] < len(out):
            a = out[partner_of[i]]
            u = a.waypoints[2] - a.waypoints[1]
            u /= np.hypot(*u)
            spot = a.waypoints[2] + u * rng.uniform(d_lo, d_hi)  # ahead of the partner, facing back
            if (not range_m[0] <= np.hypot(*(spot - sensor)) <= range_m[1]
                    or any(np.hypot(*(spot - q)) <= r for q, r in furniture_clear)):
                spot = None
            else:
                pre, t = spot + 1.0 * u, t + float(rng.uniform(2.0, 6.0))
        if spot is None:
            if i > 0:
                t += float(rng.uniform(*every))
            busy = [(p, 1.2) for p, t0, t1 in spots if t0 < t + stand_s + 60.0 and t1 > t - 60.0]
            spot = _place(rng, area, range_m, sensor, furniture_clear + busy)
            if spot is None:
                continue
            # they come in from the door's side, not straight at the spot
            a = math.atan2(*(spot - door)[::-1]) + rng.uniform(-1.0, 1.0)
            pre = spot - np.array([math.cos(a), math.sin(a)])
        path = np.array([door, pre, spot, door])
        arrive = float(np.hypot(*(pre - door)) + 1.0)
        L = body.step_length
        walker = Walker(first_id + len(out), path, speed, {2: stand_s}, t, True, body,
                        step_phase_m=(arrive - 0.5 * L) % L)
        spots.append((spot, t, t + arrive / speed + stand_s))
        out.append(walker)
    return out


def _passers(spec: dict, first_id: int, rng: np.random.Generator, person: Walker, duration_s: float) -> list[Walker]:
    """People who cross ``person``'s path ``offset_m`` ahead of them (negative: behind) and leave."""
    w = "passers."
    per_minute = _num(spec, "per_minute", 3.0, w, 0.0, 600.0)
    v_lo, v_hi = _interval(spec, "speed", [0.9, 1.5], w, lo=0.1)
    try:
        o_lo, o_hi = (float(a) for a in spec.get("offset_m", [-1.2, -0.5]))
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{w}offset_m' must be [lo, hi]") from None
    half = _num(spec, "half_width_m", 4.0, w, 0.5, 100.0)
    same = bool(spec.get("same_build", False))
    heading = spec.get("heading", "across")
    if heading not in ("across", "oncoming"):
        raise ScenarioError(f"scenario key '{w}heading' must be across or oncoming, got {heading!r}")
    out: list[Walker] = []
    if per_minute <= 0:
        return out
    t = _num(spec, "start_s", 5.0, w, 0.0)
    while True:
        t += float(rng.uniform(0.5, 1.5)) * 60.0 / per_minute
        if t >= duration_s:
            return out
        speed = float(rng.uniform(v_lo, v_hi))
        body = PersonModel.sample(rng, speed)
        if same:
            body = PersonModel(person.body.leg_radius, person.body.leg_spacing, body.step_length)
        offset, side = float(rng.uniform(o_lo, o_hi)), float(rng.choice([-1.0, 1.0]))
        if not person.present(t):
            continue
        where, u = person._at(person.arc_length(t))
        n = side * np.array([-u[1], u[0]])
        if heading == "across":
            cross, d = where + offset * u, n
        else:  # they meet where the person is at t, offset to one side, walking the other way
            cross, d = where + abs(offset) * n, -u
        start = t - half / speed
        if start < 0:
            continue
        out.append(Walker(first_id + len(out), np.array([cross - half * d, cross + half * d]), speed, {}, start,
                          True, body))


def laser_names(spec: dict) -> list[str]:
    """Names of the other lasers a scenario can run with (its ``lasers`` section)."""
    return list((spec.get("lasers") or {}).keys())


def build_simulation(spec: dict, seed: int | None = None, crowd_count: int | None = None,
                     laser: str | None = None) -> tuple[Simulation, int]:
    """The simulation of a scenario and its number of scans.

    ``seed`` and ``crowd_count`` override the scenario's own values; ``laser`` names one of
    its ``lasers`` to use instead of ``laser``.
    """
    seed = int(spec.get("seed", 0) if seed is None else seed)
    rng = np.random.default_rng(seed)
    if laser is not None and laser not in laser_names(spec):
        raise ScenarioError(f"no laser '{laser}' in the scenario (it has: {', '.join(laser_names(spec)) or 'none'})")
    laser = build_laser((spec.get("laser", {}) if laser is None else spec["lasers"][laser]) or {})
    try:
        world = build_world(spec.get("world"))
    except (TypeError, ValueError):
        raise ScenarioError("scenario key 'world' has a malformed shape (see the scenario format)") from None
    robot = spec.get("robot", {}) or {}
    start = _pose(robot.get("start", [0, 0, 0]), "robot.start")
    mount = _pose(robot.get("mount", [0, 0, 0]), "robot.mount")
    noise = robot.get("odometry_noise", {}) or {}
    walkers = [_walker(i, p, rng) for i, p in enumerate(spec.get("people", []) or [])]
    crowd: list[Walker] = []
    if "crowd" in spec or crowd_count is not None:
        crowd = _crowd(spec.get("crowd", {}) or {}, 1 + max([w.person_id for w in walkers], default=0), rng,
                       crowd_count, _num(spec, "duration_s", 20.0, "", 0.0, 86400.0, lo_open=True), seed)
        walkers += crowd
    sensor = start.compose(mount)
    sensor_xy = np.array([sensor.x, sensor.y])
    furniture = _furniture(spec["furniture"] or {}, rng, sensor_xy) if "furniture" in spec else np.zeros((0, 3))
    if len(furniture):
        world = World(world.segments, np.vstack([world.circles, furniture]))
    visitors = []
    if "visitors" in spec:
        visitors = _visitors(spec["visitors"] or {}, 1 + max([w.person_id for w in walkers], default=0), rng,
                             sensor_xy, furniture)
        walkers += visitors
    duration = _num(spec, "duration_s", 20.0, "", 0.0, 86400.0, lo_open=True)
    target_id = None
    if "follow" in robot:
        f = robot["follow"]
        target = next((w for w in walkers if w.person_id == f.get("person")), None)
        if target is None:
            raise ScenarioError(f"scenario key 'robot.follow.person': no person with id {f.get('person')!r}")
        target_id = target.person_id
    make_driver = _driver_factory(robot, walkers, target_id)
    driver = make_driver()
    passers: list[Walker] = []
    for p in _as_list(spec.get("passers")):
        pid = p.get("person", target_id if target_id is not None else walkers[0].person_id if walkers else None)
        person = next((w for w in walkers if w.person_id == pid), None)
        if person is None:
            raise ScenarioError(f"scenario key 'passers.person': no person with id {pid!r}")
        group = _passers(p, 1 + max(w.person_id for w in walkers), rng, person, duration)
        passers += group
        walkers += group
    yielding = crowd + passers
    moved = {id(w) for w in yielding + visitors}
    fixed = [w for w in walkers if id(w) not in moved]  # the people listed
    area = _crowd_area(spec.get("crowd", {}) or {})
    radius = _num(robot, "radius_m", ROBOT_RADIUS_M, "robot.", 0.0, 5.0)
    keep_apart(fixed, yielding, duration, _num(spec, "keep_apart_m", GAP_M, "", 0.0, 5.0),
               bounds={w.person_id: area for w in crowd}, obstacles=world.circles, visitors=visitors,
               robot=_robot_base_path(make_driver(), start, duration) if radius > 0 else None,
               robot_radius_m=radius)
    sim = Simulation(laser, world, walkers, rng, mount=mount, start=start, driver=driver,
                     odom_trans_noise=_num(noise, "trans", 0.0, "robot.odometry_noise.", 0.0, 1.0),
                     odom_rot_noise=_num(noise, "rot", 0.0, "robot.odometry_noise.", 0.0, 1.0),
                     has_odometry=bool(robot.get("odometry", True)), target_id=target_id)
    return sim, int(round(duration * laser.rate_hz))


def _driver_factory(robot: dict, walkers: list[Walker], target_id: int | None):
    """A function that builds the robot's driver afresh (drivers keep state: a trail, a
    waypoint reached), or returns None when the robot stands still."""
    if target_id is not None:
        f = robot["follow"]
        target = next(w for w in walkers if w.person_id == target_id)
        distance = _num(f, "distance", 1.0, "robot.follow.", 0.1, 20.0)
        max_speed = _num(f, "max_speed", 1.2, "robot.follow.", 0.0, 5.0)
        max_turn = (math.radians(_num(f, "max_turn_degps", 1.0, "robot.follow.", 1.0, 1000.0))
                    if "max_turn_degps" in f else 1.5)
        trail, hold, beside = bool(f.get("trail", False)), _hold(f.get("hold")), _beside(f.get("beside"))
        return lambda: FollowDriver(lambda t, w=target: w.torso(t) if w.present(t) else None, distance,
                                    max_speed, max_turn, trail, hold, beside)
    if "drive" in robot:
        try:
            pieces = [(float(d), float(v), math.radians(float(w))) for d, v, w in robot["drive"]]
        except (TypeError, ValueError):
            raise ScenarioError("scenario key 'robot.drive' must be a list of [duration_s, v_mps, omega_degps]") from None
        return lambda: ScriptedDriver(pieces)
    if "waypoints" in robot:
        speed = _num(robot, "speed", 0.8, "robot.", 0.0, 5.0)
        max_turn = math.radians(_num(robot, "max_turn_degps", 60.0, "robot.", 0.0, 1000.0))
        return lambda: WaypointDriver(robot["waypoints"], speed, max_turn)
    return lambda: None


def _robot_base_path(driver, start: Pose2D, duration_s: float, steps_hz: float = 50.0):
    """Where the robot's base will be (m, world frame), as a function of an array of times (s):
    ``driver`` run from ``start`` for ``duration_s``, asked ``steps_hz`` times a second. The
    drivers steer by time and by the people's scripted paths (a followed person never steps
    aside), not by anyone who makes way, so the path is known before the scene is built. The
    simulation asks its driver at 200 Hz; at 50 Hz the path stays within 4 cm of it over
    ``follow_indoor_crowd``'s 10 minutes, at a quarter of the cost (ad hoc, 2026-11-28). The
    driver runs when the function is called: a scene where nobody makes way never asks."""
    def at_times(times: np.ndarray) -> np.ndarray:
        if driver is None:
            return np.tile([start.x, start.y], (len(times), 1))
        dt = 1.0 / steps_hz
        steps = int(math.ceil(duration_s * steps_hz)) + 1
        xy = np.empty((steps + 1, 2))
        pose = start
        xy[0] = pose.x, pose.y
        for k in range(steps):
            pose = integrate(pose, driver(k * dt, pose), dt)
            xy[k + 1] = pose.x, pose.y
        at = np.arange(steps + 1) * dt
        return np.column_stack([np.interp(times, at, xy[:, 0]), np.interp(times, at, xy[:, 1])])

    return at_times


def _as_list(section) -> list:
    """A section that may be one mapping or a list of them (``passers``)."""
    if section is None:
        return []
    return list(section) if isinstance(section, list) else [section]


def _hold(spec: dict | None):
    """``robot.follow.hold`` as (points (k, 2), radius_m, seconds), or None."""
    if not spec:
        return None
    w = "robot.follow.hold."
    try:
        points = np.array(spec.get("at", []), dtype=float).reshape(-1, 2)
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{w}at' must be a list of [x, y]") from None
    return points, _num(spec, "radius_m", 0.5, w, 0.01, 100.0), _num(spec, "seconds", 2.0, w, 0.0, 3600.0)


def _beside(spec: dict | None):
    """``robot.follow.beside`` as ([(t0, t1), …], offset_m), or None."""
    if not spec:
        return None
    w = "robot.follow.beside."
    try:
        windows = [(float(a), float(b)) for a, b in spec.get("windows", [])]
    except (TypeError, ValueError):
        raise ScenarioError(f"scenario key '{w}windows' must be a list of [t0, t1]") from None
    return windows, _num(spec, "offset_m", 1.0, w, 0.1, 10.0)
