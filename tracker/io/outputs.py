"""The CSV outputs of the contract: detections (one row per moving object per scan) and
tracks (one row per reported track per scan)."""

from __future__ import annotations

from typing import IO

import numpy as np
import shapely

from people_tracker.detection.objects import MovingObject

DETECTION_COLUMNS = ("scan_index", "stamp", "object_id", "first_beam", "last_beam", "n_points", "x", "y",
                     "width", "length", "recovered_from")


def write_header(fh: IO) -> None:
    fh.write(",".join(DETECTION_COLUMNS) + "\n")


def write_rows(fh: IO, scan_index: int, stamp: float, objects: list[MovingObject]) -> None:
    """Rows of one scan: x, y the hull centroid in the sensor frame (m); width <= length (m)."""
    for o in objects:
        fh.write(f"{scan_index},{stamp:.6f},{o.object_id},{o.first_beam},{o.last_beam},{o.n_points},"
                 f"{o.x:.4f},{o.y:.4f},{o.width:.4f},{o.length:.4f},{o.recovered_from}\n")


TRACK_COLUMNS = ("scan_index", "stamp", "track_id", "x", "y", "world_x", "world_y", "world_vx", "world_vy",
                 "confidence", "target")


def write_tracks_header(fh: IO) -> None:
    fh.write(",".join(TRACK_COLUMNS) + "\n")


def write_track_rows(fh: IO, scan_index: int, stamp: float, tracks, sensor_xy) -> None:
    """Rows of one scan: x, y in the scan's sensor frame; world_* in the fixed frame (m, m/s)."""
    for t, (x, y) in zip(tracks, sensor_xy):
        fh.write(f"{scan_index},{stamp:.6f},{t.track_id},{x:.4f},{y:.4f},{t.x:.4f},{t.y:.4f},{t.vx:.4f},"
                 f"{t.vy:.4f},{t.confidence:.3f},{int(t.target)}\n")


LEG_COLUMNS = ("scan_index", "stamp", "x", "y", "score")
MIN_LEG_SCORE = 0.01  # candidates scored lower are left out of legs.csv


def write_legs_header(fh: IO) -> None:
    fh.write(",".join(LEG_COLUMNS) + "\n")


def write_leg_rows(fh: IO, scan_index: int, stamp: float, points: np.ndarray, legs, scores: np.ndarray) -> None:
    """Rows of one scan: each leg candidate scored at least MIN_LEG_SCORE, at the centroid of
    its readings' convex hull in the sensor frame (m), with the leg model's probability.

    ``points`` are the scan's valid readings in beam order (sensor frame); ``legs`` the
    scan's :class:`~people_tracker.detection.leg_features.LegCandidates`."""
    keep = np.flatnonzero(scores >= MIN_LEG_SCORE)
    if not len(keep):
        return
    sizes = legs.stop[keep] - legs.start[keep]
    idx = np.concatenate([np.arange(a, b) for a, b in zip(legs.start[keep], legs.stop[keep])])
    hulls = shapely.convex_hull(shapely.multipoints(points[idx], indices=np.repeat(np.arange(len(keep)), sizes)))
    xy = shapely.get_coordinates(shapely.centroid(hulls))
    for (x, y), p in zip(xy, scores[keep]):
        fh.write(f"{scan_index},{stamp:.6f},{x:.4f},{y:.4f},{p:.4f}\n")
