"""Leg candidates of one scan and their shape, in metres: what a leg looks like to a laser.

Every run of consecutive readings closer than ``max(gap_m, gap_beams · r · res)`` to the
next is a candidate (Leigh et al. cluster at 0.13 m; the beam-spacing term keeps a far leg
of a coarse scanner in one piece). Its features describe the shape in metric,
scanner-independent terms, so a model trained on one laser holds on another: how wide it
is, how well a circle fits it and of what radius, how straight it is, how it bulges
towards the sensor, how far the readings beside it lie behind it or in front, and how
many readings it has compared with what the beam spacing gives at its range. Nothing here
looks at motion or at earlier scans: the score is about shape alone.

Every feature is symmetric in beam order (a clockwise laser gives the same values), and
computed for all candidates of a scan at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.compiled import beam_of, njit, reduceat_sum
from people_tracker.models.scan import Scan

FEATURES = (
    "n_rel",               # readings / (readings the beam spacing gives over the width at that range)
    "width_m",             # first to last reading
    "range_m",             # sensor to the readings' mean
    "spread_m",            # RMS distance of the readings from their mean
    "circle_radius_m",     # radius of the least-squares circle (1 m for a straight line)
    "circle_residual_m",   # RMS distance of the readings from that circle
    "line_residual_m",     # RMS distance from the best straight line
    "boundary_m",          # length of the polyline through the readings
    "boundary_ratio",      # boundary / width: 1 for a straight run, more for a curve or a zigzag
    "bulge_m",             # mean distance of the readings from the chord, towards the sensor
    "centre_depth_m",      # how far the circle's centre lies behind the readings (a round leg: its radius)
    "jump_near_m",         # range step to the readings just outside, the smaller of the two ends ...
    "jump_far_m",          # ... and the larger (3 m: nothing measured there)
    "gap_near_m",          # distance to the nearest reading outside, either end (3 m: none)
    # what the laser sees beside the candidate, 0.1, 0.2, 0.3 and 0.5 m beyond each edge at
    # its range: the range there minus the candidate's, the nearer and the farther side
    "side_0.1_near_m", "side_0.1_far_m", "side_0.2_near_m", "side_0.2_far_m",
    "side_0.3_near_m", "side_0.3_far_m", "side_0.5_near_m", "side_0.5_far_m",
)
SIDE_OFFSETS_M = (0.1, 0.2, 0.3, 0.5)
# What a place beside a candidate where the laser measured nothing counts as. Drivers say
# "no echo" in different ways (inf, range_max, 0, nan: Leigh et al.'s Hokuyo gives 0, the
# annotated hallway recording inf), so the features do not tell them apart: a model that
# did learned one driver's convention and failed on the other.
NO_RETURN_M = 3.0
# how far beside a candidate's end the jump and gap features look: this far across at the
# end's range, at most this many beams
BESIDE_M = 0.3
BESIDE_MAX_BEAMS = 12


@dataclass(frozen=True, eq=False)
class LegCandidates:
    """The candidate segments of one scan.

    Attributes
    ----------
    first_beam, last_beam : ndarray of int, shape (k,)
        Beam span of each candidate in the scan's ``ranges``.
    start, stop : ndarray of int, shape (k,)
        The same as indices into the scan's valid readings (stop exclusive).
    xy : ndarray, shape (k, 2)
        Mean of each candidate's readings, sensor frame, metres.
    features : ndarray, shape (k, len(FEATURES))
    """

    first_beam: np.ndarray
    last_beam: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    xy: np.ndarray
    features: np.ndarray

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def width_m(self) -> np.ndarray:
        """Each candidate's width: first to last reading, metres, shape (k,) (its feature)."""
        return self.features[:, _WIDTH]

    def touching(self, mask: np.ndarray) -> np.ndarray:
        """Which candidates span a beam where ``mask`` (bool, one per beam of the scan) is set."""
        if compiled.on and len(mask):  # the lines below as one compiled loop
            return _touching_kernel(np.ascontiguousarray(mask, dtype=np.bool_), self.first_beam, self.last_beam)
        # c[i] counts the set beams before beam i
        c = np.concatenate([[0], np.cumsum(mask)])
        return c[self.last_beam + 1] > c[self.first_beam]


_WIDTH = FEATURES.index("width_m")


def _empty() -> LegCandidates:
    z = np.zeros(0, dtype=np.int64)
    return LegCandidates(z, z, z, z, np.zeros((0, 2)), np.zeros((0, len(FEATURES))))


def leg_candidates(scan: Scan, gap_m: float = 0.13, gap_beams: float = 2.5, min_points: int = 2,
                   max_width_m: float = 0.45) -> LegCandidates:
    """Candidate segments of ``scan`` and their features.

    Parameters
    ----------
    scan : Scan
    gap_m, gap_beams : float
        Consecutive readings belong to one candidate when closer than ``gap_m`` metres or
        ``gap_beams`` beam spacings at their range (the larger).
    min_points : int
        Fewest readings of a candidate.
    max_width_m : float
        Wider runs (walls, furniture sides) are no candidates.
    """
    beams = scan.valid_index
    if len(beams) < min_points:
        return _empty()
    pts = scan.valid_points
    r = scan.ranges[beams]
    res = scan.resolution
    if compiled.on:  # the same arithmetic compiled (see models/compiled.py)
        valid_start, n, mean, shape = _shape_kernel(pts, r, res, gap_m, gap_beams, min_points, max_width_m)
        if not len(n):
            return _empty()
        end = np.concatenate([valid_start, valid_start + n - 1])  # every first reading, then every last
        first, last = beams[valid_start], beams[valid_start + n - 1]
        features = _context_kernel(shape, mean, np.concatenate([first, last]), pts[end], r[end], scan.valid,
                                   scan.ranges, scan.points, scan.angle_min, scan.angle_increment, np.array(SIDE_OFFSETS_M),
                                   NO_RETURN_M, BESIDE_M, BESIDE_MAX_BEAMS)
        return LegCandidates(first, last, valid_start, valid_start + n, mean, features)
    d = pts[1:] - pts[:-1]
    step = np.hypot(d[:, 0], d[:, 1])
    limit = np.maximum(gap_m, gap_beams * res * np.maximum(r[:-1], r[1:]))
    bounds = np.concatenate([[0], np.flatnonzero(step >= limit) + 1, [len(pts)]])
    run_start, run_stop = bounds[:-1], bounds[1:]
    run_n = run_stop - run_start
    chord = pts[run_stop - 1] - pts[run_start]
    width = np.hypot(chord[:, 0], chord[:, 1])
    k = np.flatnonzero((run_n >= min_points) & (width <= max_width_m))
    if not len(k):
        return _empty()
    # only the kept runs' readings from here on, packed one run after another
    n, width = run_n[k], width[k]
    first, last = beams[run_start[k]], beams[run_stop[k] - 1]
    valid_start = run_start[k]  # into the scan's valid readings
    start = np.concatenate([[0], np.cumsum(n)[:-1]])
    stop = start + n
    take = np.repeat(valid_start - start, n) + np.arange(int(n.sum()))
    pts, r = pts[take], r[take]
    inner = np.concatenate([step, [0.0]])[take]
    inner[stop - 1] = 0.0  # the step out of a segment is not part of its boundary
    sums = lambda a: np.add.reduceat(a, start, axis=0)  # noqa: E731
    mean = sums(pts) / n[:, None]
    seg = np.repeat(np.arange(len(start)), n)
    u = pts - mean[seg]  # readings about their segment's mean
    suu, svv, suv = sums(u[:, 0] ** 2), sums(u[:, 1] ** 2), sums(u[:, 0] * u[:, 1])
    q = u[:, 0] ** 2 + u[:, 1] ** 2
    suq, svq = sums(u[:, 0] * q), sums(u[:, 1] * q)
    # circle (Kåsa): centre c = (a, b) about the mean solves [suu suv; suv svv] c = ½ [suq; svq]
    det = suu * svv - suv ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        a = 0.5 * (svv * suq - suv * svq) / det
        b = 0.5 * (suu * svq - suv * suq) / det
        radius = np.sqrt(a ** 2 + b ** 2 + (suu + svv) / n)
    straight = ~np.isfinite(radius) | (radius > 1.0) | (n < 3)
    radius = np.where(straight, 1.0, radius)
    a, b = np.where(straight, 0.0, a), np.where(straight, 0.0, b)
    d_circle = np.hypot(u[:, 0] - a[seg], u[:, 1] - b[seg]) - radius[seg]
    circle_residual = np.where(straight, 0.0, np.sqrt(sums(d_circle ** 2) / n))
    # straight line: the smaller eigenvalue of the scatter, λ = tr/2 - sqrt(tr²/4 - det)
    tr = suu + svv
    lam_min = np.maximum(0.5 * tr - np.sqrt(np.maximum(0.25 * tr ** 2 - det, 0.0)), 0.0)
    line_residual = np.sqrt(lam_min / n)
    spread = np.sqrt(tr / n)
    boundary = sums(inner)
    # bulge: signed distance from the chord, positive on the sensor's side
    chord = pts[stop - 1] - pts[start]
    normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.maximum(width, 1e-9)[:, None]
    towards = np.sign(np.einsum("ij,ij->i", normal, -pts[start]))  # the normal's side the sensor is on
    towards[towards == 0] = 1.0
    off = np.einsum("ij,ij->i", pts - pts[start][seg], normal[seg]) * towards[seg]
    bulge = sums(off) / n
    rng = np.hypot(mean[:, 0], mean[:, 1])
    centre_depth = np.where(straight, 0.0, np.hypot(mean[:, 0] + a, mean[:, 1] + b) - rng)
    s0, s1 = start, stop - 1
    k = len(first)  # both ends of every candidate in one call: the first ends, then the last
    jumps, gaps = _beside(scan, np.concatenate([first, last]), np.repeat([-1, 1], k), pts[np.concatenate([s0, s1])],
                          r[np.concatenate([s0, s1])])
    j_first, j_last, g_first, g_last = jumps[:k], jumps[k:], gaps[:k], gaps[k:]
    expected = width / np.maximum(rng * res, 1e-6) + 1.0
    features = np.column_stack([
        n / expected, width, rng, spread, radius, circle_residual, line_residual, boundary,
        boundary / np.maximum(width, 1e-3), bulge, centre_depth,
        np.minimum(j_first, j_last), np.maximum(j_first, j_last), np.minimum(g_first, g_last),
        _sides(scan, mean, rng, width)])
    return LegCandidates(first, last, valid_start, valid_start + n, mean, features)


def _sides(scan: Scan, mean: np.ndarray, rng: np.ndarray, width: np.ndarray) -> np.ndarray:
    """For each offset of SIDE_OFFSETS_M: the range the laser measured that far beyond each
    edge of the candidate (across the line of sight, at its range) minus the candidate's
    range, clipped to -1..3 m (3 m: nothing measured there, or outside the view), as the
    smaller and the larger of the two sides. Shape (k, 2 * len(SIDE_OFFSETS_M))."""
    if not SIDE_OFFSETS_M or not len(mean):
        return np.zeros((len(mean), 2 * len(SIDE_OFFSETS_M)))
    offsets = np.array(SIDE_OFFSETS_M)
    across = (0.5 * width[:, None] + offsets[None, :]) / np.maximum(rng, 0.05)[:, None]  # (k, m) radians
    bearing = compiled.arctan2(mean[:, 1], mean[:, 0])[:, None]
    beam = scan.beam_of(np.concatenate([bearing - across, bearing + across], axis=1))  # (k, 2m)
    # the reading there, or the nearest real one within two beams of it (lost readings);
    # two real ones equally near, one either side: the nearer range, whichever way the
    # laser sweeps (taking the one before in beam order made a clockwise laser differ)
    shifts = np.array([0, -1, 1, -2, 2])
    cand = np.minimum(np.maximum(beam[:, :, None] + shifts, 0), scan.n_beams - 1)  # (k, 2m, 5)
    real = scan.valid[cand] & (beam[:, :, None] >= 0)
    ranges = np.where(real, scan.ranges[cand], np.inf)
    level = np.array([0, 1, 1, 2, 2])  # beams away from the place looked at
    first = np.min(np.where(real, level, 3), axis=2)  # the nearest level with a real reading
    nearest = np.min(np.where(level == first[:, :, None], ranges, np.inf), axis=2)
    value = np.minimum(np.maximum(nearest - rng[:, None], -1.0), NO_RETURN_M)  # none real: inf, so NO_RETURN_M
    m = len(offsets)
    lo, hi = np.minimum(value[:, :m], value[:, m:]), np.maximum(value[:, :m], value[:, m:])
    return np.column_stack([lo, hi]).reshape(len(mean), 2, m).transpose(0, 2, 1).reshape(len(mean), 2 * m)


def _beside(scan: Scan, beam: np.ndarray, side: np.ndarray, end_xy: np.ndarray, end_r: np.ndarray,
            lateral_m: float = BESIDE_M, max_beams: int = BESIDE_MAX_BEAMS) -> tuple[np.ndarray, np.ndarray]:
    """Range step and distance from each candidate end to the first reading beside it on
    its ``side`` (per end: -1 before, +1 after in beam order), looking as far as ``lateral_m`` across at
    the end's range (``max_beams`` at most): a valid reading gives its range minus the
    end's (clipped to -1..3 m) and its distance; none (no echo, however the driver says
    it, or the view's edge), 3 m and none."""
    if not len(beam):
        return np.zeros(0), np.zeros(0)
    reach = np.minimum(np.maximum(np.ceil(lateral_m / np.maximum(end_r * scan.resolution, 1e-6)), 1), max_beams)
    steps = np.arange(1, max_beams + 1)
    j = beam[:, None] + side[:, None] * steps  # (k, max_beams)
    inside = (j >= 0) & (j < scan.n_beams) & (steps[None, :] <= reach[:, None])
    jj = np.minimum(np.maximum(j, 0), scan.n_beams - 1)
    real = inside & scan.valid[jj]
    found = real.any(axis=1)
    first = jj[np.arange(len(beam)), np.argmax(real, axis=1)]
    jump = np.where(found, np.minimum(np.maximum(scan.ranges[first] - end_r, -1.0), NO_RETURN_M), NO_RETURN_M)
    d = scan.points[first] - end_xy
    gap = np.where(found, np.hypot(d[:, 0], d[:, 1]), NO_RETURN_M)
    return jump, np.minimum(gap, NO_RETURN_M)


def _shape_loop(pts, r, res, gap_m, gap_beams, min_points, max_width_m):
    """:func:`leg_candidates`' runs and their first 11 features as one loop (compiled by
    numba; the numpy code above is the reference and does the same arithmetic in the same
    order, sums included). Returns the kept runs' first reading (index into the valid
    readings), reading count, mean (k, 2) and features ``n_rel`` .. ``centre_depth_m`` (k, 11)."""
    m = len(pts)
    bounds = np.empty(m + 1, np.int64)
    bounds[0] = 0
    nb = 1
    step = np.zeros(m)
    for i in range(m - 1):
        step[i] = np.hypot(pts[i + 1, 0] - pts[i, 0], pts[i + 1, 1] - pts[i, 1])
        if step[i] >= max(gap_m, gap_beams * res * max(r[i], r[i + 1])):
            bounds[nb] = i + 1
            nb += 1
    bounds[nb] = m
    nb += 1
    keep = np.empty(nb - 1, np.int64)
    k = 0
    for j in range(nb - 1):
        a, b = bounds[j], bounds[j + 1]
        w = np.hypot(pts[b - 1, 0] - pts[a, 0], pts[b - 1, 1] - pts[a, 1])
        if b - a >= min_points and w <= max_width_m:
            keep[k] = j
            k += 1
    start = np.empty(k, np.int64)
    count = np.empty(k, np.int64)
    mean = np.empty((k, 2))
    out = np.empty((k, 11))
    for c in range(k):
        a, b = bounds[keep[c]], bounds[keep[c] + 1]
        n = b - a
        start[c], count[c] = a, n
        cx, cy = pts[b - 1, 0] - pts[a, 0], pts[b - 1, 1] - pts[a, 1]
        width = np.hypot(cx, cy)
        mx, my = reduceat_sum(pts[a:b, 0]) / n, reduceat_sum(pts[a:b, 1]) / n
        t = np.empty((5, n))  # per reading: u², v², uv, uq, vq; then the circle, boundary and chord terms
        for i in range(n):
            u, v = pts[a + i, 0] - mx, pts[a + i, 1] - my
            q = u ** 2 + v ** 2
            t[0, i], t[1, i], t[2, i], t[3, i], t[4, i] = u ** 2, v ** 2, u * v, u * q, v * q
        suu, svv, suv, suq, svq = (reduceat_sum(t[0]), reduceat_sum(t[1]), reduceat_sum(t[2]), reduceat_sum(t[3]),
                                   reduceat_sum(t[4]))
        det = suu * svv - suv ** 2
        ca = 0.5 * (svv * suq - suv * svq) / det
        cb = 0.5 * (suu * svq - suv * suq) / det
        radius = np.sqrt(ca ** 2 + cb ** 2 + (suu + svv) / n)
        straight = not np.isfinite(radius) or radius > 1.0 or n < 3
        if straight:
            radius, ca, cb = 1.0, 0.0, 0.0
        wn = max(width, 1e-9)
        nx, ny = -cy / wn, cx / wn
        towards = 1.0 if -pts[a, 0] * nx + -pts[a, 1] * ny >= 0.0 else -1.0
        for i in range(n):
            t[0, i] = (np.hypot(pts[a + i, 0] - mx - ca, pts[a + i, 1] - my - cb) - radius) ** 2
            t[1, i] = step[a + i] if i < n - 1 else 0.0
            # einsum's dot product: from +0.0, so a reading on the chord gives +0.0 whatever the signs
            t[2, i] = (0.0 + (pts[a + i, 0] - pts[a, 0]) * nx + (pts[a + i, 1] - pts[a, 1]) * ny) * towards
        boundary = reduceat_sum(t[1])
        tr = suu + svv
        lam_min = max(0.5 * tr - np.sqrt(max(0.25 * tr ** 2 - det, 0.0)), 0.0)
        rng = np.hypot(mx, my)
        mean[c, 0], mean[c, 1] = mx, my
        out[c, 0] = n / (width / max(rng * res, 1e-6) + 1.0)
        out[c, 1] = width
        out[c, 2] = rng
        out[c, 3] = np.sqrt(tr / n)
        out[c, 4] = radius
        out[c, 5] = 0.0 if straight else np.sqrt(reduceat_sum(t[0]) / n)
        out[c, 6] = np.sqrt(lam_min / n)
        out[c, 7] = boundary
        out[c, 8] = boundary / max(width, 1e-3)
        out[c, 9] = reduceat_sum(t[2]) / n
        out[c, 10] = 0.0 if straight else np.hypot(mx + ca, my + cb) - rng
    return start, count, mean, out


def _context_loop(shape, mean, end_beam, end_xy, end_r, valid, ranges, points, angle_min, angle_increment, offsets,
                  no_return, lateral_m, max_beams):
    """The features of what lies beside each candidate (:func:`_beside` at both ends,
    then :func:`_sides`) after its own shape (k, 11): the whole feature table, compiled.
    ``end_beam``, ``end_xy``, ``end_r``: every candidate's first reading, then every last."""
    k, n_beams = len(shape), len(valid)
    res = abs(angle_increment)
    m = len(offsets)
    out = np.empty((k, 14 + 2 * m))
    out[:, :11] = shape
    jump = np.full(2 * k, no_return)
    gap = np.full(2 * k, no_return)
    for e in range(2 * k):  # _beside
        side = -1 if e < k else 1
        reach = min(max(np.ceil(lateral_m / max(end_r[e] * res, 1e-6)), 1.0), float(max_beams))
        for s in range(1, max_beams + 1):
            j = end_beam[e] + side * s
            if s > reach or j < 0 or j >= n_beams:
                break
            if valid[j]:
                jump[e] = min(max(ranges[j] - end_r[e], -1.0), no_return)
                gap[e] = min(np.hypot(points[j, 0] - end_xy[e, 0], points[j, 1] - end_xy[e, 1]), no_return)
                break
    shifts = (0, -1, 1, -2, 2)
    levels = (0, 1, 1, 2, 2)
    for c in range(k):
        out[c, 11] = min(jump[c], jump[k + c])
        out[c, 12] = max(jump[c], jump[k + c])
        out[c, 13] = min(gap[c], gap[k + c])
        rng, width = shape[c, 2], shape[c, 1]
        bearing = np.arctan2(mean[c, 1], mean[c, 0])
        for o in range(m):
            across = (0.5 * width + offsets[o]) / max(rng, 0.05)
            value = np.empty(2)
            for h in range(2):
                beam = beam_of(bearing - across if h == 0 else bearing + across, angle_min, angle_increment, n_beams)
                first, nearest = 3, np.inf
                for t in range(5):
                    i = min(max(beam + shifts[t], 0), n_beams - 1)
                    if beam >= 0 and valid[i]:
                        if levels[t] < first:
                            first, nearest = levels[t], ranges[i]
                        elif levels[t] == first:
                            nearest = min(nearest, ranges[i])
                value[h] = min(max(nearest - rng, -1.0), no_return)
            out[c, 14 + 2 * o] = min(value[0], value[1])
            out[c, 15 + 2 * o] = max(value[0], value[1])
    return out


def _touching_loop(mask, first_beam, last_beam):
    """:meth:`LegCandidates.touching` as one loop (compiled by numba): whether any beam from
    each candidate's first to its last is set."""
    out = np.zeros(len(first_beam), np.bool_)
    for k in range(len(first_beam)):
        for b in range(first_beam[k], last_beam[k] + 1):
            if mask[b]:
                out[k] = True
                break
    return out


_touching_kernel = njit(_touching_loop)
_shape_kernel = njit(_shape_loop)
_context_kernel = njit(_context_loop)
