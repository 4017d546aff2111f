"""Existence: the probability that a track is a person who is there now.

Each track carries its log-odds of existence as two terms:

* **accumulated evidence** ``l_dyn`` (log-odds), updated every scan by what the scan said
  about the track's place:

  - a moving candidate associated to it (the paper's M set): ``+ln(motion_lr)``; none
    while it walks (not standing still) and its place is in view: ``+ln(motion_miss_lr)``;
  - a static update (standing leg pair, static support) of a track that walked or arrived
    (its place was seen empty before it stood there): ``+ln(present_lr)``: the person is
    still there. A track that never moved and whose place was never seen empty gains
    nothing from staying: that is what furniture does. A track that had no update for
    longer than ``report_unseen_s`` gains it again only once it has been seen moving or its
    place has shown something at least as leg-like as the leg model's base rate: static
    support from a wall the laser comes back to is no sign that a person is still there,
    and until then such updates count as a place occupied by something else (survival only);
  - no update while the scan **saw through** the place (every return beyond it):
    ``+ln(seen_through_lr)`` (< 0): strong evidence of absence;
  - no update while the place was occluded, unseen, or occupied by something else: nothing
    but survival: people leave, so with no update the probability halves every
    ``unseen_half_life_s`` seconds;
  - standing still where the laser saw the place occupied, and never empty, before the
    track came (see :class:`~people_tracker.detection.free_space.PlaceMemory`):
    ``+ln(furniture_lr)`` (< 0) instead of ``present_lr``: a table leg a track slid onto.

  Scans closer together than ``independent_s`` are not independent evidence: each scan's
  term is weighted by ``min(1, dt / independent_s)``, so the evidence per second is the same
  for a 10 Hz and a 50 Hz laser. The term starts at the prior of how the track began and
  is kept within ``[logit(delete) - 1, logit(max_evidence_probability)]``;

* **shape** ``l_shape``: the leg model's probability of the best leg candidate at the
  track's place, averaged over ``shape_time_s`` (the shape of a still object is the same
  evidence every scan, so it is averaged, never summed), as a log-likelihood ratio against
  the model's own base rate, clipped to ``[ln(min_shape_lr), ln(max_shape_lr)]``.

The existence probability is ``sigmoid(l_dyn + l_shape)``. A track is confirmed when it
reaches ``confirm`` (and, if born moving, has travelled ``tracks.confirm_min_travel_m``),
reported while at least ``keep``, and deleted below ``delete``. Nothing here depends on the
scan rate or the laser's resolution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from people_tracker.detection.free_space import OCCUPIED, SEEN_THROUGH


@dataclass(frozen=True)
class ExistenceParams:
    """Attributes (probabilities 0-1, likelihood ratios, seconds, metres)
    ----------
    prior_moving, prior_standing : float
        Probability that a new track is a person: started by a moving candidate where the
        place was seen empty just before, or by a standing leg pair.
    arrived_lr : float
        Likelihood ratio of a standing-born track's place having been seen empty within the
        free-space lookback (someone arrived there).
    motion_lr, present_lr, seen_through_lr : float
        Likelihood ratios (person there : not) per independent observation of: a moving
        candidate, a static update of a walked or arrived track, a scan that saw through
        the track's place.
    independent_s : float
        Scans closer together than this count as one observation, seconds.
    shape_time_s : float
        Time constant of the leg-shape average, seconds.
    min_shape_lr, max_shape_lr : float
        Bounds of the shape term as likelihood ratios.
    max_evidence_probability : float
        Ceiling of the accumulated evidence, as a probability.
    confirm, keep, delete : float
        Existence probability at which a track is confirmed, down to which a confirmed
        track is still reported, and below which any track is deleted.
    place_radius_m : float
        Radius of the disc around a track that the scan must see through, metres.
    furniture_lr : float
        Likelihood ratio per independent observation of a track standing still, and seen
        there, on a place that was only ever seen occupied before it came (never empty):
        furniture the track slid onto, not a person who walked in.
    place_keyframe_s, place_memory_s : float
        The place memory keeps one scan every ``place_keyframe_s`` for ``place_memory_s``, s.
    place_before_s : float
        A place's history counts up to this long before the track last moved (or began), s.
    unseen_half_life_s : float
        People leave: with no update, the existence probability halves every this many
        seconds (survival, as in IPDA trackers), whatever else the scan says, s.
    motion_miss_lr : float
        Likelihood ratio per independent observation of a walking track (not standing
        still) that got no moving candidate while its place was in view: a walking person
        is seen moving nearly every scan, clutter that flickers now and then is not.
    confidence_raw, confidence_calibrated : tuple of float
        The calibration map of the reported ``confidence``: existence probabilities and the
        share of reported tracks at them that were people, linear between (fitted by
        ``benchmarks/fit_confidence.py`` on simulated scenes). Confirming, reporting and
        deleting use the existence probability itself.
    report_unseen_s : float
        A confirmed track with no update for longer than this is kept (its id, its place,
        its evidence) but not reported until it is seen again, s; its static updates count
        as presence again once one of them looks leg-like or it is seen moving.
    """

    prior_moving: float = 0.2
    prior_standing: float = 0.05
    arrived_lr: float = 10.0
    motion_lr: float = 3.0
    present_lr: float = 1.5
    seen_through_lr: float = 0.1
    independent_s: float = 0.1
    shape_time_s: float = 1.0
    min_shape_lr: float = 0.1
    max_shape_lr: float = 7.0
    max_evidence_probability: float = 0.98
    confirm: float = 0.7
    keep: float = 0.3
    delete: float = 0.02
    place_radius_m: float = 0.25
    furniture_lr: float = 0.3
    place_keyframe_s: float = 1.0
    place_memory_s: float = 600.0
    place_before_s: float = 2.0
    unseen_half_life_s: float = 10.0
    motion_miss_lr: float = 0.5
    confidence_raw: tuple[float, ...] = (0.0, 1.0)
    confidence_calibrated: tuple[float, ...] = (0.0, 1.0)
    report_unseen_s: float = 2.0


def logit(p: float) -> float:
    p = min(max(p, 1e-9), 1.0 - 1e-9)
    return math.log(p / (1.0 - p))


def sigmoid(x: float) -> float:
    return 1.0 / (1.0 + math.exp(-x)) if x >= 0 else math.exp(x) / (1.0 + math.exp(x))


class Existence:
    """The existence state of one track (see the module docstring)."""

    def __init__(self, params: ExistenceParams, stamp: float, standing: bool, arrived: bool,
                 leg_probability: float | None, leg_base_rate: float) -> None:
        self.params = params
        # the bounds the evidence is kept in, and the shape term's, worked out once per track
        self.l_delete = logit(params.delete)
        self._l_dyn_bounds = (self.l_delete - 1.0, logit(params.max_evidence_probability))
        self._l_shape_bounds = (math.log(params.min_shape_lr), math.log(params.max_shape_lr))
        self.base = logit(leg_base_rate)
        self.base_rate = leg_base_rate
        self.vouched = True  # static updates count as presence (False after a stale spell, until leg-like or moving)
        prior = params.prior_standing if standing else params.prior_moving
        self.l_dyn = logit(prior) + (math.log(params.arrived_lr) if standing and arrived else 0.0)
        self.walked_or_arrived = arrived or not standing
        self.shape_p = leg_base_rate if leg_probability is None else leg_probability
        self.stamp = stamp

    @property
    def shape_p(self) -> float:
        """The leg-shape probability averaged over ``shape_time_s``."""
        return self._shape_p

    @shape_p.setter
    def shape_p(self, value: float) -> None:
        self._shape_p = value
        # the shape term, worked out once per change (it is read several times a scan)
        lo, hi = self._l_shape_bounds
        self._l_shape = min(max(logit(value) - self.base, lo), hi)

    @property
    def l_shape(self) -> float:
        return self._l_shape

    @property
    def probability(self) -> float:
        return sigmoid(self.l_dyn + self.l_shape)

    @property
    def confidence(self) -> float:
        """The existence probability through the calibration map: of the reported tracks
        with this confidence, about this share are people."""
        p = self.params
        return float(np.interp(self.probability, p.confidence_raw, p.confidence_calibrated))

    def update(self, stamp: float, update: str | None, visibility: int, leg_probability: float | None,
               furniture_place: bool = False, walking: bool = False, stale: bool = False) -> None:
        """Book one scan.

        Parameters
        ----------
        stamp : float
            The scan's time, s.
        update : {'moving', 'static', None}
            How the track was updated by this scan.
        visibility : int
            :func:`people_tracker.detection.free_space.place_visibility`'s code for its place.
        leg_probability : float or None
            The leg model's best probability among the leg candidates at its place, 0 when
            something updated it but nothing there looks like a leg, None when unknown.
        furniture_place : bool
            Standing still on a place only ever seen occupied before it came.
        walking : bool
            The track walks (it is not standing still): it should be seen moving.
        stale : bool
            The track has had no update for longer than ``report_unseen_s``.
        """
        p = self.params
        dt = max(stamp - self.stamp, 0.0)
        self.stamp = stamp
        if update is None:
            self.vouched = self.vouched and not stale
        elif update == "moving" or leg_probability is None or leg_probability >= self.base_rate:
            self.vouched = True
        w = min(1.0, dt / p.independent_s) if p.independent_s > 0 else 1.0
        if update == "moving":
            self.l_dyn += w * math.log(p.motion_lr)
            self.walked_or_arrived = True
        else:
            if walking and (update == "static" or visibility in (OCCUPIED, SEEN_THROUGH)):
                self.l_dyn += w * math.log(p.motion_miss_lr)
            if furniture_place and (update == "static" or visibility == OCCUPIED):
                self.l_dyn += w * math.log(p.furniture_lr)
            elif update == "static" and self.vouched:
                if self.walked_or_arrived:
                    self.l_dyn += w * math.log(p.present_lr)
            else:
                if visibility == SEEN_THROUGH:
                    self.l_dyn += w * math.log(p.seen_through_lr)
                if p.unseen_half_life_s > 0 and dt > 0:  # survival: P(still here) = P · 2^(-dt / half-life)
                    survived = self.probability * 0.5 ** (dt / p.unseen_half_life_s)
                    self.l_dyn = logit(survived) - self.l_shape
        lo, hi = self._l_dyn_bounds
        self.l_dyn = min(max(self.l_dyn, lo), hi)
        if leg_probability is not None:
            a = 1.0 - math.exp(-dt / p.shape_time_s) if p.shape_time_s > 0 else 1.0
            self.shape_p += a * (leg_probability - self.shape_p)


__all__ = ["Existence", "ExistenceParams", "logit", "sigmoid"]
