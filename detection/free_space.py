"""Free space: was a place empty in an earlier scan?

A walking person stands where, a moment before, the laser saw through to something
farther away. A wall, a chair or a table leg, however misaligned, was never seen through.
"""

from __future__ import annotations

import numpy as np

from people_tracker.detection.scan_lines import bin_to_beams
from people_tracker.models.pose import Pose2D
from people_tracker.models.scan import Scan


def seen_through(points_world: np.ndarray, scan: Scan, pose: Pose2D, margin_m: float,
                 moving: np.ndarray | None = None, no_return_free_m: float = np.inf) -> np.ndarray:
    """Whether ``scan`` (taken at ``pose``, world frame) saw past each point by ``margin_m``.

    A beam with no return (``inf``, beyond ``range_max``) saw through everything up to
    ``no_return_free_m`` (m; dark surfaces return nothing either, so a user may trust it
    only so far, or not at all with 0). A lost
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
    beam = bin_to_beams(local, scan.angle_min, scan.angle_increment, scan.n_beams)
    inside = beam >= 0
    r = np.full(len(local), -1.0)  # outside the view: neither free nor blocked
    r[inside] = scan.ranges[beam[inside]]
    no_return = np.zeros(len(local), dtype=bool)
    no_return[inside] = scan.no_return[beam[inside]]
    no_return &= dist + margin_m <= no_return_free_m
    beyond = np.isfinite(r) & (r > scan.range_min) & (r > dist + margin_m)
    free = no_return | beyond
    if moving is not None:
        hidden = np.zeros(len(local), dtype=bool)
        hidden[inside] = moving[beam[inside]]
        free |= hidden & np.isfinite(r) & (r < dist - margin_m)
    return inside & free
