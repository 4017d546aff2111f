"""Scenarios: YAML descriptions of a simulated scene, turned into a :class:`Simulation`.

A scenario is a mapping with these sections (units in the names; angles in degrees in the
file, radians inside)::

    description: text
    duration_s: 20            # s
    seed: 1                   # the same seed gives the same scans, to the byte
    laser: {fov_deg, resolution_deg, rate_hz, range_min, range_max, noise_std,
            dropout, dropout_value (nan|zero), clockwise, frame_id, sweep_fraction}
    world: {room: [x0, y0, x1, y1], walls: [[x0, y0, x1, y1]], boxes: [...], pillars: [[x, y, r]]}
    robot: {start: [x, y, yaw_deg], mount: [x, y, yaw_deg],
            drive: [[duration_s, v_mps, omega_degps], ...] | waypoints: [[x, y]], speed: m/s,
            odometry_noise: {trans: fraction, rot: rad per rad}}
    people: [{id, path: [[x, y], ...], speed: m/s or list, start_s, pauses: {waypoint: s},
              exit: bool, round_radius: m (a round object instead of legs)}]
    crowd: {count, area: [x0, y0, x1, y1], speed: [lo, hi], waypoints: n, pause_s: [lo, hi]}

Every key is checked: an unknown one is an error that names it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from people_tracker.configs import names_a_file, shipped_file, shipped_names

from people_tracker.models.laser import LaserModel
from people_tracker.models.person import PersonModel, Walker
from people_tracker.models.pose import Pose2D
from people_tracker.models.robot import FollowDriver, ScriptedDriver, WaypointDriver
from people_tracker.models.simulator import Simulation
from people_tracker.models.world import build_world


class ScenarioError(ValueError):
    """A scenario that cannot be built; the message names the key."""


_KEYS = {
    "": {"description", "duration_s", "seed", "laser", "world", "robot", "people", "crowd"},
    "laser": {"fov_deg", "resolution_deg", "rate_hz", "range_min", "range_max", "noise_std", "dropout",
              "dropout_value", "clockwise", "frame_id", "sweep_fraction"},
    "world": {"room", "walls", "boxes", "pillars"},
    "robot": {"start", "mount", "drive", "waypoints", "speed", "max_turn_degps", "odometry_noise", "follow"},
    "robot.follow": {"person", "distance", "max_speed"},
    "robot.odometry_noise": {"trans", "rot"},
    "people[]": {"id", "path", "speed", "start_s", "pauses", "exit", "round_radius"},
    "crowd": {"count", "area", "speed", "waypoints", "pause_s", "pause_probability"},
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
    for sec in ("laser", "world", "robot", "crowd"):
        if sec in spec:
            check(spec[sec], sec)
    for sub in ("odometry_noise", "follow"):
        if sub in (spec.get("robot") or {}):
            check(spec["robot"][sub], f"robot.{sub}")
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
    x0, y0, x1, y1 = (float(a) for a in spec.get("area", [0, -5, 10, 5]))
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


def build_simulation(spec: dict, seed: int | None = None, crowd_count: int | None = None) -> tuple[Simulation, int]:
    """The simulation of a scenario and its number of scans.

    ``seed`` and ``crowd_count`` override the scenario's own values.
    """
    seed = int(spec.get("seed", 0) if seed is None else seed)
    rng = np.random.default_rng(seed)
    laser = build_laser(spec.get("laser", {}) or {})
    try:
        world = build_world(spec.get("world"))
    except (TypeError, ValueError):
        raise ScenarioError("scenario key 'world' has a malformed shape (see the scenario format)") from None
    robot = spec.get("robot", {}) or {}
    start = _pose(robot.get("start", [0, 0, 0]), "robot.start")
    mount = _pose(robot.get("mount", [0, 0, 0]), "robot.mount")
    driver = None
    if "drive" in robot:
        try:
            pieces = [(float(d), float(v), math.radians(float(w))) for d, v, w in robot["drive"]]
        except (TypeError, ValueError):
            raise ScenarioError("scenario key 'robot.drive' must be a list of [duration_s, v_mps, omega_degps]") from None
        driver = ScriptedDriver(pieces)
    elif "waypoints" in robot:
        driver = WaypointDriver(robot["waypoints"], _num(robot, "speed", 0.8, "robot.", 0.0, 5.0),
                                math.radians(_num(robot, "max_turn_degps", 60.0, "robot.", 0.0, 1000.0)))
    noise = robot.get("odometry_noise", {}) or {}
    walkers = [_walker(i, p, rng) for i, p in enumerate(spec.get("people", []) or [])]
    if "crowd" in spec or crowd_count is not None:
        walkers += _crowd(spec.get("crowd", {}) or {}, 1 + max([w.person_id for w in walkers], default=0), rng,
                          crowd_count, _num(spec, "duration_s", 20.0, "", 0.0, 86400.0, lo_open=True), seed)
    if "follow" in robot:
        f = robot["follow"]
        target = next((w for w in walkers if w.person_id == f.get("person")), None)
        if target is None:
            raise ScenarioError(f"scenario key 'robot.follow.person': no person with id {f.get('person')!r}")
        driver = FollowDriver(lambda t, w=target: w.torso(t) if w.present(t) else None,
                              _num(f, "distance", 1.0, "robot.follow.", 0.1, 20.0),
                              _num(f, "max_speed", 1.2, "robot.follow.", 0.0, 5.0))
    duration = _num(spec, "duration_s", 20.0, "", 0.0, 86400.0, lo_open=True)
    sim = Simulation(laser, world, walkers, rng, mount=mount, start=start, driver=driver,
                     odom_trans_noise=_num(noise, "trans", 0.0, "robot.odometry_noise.", 0.0, 1.0),
                     odom_rot_noise=_num(noise, "rot", 0.0, "robot.odometry_noise.", 0.0, 1.0))
    return sim, int(round(duration * laser.rate_hz))
