"""Free space: was a place empty in an earlier scan?

A walking person stands where, a moment before, the laser saw through to something
farther away. A wall, a chair or a table leg, however misaligned, was never seen through.
"""

from __future__ import annotations

import numpy as np

from people_tracker.detection.scan_lines import bin_to_beams
from people_tracker.models import compiled
from people_tracker.models.compiled import bin_of, njit
from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan


def seen_through(points_world: np.ndarray, scan: Scan, pose: Pose2D, margin_m: float,
                 moving: np.ndarray | None = None, no_return_free_m: float = np.inf) -> np.ndarray:
    """Whether ``scan`` (taken at ``pose``, world frame) saw past each point by ``margin_m``.

    A beam with no return (``inf``, beyond ``range_max``) saw through everything up to
    ``no_return_free_m`` (m; dark surfaces return nothing either, so a user may trust it
    only so far, or not at all with 0), when its run of such beams opens onto the open
    (:meth:`Scan.open_no_return`). A lost
    reading (``nan``, ``0``) tells nothing: surfaces that flicker between a return and none
    (dark, shiny, glass) are exactly what looks moving when it is not. A point outside
    the field of view tells nothing either (False).
    With ``moving`` (the scan's per-beam mask of readings labelled moving), a beam stopped
    short of the point by something moving counts as free too: someone walking away along
    the line of sight hid the place themselves.

    Parameters
    ----------
    points_world : ndarray, shape (k, 2)
        Places in the world frame, metres.
    """
    if len(points_world) == 0:
        return np.zeros(0, dtype=bool)
    local = pose.inverse().transform_points(np.asarray(points_world, dtype=float))
    dist = np.hypot(local[:, 0], local[:, 1])
    if compiled.on:  # the rest, compiled
        return _seen_through_kernel(local, dist, scan.ranges, scan.open_no_return(no_return_free_m),
                            scan.angle_min, scan.angle_increment, scan.range_min, margin_m, moving is not None,
                            moving if moving is not None else scan.no_return, no_return_free_m)
    beam = bin_to_beams(local, scan.angle_min, scan.angle_increment, scan.n_beams)
    inside = beam >= 0
    r = np.full(len(local), -1.0)  # outside the view: neither free nor blocked
    r[inside] = scan.ranges[beam[inside]]
    no_return = np.zeros(len(local), dtype=bool)
    no_return[inside] = scan.open_no_return(no_return_free_m)[beam[inside]]
    no_return &= dist + margin_m <= no_return_free_m
    beyond = np.isfinite(r) & (r > scan.range_min) & (r > dist + margin_m)
    free = no_return | beyond
    if moving is not None:
        hidden = np.zeros(len(local), dtype=bool)
        hidden[inside] = moving[beam[inside]]
        free |= hidden & np.isfinite(r) & (r < dist - margin_m)
    return inside & free


def _seen_through_loop(local, dist, ranges, no_return, angle_min, angle_increment, range_min, margin_m, use_moving,
                       moving, no_return_free_m):
    """:func:`seen_through` from the points in the sensor frame on, one point at a time
    (compiled by numba; the numpy code is the reference)."""
    n_beams = len(ranges)
    out = np.zeros(len(local), np.bool_)
    for k in range(len(local)):
        b = bin_of(local[k, 0], local[k, 1], angle_min, angle_increment, n_beams)
        if b < 0:
            continue  # outside the view: neither free nor blocked
        r = ranges[b]
        free = (no_return[b] and dist[k] + margin_m <= no_return_free_m) or (
            np.isfinite(r) and r > range_min and r > dist[k] + margin_m)
        if use_moving and moving[b] and np.isfinite(r) and r < dist[k] - margin_m:
            free = True
        out[k] = free
    return out


_seen_through_kernel = njit(_seen_through_loop)

UNSEEN, OCCLUDED, OCCUPIED, SEEN_THROUGH = 0, 1, 2, 3


def place_visibility(points_world: np.ndarray, scan: Scan, pose: Pose2D, radius_m: float,
                     no_return_free_m: float = np.inf) -> np.ndarray:
    """What ``scan`` (taken at ``pose``) saw of a disc of ``radius_m`` around each place.

    Returns one code per place (int8): ``SEEN_THROUGH`` when at least half the beams across
    the disc returned and every return lies beyond it (or a beam had no return and
    ``no_return_free_m`` reaches past it): nobody stands there; ``OCCUPIED`` when a return
    lies inside it; ``OCCLUDED`` when something nearer hides it; ``UNSEEN`` when it is
    outside the field of view or too few beams returned (lost readings tell nothing).

    Parameters
    ----------
    points_world : ndarray, shape (k, 2)
        Places in the world frame, metres.
    """
    if len(points_world) == 0:
        return np.full(0, UNSEEN, dtype=np.int8)
    local = pose.inverse().transform_points(np.asarray(points_world, dtype=float))
    dist = np.hypot(local[:, 0], local[:, 1])
    if compiled.on:  # the loop below, compiled
        return _visibility_kernel(local, dist, scan.ranges, scan.valid, scan.open_no_return(no_return_free_m),
                                  scan.angle_min, scan.angle_increment, radius_m, no_return_free_m)
    out = np.full(len(points_world), UNSEEN, dtype=np.int8)
    centre = bin_to_beams(local, scan.angle_min, scan.angle_increment, scan.n_beams)
    inc = abs(scan.angle_increment)
    through = scan.open_no_return(no_return_free_m)
    for k in np.flatnonzero((centre >= 0) & (dist > radius_m)):
        half = int(np.ceil(np.arcsin(min(1.0, radius_m / dist[k])) / inc))
        lo, hi = max(0, centre[k] - half), min(scan.n_beams, centre[k] + half + 1)
        r = scan.ranges[lo:hi]
        valid = scan.valid[lo:hi]
        free = through[lo:hi] & (dist[k] + radius_m <= no_return_free_m)
        rv = r[valid]
        if (np.abs(rv - dist[k]) <= radius_m).any():
            out[k] = OCCUPIED
        elif (rv < dist[k] - radius_m).any():
            out[k] = OCCLUDED
        elif valid.sum() + free.sum() >= 0.5 * (hi - lo):
            out[k] = SEEN_THROUGH
    return out


def _visibility_loop(local, dist, ranges, valid, no_return, angle_min, angle_increment, radius_m, no_return_free_m):
    """:func:`place_visibility` from the places in the sensor frame on, as one loop
    (compiled by numba; the numpy code is the reference)."""
    n_beams = len(ranges)
    inc = abs(angle_increment)
    out = np.full(len(local), UNSEEN, np.int8)
    for k in range(len(local)):
        centre = bin_of(local[k, 0], local[k, 1], angle_min, angle_increment, n_beams)
        if centre < 0 or not dist[k] > radius_m:
            continue
        half = int(np.ceil(np.arcsin(min(1.0, radius_m / dist[k])) / inc))
        lo, hi = max(0, centre - half), min(n_beams, centre + half + 1)
        reach = dist[k] + radius_m <= no_return_free_m
        occupied = occluded = False
        count = 0
        for b in range(lo, hi):
            if valid[b]:
                count += 1
                if np.abs(ranges[b] - dist[k]) <= radius_m:
                    occupied = True
                elif ranges[b] < dist[k] - radius_m:
                    occluded = True
            elif no_return[b] and reach:
                count += 1
        if occupied:
            out[k] = OCCUPIED
        elif occluded:
            out[k] = OCCLUDED
        elif count >= 0.5 * (hi - lo):
            out[k] = SEEN_THROUGH
    return out


_visibility_kernel = njit(_visibility_loop)


class PlaceMemory:
    """What the laser saw of each place over the last minutes: sparse keyframes (one scan
    every ``keyframe_s`` seconds, ``memory_s`` seconds of them) and their sensor poses.

    It answers whether a place was ever seen empty, or only ever seen occupied, before a
    given time: someone who walked in and stopped stands where the laser once saw through;
    a table leg stands where it was occupied from the first scan on.
    """

    EMPTY, OCCUPIED_ONLY, UNKNOWN = "empty", "occupied", "unknown"

    def __init__(self, keyframe_s: float = 1.0, memory_s: float = 600.0) -> None:
        from collections import deque
        self.keyframe_s = keyframe_s
        self._frames: deque = deque(maxlen=max(1, int(round(memory_s / keyframe_s))) if keyframe_s > 0 else 1)
        self._xy: np.ndarray | None = None  # the keyframes' sensor positions (see _positions)
        self._from_first = True  # the oldest keyframe is the first scan the laser took (none dropped yet)

    def add(self, scan: Scan, pose: Pose2D) -> None:
        """Offer a scan (sensor pose in the world frame); kept when a keyframe is due."""
        if self.keyframe_s <= 0:
            return
        if not self._frames or scan.stamp - self._frames[-1][0].stamp >= self.keyframe_s or \
                scan.stamp < self._frames[-1][0].stamp:
            if self._frames and (len(self._frames) == self._frames.maxlen or scan.stamp < self._frames[-1][0].stamp):
                self._from_first = False
            self._frames.append((scan, pose))
            self._xy = None

    def history(self, xy_world: np.ndarray, before_s: float, radius_m: float,
                no_return_free_m: float = np.inf, min_occupied_s: float = 10.0,
                min_occupied_from_first_s: float = 2.0) -> str:
        """``EMPTY`` when a keyframe older than ``before_s`` (a stamp, s) saw through the disc
        of ``radius_m`` around the place, else ``OCCUPIED_ONLY`` when keyframes worth at
        least ``min_occupied_s`` of time saw a return in it (a person passing by does not
        make a place occupied), or when every keyframe from the laser's first scan on saw a
        return in it, worth at least ``min_occupied_from_first_s`` (occupied as long as the
        laser has looked: a pillar a track slid onto in the first seconds of a recording),
        else ``UNKNOWN`` (never in view, or mostly hidden)."""
        return self.histories(np.asarray(xy_world, dtype=float).reshape(1, 2), before_s, radius_m,
                              no_return_free_m, min_occupied_s, min_occupied_from_first_s=min_occupied_from_first_s)[0]

    def histories(self, xy_world: np.ndarray, before_s: float, radius_m: float,
                  no_return_free_m: float = np.inf, min_occupied_s: float = 10.0,
                  viewpoint: np.ndarray | None = None, viewpoint_radius_m: float = np.inf,
                  min_occupied_from_first_s: float = 2.0) -> list[str]:
        """:meth:`history` of each of several places (shape (k, 2), world frame, m), one pass
        over the keyframes; with ``viewpoint`` (a sensor position, world frame, m), only of
        the keyframes taken within ``viewpoint_radius_m`` of it (then the laser's first scan
        counts as the first only when it was taken there)."""
        points = np.asarray(xy_world, dtype=float).reshape(-1, 2)
        empty = np.zeros(len(points), dtype=bool)
        occupied = np.zeros(len(points), dtype=np.int64)
        frames = list(self._frames)
        from_first = self._from_first
        if viewpoint is not None and frames:
            near = np.hypot(*(self._positions() - np.asarray(viewpoint, dtype=float)).T) <= viewpoint_radius_m
            from_first = from_first and bool(near[0])
            frames = [f for f, ok in zip(frames, near) if ok]
        looked = 0
        for scan, pose in frames:
            if scan.stamp >= before_s or empty.all():
                break
            open_ = np.flatnonzero(~empty)
            code = place_visibility(points[open_], scan, pose, radius_m, no_return_free_m)
            empty[open_[code == SEEN_THROUGH]] = True
            occupied[open_] += code == OCCUPIED
            looked += 1
        # occupied in every keyframe since the laser's first scan: as long as it has looked
        always = (occupied == looked) if from_first else np.zeros(len(points), dtype=bool)
        return [self.EMPTY if e else self.OCCUPIED_ONLY
                if o * self.keyframe_s >= min_occupied_s or (a and o * self.keyframe_s >= min_occupied_from_first_s)
                else self.UNKNOWN for e, o, a in zip(empty, occupied, always)]

    def _positions(self) -> np.ndarray:
        """The keyframes' sensor positions (world frame, m), shape (n, 2), kept until the next keyframe."""
        if self._xy is None:
            self._xy = np.array([(pose.x, pose.y) for _, pose in self._frames], dtype=float).reshape(-1, 2)
        return self._xy

    def reset(self) -> None:
        self._frames.clear()
        self._xy = None
        self._from_first = True
