"""Stage 2: Algorithm 1. Readings not static are split into M, O and N by comparing ranges
along the current scan's lines of sight."""

from __future__ import annotations

import numpy as np

from people_tracker.detection.labels import MOVING, OCCLUDED, OUT_OF_VIEW
from people_tracker.models.compiled import arctan2, bin_of, njit
from people_tracker.models.scan import beam_index


def bin_to_beams(points: np.ndarray, angle_min: float, angle_increment: float, n_beams: int) -> np.ndarray:
    """Index of the current beam whose line of sight passes nearest each point, -1 outside the view.

    Parameters
    ----------
    points : ndarray, shape (m, 2)
        Points in the current sensor frame, metres.
    """
    return beam_index(arctan2(points[:, 1], points[:, 0]), angle_min, angle_increment, n_beams)


def _nearest_per_beam(beam: np.ndarray, rng: np.ndarray, n_beams: int) -> np.ndarray:
    """Per beam, the index of the nearest reading binned to it (-1 for none)."""
    at_beam = np.full(n_beams, -1, dtype=np.int64)
    inside = np.flatnonzero(beam >= 0)
    # farthest first: where several readings share a beam, the nearest is written last and stays
    order = inside[np.argsort(-rng[inside], kind="stable")]
    at_beam[beam[order]] = order
    return at_beam


def _partner(beam_c: np.ndarray, at_beam: np.ndarray, rng: np.ndarray, window: int) -> np.ndarray:
    """For each current beam, the reading on its line of sight, else the nearest within ``window`` beams.

    Of the two readings equally many beams away on either side, the one nearer the sensor
    (``rng``, metres) is taken: what the widened line of sight meets first, as within one
    beam. So the choice is the same whichever way the scanner counts its beams.
    """
    n_beams = len(at_beam)
    partner = at_beam[beam_c]
    if not len(rng):
        return partner
    for step in range(1, window + 1):
        need = np.flatnonzero(partner < 0)
        if not len(need):
            break
        lo = at_beam[np.maximum(beam_c[need] - step, 0)]
        hi = at_beam[np.minimum(beam_c[need] + step, n_beams - 1)]
        r_lo = np.where(lo >= 0, rng[np.maximum(lo, 0)], np.inf)
        r_hi = np.where(hi >= 0, rng[np.maximum(hi, 0)], np.inf)
        partner[need] = np.where(r_hi < r_lo, hi, lo)
    return partner


def scan_line_labels(beam_c: np.ndarray, range_c: np.ndarray, beam_p: np.ndarray, range_p: np.ndarray,
                     n_beams: int, window: int, beam_all: np.ndarray | None = None,
                     range_all: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Algorithm 1 on the non-static readings B_C and B_P.

    Each B_C reading on beam i looks for a B_P reading binned to beam i, or failing that to
    the nearest beam within ``window`` beams. With one: the nearer of the two is moving
    (M) and the farther one occluded (O). Without: the current reading is out of the
    previous scan's view (N_C). B_P readings that no B_C reading paired with are N_P.

    Parameters
    ----------
    beam_c : ndarray of int, shape (n,)
        Beam index of each B_C reading.
    range_c : ndarray, shape (n,)
        Its range, metres.
    beam_p : ndarray of int, shape (m,)
        Current beam each B_P reading is binned to (-1 outside the current view).
    range_p : ndarray, shape (m,)
        Its range from the current sensor origin, metres.

    beam_all, range_all : ndarray, optional
        Every valid previous reading (static ones too), and a point on each previous beam
        with no return as far as it is trusted to be free, binned and ranged the same way.
        A B_C reading with no B_P partner is compared with these before it is called N:
        a reading in front of a surface the previous scan saw on the same line of sight is
        moving even though that surface is static (an object's edge against the
        background), and only a line the previous scan did not see at all is out of view.

    Returns
    -------
    label_c, label_p : ndarray of int, shapes (n,), (m,)
        MOVING, OCCLUDED or OUT_OF_VIEW for each reading.
    """
    label_c = np.full(len(beam_c), OUT_OF_VIEW, dtype=np.int8)
    label_p = np.full(len(beam_p), OUT_OF_VIEW, dtype=np.int8)
    if len(beam_c) == 0:
        return label_c, label_p
    partner = _partner(beam_c, _nearest_per_beam(beam_p, range_p, n_beams), range_p, window)
    has = partner >= 0
    if beam_all is not None:
        fallback = _partner(beam_c[~has], _nearest_per_beam(beam_all, range_all, n_beams), range_all, window)
        seen = fallback >= 0
        idx = np.flatnonzero(~has)[seen]
        ahead = range_c[idx] < range_all[fallback[seen]]
        label_c[idx[ahead]] = MOVING
        label_c[idx[~ahead]] = OCCLUDED
    r_partner = np.full(len(beam_c), np.nan)
    r_partner[has] = range_p[partner[has]]
    nearer = has & (range_c < r_partner)
    farther = has & (range_c > r_partner)
    # current nearer: M_C and O_P; current farther: O_C and M_P
    label_c[nearer] = MOVING
    label_c[farther] = OCCLUDED
    label_c[has & ~nearer & ~farther] = OCCLUDED  # equal ranges: not evidence of motion
    label_p[partner[nearer]] = OCCLUDED
    label_p[partner[farther]] = MOVING
    return label_c, label_p


def _nearest_per_beam_loop(beam, rng, use, n_beams):
    """:func:`_nearest_per_beam` of the readings ``use`` marks: per beam the nearest, and of
    equally near ones the last (as the stable sort and its last write there)."""
    at_beam = np.full(n_beams, -1, np.int64)
    for i in range(len(beam)):
        b = beam[i]
        if use[i] and b >= 0:
            j = at_beam[b]
            if j < 0 or rng[i] < rng[j] or (rng[i] == rng[j] and i > j):
                at_beam[b] = i
    return at_beam


def _partner_of(b, at_beam, rng, window):
    """:func:`_partner` for the one current beam ``b``."""
    n_beams = len(at_beam)
    partner = at_beam[b]
    step = 1
    while partner < 0 and step <= window:
        lo = at_beam[max(b - step, 0)]
        hi = at_beam[min(b + step, n_beams - 1)]
        r_lo = rng[lo] if lo >= 0 else np.inf
        r_hi = rng[hi] if hi >= 0 else np.inf
        partner = hi if r_hi < r_lo else lo
        step += 1
    return partner


def _line_labels_loop(beam_c, range_c, pts_p, range_p, static_p, pts_far, angle_min, angle_increment, n_beams,
                      window):
    """The current readings' labels of :func:`scan_line_labels` as the detector asks for them
    (B_P: the previous readings ``pts_p``, current frame, not ``static_p``; the fall-back:
    all of them and the free points ``pts_far``), the binning (:func:`bin_to_beams`)
    included; compiled by numba, the numpy functions above are the reference."""
    m, f = len(pts_p), len(pts_far)
    beam_all = np.empty(m + f, np.int64)
    range_all = np.empty(m + f)
    for i in range(m):
        beam_all[i] = bin_of(pts_p[i, 0], pts_p[i, 1], angle_min, angle_increment, n_beams)
        range_all[i] = range_p[i]
    for i in range(f):
        beam_all[m + i] = bin_of(pts_far[i, 0], pts_far[i, 1], angle_min, angle_increment, n_beams)
        range_all[m + i] = np.hypot(pts_far[i, 0], pts_far[i, 1])
    moving_p = np.zeros(m + f, np.bool_)
    moving_p[:m] = ~static_p
    at_p = _nearest_per_beam_loop(beam_all, range_all, moving_p, n_beams)
    at_all = _nearest_per_beam_loop(beam_all, range_all, np.ones(m + f, np.bool_), n_beams)
    label = np.full(len(beam_c), OUT_OF_VIEW, np.int8)
    for i in range(len(beam_c)):
        p = _partner_of(beam_c[i], at_p, range_all, window)
        if p < 0:  # the fall-back: every earlier reading, and the free points
            p = _partner_of(beam_c[i], at_all, range_all, window)
        if p >= 0:
            label[i] = MOVING if range_c[i] < range_all[p] else OCCLUDED  # equal ranges: not evidence of motion
    return label


_nearest_per_beam_loop = njit(_nearest_per_beam_loop, helper=True) or _nearest_per_beam_loop
_partner_of = njit(_partner_of, helper=True) or _partner_of
line_labels_kernel = njit(_line_labels_loop, helper=True)  # called from the detector's label_pair kernel (and its fallback)
