"""The laser scan: what a planar laser scanner gives, in its own sensor frame."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from people_tracker.models.cached import cached_property

TWO_PI = 2.0 * np.pi


def beam_index(bearing, angle_min: float, angle_increment: float, n_beams: int) -> np.ndarray:
    """Index of the beam whose line of sight lies nearest each bearing; -1 outside the view.

    The one place that turns a bearing into a beam: it follows the scan's direction (a
    negative ``angle_increment`` counts clockwise) and works for any field of view up to a
    full turn, where the last beam and the first are neighbours.

    Parameters
    ----------
    bearing : array_like of float, shape (m,)
        Bearings in the sensor frame, radians, any branch (they are wrapped here).
    angle_min, angle_increment : float
        Bearing of beam 0 and the step between beams, radians.
    n_beams : int

    Returns
    -------
    ndarray of int64, shape (m,)
        Beam index in ``0 .. n_beams-1``, or -1 for a bearing more than half a beam outside
        the field of view.
    """
    res = abs(angle_increment)
    # the offset from beam 0 in the scan's own direction, wrapped to the one turn centred on
    # the middle of the view, so the blind sector behind splits evenly between the two ends
    centre = 0.5 * (n_beams - 1) * res
    offset = np.array(bearing, dtype=np.float64)  # a private copy, worked on in place
    offset -= angle_min
    if angle_increment < 0:
        np.negative(offset, out=offset)
    offset -= centre
    offset += np.pi
    np.mod(offset, TWO_PI, out=offset)
    offset -= np.pi
    offset += centre
    offset /= res
    step = np.rint(offset, out=offset)
    if n_beams * res >= TWO_PI - 0.5 * res:  # a full turn: the ends meet
        idx = np.full(step.shape, -1, dtype=np.int64)
        inside = np.isfinite(step) & (step > -n_beams) & (step < 2 * n_beams)  # a non-finite bearing is nowhere
        idx[inside] = np.mod(step[inside].astype(np.int64), n_beams)
        return idx
    with np.errstate(invalid="ignore"):
        inside = (step >= 0) & (step < n_beams)  # false for nan: a non-finite bearing is nowhere
    return np.where(inside, step, -1).astype(np.int64)


OPEN_RUN_MIN_WIDTH_M = 0.1  # m: a run of no-return beams narrower than a leg at the reach is a dropout


@dataclass(frozen=True, eq=False)
class Scan:
    """One sweep of a planar laser scanner (ROS ``sensor_msgs/LaserScan`` semantics).

    Beam ``i`` points at ``angle_min + i * angle_increment`` radians in the sensor frame
    (REP 103: x forward, y left, counter-clockwise positive). The increment may be
    negative: some scanners count clockwise.

    Parameters
    ----------
    ranges : ndarray, shape (n,)
        Measured range of each beam, metres. May hold ``nan``, ``inf`` and ``0``;
        see :attr:`valid`. Stored as a read-only float64 copy.

    Raises
    ------
    ValueError
        When the scan is malformed: ``ranges`` not one-dimensional, ``angle_increment``
        zero or not finite, any other number not finite.
    angle_min : float
        Bearing of beam 0 in the sensor frame, radians.
    angle_increment : float
        Bearing step between consecutive beams, radians; non-zero, may be negative.
    range_min, range_max : float
        Limits of a trustworthy reading, metres.
    stamp : float
        Acquisition time of beam 0 (the header stamp), seconds.
    frame_id : str
        Name of the sensor frame, without a leading ``/``.
    time_increment : float
        Time between consecutive beams, seconds (0 when unknown).
    bearings : ndarray, shape (n,), optional
        Exact bearing of each beam's reading, radians, where it is not quite the grid's: a
        de-skewed scan (:func:`people_tracker.detection.deskew.deskew`) keeps each reading on the beam
        nearest its true bearing, and its true bearing here, so :attr:`points` are exact.
        The grid (``angle_min``, ``angle_increment``) still says which beam looks where.
    """

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    stamp: float
    frame_id: str = "laser"
    time_increment: float = 0.0
    bearings: np.ndarray | None = None

    def __post_init__(self) -> None:
        ranges = np.array(self.ranges, dtype=np.float64)  # always a private copy
        if ranges.ndim != 1:
            raise ValueError(f"ranges must be one-dimensional, got shape {ranges.shape}")
        if not math.isfinite(self.angle_increment) or self.angle_increment == 0.0:
            raise ValueError(f"angle_increment must be finite and non-zero, got {self.angle_increment}")
        for name in ("angle_min", "range_min", "range_max", "stamp", "time_increment"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"{name} must be finite, got {getattr(self, name)}")
        ranges.setflags(write=False)
        object.__setattr__(self, "ranges", ranges)
        if self.bearings is not None:
            bearings = np.array(self.bearings, dtype=np.float64)
            if bearings.shape != ranges.shape:
                raise ValueError(f"bearings must have the shape of ranges {ranges.shape}, got {bearings.shape}")
            bearings.setflags(write=False)
            object.__setattr__(self, "bearings", bearings)
        object.__setattr__(self, "frame_id", str(self.frame_id).lstrip("/"))

    @classmethod
    def _made_here(cls, ranges: np.ndarray, like: "Scan", angle_increment: float,
                   bearings: np.ndarray | None) -> "Scan":
        """A scan with ``like``'s other fields, from arrays the caller has just made and
        hands over (float64, one-dimensional, ``bearings`` of their shape or None; a
        finite non-zero increment): what the constructor would make of them, without its
        checks and copies (the de-skew's new scan, every scan)."""
        new = object.__new__(cls)
        ranges.setflags(write=False)
        if bearings is not None:
            bearings.setflags(write=False)
        new.__dict__.update(ranges=ranges, angle_min=like.angle_min, angle_increment=angle_increment,
                            range_min=like.range_min, range_max=like.range_max, stamp=like.stamp,
                            frame_id=like.frame_id, time_increment=like.time_increment, bearings=bearings)
        return new

    @property
    def n_beams(self) -> int:
        """Number of beams, valid or not."""
        return int(self.ranges.shape[0])

    @cached_property
    def valid(self) -> np.ndarray:
        """Boolean mask, shape (n,): finite and strictly between range_min and range_max."""
        r = self.ranges
        with np.errstate(invalid="ignore"):
            mask = np.isfinite(r) & (r > self.range_min) & (r < self.range_max)
        mask.setflags(write=False)
        return mask

    @cached_property
    def no_return(self) -> np.ndarray:
        """Boolean mask, shape (n,): beams that saw nothing within range (``+inf`` or at or
        beyond range_max, REP 117): the line of sight was free up to range_max. ``nan`` and
        ``0`` (a lost reading) say nothing and are not included."""
        r = self.ranges
        with np.errstate(invalid="ignore"):
            mask = np.isposinf(r) | (np.isfinite(r) & (r >= self.range_max))
        mask.setflags(write=False)
        return mask

    def open_no_return(self, reach_m: float) -> np.ndarray:
        """Beams with no return (:attr:`no_return`) in a run of them that opens onto free space:
        the nearest valid reading beside the run, on at least one side, lies beyond
        ``reach_m`` (m), or there is none on that side, and the run is at least
        ``OPEN_RUN_MIN_WIDTH_M`` (a leg) wide at ``reach_m``. A run with a return nearer than
        that on both sides is a dark or shiny patch of one surface, and a narrower one a
        dropout (at an edge, say), not a line of sight into the open. With ``reach_m`` at or
        beyond range_max (the laser trusted to return from everything in its range) every
        beam with no return counts; at 0 or below, none is trusted and the mask is
        :attr:`no_return`. Boolean mask, shape (n,)."""
        if reach_m <= 0 or reach_m >= self.range_max:
            return self.no_return  # trusted nowhere (which beams does not matter), or everywhere
        cache = self.__dict__.setdefault("_open_no_return", {})
        if reach_m not in cache:
            nr = self.no_return
            out = np.zeros(len(nr), dtype=bool)
            if nr.any():
                d = np.diff(np.r_[0, nr.astype(np.int8), 0])
                starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
                idx = self.valid_index
                k = np.searchsorted(idx, starts)  # the first valid reading after each run
                r = self.ranges[idx] if len(idx) else np.zeros(1)
                wide = (ends - starts) * abs(self.angle_increment) * reach_m >= OPEN_RUN_MIN_WIDTH_M
                opens = wide & ((k == 0) | (k == len(idx))  # no reading on one side
                         | (r[np.clip(k - 1, 0, len(r) - 1)] > reach_m) | (r[np.clip(k, 0, len(r) - 1)] > reach_m))
                for a, b in zip(starts[opens].tolist(), ends[opens].tolist()):
                    out[a:b] = True
            out.setflags(write=False)
            cache[reach_m] = out
        return cache[reach_m]

    @property
    def n_valid(self) -> int:
        """Number of valid readings."""
        return int(np.count_nonzero(self.valid))

    @cached_property
    def angles(self) -> np.ndarray:
        """Bearing of every beam in the sensor frame, radians, shape (n,): the grid's, or
        :attr:`bearings` where the scan has them."""
        if self.bearings is not None:
            return self.bearings
        a = self.angle_min + np.arange(self.n_beams, dtype=np.float64) * self.angle_increment
        a.setflags(write=False)
        return a

    @property
    def angle_max(self) -> float:
        """Bearing of the last beam, radians (below ``angle_min`` when counting clockwise)."""
        return self.angle_min + (self.n_beams - 1) * self.angle_increment

    @property
    def resolution(self) -> float:
        """Angular resolution ``|angle_increment|``, radians."""
        return abs(self.angle_increment)

    @cached_property
    def points(self) -> np.ndarray:
        """Cartesian reading of every beam in the sensor frame, metres, shape (n, 2).

        Rows of invalid beams are ``nan``; index with :attr:`valid` for the usable ones.
        """
        r = np.where(self.valid, self.ranges, np.nan)
        xy = np.empty((self.n_beams, 2))
        np.multiply(r, np.cos(self.angles), out=xy[:, 0])
        np.multiply(r, np.sin(self.angles), out=xy[:, 1])
        xy.setflags(write=False)
        return xy

    @cached_property
    def valid_index(self) -> np.ndarray:
        """Beam index of each valid reading, in beam order, shape (m,) (read-only)."""
        idx = np.flatnonzero(self.valid)
        idx.setflags(write=False)
        return idx

    @cached_property
    def valid_points(self) -> np.ndarray:
        """Cartesian readings of the valid beams only, sensor frame, metres, shape (m, 2)
        (read-only)."""
        pts = self.points[self.valid_index]
        pts.setflags(write=False)
        return pts

    def beam_of(self, bearing) -> np.ndarray:
        """Beam nearest each sensor-frame bearing (radians), -1 outside the view; see :func:`beam_index`."""
        return beam_index(bearing, self.angle_min, self.angle_increment, self.n_beams)

    @property
    def beam_times(self) -> np.ndarray:
        """Firing time of every beam relative to :attr:`stamp`, seconds, shape (n,)."""
        return np.arange(self.n_beams, dtype=np.float64) * self.time_increment
