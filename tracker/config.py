"""Configuration: YAML → frozen dataclasses, every key checked.

``configs/default.yaml`` (shipped in the wheel) holds every tunable and its unit; a user
file given with ``--config`` overrides any subset of it. Unknown keys, wrong types and
out-of-range values raise :class:`~people_tracker.tracker.errors.InputError` naming the key.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from people_tracker.configs import names_a_file, shipped_file, shipped_names
from people_tracker.tracker.errors import InputError


def _spec(*, lo: float | None = None, hi: float | None = None, lo_open: bool = False,
          choices: tuple[str, ...] | None = None) -> dict:
    return {"lo": lo, "hi": hi, "lo_open": lo_open, "choices": choices}


@dataclass(frozen=True)
class OdometryConfig:
    """Where the sensor pose in the fixed frame comes from, and how it is interpolated."""

    source: str = field(metadata=_spec(choices=("auto", "odom", "tf", "none")))
    odom_topic: str = field(metadata=_spec())
    tf_discovery_s: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=3600.0))
    max_wait_s: float = field(metadata=_spec(lo=0.0, hi=60.0))
    max_interpolation_gap_s: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=60.0))
    max_extrapolation_s: float = field(metadata=_spec(lo=0.0, hi=10.0))


@dataclass(frozen=True)
class ScanChecksConfig:
    """Rules for bad scans inside a good recording."""

    stamp_jump_periods: float = field(metadata=_spec(lo=1.0, lo_open=True, hi=1e6))
    beam_count_confirm: int = field(metadata=_spec(lo=1, hi=1000))


@dataclass(frozen=True)
class DetectorConfig:
    """The paper's detector; see :class:`people_tracker.detection.detector.DetectorParams`."""

    compare_dt_s: tuple = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    k_closest: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1000.0))
    closest_floor_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    k_segment: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1000.0))
    segment_floor_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    scan_line_window: int = field(metadata=_spec(lo=0, hi=100))
    min_seed_points: int = field(metadata=_spec(lo=1, hi=10000))
    min_seed_width_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    min_object_points: int = field(metadata=_spec(lo=1, hi=10000))
    min_object_width_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    max_object_size_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=100.0))
    single_object_max_o: int = field(metadata=_spec(lo=0, hi=10000))
    isolated_o_objects: bool = field(metadata=_spec())
    no_return_free_m: float = field(metadata=_spec(lo=0.0, hi=1000.0))
    static_memory_s: tuple = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    static_memory_k: float = field(metadata=_spec(lo=0.0, hi=1000.0))
    static_memory_share: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    static_memory_min_scans: int = field(metadata=_spec(lo=1, hi=100))
    static_memory_keep_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    drop_carried: bool = field(metadata=_spec())

    def params(self):
        """The detector's own parameter object."""
        from people_tracker.detection.detector import DetectorParams
        return _params_of(self, DetectorParams)


def _params_of(section, cls):
    return cls(**dataclasses.asdict(section))


@dataclass(frozen=True)
class PairingConfig:
    """Leg pairing; see :class:`people_tracker.tracker.pairing.PairingParams`."""

    min_leg_size_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    max_leg_size_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=5.0))
    max_person_size_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    max_leg_separation_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=5.0))
    sigma_pair_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    sigma_single_leg_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    sigma_blob_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    max_leg_radius_m: float = field(metadata=_spec(lo=0.0, hi=1.0))
    flat_min_length_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    flat_max_depth_m: float = field(metadata=_spec(lo=0.0, hi=1.0))
    stance_partner: bool = field(metadata=_spec())
    max_leg_spread_m: float = field(metadata=_spec(lo=0.0, hi=5.0))

    def params(self):
        from people_tracker.tracker.pairing import PairingParams
        return _params_of(self, PairingParams)


@dataclass(frozen=True)
class TracksConfig:
    """Track filter and lifecycle; see :class:`people_tracker.tracker.tracks.TrackParams`."""

    accel_std_mps2: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=100.0))
    init_speed_std_mps: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=100.0))
    max_position_std_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1000.0))
    confirm_min_travel_m: float = field(metadata=_spec(lo=0.0, hi=100.0))
    confirm_leg_probability: float = field(metadata=_spec(lo=0.0, hi=1.01))
    max_tentative_s: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=3600.0))
    still_after_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))
    still_drift_mps: float = field(metadata=_spec(lo=0.0, hi=100.0))
    min_person_separation_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    same_person_after_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))
    unobserved_sensor_speed_mps: float = field(metadata=_spec(lo=0.0, hi=100.0))
    unobserved_sensor_turn_radps: float = field(metadata=_spec(lo=0.0, hi=100.0))

    def params(self):
        from people_tracker.tracker.tracks import TrackParams
        return _params_of(self, TrackParams)


@dataclass(frozen=True)
class ExistenceConfig:
    """Existence probability of a track; see :class:`people_tracker.tracker.existence.ExistenceParams`."""

    prior_moving: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    prior_standing: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    arrived_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    motion_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    present_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    seen_through_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    independent_s: float = field(metadata=_spec(lo=0.0, hi=60.0))
    shape_time_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))
    min_shape_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    max_shape_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    max_evidence_probability: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    confirm: float = field(metadata=_spec(lo=0.0, hi=1.0))
    keep: float = field(metadata=_spec(lo=0.0, hi=1.0))
    delete: float = field(metadata=_spec(lo=0.0, hi=1.0))
    place_radius_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    furniture_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    place_keyframe_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))
    place_memory_s: float = field(metadata=_spec(lo=0.0, hi=86400.0))
    place_before_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))
    unseen_half_life_s: float = field(metadata=_spec(lo=0.0, hi=86400.0))
    report_unseen_s: float = field(metadata=_spec(lo=0.0, hi=86400.0))
    motion_miss_lr: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    confidence_raw: tuple = field(metadata=_spec(lo=0.0, hi=1.0))
    confidence_calibrated: tuple = field(metadata=_spec(lo=0.0, hi=1.0))

    def __post_init__(self) -> None:
        raw, cal = self.confidence_raw, self.confidence_calibrated
        if len(raw) != len(cal):
            raise InputError(f"configuration keys 'existence.confidence_raw' and 'existence.confidence_calibrated' "
                             f"must have the same length ({len(raw)} and {len(cal)})")
        if any(b <= a for a, b in zip(raw, raw[1:])) or any(b < a for a, b in zip(cal, cal[1:])):
            raise InputError("configuration key 'existence.confidence_raw' must increase and "
                             "'existence.confidence_calibrated' must not decrease")

    def params(self):
        from people_tracker.tracker.existence import ExistenceParams
        return _params_of(self, ExistenceParams)


@dataclass(frozen=True)
class AssociationConfig:
    """Association and static support; see :class:`people_tracker.tracker.people_tracker.AssociationParams`."""

    method: str = field(metadata=_spec(choices=("gnn", "nn")))
    gate_chi2: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1e6))
    spawn_exclusion_m: float = field(metadata=_spec(lo=0.0, hi=100.0))
    support_radius_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    support_sigma_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    support_min_points: int = field(metadata=_spec(lo=1, hi=10000))
    support_min_width_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    support_anchor_m: float = field(metadata=_spec(lo=0.0, hi=100.0))
    free_space_lookback_s: float = field(metadata=_spec(lo=0.0, hi=60.0))
    free_space_margin_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    recover_radius_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    start_leg_probability: float = field(metadata=_spec(lo=0.0, hi=1.01))
    receding: bool = field(metadata=_spec())
    set_off_speed_mps: float = field(metadata=_spec(lo=0.0, hi=10.0))
    contested_set_off_probability: float = field(metadata=_spec(lo=0.0, hi=1.0))
    stopping_speed_mps: float = field(metadata=_spec(lo=0.0, hi=10.0))

    def params(self):
        from people_tracker.tracker.people_tracker import AssociationParams
        return _params_of(self, AssociationParams)


@dataclass(frozen=True)
class StandingConfig:
    """Standing people found by leg shape; see :class:`people_tracker.tracker.standing.StandingParams`."""

    enabled: bool = field(metadata=_spec())
    min_leg_probability: float = field(metadata=_spec(lo=0.0, hi=1.0))
    min_leg_separation_m: float = field(metadata=_spec(lo=0.0, hi=5.0))
    max_leg_separation_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=5.0))
    confirm_window_s: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=60.0))
    confirm_share: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    confirm_radius_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    furniture_radius_m: float = field(metadata=_spec(lo=0.0, hi=100.0))
    arrivals: bool = field(metadata=_spec())

    def params(self):
        from people_tracker.tracker.standing import StandingParams
        return _params_of(self, StandingParams)


@dataclass(frozen=True)
class LegsConfig:
    """The leg model; see :mod:`people_tracker.models.leg_model`."""

    model: str = field(metadata=_spec())

    def load(self):
        """The leg model this configuration names, or :class:`InputError` saying why not."""
        from people_tracker.models.leg_model import LegModelError, load_leg_model
        try:
            return load_leg_model(self.model)
        except LegModelError as exc:
            raise InputError(f"configuration key 'legs.model': {exc}") from None


@dataclass(frozen=True)
class AlignmentConfig:
    """Scan matching; see :class:`people_tracker.detection.align.AlignParams` and :class:`people_tracker.detection.icp.IcpParams`."""

    enabled: bool = field(metadata=_spec())
    exclude_radius_m: float = field(metadata=_spec(lo=0.0, hi=10.0))
    max_iterations: int = field(metadata=_spec(lo=1, hi=1000))
    max_correspondence_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    min_correspondence_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    trim_fraction: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=1.0))
    normal_max_gap_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    degeneracy_ratio: float = field(metadata=_spec(lo=0.0, hi=1.0))
    min_pairs: int = field(metadata=_spec(lo=3, hi=100000))
    min_overlap: float = field(metadata=_spec(lo=0.0, hi=1.0))
    max_rms_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=10.0))
    max_correction_m: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=100.0))
    max_correction_rad: float = field(metadata=_spec(lo=0.0, lo_open=True, hi=3.15))
    max_source_points: int = field(metadata=_spec(lo=0, hi=1000000))
    fade_s: float = field(metadata=_spec(lo=0.0, hi=3600.0))

    def params(self):
        from people_tracker.detection.align import AlignParams
        from people_tracker.detection.icp import IcpParams
        own = ("enabled", "exclude_radius_m", "fade_s")
        icp = {k: v for k, v in dataclasses.asdict(self).items() if k not in own}
        return AlignParams(self.enabled, self.exclude_radius_m, IcpParams(**icp), self.fade_s)


@dataclass(frozen=True)
class Config:
    """The whole resolved configuration."""

    odometry: OdometryConfig
    scan_checks: ScanChecksConfig
    detector: DetectorConfig
    pairing: PairingConfig
    tracks: TracksConfig
    existence: ExistenceConfig
    association: AssociationConfig
    standing: StandingConfig
    legs: LegsConfig
    alignment: AlignmentConfig

    def to_dict(self) -> dict:
        def plain(v):
            if isinstance(v, dict):
                return {k: plain(x) for k, x in v.items()}
            return list(v) if isinstance(v, tuple) else v
        return plain(dataclasses.asdict(self))


def _default_text() -> str:
    return shipped_file("default").read_text(encoding="utf-8")


def _merge(base: dict, override: dict, where: str) -> dict:
    out = dict(base)
    for key, value in override.items():
        name = f"{where}{key}"
        if key not in base:
            raise InputError(f"unknown configuration key '{name}' (known: {', '.join(sorted(base))})")
        if isinstance(base[key], dict):
            if not isinstance(value, dict):
                raise InputError(f"configuration key '{name}' must be a mapping of its keys")
            out[key] = _merge(base[key], value, f"{name}.")
        else:
            out[key] = value
    return out


def _check_value(name: str, value: Any, typ: type, spec: dict) -> Any:
    if typ is tuple:  # a non-empty list of numbers, each checked against the range
        if not isinstance(value, list) or not value:
            raise InputError(f"configuration key '{name}' must be a non-empty list of numbers, got {value!r}")
        return tuple(_check_value(name, v, float, spec) for v in value)
    if typ is bool:
        if not isinstance(value, bool):
            raise InputError(f"configuration key '{name}' must be true or false, got {value!r}")
        return value
    if typ is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(f"configuration key '{name}' must be a whole number, got {value!r}")
    elif typ is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"configuration key '{name}' must be a number, got {value!r}")
        value = float(value)
        if not math.isfinite(value):
            raise InputError(f"configuration key '{name}' must be finite, got {value!r}")
    elif typ is str:
        if not isinstance(value, str):
            raise InputError(f"configuration key '{name}' must be a string, got {value!r}")
        if spec["choices"] and value not in spec["choices"]:
            raise InputError(
                f"configuration key '{name}' must be one of {', '.join(spec['choices'])}; got {value!r}"
            )
        return value
    lo, hi = spec["lo"], spec["hi"]
    if lo is not None and (value < lo or (spec["lo_open"] and value == lo)):
        rel = ">" if spec["lo_open"] else ">="
        raise InputError(f"configuration key '{name}' must be {rel} {lo}, got {value!r}")
    if hi is not None and value > hi:
        raise InputError(f"configuration key '{name}' must be <= {hi}, got {value!r}")
    return value


# pairs of keys of one section where the first must not exceed the second (besides every
# min_X and max_X, found by name)
_ORDERED = (("delete", "keep"), ("keep", "confirm"))


def _check_order(values: dict, where: str) -> None:
    """Every ``min_X`` at most its ``max_X``, and the pairs of ``_ORDERED``, in one section."""
    pairs = [(k, "max_" + k[4:]) for k in values if k.startswith("min_") and "max_" + k[4:] in values]
    pairs += [(a, b) for a, b in _ORDERED if a in values and b in values]
    for lo, hi in pairs:
        if isinstance(values[lo], (int, float)) and isinstance(values[hi], (int, float)) and values[lo] > values[hi]:
            raise InputError(f"configuration key '{where}{lo}' ({values[lo]:g}) must not exceed "
                             f"'{where}{hi}' ({values[hi]:g})")


def _build(cls: type, data: dict, where: str):
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        name = f"{where}{f.name}"
        if f.name not in data:
            raise InputError(f"configuration key '{name}' is missing")
        typ = hints[f.name]
        if dataclasses.is_dataclass(typ):
            if not isinstance(data[f.name], dict):
                raise InputError(f"configuration key '{name}' must be a mapping of its keys")
            kwargs[f.name] = _build(typ, data[f.name], f"{name}.")
        else:
            kwargs[f.name] = _check_value(name, data[f.name], typ, f.metadata)
    _check_order(kwargs, where)
    return cls(**kwargs)


def _parse_yaml(text: str, origin: str) -> dict:
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}" if mark is not None else ""
        raise InputError(f"configuration {origin} is not valid YAML{at}") from None
    if data is None:
        raise InputError(f"configuration {origin} is empty")
    if not isinstance(data, dict):
        raise InputError(f"configuration {origin} must be a mapping of sections, got {type(data).__name__}")
    return data


def default_config_dict() -> dict:
    """The shipped defaults as a plain nested dict."""
    return _parse_yaml(_default_text(), "default.yaml")


def config_from_dict(overrides: dict | None = None) -> Config:
    """Build a :class:`Config` from the defaults with ``overrides`` (a nested dict) applied."""
    merged = _merge(default_config_dict(), overrides or {}, "")
    return _build(Config, merged, "")


def load_config(path: str | Path | None = None) -> Config:
    """Load the defaults, overridden by a shipped configuration (a name such as
    ``moving_robot``) or by the YAML file at ``path`` (it ends in ``.yaml``/``.yml`` or holds
    a path separator)."""
    if path is None:
        return config_from_dict()
    if not names_a_file(path):
        f = shipped_file(str(path))
        if f is None:
            raise InputError(f"no shipped configuration '{path}' (shipped: {', '.join(shipped_names())}; "
                             f"a file needs .yaml or a path separator, e.g. ./{path}.yaml)")
        return config_from_dict(_parse_yaml(f.read_text(encoding="utf-8"), f"shipped configuration '{path}'"))
    p = Path(path)
    if not p.exists():
        raise InputError(f"configuration file '{p}' does not exist")
    if p.is_dir():
        raise InputError(f"configuration file '{p}' is a directory")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"configuration file '{p}' cannot be read: {exc}") from None
    return config_from_dict(_parse_yaml(text, f"file '{p}'"))


def load_config_or_exit(path: str | Path | None, program: str) -> Config:
    """:func:`load_config` for a script's ``--config``: a bad name, file or configuration is
    one line on stderr (``program: ...``) and exit status 2, never a traceback."""
    try:
        return load_config(path)
    except InputError as exc:
        print(f"{program}: {exc}", file=sys.stderr)
        raise SystemExit(2) from None


def dump_config(config: Config) -> str:
    """YAML text of the resolved configuration (written next to every output)."""
    return yaml.safe_dump(config.to_dict(), sort_keys=False)
