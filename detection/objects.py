"""Stage 5: each recovered segment becomes a moving object with a position and a box."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from people_tracker.detection.labels import MOVING, NAMES, OCCLUDED, STATIC
from people_tracker.models import compiled


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
    if compiled.on:  # the same geometry in one compiled loop (shapely stays the reference)
        offsets = np.zeros(len(points) + 1, np.int64)
        np.cumsum(counts, out=offsets[1:])
        cx, cy, width, length, unsure = _describe_kernel(np.concatenate(points), offsets)
        if unsure.any():  # too close to call in floating point: as the reference does it
            which = np.flatnonzero(unsure)
            with compiled.numpy_only():
                ref = describe_all(0, [beams[k] for k in which], [points[k] for k in which],
                                   [sets[k] for k in which])
            for k, o in zip(which, ref):
                cx[k], cy[k], width[k], length[k] = o.x, o.y, o.width, o.length
        return [MovingObject(first_id + k, beams[k], points[k], float(cx[k]), float(cy[k]), float(width[k]),
                             float(length[k]), recovered_name(sets[k])) for k in range(len(points))]
    clouds = shapely.multipoints(np.concatenate(points), indices=np.repeat(np.arange(len(points)), counts))
    # GEOS divides by a side's length, which underflows for objects a few nanometres across
    # (readings of 1e-200 m, say, when a driver's range_min is 0): the rectangle it returns is
    # still right to within rounding, so the floating-point warnings say nothing to a user
    with np.errstate(all="ignore"):
        centroids = shapely.centroid(shapely.convex_hull(clouds))
        rects = shapely.minimum_rotated_rectangle(clouds)
    cx, cy = shapely.get_x(centroids), shapely.get_y(centroids)
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


def _orient(ax, ay, bx, by, cx, cy):
    """Which way ``a``, ``b``, ``c`` turn, by GEOS's floating-point filter (the test its
    robust orientation makes first): 1 counter-clockwise, -1 clockwise, 0 on a line, 2 when
    rounding leaves it unsure (GEOS then works in double-double precision)."""
    detleft = (ax - cx) * (by - cy)
    detright = (ay - cy) * (bx - cx)
    det = detleft - detright
    if detleft > 0.0:
        if detright <= 0.0:
            return (det > 0.0) - (det < 0.0)
        detsum = detleft + detright
    elif detleft < 0.0:
        if detright >= 0.0:
            return (det > 0.0) - (det < 0.0)
        detsum = -detleft - detright
    else:
        return (det > 0.0) - (det < 0.0)
    bound = 1e-15 * detsum
    if det >= bound or -det >= bound:
        return (det > 0.0) - (det < 0.0)
    return 2


def _hull(pts):
    """Indices into ``pts`` (shape (n, 2)) of the convex hull's corners, counter-clockwise,
    without collinear or repeated points (Andrew's monotone chain), starting from the
    lexicographically first point; one index when every point is the same, two when they lie
    on a line. None when a turn is too close to call in floating point."""
    n = len(pts)
    order = np.argsort(pts[:, 0], kind="mergesort")
    for i in range(1, n):  # ties in x by y: lexicographic order (nearly sorted already)
        j = i
        while j > 0 and pts[order[j - 1], 0] == pts[order[j], 0] and pts[order[j - 1], 1] > pts[order[j], 1]:
            order[j - 1], order[j] = order[j], order[j - 1]
            j -= 1
    hull = np.empty(2 * n + 1, np.int64)
    h = 0
    for chain in range(2):  # the lower chain left to right, then the upper one back
        start = h
        for t in range(n):
            i = order[t] if chain == 0 else order[n - 1 - t]
            if h > start and pts[hull[h - 1], 0] == pts[i, 0] and pts[hull[h - 1], 1] == pts[i, 1]:
                continue  # a repeated point
            while h >= start + 2:
                a, b = hull[h - 2], hull[h - 1]
                turn = _orient(pts[a, 0], pts[a, 1], pts[b, 0], pts[b, 1], pts[i, 0], pts[i, 1])
                if turn == 2:
                    return None
                if turn > 0:
                    break
                h -= 1
            hull[h] = i
            h += 1
        h -= 1  # each chain's last point starts the other
    return hull[:max(h, 1)]


def _distance(ax, ay, bx, by):
    """GEOS's point distance (a square root, not ``hypot``)."""
    dx, dy = ax - bx, ay - by
    return np.sqrt(dx * dx + dy * dy)


def _off_line(ax, ay, bx, by, px, py, orient):
    """GEOS's distance of ``p`` from the line through ``a`` and ``b``: unsigned when ``orient`` is
    0, else positive to the left; nan when the side is too close to call."""
    if ax == bx and ay == by:
        return _distance(ax, ay, px, py)
    len2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay)
    d = abs(((ay - py) * (bx - ax) - (ax - px) * (by - ay)) / len2) * np.sqrt(len2)
    if orient != 0:
        side = _orient(ax, ay, bx, by, px, py)
        if side == 2:
            return np.nan
        if side < 0:
            d = -d
    return d


def _furthest(p, ring, nh, ax, ay, bx, by, start, orient):
    """GEOS's caliper: from ring corner ``start`` on, the corner farthest from the line ``a``-``b``
    (``orient`` 0: either side, 1: to the left, -1: to the right); -1 when a side is unsure."""
    best = _off_line(ax, ay, bx, by, p[ring[start], 0], p[ring[start], 1], orient)
    nxt, at, at_next = best, start, start
    while True:
        if np.isnan(nxt):
            return -1
        if not ((abs(nxt) >= abs(best)) if orient == 0 else (nxt >= best if orient > 0 else nxt <= best)):
            break
        best, at = nxt, at_next
        at_next = at + 1 if at + 1 < nh else 0
        if at_next == start:
            break
        nxt = _off_line(ax, ay, bx, by, p[ring[at_next], 0], p[ring[at_next], 1], orient)
    return at


def _rectangle(p, ring, nh):
    """The sides (m) of the minimum-area rectangle round the clockwise hull ``p[ring]`` (``ring``
    closed, ``nh`` corners) as GEOS chooses it (its rotating calipers, the first strictly
    smallest area in ring order): the side along the chosen edge and the one across it; nan
    when a side test is too close to call."""
    best = np.inf
    along = across = np.nan
    diam, left, right = 1, 1, -1
    for i in range(nh):
        b0x, b0y, b1x, b1y = p[ring[i], 0], p[ring[i], 1], p[ring[i + 1], 0], p[ring[i + 1], 1]
        diam = _furthest(p, ring, nh, b0x, b0y, b1x, b1y, diam, 0)
        if diam < 0:
            return np.nan, np.nan
        dx, dy = p[ring[diam], 0], p[ring[diam], 1]
        if (dx == b0x and dy == b0y) or (dx == b1x and dy == b1y):
            fx, fy = dx, dy  # the foot of the caliper on the edge's line
        else:
            ex, ey = b1x - b0x, b1y - b0y
            r = ((dx - b0x) * ex + (dy - b0y) * ey) / (ex * ex + ey * ey)
            fx, fy = b0x + r * (b1x - b0x), b0y + r * (b1y - b0y)
        left = _furthest(p, ring, nh, fx, fy, dx, dy, left, 1)
        if i == 0:
            right = diam
        right = _furthest(p, ring, nh, fx, fy, dx, dy, right, -1)
        if left < 0 or right < 0:
            return np.nan, np.nan
        wide = (_off_line(fx, fy, dx, dy, p[ring[left], 0], p[ring[left], 1], 0)
                + _off_line(fx, fy, dx, dy, p[ring[right], 0], p[ring[right], 1], 0))
        deep = _distance(fx, fy, dx, dy)
        if deep * wide < best:
            best, along, across = deep * wide, wide, deep
    return along, across


def _describe_loop(pts, offsets):
    """:func:`describe_all`'s geometry for the objects ``pts[offsets[k]:offsets[k + 1]]`` in one
    compiled loop, as GEOS (through shapely, the numpy path and the reference) computes it: the
    centroid of the convex hull (the ring clockwise from its lowest point, triangles from its
    first corner), the minimum-area rectangle chosen by GEOS's rotating calipers, a line's
    midpoint and length, a point itself. The rectangle's sides come from the calipers' own
    distances rather than from its corners (which GEOS intersects in double-double
    precision), so they may differ from shapely's in the last bits. Returns the centroids,
    widths, lengths, and which objects were too close to call in floating point (for the
    reference to describe)."""
    m = len(offsets) - 1
    cx, cy, width, length = np.empty(m), np.empty(m), np.zeros(m), np.zeros(m)
    unsure = np.zeros(m, np.bool_)
    for k in range(m):
        p = pts[offsets[k]:offsets[k + 1]]
        ccw = _hull(p)
        if ccw is None:
            unsure[k] = True
            continue
        nh = len(ccw)
        if nh == 1:
            cx[k], cy[k] = p[ccw[0], 0], p[ccw[0], 1]
            continue
        if nh == 2:  # a line: its centroid and its length as GEOS sums them
            ax, ay, bx, by = p[ccw[0], 0], p[ccw[0], 1], p[ccw[1], 0], p[ccw[1], 1]
            seg = _distance(ax, ay, bx, by)
            cx[k], cy[k] = seg * ((ax + bx) / 2.0) / seg, seg * ((ay + by) / 2.0) / seg
            length[k] = seg
            continue
        first = 0  # the ring as GEOS gives it: clockwise, from the lowest point (the leftmost of those)
        for t in range(1, nh):
            a, b = ccw[t], ccw[first]
            if p[a, 1] < p[b, 1] or (p[a, 1] == p[b, 1] and p[a, 0] < p[b, 0]):
                first = t
        ring = np.empty(nh + 1, np.int64)
        for t in range(nh + 1):
            ring[t] = ccw[(first - t) % nh]
        bx, by = p[ring[0], 0], p[ring[0], 1]
        sx = sy = area2 = 0.0
        for t in range(nh):
            x1, y1, x2, y2 = p[ring[t], 0], p[ring[t], 1], p[ring[t + 1], 0], p[ring[t + 1], 1]
            a2 = (x1 - bx) * (y2 - by) - (x2 - bx) * (y1 - by)
            sx += a2 * (bx + x1 + x2)
            sy += a2 * (by + y1 + y2)
            area2 += a2
        if area2 == 0.0:
            unsure[k] = True
            continue
        cx[k], cy[k] = sx / 3.0 / area2, sy / 3.0 / area2
        along, across = _rectangle(p, ring, nh)
        if not across > 1e-9:  # unsure, or a sliver (nearly a line) whose calipers point anywhere
            unsure[k] = True
            continue
        width[k], length[k] = min(along, across), max(along, across)
    return cx, cy, width, length, unsure


_orient = compiled.njit(_orient, helper=True) or _orient
_hull = compiled.njit(_hull, helper=True) or _hull
_distance = compiled.njit(_distance, helper=True) or _distance
_off_line = compiled.njit(_off_line, helper=True) or _off_line
_furthest = compiled.njit(_furthest, helper=True) or _furthest
_rectangle = compiled.njit(_rectangle, helper=True) or _rectangle
_describe_kernel = compiled.njit(_describe_loop)
