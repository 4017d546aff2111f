"""Leg pairing: moving objects (legs, merged legs, bodies) become person candidates.

Two leg-sized objects closer than a stride pair into a person at their midpoint (the
torso). A lone leg is a candidate too, with a larger measurement uncertainty, and so is an
object too wide for a leg but person-sized (two legs merged, a body). Anything larger is
not a person.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from people_tracker.models import compiled
from people_tracker.models.pose import pairwise_distances


@dataclass(frozen=True)
class PairingParams:
    """Sizes in metres (from the person model: legs 5–8 cm in radius, up to a stride apart).

    Attributes
    ----------
    min_leg_size_m : float
        Shortest longest-side of an object that can be a leg: a leg 5 cm or more in radius
        shows a chord of several centimetres even when partly hidden; thinner things (posts,
        cables, chair legs) are not people.
    max_leg_size_m : float
        Longest side of an object that can be one leg.
    max_person_size_m : float
        Longest side of an object that can be a person (two legs merged or a body).
    max_leg_separation_m : float
        Largest distance between two legs of one person (a stride).
    sigma_pair_m, sigma_single_leg_m, sigma_blob_m : float
        Standard deviation of the torso position measured from a leg pair, one leg, or a
        person-sized object.
    max_leg_radius_m : float
        Largest leg radius: see :func:`leg_centres` (0 keeps the readings' hull centroid).
    flat_min_length_m, flat_max_depth_m : float
        An object at least ``flat_min_length_m`` long (longer than a leg is wide) whose
        readings all lie within ``flat_max_depth_m`` of a straight line (its bounding
        rectangle's short side) is a flat surface, not a leg or a person: a round leg as
        wide as that bulges several centimetres towards the laser, and two legs side by
        side bulge twice. Walls seen at a grazing angle slide along themselves as the
        sensor moves and are labelled moving; this keeps them from becoming people. The
        depth must exceed a flat surface's thickness in the laser's noise for the rule to
        act (with a noisier laser it acts less, never on people); at 2 cm it took some of a
        simulated crowd's leg pairs seen as one object for walls. 0 turns it off.
    stance_partner : bool
        Pair a walking person's lone moving leg with their standing leg, a still
        leg-shaped segment beside it, or with their revealed far leg behind it when they
        walk away from the laser (see ``PeopleTracker._stance_partners``).
    max_leg_spread_m : float
        Farthest a walking person's two legs lie apart across their heading: hip width and
        step width, with room for a turn the velocity has not caught up with yet. A pair
        with a leg a walker owns that is wider across their heading is their leg and
        somebody else's, for example the first step of someone setting off beside them
        (see :func:`pair_legs`). 0 turns it off.
    """

    min_leg_size_m: float = 0.04
    max_leg_size_m: float = 0.3
    max_person_size_m: float = 0.8
    max_leg_separation_m: float = 0.8
    sigma_pair_m: float = 0.08
    sigma_single_leg_m: float = 0.2
    sigma_blob_m: float = 0.12
    max_leg_radius_m: float = 0.08
    flat_min_length_m: float = 0.16
    flat_max_depth_m: float = 0.015
    stance_partner: bool = True
    max_leg_spread_m: float = 0.5

    @property
    def half_stride_m(self) -> float:
        """Half of ``max_leg_separation_m``: farthest a leg lies from its person's torso, and
        where a stepping leg lands from where they stood, m."""
        return 0.5 * self.max_leg_separation_m


@dataclass(frozen=True, eq=False)
class PersonCandidate:
    """A possible person in one scan.

    Attributes
    ----------
    x, y : float
        Torso position in the world frame, metres.
    sigma : float
        Standard deviation of that position, metres (isotropic).
    kind : str
        ``pair``, ``leg``, ``blob`` (from moving objects), ``static`` (static support) or
        ``receding`` (a walker's revealed readings, ``association.receding``).
    object_ids : tuple of int
        The moving objects it was made from.
    legs : tuple of (float, float)
        A standing pair's two leg centres, world frame, metres (empty for other kinds).
    """

    x: float
    y: float
    sigma: float
    kind: str
    object_ids: tuple[int, ...] = ()
    legs: tuple[tuple[float, float], ...] = ()

    @property
    def R(self) -> np.ndarray:
        """Measurement covariance, m² (``np.eye(2) * sigma²``, without making the identity)."""
        v = self.sigma ** 2
        return np.array([[v, 0.0], [0.0, v]])


def leg_centres(means: np.ndarray, widths: np.ndarray, max_radius_m: float) -> np.ndarray:
    """Where round legs' centres lie, from their readings (sensor frame, metres).

    A laser sees the near half of a leg and samples it evenly across the beam (the leg is
    far compared with its size), so the readings' mean lies π/4 of the radius in front of
    the centre, along the beam. The radius is half the readings' width across the beam,
    at most ``max_radius_m`` (a partly hidden leg shows less, and is stepped back less;
    two merged legs step back one leg's radius).

    Parameters
    ----------
    means : ndarray, shape (k, 2)
        Mean of each leg's readings, sensor frame.
    widths : ndarray, shape (k,)
        Distance between each leg's first and last reading, metres.
    """
    means = np.asarray(means, dtype=float).reshape(-1, 2)
    widths = np.asarray(widths, dtype=float)
    if compiled.on and widths.shape == (len(means),):  # the lines below, compiled: the same arithmetic
        return _leg_centres_kernel(np.ascontiguousarray(means), np.ascontiguousarray(widths), float(max_radius_m))
    r = np.clip(0.5 * widths, 0.0, max_radius_m)
    u = means / np.maximum(np.hypot(means[:, 0], means[:, 1]), 1e-9)[:, None]
    return means + u * (0.25 * np.pi * r)[:, None]


def _leg_centres_loop(means, widths, max_radius_m):
    """:func:`leg_centres` as one loop (compiled by numba): numpy's operations on each leg."""
    out = np.empty_like(means)
    for k in range(len(means)):
        r = min(max(0.5 * widths[k], 0.0), max_radius_m)  # np.clip
        norm = max(np.hypot(means[k, 0], means[k, 1]), 1e-9)
        step = 0.25 * np.pi * r
        out[k, 0] = means[k, 0] + means[k, 0] / norm * step
        out[k, 1] = means[k, 1] + means[k, 1] / norm * step
    return out


_leg_centres_kernel = compiled.njit(_leg_centres_loop)


def owners(xy: np.ndarray, predictions: np.ndarray, radius: float) -> np.ndarray:
    """For each object, the index of the nearest predicted person within ``radius`` metres, else -1."""
    if len(xy) == 0 or len(predictions) == 0:
        return np.full(len(xy), -1, dtype=np.int64)
    d = pairwise_distances(xy, predictions)
    nearest = d.argmin(axis=1)
    return np.where(d[np.arange(len(xy)), nearest] <= radius, nearest, -1)


@functools.lru_cache(maxsize=32)
def _upper_pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.triu_indices(n, k=1)``, made once per ``n`` (read-only)."""
    a, b = np.triu_indices(n, k=1)
    a.setflags(write=False)
    b.setflags(write=False)
    return a, b


def nearest_pairs(xy: np.ndarray, min_separation_m: float, max_separation_m: float,
                  allowed: np.ndarray | None = None) -> list[tuple[int, int]]:
    """Disjoint pairs of points, nearest first, each point used once.

    Parameters
    ----------
    xy : ndarray, shape (k, 2)
        Points (leg centres), metres, any one frame.
    min_separation_m, max_separation_m : float
        Only pairs this far apart, metres.
    allowed : ndarray of bool, shape (k, k), optional
        Which pairs may form.
    """
    if len(xy) < 2:
        return []
    d = pairwise_distances(xy, xy)
    a, b = _upper_pairs(len(xy))
    ok = (d[a, b] >= min_separation_m) & (d[a, b] <= max_separation_m)
    if allowed is not None:
        ok &= allowed[a, b]
    a, b = a[ok], b[ok]
    used: set[int] = set()
    out = []
    for k in np.argsort(d[a, b], kind="stable"):
        i, j = int(a[k]), int(b[k])
        if i not in used and j not in used:
            out.append((i, j))
            used.update((i, j))
    return out


def _stays_with_owner(xy: np.ndarray, g: np.ndarray, predictions: np.ndarray, half_stride_m: float) -> np.ndarray:
    """(k, k) mask: False where an owned leg (``g`` >= 0) and an unowned one would pair
    into a midpoint farther than half a stride from the owner's prediction and farther
    from it than the owned leg (see :func:`pair_legs`)."""
    owned = g >= 0
    mixed = owned[:, None] != owned[None, :]
    if not mixed.any():
        return np.ones(mixed.shape, dtype=bool)
    own = np.where(owned[:, None], np.arange(len(g))[:, None], np.arange(len(g))[None, :])  # the owned one of each pair
    centre = predictions[np.maximum(g[own], 0)]  # (k, k, 2)
    mid = 0.5 * (xy[:, None, :] + xy[None, :, :])
    d_mid = np.hypot(*np.moveaxis(mid - centre, -1, 0))
    d_own = np.hypot(*np.moveaxis(xy[own] - centre, -1, 0))
    return ~mixed | (d_mid <= half_stride_m) | (d_mid < d_own)


def _across_heading(xy: np.ndarray, g: np.ndarray, headings: np.ndarray, spread_m: float) -> np.ndarray:
    """(k, k) mask: False where a leg a walker owns (``g`` >= 0, with a heading) and another
    leg lie farther than ``spread_m`` apart across that walker's heading."""
    h = headings[np.maximum(g, 0)] * (g >= 0)[:, None]  # (k, 2): the owner's heading, or 0
    dx = xy[None, :, 0] - xy[:, None, 0]
    dy = xy[None, :, 1] - xy[:, None, 1]
    across = np.abs(h[:, 0, None] * dy - h[:, 1, None] * dx)  # row leg's owner's heading
    return (across <= spread_m) & (across.T <= spread_m)


def pair_legs(xy: np.ndarray, sizes: np.ndarray, ids: list[int], params: PairingParams,
              groups: np.ndarray | None = None, depths: np.ndarray | None = None,
              predictions: np.ndarray | None = None, headings: np.ndarray | None = None) -> list[PersonCandidate]:
    """Person candidates from moving objects.

    Parameters
    ----------
    xy : ndarray, shape (k, 2)
        Object centroids in the world frame, metres.
    sizes : ndarray, shape (k,)
        Longest side of each object's bounding rectangle, metres.
    ids : list of int
        Object ids.
    groups : ndarray of int, shape (k,), optional
        Owner of each object (-1 for none, see :func:`owners`): two legs owned by two
        different people never pair, so two people passing close never pair across.
    depths : ndarray, shape (k,), optional
        Shortest side of each object's bounding rectangle, metres: flat objects (see
        :class:`PairingParams`) are neither legs nor people.
    predictions : ndarray, shape (p, 2), optional
        The owners' predicted torso positions (same frame as ``xy``, m; ``groups`` index
        them). A leg one person owns pairs with a leg nobody owns only when the pair stays
        that person's: its midpoint lies within half a stride of their prediction, or
        nearer it than their own leg does. A pair that pulls their leg away from them is
        their leg and somebody else's (a passer-by's leg with the one of a person they
        half hide), a torso where nobody is.
    headings : ndarray, shape (p, 2), optional
        The owners' walking directions (unit vectors, same frame; zero where they walk too
        slowly to tell): a pair with a leg a walker owns lies no wider than
        ``max_leg_spread_m`` across their heading.
    """
    round_ = np.ones(len(sizes), dtype=bool)
    if depths is not None and params.flat_max_depth_m > 0:
        round_ = ~((sizes >= params.flat_min_length_m) & (depths < params.flat_max_depth_m))
    legs = np.flatnonzero((sizes >= params.min_leg_size_m) & (sizes <= params.max_leg_size_m) & round_)
    blobs = np.flatnonzero((sizes > params.max_leg_size_m) & (sizes <= params.max_person_size_m) & round_)
    out = [PersonCandidate(float(xy[i, 0]), float(xy[i, 1]), params.sigma_blob_m, "blob", (ids[i],)) for i in blobs]
    allowed = None
    if groups is not None:  # never two legs that belong to two different people
        g = groups[legs]
        allowed = (g[:, None] == g[None, :]) | (g[:, None] < 0) | (g[None, :] < 0)
        if predictions is not None and len(predictions):
            allowed &= _stays_with_owner(xy[legs], g, predictions, params.half_stride_m)
        if headings is not None and len(headings) and params.max_leg_spread_m > 0:
            allowed &= _across_heading(xy[legs], g, headings, params.max_leg_spread_m)
    paired = set()
    for a, b in nearest_pairs(xy[legs], 0.0, params.max_leg_separation_m, allowed):
        i, j = int(legs[a]), int(legs[b])
        mid = 0.5 * (xy[i] + xy[j])
        out.append(PersonCandidate(float(mid[0]), float(mid[1]), params.sigma_pair_m, "pair", (ids[i], ids[j])))
        paired.update((i, j))
    out += [PersonCandidate(float(xy[i, 0]), float(xy[i, 1]), params.sigma_single_leg_m, "leg", (ids[i],))
            for i in legs if i not in paired]
    return out
