"""Nearest-neighbour search over a scan's readings (2-D points, metres, one frame).

Every stage asks the same question many times a scan: which reading of another scan lies
nearest this point, if any within a bound. The search is exact whichever library answers it:
``pykdtree`` (a core dependency: a compiled tree that builds about 4 times and answers a
scan's few hundred queries about 2-3 times faster than scipy's, where the per-call overhead
dominates) or, when it is not installed (or was loaded with threads by someone else), scipy's
``cKDTree``. ``tests/detection/test_kdtree.py``
checks that both give the same answers on real scans.
"""

from __future__ import annotations

import os
import sys

import numpy as np


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

BACKENDS = ("pykdtree", "scipy") if _PyKDTree is not None else ("scipy",)


class PointTree:
    """A KD-tree of 2-D points with the one query the pipeline needs.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Metres, in whatever frame the queries use. May be empty.
    backend : {"pykdtree", "scipy"}, optional
        Default: the fastest installed.
    """

    __slots__ = ("n", "_tree")

    def __init__(self, points: np.ndarray, backend: str | None = None) -> None:
        points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        self.n = len(points)
        backend = backend or BACKENDS[0]
        if backend not in BACKENDS:
            raise ValueError(f"KD-tree backend {backend!r} is not installed (have: {', '.join(BACKENDS)})")
        if self.n == 0:
            self._tree = None
        elif backend == "pykdtree":
            self._tree = _PyKDTree(points)
        else:
            from scipy.spatial import cKDTree
            self._tree = cKDTree(points)

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
        if self._tree is None:
            return np.full(len(q), np.inf), np.zeros(len(q), dtype=np.int64)
        return self._tree.query(q, k=1, distance_upper_bound=float(distance_upper_bound))
