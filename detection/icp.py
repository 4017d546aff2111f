"""Scan matching: point-to-line ICP between two planar scans.

The paper assumes "the initial alignment of the two consecutive laser scans"; on a robot
that moves, everything rests on it (a 1° error at 5 m puts a wall 9 cm off). The matcher
refines a prior (odometry, or a motion prediction) and says how much to trust the result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from people_tracker.detection.kdtree import PointTree, grid_query_kernel as _grid_kernel
from people_tracker.models import compiled
from people_tracker.models.compiled import njit, reduceat_sum
from people_tracker.models.pose import Pose2D, rotate_translate, transform_kernel as _transform_kernel, wrap_angle


@dataclass(frozen=True)
class IcpParams:
    """Tunables of the matcher (units in the names).

    Attributes
    ----------
    max_iterations : int
    max_correspondence_m : float
        Pairs farther apart than this are not matched (first iteration); the gate shrinks
        to ``min_correspondence_m`` as the estimate settles.
    min_correspondence_m : float
    trim_fraction : float
        Share of the pairs kept, the best ones (robust to people and clutter).
    normal_max_gap_m : float
        Neighbours farther apart than this give no normal (an edge, a depth jump).
    degeneracy_ratio : float
        An eigenvalue of the normal equations below this share of the largest marks a
        direction the scene does not constrain (a long corridor); the prior is kept along it.
    min_pairs : int
        Fewer inlier pairs than this: matching fails.
    min_overlap : float
        Share of the usable readings that must find a partner, else matching fails.
    max_rms_m : float
        Inlier residual (RMS, metres) above which matching fails.
    max_correction_m, max_correction_rad : float
        A result farther than this from the prior is not believed (matching fails).
    max_source_points : int
        At most this many of the current scan's readings are matched, evenly spread in
        beam order (0: all of them).
    """

    max_iterations: int = 20
    max_correspondence_m: float = 0.5
    min_correspondence_m: float = 0.1
    trim_fraction: float = 0.8
    normal_max_gap_m: float = 0.2
    degeneracy_ratio: float = 0.06
    min_pairs: int = 30
    min_overlap: float = 0.3
    max_rms_m: float = 0.05
    max_correction_m: float = 0.5
    max_correction_rad: float = 0.35
    max_source_points: int = 0


@dataclass(frozen=True)
class MatchResult:
    """The outcome of matching one scan against a reference scan.

    Attributes
    ----------
    pose : Pose2D
        reference_T_current: the current sensor pose in the reference sensor frame. Equal
        to the prior when matching failed.
    ok : bool
        Whether the match is trusted (otherwise ``pose`` is the prior and ``reason`` says why).
    rms_m : float
        RMS of the inlier point-to-line residuals, metres.
    overlap : float
        Share of the usable current readings with an inlier partner.
    conditioning : float
        Smallest over largest eigenvalue of the normal equations (0: degenerate).
    degenerate : bool
        A direction was unconstrained and kept at the prior.
    iterations : int
    reason : str or None
    """

    pose: Pose2D
    ok: bool
    rms_m: float
    overlap: float
    conditioning: float
    degenerate: bool
    iterations: int
    reason: str | None = None


def line_normals(points: np.ndarray, max_gap: float, half_width: int = 2) -> np.ndarray:
    """Unit normals of readings in scan order, from the neighbours ``half_width`` places
    either side (a wider baseline averages the range noise out); nan where a gap between
    consecutive readings on that span exceeds ``max_gap`` (edges, depth jumps).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Valid readings in beam order, metres.
    """
    if compiled.on:
        return _normals_kernel(points, max_gap, half_width)
    n = len(points)
    k = half_width
    normals = np.full((n, 2), np.nan)
    if n < 2 * k + 1:
        return normals
    d = points[1:] - points[:-1]
    step_ok = np.hypot(d[:, 0], d[:, 1]) < max_gap  # (n-1,)
    # every step on the span i-k .. i+k must be short: a sliding window over the steps
    bad = np.concatenate([[0], np.cumsum(~step_ok)])
    span_bad = bad[2 * k:] - bad[: n - 2 * k]  # steps i-k..i+k-1 for i = k .. n-k-1
    tangent = points[2 * k:] - points[: n - 2 * k]
    length = np.hypot(tangent[:, 0], tangent[:, 1])
    ok = (span_bad == 0) & (length > 1e-9)
    nrm = np.column_stack([-tangent[:, 1], tangent[:, 0]]) / np.where(length > 0, length, 1.0)[:, None]
    normals[k: n - k][ok] = nrm[ok]
    return normals


class ReferenceScan:
    """A scan prepared as the target of matching (its own frame): its readings, their normals
    (nan where a reading has none: an edge, a depth jump) and a KD-tree of all of them.

    ``tree``, when given, is a KD-tree of ``points`` built elsewhere (the detector's own,
    so it is built once a scan).
    """

    def __init__(self, points: np.ndarray, params: IcpParams, tree: PointTree | None = None) -> None:
        self.points = points
        self.normals = line_normals(points, params.normal_max_gap_m)
        self._set_usable(np.isfinite(self.normals[:, 0]))
        self.tree = (tree if tree is not None else PointTree(points)) if self.n_usable else None

    def _set_usable(self, usable: np.ndarray) -> None:
        self.usable = usable
        self.n_usable = int(np.count_nonzero(usable))
        # per KD-tree answer (an index, or one past the last for none): a partner with a normal
        self.usable_or_none = np.zeros(len(usable) + 1, dtype=bool)
        self.usable_or_none[:-1] = usable

    def exclude(self, mask: np.ndarray) -> None:
        """Leave the readings ``mask`` marks (shape (n,)) out of matching."""
        self._set_usable(self.usable & ~mask)


@lru_cache(maxsize=1024)  # one per reading count a laser gives (an array of m indices each)
def _spread(n: int, m: int) -> np.ndarray:
    """``m`` indices evenly spread over ``n`` readings (read-only, shared)."""
    index = np.linspace(0, n - 1, m).round().astype(np.int64)
    index.setflags(write=False)
    return index


def match(current: np.ndarray, reference: ReferenceScan, prior: Pose2D, params: IcpParams,
          exclude: np.ndarray | None = None) -> MatchResult:
    """Point-to-line ICP of ``current`` readings onto ``reference``.

    Parameters
    ----------
    current : ndarray, shape (n, 2)
        The current scan's valid readings, current sensor frame, metres.
    reference : ReferenceScan
        The scan matched against, in its own sensor frame.
    prior : Pose2D
        Initial reference_T_current (odometry or a motion prediction).
    exclude : ndarray of bool, shape (n,), optional
        Readings to leave out (moving objects, tracked people).

    Returns
    -------
    MatchResult
    """
    src = current if exclude is None else current[~exclude]
    if params.max_source_points and len(src) > params.max_source_points:
        # evenly spread readings constrain the pose as well as all of them do, at a fraction
        # of the cost of the nearest-neighbour queries
        src = src[_spread(len(src), params.max_source_points)]
    n_src = len(src)

    def fail(reason: str, rms=math.nan, overlap=0.0, cond=0.0, it=0) -> MatchResult:
        return MatchResult(prior, False, rms, overlap, cond, False, it, reason)

    if reference.tree is None or reference.n_usable < params.min_pairs or n_src < params.min_pairs:
        return fail("too few readings")
    grid = reference.tree.grid
    if compiled.on and grid is not None:  # the whole loop below as one compiled call
        src = np.ascontiguousarray(src, dtype=np.float64)
        if src.flags.writeable:  # one signature for numba whichever src is (a scan's points are read-only)
            src = src.view()
            src.setflags(write=False)
        paired, x, y, th, it, rms, overlap, cond, degenerate = _icp_kernel(
            src, float(prior.x), float(prior.y), float(prior.yaw), *grid,
            reference.usable_or_none, reference.points, reference.normals, params.max_iterations,
            params.max_correspondence_m, params.min_correspondence_m, params.trim_fraction, params.min_pairs,
            params.degeneracy_ratio)
    else:
        paired, x, y, th, it, rms, overlap, cond, degenerate = _icp_numpy(src, reference, prior, params)
    if not paired:
        return fail("too few correspondences", it=it)
    result = Pose2D(x, y, th)
    correction = prior.between(result)
    if overlap < params.min_overlap:
        return fail(f"overlap {overlap:.2f} below {params.min_overlap}", rms, overlap, cond, it)
    if not rms <= params.max_rms_m:
        return fail(f"residual {rms:.3f} m above {params.max_rms_m} m", rms, overlap, cond, it)
    if math.hypot(correction.x, correction.y) > params.max_correction_m or abs(correction.yaw) > params.max_correction_rad:
        return fail("result too far from the prior", rms, overlap, cond, it)
    return MatchResult(result, True, rms, overlap, cond, bool(degenerate), it)


# The sums of one iteration, per kept pair: the normal equations' six distinct entries
# (AᵀA, A's columns a0 a1 a2: a0a0 a0a1 a0a2 a1a1 a1a2 a2a2), Aᵀr (three), the squared
# distance of the reading from the sensor and the squared residual. Both paths add each
# column in the order np.add.reduceat adds (compiled.reduceat_sum), so they agree to the bit.
_N_SUMS = 11


def _icp_numpy(src, reference: ReferenceScan, prior: Pose2D, params: IcpParams):
    """The ICP iterations in numpy (the reference for :func:`_icp_loop`): whether enough
    pairs were found every iteration, the pose (x, y, yaw), the iterations run, the inlier
    RMS (m), the overlap, the conditioning and whether a direction was degenerate."""
    x, y, th = float(prior.x), float(prior.y), float(prior.yaw)
    gate = params.max_correspondence_m
    cond, degenerate, rms, overlap, it = 0.0, False, math.nan, 0.0, 0
    for it in range(1, params.max_iterations + 1):
        c, s = math.cos(th), math.sin(th)
        p = rotate_translate(src, c, s, x, y)  # R p + t, in the reference frame
        _, j = reference.tree.query(p, gate)
        found = reference.usable_or_none[j]  # none within the gate, or a partner without a normal: no line
        if np.count_nonzero(found) < params.min_pairs:
            return False, x, y, th, it, rms, overlap, cond, degenerate
        j = j[found]
        p, q, nq = p[found], reference.points[j], reference.normals[j]
        # point-to-line residual (from +0.0, as the compiled pairs start it)
        r = 0.0 + (p[:, 0] - q[:, 0]) * nq[:, 0] + (p[:, 1] - q[:, 1]) * nq[:, 1]
        # trimmed: keep the best share of the pairs (a partition, not a sort)
        absr = np.abs(r)
        k = int(params.trim_fraction * (len(absr) - 1))
        keep = absr <= np.partition(absr, k)[k]
        p, nq, r = p[keep], nq[keep], r[keep]
        # Jacobian of n·(R(dθ) p + d - q) at zero: [n_x, n_y, n·(J p)], J p = (-p_y, p_x)
        a0, a1, a2 = nq[:, 0], nq[:, 1], nq[:, 1] * p[:, 0] - nq[:, 0] * p[:, 1]
        terms = np.column_stack([a0 * a0, a0 * a1, a0 * a2, a1 * a1, a1 * a2, a2 * a2, a0 * r, a1 * r, a2 * r,
                                 p[:, 0] * p[:, 0] + p[:, 1] * p[:, 1], r * r])
        sums = np.add.reduceat(terms, [0], axis=0)[0]
        dx, dy, dth, cond, degenerate = _solve_step(*sums[:9], math.sqrt(sums[9] / len(r)), params.degeneracy_ratio)
        # compose the increment on the left: T ← ΔT ∘ T
        cd, sd = math.cos(dth), math.sin(dth)
        x, y = cd * x - sd * y + dx, sd * x + cd * y + dy
        th = wrap_angle(th + dth)
        rms = math.sqrt(sums[10] / len(r))
        overlap = len(r) / len(src)  # the pairs kept
        gate = max(params.min_correspondence_m, gate * 0.5)
        if it >= 2 and abs(dx) < 2e-3 and abs(dy) < 2e-3 and abs(dth) < 2e-4:
            break  # settled: a further step would move a reading less than 1 mm (at 10 m)
    return True, x, y, th, it, rms, overlap, cond, degenerate


def _icp_loop(src, x, y, th, tree_points, geometry, shape, start, order, usable_or_none, ref_points, ref_normals,
              max_iterations, max_gate, min_gate, trim_fraction, min_pairs, degeneracy_ratio):
    """:func:`_icp_numpy` as one loop (compiled by numba): the same operations in the same order."""
    gate = max_gate
    cond, degenerate, rms, overlap, it = 0.0, False, np.nan, 0.0, 0
    sums = np.empty(_N_SUMS)
    for it in range(1, max_iterations + 1):
        c, s = math.cos(th), math.sin(th)
        p = _transform_kernel(src, c, s, x, y)
        _, j = _grid_kernel(tree_points, geometry, shape, start, order, p, gate)
        n_found, p, r, A = _pairs_kernel(p, j, usable_or_none, ref_points, ref_normals, trim_fraction)
        if n_found < min_pairs:
            return False, x, y, th, it, rms, overlap, cond, degenerate
        m = len(r)
        terms = np.empty((_N_SUMS, m))
        for i in range(m):
            a0, a1, a2, ri = A[i, 0], A[i, 1], A[i, 2], r[i]
            terms[0, i], terms[1, i], terms[2, i] = a0 * a0, a0 * a1, a0 * a2
            terms[3, i], terms[4, i], terms[5, i] = a1 * a1, a1 * a2, a2 * a2
            terms[6, i], terms[7, i], terms[8, i] = a0 * ri, a1 * ri, a2 * ri
            terms[9, i], terms[10, i] = p[i, 0] * p[i, 0] + p[i, 1] * p[i, 1], ri * ri
        for k in range(_N_SUMS):
            sums[k] = reduceat_sum(terms[k])
        dx, dy, dth, cond, degenerate = _solve_step(sums[0], sums[1], sums[2], sums[3], sums[4], sums[5], sums[6],
                                                    sums[7], sums[8], math.sqrt(sums[9] / m), degeneracy_ratio)
        cd, sd = math.cos(dth), math.sin(dth)
        x, y = cd * x - sd * y + dx, sd * x + cd * y + dy
        th = (th + dth + math.pi) % (2.0 * math.pi) - math.pi  # wrap_angle's arithmetic
        rms = math.sqrt(sums[10] / m)
        overlap = m / len(src)
        gate = max(min_gate, gate * 0.5)
        if it >= 2 and abs(dx) < 2e-3 and abs(dy) < 2e-3 and abs(dth) < 2e-4:
            break
    return True, x, y, th, it, rms, overlap, cond, degenerate


def _solve_step(h00, h01, h02, h11, h12, h22, g0, g1, g2, rms_range, degeneracy_ratio):
    """One Gauss-Newton step from the normal equations H δ = -g (H = AᵀA given by its six
    distinct entries, g = Aᵀr), δ = (dx, dy, dθ): the rotation column measured in metres at
    the scene's typical range (``rms_range``, at least 1 m) for a fair comparison, directions
    the scene does not constrain (eigenvalue below ``degeneracy_ratio`` of the largest) left
    out. Returns dx, dy, dθ, the conditioning (smallest over largest eigenvalue) and whether
    a direction was left out. Plain arithmetic (a cyclic Jacobi eigen-decomposition of the
    3x3 matrix), the same from Python and compiled."""
    d2 = 1.0 / max(rms_range, 1.0)  # D = diag(1, 1, d2)
    # M = D H D
    a = [[h00, h01, h02 * d2], [h01, h11, h12 * d2], [h02 * d2, h12 * d2, h22 * d2 * d2]]
    v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    for _sweep in range(32):
        off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2]
        diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2]
        if not off > 1e-32 * diag:
            break
        for pq in range(3):
            pi_, qi = (0, 1) if pq == 0 else ((0, 2) if pq == 1 else (1, 2))
            apq = a[pi_][qi]
            if apq == 0.0:
                continue
            # the rotation that zeroes a[p][q]: t = tan of its angle, the smaller root
            theta = (a[qi][qi] - a[pi_][pi_]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):  # M ← M J (columns p and q)
                akp, akq = a[k][pi_], a[k][qi]
                a[k][pi_], a[k][qi] = c * akp - s * akq, s * akp + c * akq
            for k in range(3):  # M ← Jᵀ M (rows p and q)
                apk, aqk = a[pi_][k], a[qi][k]
                a[pi_][k], a[qi][k] = c * apk - s * aqk, s * apk + c * aqk
            for k in range(3):  # V ← V J
                vkp, vkq = v[k][pi_], v[k][qi]
                v[k][pi_], v[k][qi] = c * vkp - s * vkq, s * vkp + c * vkq
    # eigenvalues in ascending order, with their vectors (V's columns)
    w = [a[0][0], a[1][1], a[2][2]]
    idx = [0, 1, 2]
    for i in range(3):
        for k in range(2 - i):
            if w[idx[k]] > w[idx[k + 1]]:
                idx[k], idx[k + 1] = idx[k + 1], idx[k]
    w_max = w[idx[2]]
    cond = w[idx[0]] / w_max if w_max > 0.0 else 0.0
    dg = [g0, g1, g2 * d2]  # D g
    step = [0.0, 0.0, 0.0]  # in the scaled space, -Σ over constrained directions of v (v·Dg) / w
    degenerate = False
    for e in idx:
        if not w[e] > degeneracy_ratio * w_max:
            degenerate = True
            continue
        coef = (v[0][e] * dg[0] + v[1][e] * dg[1] + v[2][e] * dg[2]) / w[e]
        for i in range(3):
            step[i] -= v[i][e] * coef
    return step[0], step[1], step[2] * d2, cond, degenerate


def _pairs_loop(p, j, usable_or_none, ref_points, ref_normals, trim_fraction):
    """One ICP iteration's pairs as :func:`_icp_numpy` makes them (the reference): the
    readings ``p`` (reference frame) whose nearest reference reading ``j`` has a normal,
    their point-to-line residuals, the best ``trim_fraction`` of them kept, and the
    Jacobian rows. Returns the number paired, the kept readings, residuals and Jacobian."""
    n = len(p)
    found = np.empty(n, np.int64)
    m = 0
    for i in range(n):
        if usable_or_none[j[i]]:
            found[m] = i
            m += 1
    r = np.empty(m)
    for t in range(m):
        i, q = found[t], j[found[t]]
        # einsum's dot product: from +0.0
        r[t] = 0.0 + (p[i, 0] - ref_points[q, 0]) * ref_normals[q, 0] + (p[i, 1] - ref_points[q, 1]) * ref_normals[q, 1]
    absr = np.abs(r)
    k = int(trim_fraction * (m - 1))
    bound = np.partition(absr, k)[k] if m > 0 else 0.0
    n_keep = 0
    for t in range(m):
        if absr[t] <= bound:
            n_keep += 1
    kept_p = np.empty((n_keep, 2))
    kept_r = np.empty(n_keep)
    jac = np.empty((n_keep, 3))
    c = 0
    for t in range(m):
        if absr[t] <= bound:
            i, q = found[t], j[found[t]]
            kept_p[c, 0], kept_p[c, 1] = p[i, 0], p[i, 1]
            kept_r[c] = r[t]
            jac[c, 0], jac[c, 1] = ref_normals[q, 0], ref_normals[q, 1]
            jac[c, 2] = ref_normals[q, 1] * p[i, 0] - ref_normals[q, 0] * p[i, 1]
            c += 1
    return m, kept_p, kept_r, jac


_pairs_kernel = njit(_pairs_loop, helper=True)


def _normals_loop(points, max_gap, k):
    """:func:`line_normals` as one loop (compiled by numba; the numpy code is the reference)."""
    n = len(points)
    normals = np.full((n, 2), np.nan)
    if n < 2 * k + 1:
        return normals
    short = np.empty(n - 1, np.bool_)
    for i in range(n - 1):
        short[i] = np.hypot(points[i + 1, 0] - points[i, 0], points[i + 1, 1] - points[i, 1]) < max_gap
    for i in range(k, n - k):
        ok = True
        for s in range(i - k, i + k):
            if not short[s]:
                ok = False
                break
        if not ok:
            continue
        tx, ty = points[i + k, 0] - points[i - k, 0], points[i + k, 1] - points[i - k, 1]
        length = np.hypot(tx, ty)
        if length > 1e-9:
            normals[i, 0], normals[i, 1] = -ty / length, tx / length
    return normals


_normals_kernel = njit(_normals_loop)


_solve_step = njit(_solve_step, helper=True) or _solve_step
_icp_kernel = njit(_icp_loop)
