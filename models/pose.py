"""Planar rigid-body poses (SE(2)) in metres and radians."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.cached import cached_property


def wrap_angle(angle):
    """Wrap an angle (or array of angles) in radians to [-pi, pi)."""
    if type(angle) is float:  # the common scalar case, without numpy's overhead (the same arithmetic)
        return (angle + math.pi) % (2.0 * math.pi) - math.pi
    return (np.asarray(angle) + np.pi) % (2.0 * np.pi) - np.pi


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Rotation about z of the quaternion (x, y, z, w), radians.

    This is the heading of the rotated frame's x axis projected on the xy plane, which is
    exact for the planar robots this tracker serves.
    """
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True)
class Pose2D:
    """Pose of a child frame in a parent frame: translation (m) and heading (rad).

    ``parent_T_child`` maps points in the child frame to the parent frame:
    ``p_parent = R(yaw) p_child + (x, y)``.
    """

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    @staticmethod
    def identity() -> "Pose2D":
        return Pose2D(0.0, 0.0, 0.0)

    def compose(self, other: "Pose2D") -> "Pose2D":
        """``self ∘ other``: a_T_c from self = a_T_b and other = b_T_c."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        # t_ac = R_ab t_bc + t_ab ; yaw_ac = yaw_ab + yaw_bc
        return _pose(self.x + c * other.x - s * other.y, self.y + s * other.x + c * other.y,
                     _wrap(self.yaw + other.yaw))

    def __matmul__(self, other: "Pose2D") -> "Pose2D":
        return self.compose(other)

    def inverse(self) -> "Pose2D":
        """b_T_a from self = a_T_b (worked out once per pose: poses are immutable)."""
        inv = self.__dict__.get("_inverse")
        if inv is None:
            c, s = math.cos(self.yaw), math.sin(self.yaw)
            # t_ba = -R_abᵀ t_ab
            inv = self.__dict__["_inverse"] = _pose(-(c * self.x + s * self.y), -(-s * self.x + c * self.y),
                                                    _wrap(-self.yaw))
        return inv

    def between(self, other: "Pose2D") -> "Pose2D":
        """Relative pose self⁻¹ ∘ other: where ``other`` is, seen from ``self``
        (:meth:`compose` written out, with the inverse's cached cosine and sine)."""
        inv = self.inverse()
        c, s = inv._cos_sin
        return _pose(inv.x + c * other.x - s * other.y, inv.y + s * other.x + c * other.y, _wrap(inv.yaw + other.yaw))

    @cached_property
    def _cos_sin(self) -> tuple[float, float]:
        """cos and sin of the heading, once per pose (poses are immutable)."""
        return math.cos(self.yaw), math.sin(self.yaw)

    def transform_points(self, points: np.ndarray) -> np.ndarray:
        """Map points (n, 2) from the child frame to the parent frame, metres.

        ``x' = (x c - y s) + t_x``, ``y' = (x s + y c) + t_y``, in that order, element by
        element: the same bits from the compiled loop as from numpy, and on every machine
        (a matrix product goes through the BLAS, whose kernels differ from CPU to CPU)."""
        c, s = self._cos_sin
        return rotate_translate(points, c, s, self.x, self.y)

    def as_matrix(self) -> np.ndarray:
        """Homogeneous 3x3 matrix of this pose."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, -s, self.x], [s, c, self.y], [0.0, 0.0, 1.0]])


_new = object.__new__


def _pose(x: float, y: float, yaw: float) -> Pose2D:
    """``Pose2D(x, y, yaw)`` without the frozen dataclass's ``__init__`` (three
    ``object.__setattr__`` calls, 0.2 µs of a step's dozens of poses): the fields go into the
    instance's ``__dict__``, where that ``__init__`` puts them."""
    p = _new(Pose2D)
    d = p.__dict__
    d["x"], d["y"], d["yaw"] = x, y, yaw
    return p


def _wrap(angle: float) -> float:
    """:func:`wrap_angle` of a scalar, as a float (the same arithmetic)."""
    return float((angle + math.pi) % (2.0 * math.pi) - math.pi)


def rotate_translate(points: np.ndarray, c: float, s: float, tx: float, ty: float) -> np.ndarray:
    """Points (n, 2) rotated by the angle of cosine ``c`` and sine ``s`` and moved by
    (``tx``, ``ty``) metres: :meth:`Pose2D.transform_points`' arithmetic, for callers that
    hold the cosine and sine already (the scan matcher's iterations)."""
    pts = np.asarray(points, dtype=np.float64)
    if compiled.on and pts.ndim == 2 and pts.shape[1] == 2:
        return _transform_kernel(np.ascontiguousarray(pts), float(c), float(s), float(tx), float(ty))
    x, y = pts[..., 0], pts[..., 1]
    out = np.empty(np.broadcast_shapes(pts.shape, (2,)))
    out[..., 0] = x * c - y * s + tx
    out[..., 1] = x * s + y * c + ty
    return out


def _transform_loop(pts, c, s, tx, ty):
    """:meth:`Pose2D.transform_points` of (n, 2) points, the same arithmetic in the same order."""
    out = np.empty_like(pts)
    for i in range(len(pts)):
        x, y = pts[i, 0], pts[i, 1]
        out[i, 0] = x * c - y * s + tx
        out[i, 1] = x * s + y * c + ty
    return out


_transform_kernel = compiled.njit(_transform_loop)
transform_kernel = _transform_kernel  # for kernels that move points themselves; None without numba


def interpolate_pose(p0: Pose2D, p1: Pose2D, fraction: float) -> Pose2D:
    """Pose a ``fraction`` of the way from p0 to p1 (0 → p0, 1 → p1; beyond extrapolates).

    Translation is linear and heading follows the shorter arc.
    """
    dyaw = _wrap(p1.yaw - p0.yaw)
    return _pose(p0.x + fraction * (p1.x - p0.x), p0.y + fraction * (p1.y - p0.y), _wrap(p0.yaw + fraction * dyaw))


def pairwise_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance of every point of ``a`` (shape (n, 2)) to every point of ``b``
    (shape (m, 2)), both in one frame, metres; shape (n, m). A compiled loop when numba is
    on (the same subtractions and ``hypot``; numpy's broadcasting costs more than the
    arithmetic for the few points a step compares)."""
    if compiled.on:
        a2, b2 = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
        if a2.ndim == 2 and b2.ndim == 2 and a2.shape[1] == 2 and b2.shape[1] == 2:
            return _pairwise_kernel(a2, b2)
    return np.hypot(a[:, None, 0] - b[None, :, 0], a[:, None, 1] - b[None, :, 1])


def _pairwise_loop(a, b):
    """:func:`pairwise_distances` as one loop (compiled by numba)."""
    out = np.empty((len(a), len(b)))
    for i in range(len(a)):
        for j in range(len(b)):
            out[i, j] = np.hypot(a[i, 0] - b[j, 0], a[i, 1] - b[j, 1])
    return out


_pairwise_kernel = compiled.njit(_pairwise_loop)


def near_any(a: np.ndarray, b: np.ndarray, radius_m: float) -> np.ndarray:
    """Whether each point of ``a`` (shape (n, 2)) lies closer than ``radius_m`` metres to some
    point of ``b`` (shape (m, 2)), both in one frame: ``pairwise_distances(a, b).min(axis=1) <
    radius_m``, and the same answer (a compiled loop that skips the distance of a pair
    farther apart than the radius along x or y, when numba is on and ``b`` holds no nan: one
    would make numpy's minimum of every row nan, and so no point near)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if not len(a) or not len(b):
        return np.zeros(len(a), dtype=bool)
    if compiled.on and not np.isnan(b).any():
        return _near_any_kernel(np.ascontiguousarray(a), np.ascontiguousarray(b), float(radius_m))
    return pairwise_distances(a, b).min(axis=1) < radius_m


def _near_any_loop(a, b, radius_m):
    """:func:`near_any` when ``b`` holds no nan: a distance is at least its larger side, so a
    pair that far apart along x or y is not near (nor one with a nan in ``a``, which numpy
    finds near nothing either), and the others are measured as numpy does (``hypot``)."""
    out = np.zeros(len(a), np.bool_)
    for i in range(len(a)):
        for j in range(len(b)):
            dx, dy = a[i, 0] - b[j, 0], a[i, 1] - b[j, 1]
            if abs(dx) < radius_m and abs(dy) < radius_m and np.hypot(dx, dy) < radius_m:
                out[i] = True
                break
    return out


_near_any_kernel = compiled.njit(_near_any_loop)


def best_within(places: np.ndarray, legs: np.ndarray, scores: np.ndarray, radius_m: float) -> np.ndarray:
    """The best of ``scores`` (one per row of ``legs``) among the legs within ``radius_m``
    metres of each of ``places`` (both (n, 2), one frame); nan where there is none. A compiled
    loop when numba is on and the scores are finite (a pair farther apart along x or y than
    the radius is not within it; the others are measured with ``hypot``, as numpy does), the
    same answers as the numpy expression, which stays the reference."""
    out = np.full(len(places), np.nan)
    if not len(places) or not len(legs):
        return out
    if compiled.on and np.isfinite(scores).all():
        return _best_within_kernel(np.ascontiguousarray(places, dtype=np.float64),
                                   np.ascontiguousarray(legs, dtype=np.float64),
                                   np.ascontiguousarray(scores, dtype=np.float64), float(radius_m))
    near = pairwise_distances(places, legs) <= radius_m
    best = np.where(near, scores[None, :], -1.0).max(axis=1)
    return np.where(near.any(axis=1), best, np.nan)


def _best_within_loop(places, legs, scores, radius_m):
    """:func:`best_within` as one compiled loop (finite scores)."""
    out = np.full(len(places), np.nan)
    for i in range(len(places)):
        best, found = -1.0, False
        for j in range(len(legs)):
            dx, dy = places[i, 0] - legs[j, 0], places[i, 1] - legs[j, 1]
            if abs(dx) <= radius_m and abs(dy) <= radius_m and np.hypot(dx, dy) <= radius_m:
                found = True
                if scores[j] > best:
                    best = scores[j]
        if found:
            out[i] = best
    return out


_best_within_kernel = compiled.njit(_best_within_loop)
