"""Stage 5: each recovered segment becomes a moving object with a position and a box."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from people_tracker.detection.labels import MOVING, NAMES, OCCLUDED, STATIC


@dataclass(frozen=True, eq=False)
class MovingObject:
    """A moving object found in one scan (sensor frame, metres).

    Attributes
    ----------
    object_id : int
        Unique within one detector's run.
    beams : ndarray of int, shape (k,)
        Indices into the scan's ``ranges`` of the object's readings.
    points : ndarray, shape (k, 2)
        The readings.
    x, y : float
        Centroid of the readings' convex hull.
    width, length : float
        Sides of the minimum rotated bounding rectangle, ``width <= length``.
    recovered_from : str
        Which sets formed it: ``M``, ``M+A``, ``M+O``, ``M+A+O`` or ``O``.
    """

    object_id: int
    beams: np.ndarray
    points: np.ndarray
    x: float
    y: float
    width: float
    length: float
    recovered_from: str

    @property
    def first_beam(self) -> int:
        return int(self.beams.min())

    @property
    def last_beam(self) -> int:
        return int(self.beams.max())

    @property
    def n_points(self) -> int:
        return int(len(self.beams))


_ORDER = (MOVING, STATIC, OCCLUDED)


def recovered_name(sets: tuple[int, ...]) -> str:
    """'M', 'M+A', 'M+O', 'M+A+O' or 'O' for the sets a segment was built from."""
    return "+".join(NAMES[s] for s in _ORDER if s in sets)


def describe(object_id: int, beams: np.ndarray, points: np.ndarray, sets: tuple[int, ...]) -> MovingObject:
    """Convex-hull centroid and minimum rotated rectangle of an object's readings."""
    cloud = shapely.multipoints(points)
    hull = shapely.convex_hull(cloud)
    centroid = shapely.centroid(hull)
    rect = shapely.minimum_rotated_rectangle(cloud)
    if isinstance(rect, shapely.Polygon) and not rect.is_empty:
        c = np.asarray(rect.exterior.coords)[:3]
        sides = sorted([float(np.hypot(*(c[1] - c[0]))), float(np.hypot(*(c[2] - c[1])))])
    else:  # collinear or a single point: a line's length, no width
        sides = [0.0, float(rect.length)]
    return MovingObject(object_id, beams, points, float(centroid.x), float(centroid.y), sides[0], sides[1],
                        recovered_name(sets))
