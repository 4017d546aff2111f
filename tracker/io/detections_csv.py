"""The detections CSV of the contract: one row per moving object per scan."""

from __future__ import annotations

from typing import IO

from detection.objects import MovingObject

DETECTION_COLUMNS = ("scan_index", "stamp", "object_id", "first_beam", "last_beam", "n_points", "x", "y",
                     "width", "length", "recovered_from")


def write_header(fh: IO) -> None:
    fh.write(",".join(DETECTION_COLUMNS) + "\n")


def write_rows(fh: IO, scan_index: int, stamp: float, objects: list[MovingObject]) -> None:
    """Rows of one scan: x, y the hull centroid in the sensor frame (m); width <= length (m)."""
    for o in objects:
        fh.write(f"{scan_index},{stamp:.6f},{o.object_id},{o.first_beam},{o.last_beam},{o.n_points},"
                 f"{o.x:.4f},{o.y:.4f},{o.width:.4f},{o.length:.4f},{o.recovered_from}\n")
