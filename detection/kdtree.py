"""Nearest-neighbour search over a scan's readings (2-D points, metres, one frame).

Every stage asks the same question many times a scan: which reading of another scan lies
nearest this point, if any within a bound. The search is exact whichever code answers it:
a uniform grid searched ring by ring in one compiled loop (``grid``, when the compiled
kernels are on: :mod:`people_tracker.models.compiled`), which builds about 3 times and
answers a scan's queries about 4-5 times faster than ``pykdtree`` (a core dependency: a
compiled tree that builds about 4 times and answers about 2-3 times faster than scipy's,
where the per-call overhead dominates) or, when neither is there (or pykdtree was loaded
with threads by someone else), scipy's ``cKDTree``. ``tests/detection/test_kdtree.py``
checks that all give the same answers on real scans.
"""

from __future__ import annotations

import math
import os
import sys

import numpy as np

from people_tracker.models import compiled


def _import_single_threaded():
    """pykdtree's KDTree, its OpenMP queries held to the calling thread; None without it.

    The Linux wheels bring their own copy of libgomp, which reads ``OMP_NUM_THREADS`` once,
    when it loads. Left at its default it starts a worker per core, and between the
    pipeline's queries (a few hundred points, every ~100 us) the workers spin waiting for the
    next one: a whole second core kept busy, and on one core the tracker at half speed. So
    the variable is 1 while it loads, and put back at once (nothing else sees it). A
    pykdtree someone else loaded first keeps its threads: then scipy's tree answers instead.
    """
    if "pykdtree.kdtree" in sys.modules:
        return None
    saved = os.environ.get("OMP_NUM_THREADS")
    os.environ["OMP_NUM_THREADS"] = "1"
    try:
        from pykdtree.kdtree import KDTree
    except ImportError:  # pragma: no cover - depends on the installation
        return None
    finally:
        if saved is None:
            del os.environ["OMP_NUM_THREADS"]
        else:
            os.environ["OMP_NUM_THREADS"] = saved
    return KDTree


_PyKDTree = _import_single_threaded()

LIBRARIES = ("pykdtree", "scipy") if _PyKDTree is not None else ("scipy",)
BACKENDS = (("grid",) if compiled.ENABLED else ()) + LIBRARIES

# The grid's cells: small enough that a cell holds a few readings of a scan's surfaces, few
# enough that building it (a count per cell) costs little beside the queries. Neither changes
# an answer, only how fast it comes.
GRID_CELL_M = 0.1
GRID_MAX_CELLS = 16384


def _grid_build(points, cell_m, max_cells):
    """Bucket ``points`` (n >= 1, metres) into a grid of square cells at least ``cell_m``
    wide, at most about ``max_cells`` of them: the grid's origin and cell size, its
    columns and rows, and the points' indices cell by cell (``order``, from
    ``start[c]`` to ``start[c + 1]`` for cell ``c = column * rows + row``)."""
    n = len(points)
    x0, y0, x1, y1 = np.inf, np.inf, -np.inf, -np.inf
    for i in range(n):
        x, y = points[i, 0], points[i, 1]
        x0, x1 = min(x0, x), max(x1, x)
        y0, y1 = min(y0, y), max(y1, y)
    cell = max(cell_m, math.sqrt((x1 - x0) * (y1 - y0) / max_cells))
    nx = int((x1 - x0) / cell) + 1
    ny = int((y1 - y0) / cell) + 1
    start = np.zeros(nx * ny + 1, np.int64)
    key = np.empty(n, np.int64)
    for i in range(n):
        c = int((points[i, 0] - x0) / cell) * ny + int((points[i, 1] - y0) / cell)
        key[i] = c
        start[c + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[fill[key[i]]] = i
        fill[key[i]] += 1
    return np.array([x0, y0, cell]), np.array([nx, ny]), start, order


def _grid_query(points, geometry, shape, start, order, q, bound):
    """For each of ``q`` (m, 2), the nearest of ``points`` closer than ``bound`` (metres):
    its distance (inf for none) and index (``len(points)`` for none); on an exact tie the
    lower index. The cells are searched in square rings around the query's cell, and the
    search stops once the next ring lies farther than the nearest point found."""
    x0, y0, cell = geometry[0], geometry[1], geometry[2]
    nx, ny = shape[0], shape[1]
    n = len(points)
    dist = np.full(len(q), np.inf)
    index = np.full(len(q), n, np.int64)
    for t in range(len(q)):
        qx, qy = q[t, 0], q[t, 1]
        fx, fy = (qx - x0) / cell, (qy - y0) / cell
        if not (np.isfinite(fx) and np.isfinite(fy)):
            continue
        cx, cy = int(math.floor(fx)), int(math.floor(fy))
        best, bi = bound * bound, n  # squared distances, as the trees compare them
        near = min(fx - cx, cx + 1 - fx, fy - cy, cy + 1 - fy)  # to the own cell's nearest side, cells
        k = max(0, -cx, cx - (nx - 1), -cy, cy - (ny - 1))  # the first ring that meets the grid
        k_last = max(cx, nx - 1 - cx, cy, ny - 1 - cy)
        while k <= k_last:
            if k > 0:
                gap = (k - 1 + near) * cell  # the nearest any point of ring k can be
                if gap * gap >= best:
                    break
            i_lo, i_hi = max(cx - k, 0), min(cx + k, nx - 1)
            j_lo, j_hi = max(cy - k, 0), min(cy + k, ny - 1)
            for i in range(i_lo, i_hi + 1):
                if i == cx - k or i == cx + k:  # the ring's whole column ...
                    j_first, j_step = j_lo, 1
                else:  # ... else only its two ends, each where it lies inside the grid
                    j_first, j_step = cy - k, 2 * k
                for j in range(j_first, j_hi + 1, j_step):
                    if j < j_lo:
                        continue
                    c = i * ny + j
                    for s in range(start[c], start[c + 1]):
                        p = order[s]
                        dx, dy = qx - points[p, 0], qy - points[p, 1]
                        d2 = dx * dx + dy * dy
                        if d2 < best or (d2 == best and bi < n and p < bi):
                            best, bi = d2, p
            k += 1
        if bi < n:
            dist[t], index[t] = math.sqrt(best), bi
    return dist, index


def _any_within(points, ny, start, order, i_lo, i_hi, j_lo, j_hi, qx, qy, r, bound, inclusive):
    """Whether a point of the cells ``i_lo..i_hi`` × ``j_lo..j_hi`` lies within ``r`` of
    (``qx``, ``qy``): closer (or as close, ``inclusive``), and closer than ``bound``, as the
    search compares squared distances; the first such point ends the search."""
    for i in range(i_lo, i_hi + 1):
        for j in range(j_lo, j_hi + 1):
            c = i * ny + j
            for s in range(start[c], start[c + 1]):
                p = order[s]
                dx, dy = qx - points[p, 0], qy - points[p, 1]
                d2 = dx * dx + dy * dy
                if d2 < bound * bound:
                    d = math.sqrt(d2)
                    if d < r or (inclusive and d == r):
                        return True
    return False


def _grid_within(points, geometry, shape, start, order, q, radius, bound, inclusive):
    """For each of ``q`` (m, 2), whether its nearest point, searched closer than ``bound``
    (metres), lies closer than ``radius[t]`` (or as close, ``inclusive``): what
    :func:`_grid_query` answers with the distance compared to ``radius``, but the search
    ends at the first point close enough, and covers only the cells within ``radius[t]``."""
    x0, y0, cell = geometry[0], geometry[1], geometry[2]
    nx, ny = shape[0], shape[1]
    out = np.zeros(len(q), np.bool_)
    for t in range(len(q)):
        qx, qy, r = q[t, 0], q[t, 1], radius[t]
        if not (np.isfinite(qx) and np.isfinite(qy)) or not r >= 0.0:
            continue
        # the cells a point within r can lie in (a millionth of a cell wider: rounding)
        i_lo = max(int(math.floor((qx - r - x0) / cell - 1e-6)), 0)
        i_hi = min(int(math.floor((qx + r - x0) / cell + 1e-6)), nx - 1)
        j_lo = max(int(math.floor((qy - r - y0) / cell - 1e-6)), 0)
        j_hi = min(int(math.floor((qy + r - y0) / cell + 1e-6)), ny - 1)
        out[t] = _any_within(points, ny, start, order, i_lo, i_hi, j_lo, j_hi, qx, qy, r, bound, inclusive)
    return out


_grid_build = compiled.njit(_grid_build)
_any_within = compiled.njit(_any_within, helper=True) or _any_within
_grid_within = compiled.njit(_grid_within, helper=True)  # called from the detector's kernels (and PointTree.within)
grid_within_kernel = _grid_within  # for kernels that test radii themselves; None without numba
_grid_query = compiled.njit(_grid_query)
grid_query_kernel = _grid_query  # for kernels that search a grid themselves (the scan matcher's); None without numba


class PointTree:
    """A KD-tree of 2-D points with the one query the pipeline needs.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Metres, in whatever frame the queries use. May be empty.
    backend : {"grid", "pykdtree", "scipy"}, optional
        Default: the grid when the compiled kernels are on, else the fastest library installed.
    """

    __slots__ = ("n", "_tree", "_points", "_grid")

    def __init__(self, points: np.ndarray, backend: str | None = None) -> None:
        points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        self.n = len(points)
        if backend is None:  # the first there is, the grid only while the kernels are on
            backend = next(b for b in BACKENDS if b != "grid" or compiled.on)
        if backend not in BACKENDS:
            raise ValueError(f"KD-tree backend {backend!r} is not installed (have: {', '.join(BACKENDS)})")
        self._tree = self._grid = None
        if self.n == 0:
            return
        if backend == "grid":
            self._points = points
            self._grid = _grid_build(points, GRID_CELL_M, GRID_MAX_CELLS)
        elif backend == "pykdtree":
            self._tree = _PyKDTree(points)
        else:
            from scipy.spatial import cKDTree
            self._tree = cKDTree(points)

    @property
    def grid(self) -> tuple | None:
        """The grid's arrays, as :data:`grid_query_kernel` takes them before the queries:
        the points and the grid's geometry, shape, cell starts and order; None when another
        backend answers (or the tree is empty)."""
        return None if self._grid is None else (self._points, *self._grid)

    def within(self, points: np.ndarray, radius: np.ndarray, inclusive: bool = False) -> np.ndarray:
        """Whether each of ``points`` (m, 2; metres, the tree's frame) has a point of the
        tree closer than its ``radius`` (m,; metres), or as close when ``inclusive``:
        ``d < radius`` (``d <= radius``) for ``d, _ = query(points, radius.max())``, the same
        answer, found faster on the grid (the search stops at the first point close enough).
        """
        q = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        radius = np.ascontiguousarray(radius, dtype=np.float64)
        bound = float(radius.max()) if len(radius) else 0.0
        if self._grid is not None and compiled.on:
            return _grid_within(self._points, *self._grid, q, radius, bound, inclusive)
        d, _ = self.query(q, bound)
        return d <= radius if inclusive else d < radius

    def query(self, points: np.ndarray, distance_upper_bound: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
        """Distance to, and index of, the nearest point for each of ``points``.

        Parameters
        ----------
        points : ndarray, shape (m, 2)
            Metres, the tree's frame.
        distance_upper_bound : float
            Metres; a nearest point this far or farther is not returned.

        Returns
        -------
        dist : ndarray of float, shape (m,)
            Metres; ``inf`` where no point lies closer than the bound.
        index : ndarray of int, shape (m,)
            Index into the tree's points; ``n`` (one past the last) where none.
        """
        q = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        if self._grid is not None:
            return _grid_query(self._points, *self._grid, q, float(distance_upper_bound))
        if self._tree is None:
            return np.full(len(q), np.inf), np.zeros(len(q), dtype=np.int64)
        return self._tree.query(q, k=1, distance_upper_bound=float(distance_upper_bound))
