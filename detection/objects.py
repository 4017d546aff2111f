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
    return describe_all(object_id, [beams], [points], [sets])[0]


def describe_all(first_id: int, beams: list[np.ndarray], points: list[np.ndarray],
                 sets: list[tuple[int, ...]]) -> list[MovingObject]:
    """:func:`describe` for many objects at once (ids ``first_id``, ``first_id + 1``, ...): one
    call of each geometry operation over all of them, the same geometry as one by one."""
    if not points:
        return []
    counts = [len(p) for p in points]
    clouds = shapely.multipoints(np.concatenate(points), indices=np.repeat(np.arange(len(points)), counts))
    centroids = shapely.centroid(shapely.convex_hull(clouds))
    cx, cy = shapely.get_x(centroids), shapely.get_y(centroids)
    rects = shapely.minimum_rotated_rectangle(clouds)
    # collinear or a single point: a line (or point) with a length and no width
    width, length = np.zeros(len(points)), shapely.length(rects)
    box = (shapely.get_type_id(rects) == shapely.GeometryType.POLYGON) & ~shapely.is_empty(rects)
    if box.any():
        coords, which = shapely.get_coordinates(rects[box], return_index=True)
        first = np.flatnonzero(np.r_[True, which[1:] != which[:-1]])  # each rectangle's first corner
        c0, c1, c2 = coords[first], coords[first + 1], coords[first + 2]
        side_a = np.hypot(c1[:, 0] - c0[:, 0], c1[:, 1] - c0[:, 1])
        side_b = np.hypot(c2[:, 0] - c1[:, 0], c2[:, 1] - c1[:, 1])
        width[box], length[box] = np.minimum(side_a, side_b), np.maximum(side_a, side_b)
    return [MovingObject(first_id + k, beams[k], points[k], float(cx[k]), float(cy[k]), float(width[k]),
                         float(length[k]), recovered_name(sets[k])) for k in range(len(points))]
