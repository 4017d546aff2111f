"""The people tracker: scans in, one track per person out.

:class:`PeopleTracker` is the object to embed in a robot's loop or a ROS node::

    tracker = PeopleTracker.from_config(load_config())
    for scan, pose in source:
        tracks = tracker.step(scan, pose)   # confirmed people, coasting ones included
"""

from __future__ import annotations

import logging
import math
import time
import weakref
from collections import deque
from dataclasses import dataclass

import numpy as np

from people_tracker.detection.align import Alignment, AlignParams, ScanAligner
from people_tracker.detection.detector import Detection, DetectorParams, MovingObjectDetector
from people_tracker.detection import labels as L
from people_tracker.detection.free_space import (OCCLUDED, OCCUPIED, SEEN_THROUGH, UNSEEN, PlaceMemory, place_visibility,
                                                 seen_through)
from people_tracker.detection.leg_features import LegCandidates, leg_candidates
from people_tracker.detection.segments import means_and_chords
from people_tracker.models import compiled
from people_tracker.models.leg_model import LegModel, load_leg_model
from people_tracker.models.pose import Pose2D, best_within, pairwise_distances, wrap_angle
from people_tracker.models.scan import Scan, beam_index
from people_tracker.tracker.association import associate, mahalanobis_costs
from people_tracker.tracker.existence import Existence, ExistenceParams
from people_tracker.tracker.following import TargetSelector
from people_tracker.tracker.pairing import PairingParams, PersonCandidate, leg_centres, owners, pair_legs
from people_tracker.tracker.standing import StandingInitiator, StandingParams, standing_pairs
from people_tracker.tracker.static_support import scan_segments, static_support
from people_tracker.tracker.tracks import Track, TrackParams, TrackState


@dataclass(frozen=True)
class AssociationParams:
    """Attributes
    ----------
    method : {'gnn', 'nn'}
        Global nearest neighbour (optimal assignment) or greedy nearest neighbour.
    gate_chi2 : float
        Largest squared Mahalanobis distance of a match (9.21: 99 % for 2 dof).
    spawn_exclusion_m : float
        A candidate left over within this distance of a track starts no new track (the
        other leg of a tracked person, say).
    support_radius_m, support_sigma_m, support_min_points : float, float, int
        Static support: how near the prediction readings must be (m), the standard
        deviation of the position they give (m), and how many are needed where the beams
        are dense enough that ...
    support_min_width_m : float
        ... something this wide (m) at the prediction's range is sure to show that many;
        elsewhere as many as it shows there, at least 2. 0, the default: the count
        everywhere (0.15 m, measured in the sixty-fourth session, held people standing on a
        1° laser but gave the 0.35° crowd more false people).
    support_anchor_m : float
        Static support must also lie this close to where the track's last moving
        candidate put it (m): a standing leg or a pausing person stays where their legs
        were last seen moving, so a coasting track cannot slide from clutter to clutter.
    free_space_lookback_s, free_space_margin_m : float
        A candidate starts a track only where one of the scans about ½, 1 and 1½ times
        ``free_space_lookback_s`` earlier saw at least ``free_space_margin_m`` past it (the
        place was empty: someone walked in). Static surfaces that look moving (misaligned,
        or flickering between a return and none) were never seen through. 0 s turns the
        test off.
    start_leg_probability : float
        A candidate where the leg model gives a leg at least this probability starts a
        track even where no earlier scan saw the place empty: someone walking straight away
        from a robot that follows them stays in their own shadow, and outdoors nothing
        behind them returns a reading to see past.
    receding : bool
        A confirmed walking track moving away from the laser at ``PASSING_MPS`` or faster
        may take, as a moving candidate, a person-sized group of the readings at its
        prediction that belong to no moving object and hold at least
        ``support_min_points`` readings the detector labelled ``OCCLUDED`` and lying by a
        leg-shaped segment (see :meth:`PeopleTracker._receding`). On by default.
    set_off_speed_mps : float
        How fast (m/s) someone standing still may have walked, unseen, since their standing
        track was last updated: a walking track born within ``recover_radius_m`` plus this
        times that time of where they stood may be their first steps, while that time is
        within ``existence.report_unseen_s`` (see :meth:`PeopleTracker._born_beside`). A
        first step from rest is slower than a walk.
    contested_set_off_probability : float
        A moving candidate within the gate of someone standing still and of a confirmed
        walker: the prior probability that it is the standing person's first step rather
        than the walker's leg. The standing track pays ``-2 ln`` of it on top of its squared
        Mahalanobis distance (a walker passing close by someone standing must not carry
        their track off); 1 turns it off.
    stopping_speed_mps : float
        A confirmed walking track slower than this (m/s) that was this fast or faster within
        the last ``tracks.still_after_s`` is slowing to a stop. While a person-sized group of
        readings that belong to no moving object lies at its prediction (static support), it
        takes no moving candidate lying more than ``tracks.min_person_separation_m`` farther
        from its prediction than that group, and the re-join of sharp turns gives it none:
        someone who stops has no moving legs, and a passer-by's leg beside them must not
        carry their track off before it counts as standing still. 0 turns it off.
    """

    method: str = "gnn"
    gate_chi2: float = 9.21
    spawn_exclusion_m: float = 0.6
    support_radius_m: float = 0.35
    support_sigma_m: float = 0.12
    support_min_points: int = 3
    support_min_width_m: float = 0.0
    support_anchor_m: float = 0.5
    free_space_lookback_s: float = 1.0
    free_space_margin_m: float = 0.3
    recover_radius_m: float = 0.8
    start_leg_probability: float = 0.5
    receding: bool = True
    set_off_speed_mps: float = 0.5
    contested_set_off_probability: float = 0.1
    stopping_speed_mps: float = 0.6


@dataclass(frozen=True, eq=False)
class StepResult:
    """Everything one step produced, for sinks (files, visualisation, metrics)."""

    tracks: list[Track]
    detection: Detection
    candidates: list[PersonCandidate]
    pose: Pose2D
    scan: Scan  # as the detector saw it (de-skewed)
    alignment: Alignment
    standing: list[PersonCandidate] = ()  # leg pairs found by shape (world frame)
    legs: LegCandidates | None = None  # every leg candidate of the scan (sensor frame) ...
    leg_scores: np.ndarray | None = None  # ... and the leg model's probability for each
    matched: tuple[tuple[int, int], ...] = ()  # (track id when it took it, index into candidates): moving candidates taken this scan


@dataclass(eq=False)
class StoodPlace:
    """Where someone who walked in stood still (or is guessed to stand, out of sight)."""

    xy: np.ndarray  # world frame, m
    stamp: float  # last seen there, s
    track_id: int
    l_dyn: float  # their accumulated existence evidence, log-odds
    guess: bool  # only guessed (lost out of sight): what is found there must look like a leg
    came: float  # when they came (their track last moved), s
    # a guess's places along the hidden stretch of their path (world frame, m, shape (k, 2)):
    # they stopped somewhere on it; xy is the middle of what is left of it. None: one place, xy
    along: np.ndarray | None = None

    @classmethod
    def hidden_stop(cls, t: TrackState, along: np.ndarray, stamp: float) -> "StoodPlace":
        """A guess of where the walker of track ``t``, lost out of sight, stands: somewhere
        on ``along`` (the hidden stretch of its path), with the evidence it had when last seen."""
        return cls(along.mean(axis=0), stamp, t.track_id, t.seen_evidence, True, t.last_moving_update, along)

    @property
    def places(self) -> np.ndarray:
        """Where they may stand (world frame, m), shape (k, 2)."""
        return self.xy[None] if self.along is None else self.along

    def narrow(self, left: np.ndarray) -> None:
        """Keep only the places ``left`` (a mask over :attr:`places`) of a guess's stretch."""
        if self.along is not None:
            self.along = self.along[left]
            if len(self.along):
                self.xy = self.along.mean(axis=0)


@dataclass(eq=False)
class VanishedWalker:
    """A confirmed walker whose track ended where the scan did not see their place empty:
    hidden, or glimpsed on too few readings to be seen moving (behind furniture)."""

    track_id: int
    xy: np.ndarray  # its last predicted place (world frame, m) ...
    velocity: np.ndarray  # ... its velocity (world frame, m/s) ...
    stamp: float  # ... at this time, s
    seen: float  # its last update, s

    def at(self, stamp: float) -> np.ndarray:
        """Where they would be at ``stamp`` walking on as they were (world frame, m)."""
        return self.xy + self.velocity * (stamp - self.stamp)


# m/s: a track this fast passing close by someone standing is a passer-by, not them twice (a
# walker's estimated speed lags: one setting off or slowing beside them reads 0.4-0.5 m/s at 0.7)
PASSING_MPS = 0.3
SET_OFF_S = 3.0  # s: a track this young that began beside someone standing may be them, set off
TURN_S = 1.0  # s: a walker whose legs were last seen moving this recently may have turned sharply
HEADING_MPS = 0.5  # m/s: a track at least this fast has a heading its legs are spread along


class PeopleTracker:
    """Detector → leg pairing → Kalman tracks with association, lifecycle and following.

    Parameters
    ----------
    detector, pairing, tracks, association : parameter objects
    follow : 'auto', a track id, or None
        Which person to follow (see :class:`~people_tracker.tracker.following.TargetSelector`).
    """

    def __init__(self, detector: DetectorParams | None = None, pairing: PairingParams | None = None,
                 tracks: TrackParams | None = None, association: AssociationParams | None = None,
                 follow: str | int | None = None, alignment: AlignParams | None = None,
                 standing: StandingParams | None = None, leg_model: LegModel | None = None,
                 existence: ExistenceParams | None = None) -> None:
        self.aligner = ScanAligner(alignment or AlignParams())
        self.detector = MovingObjectDetector(detector or DetectorParams())
        self.pairing = pairing or PairingParams()
        self.track_params = tracks or TrackParams()
        self.assoc = association or AssociationParams()
        # tracks ahead closer together than two people's torsos can be are one person seen twice
        self.selector = (TargetSelector(follow, same_person_m=self.track_params.min_person_separation_m)
                         if follow is not None else None)
        self.standing = StandingInitiator(standing or StandingParams())
        self._arrivals = self.standing.twin()  # single segments (standing.arrivals), the same furniture
        self._judged = np.zeros((0, 4))  # ... places never seen empty: x, y and the laser's x, y (world frame, m)
        self.leg_model = leg_model if leg_model is not None else load_leg_model()
        self.existence = existence or ExistenceParams()
        self.places = PlaceMemory(self.existence.place_keyframe_s, self.existence.place_memory_s)
        self._stood: list[StoodPlace] = []
        self._vanished: list[VanishedWalker] = []  # walkers whose tracks ended unseen (see _walked_on_unseen)
        self._legs_world = np.zeros((0, 2))  # this scan's leg candidates (world frame, m) ...
        self._leg_scores = np.zeros(0)  # ... and their leg probabilities
        self._stopping: dict[int, np.ndarray] = {}  # track index -> the candidates it may not take this scan
        self._explained: np.ndarray | None = None  # this scan's readings taken by moving candidates given to tracks
        self._segments: tuple = (None, None)  # (scan, its scan_segments) for static support's calls on it
        self._tracks: list[TrackState] = []
        # each track's places in the sensor frame over the selector's trail_s: (stamp s, place m)
        self._trails: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
        # pairs of walking tracks closer than tracks.min_person_separation_m: since when (s)
        self._close_since: dict[tuple[TrackState, TrackState], float] = {}
        self._next_id = 1
        self.last: StepResult | None = None
        self.bad_poses = 0  # poses given with a scan that were not finite (the scan was used without)

    @classmethod
    def from_config(cls, config, follow: str | int | None = None) -> "PeopleTracker":
        """A tracker from a resolved :class:`people_tracker.tracker.config.Config`."""
        return cls(config.detector.params(), config.pairing.params(), config.tracks.params(),
                   config.association.params(), follow, config.alignment.params(), config.standing.params(),
                   config.legs.load(), config.existence.params())

    def reset(self) -> None:
        """Forget the scan history (a stamp jump, a new scanner); tracks coast on."""
        self.detector.reset()
        self.aligner.reset()
        self.standing.reset()
        self._arrivals.reset()
        self._judged = np.zeros((0, 4))
        self.places.reset()
        if self.selector is not None:
            self.selector.forget_path()  # the world frame may start anew: no velocity across the jump

    def step(self, scan: Scan, pose: Pose2D | None = None, pose_last_beam: Pose2D | None = None) -> list[Track]:
        """Process one scan; return the confirmed tracks (coasting ones included).

        Parameters
        ----------
        scan : Scan
        pose : Pose2D, optional
            Sensor pose from odometry in its fixed frame at the scan stamp (its first beam).
            Scan matching refines it (or, without it, finds the motion on its own); the
            world frame is this fixed frame, or the first scan's sensor frame.
        pose_last_beam : Pose2D, optional
            Sensor pose from odometry when the last beam fired, for de-skew.
        """
        pose, pose_last_beam = self._usable(pose, scan.stamp), self._usable(pose_last_beam, scan.stamp)
        if pose is None:
            pose_last_beam = None
        people = np.array([t.position for t in self._tracks if t.reported]).reshape(-1, 2)
        aligned = self.aligner.align(scan, pose, pose_last_beam, people)  # 0. de-skew and align
        scan, world = aligned.scan, aligned.pose
        # 1. moving objects (sensor frame)
        detection = self.detector.detect(scan, world, world.inverse().transform_points(people) if len(people) else None,
                                         aligned.tree)
        # the sensor's motion since the last scan was measured by neither odometry nor a match
        # (a match needs a previous scan, so there was a last step)
        unmeasured = aligned.prior == "prediction" and aligned.match is not None and not aligned.match.ok
        for t in self._tracks:  # 2. predict every track to the scan time
            t.predict(scan.stamp)
            if unmeasured:
                t.widen_for_sensor_motion((world.x, world.y), scan.stamp - self.last.scan.stamp)
        legs = leg_candidates(scan)  # every leg candidate and its probability, by shape alone
        leg_scores = self.leg_model.probability(legs.features)
        self._legs_world = world.transform_points(legs.xy) if len(legs.xy) else np.zeros((0, 2))
        self._leg_scores = leg_scores
        candidates = self._candidates(detection, world, legs, leg_scores)  # 3. legs paired into people (world frame)
        candidates += self._receding(detection, scan, world)  # 3b. walkers in their own shadow
        self._stopping = self._stopping_at_own_readings(candidates, detection, scan, world)
        matched = self._associate(candidates)  # 4. associate candidates to tracks
        matched += self._recover(candidates, matched)  # 4b. re-join sharp turns the gate missed
        took = tuple((self._tracks[ti].track_id, ci) for ti, ci in matched)
        for ti, ci in matched:  # 5. update the matched tracks
            c = candidates[ci]
            self._tracks[ti].update(np.array([c.x, c.y]), c.R, moving=True)
        self._explained = self._object_readings(detection, {i for _, ci in matched for i in candidates[ci].object_ids})
        self._unmatchable_legs(scan, legs, leg_scores)  # 6. leg-shaped readings
        still = self._still_legs(legs) if self.standing.params.enabled else None
        standing = self._standing_candidates(still, leg_scores, world)  # 6b. standing people: leg pairs
        arrivals = self._arrival_candidates(still, leg_scores, world)  # ... and single segments
        matched_t = {ti for ti, _ in matched} | self._update_standing(standing)
        self._support(scan, world, matched_t)  # 7. static support for the rest
        self._weigh(scan, world)  # 7b. evidence of existence
        self._walked_off_unseen(scan.stamp)  # 7c. a walker confirmed where someone stood hidden: them
        self._walked_on_unseen(scan.stamp)  # 7d. ... or on the path of a walker whose track ended unseen
        self.places.add(scan, world)
        self._remember_standing(scan, world)
        self._reacquire_standing(scan, world)
        self._initiate(candidates, {ci for _, ci in matched}, scan.stamp, world)  # 8. new tentative tracks
        self._initiate_standing(standing, scan.stamp)  # 8b. and standing people who persist
        self._initiate_arrivals(arrivals, world, scan.stamp)  # 8c. and who arrived, legs merged or hidden
        self._delete(scan.stamp)  # 9. delete what the lifecycle rules end
        first = self._first_steps(scan.stamp)  # not reported yet
        target = self._follow(world, scan.stamp, first)  # 10. the followed person
        shown = [t for t in self._tracks if t.reported and t not in first]
        after_s = self._seen_after_stamp(np.array([t.position for t in shown]).reshape(-1, 2), scan, world)
        reported = [t.report(target=(t.track_id == target), seen_after_s=float(a)) for t, a in zip(shown, after_s)]
        self.last = StepResult(reported, detection, candidates, world, scan, aligned, standing, legs, leg_scores, took)
        return reported

    @staticmethod
    def _seen_after_stamp(xy: np.ndarray, scan: Scan, world: Pose2D) -> np.ndarray:
        """Seconds after the scan's stamp (its first beam) at which its beams looked at the
        places ``xy`` (world frame, m; shape (k, 2)): a scanner sweeps its beams over most of
        its period (0.1 s for a 270° one at 7.5 Hz), and a walker moves on meanwhile. Places
        outside the field of view take the nearest edge's beam."""
        if not len(xy) or scan.time_increment <= 0 or scan.n_beams < 2:
            return np.zeros(len(xy))
        seen = world.inverse().transform_points(xy)
        bearing = np.arctan2(seen[:, 1], seen[:, 0])
        beam = beam_index(bearing, scan.angle_min, scan.angle_increment, scan.n_beams)
        out = beam < 0
        if out.any():  # behind the laser: the nearer end of the sweep, the one on its side of the view's middle
            middle = scan.angle_min + 0.5 * (scan.n_beams - 1) * scan.angle_increment
            nearer_last = wrap_angle(bearing[out] - middle) * scan.angle_increment > 0
            beam[out] = np.where(nearer_last, scan.n_beams - 1, 0)
        return beam * scan.time_increment

    @staticmethod
    def _object_readings(detection: Detection, ids: set[int] | None = None) -> np.ndarray:
        """The readings (per beam) of the moving objects with these ids (None: of every one)."""
        mask = np.zeros(detection.labels.shape, dtype=bool)
        for o in detection.objects:
            if ids is None or o.object_id in ids:
                mask[o.beams] = True
        return mask

    def _unmatchable_legs(self, scan: Scan, legs: LegCandidates, scores: np.ndarray) -> None:
        """Leg-shaped readings take no part in matching the next scan: legs walk."""
        keep = scores >= self.assoc.start_leg_probability
        if keep.any():
            mask = np.zeros(scan.n_valid, dtype=bool)
            for a, b in zip(legs.start[keep], legs.stop[keep]):
                mask[a:b] = True
            self.aligner.exclude_from_reference(mask)

    def _best_leg(self, xy_world: np.ndarray, radius_m: float | None = None) -> np.ndarray:
        """The best leg probability among this scan's leg candidates within ``radius_m``
        (default: the support radius) of each place (world frame); nan where there is none."""
        return best_within(xy_world, self._legs_world, self._leg_scores,
                           self.assoc.support_radius_m if radius_m is None else radius_m)

    def _weigh(self, scan: Scan, world: Pose2D) -> None:
        """Each track's existence evidence from this scan: its update, whether the scan saw
        through its place, and the leg shape there."""
        if not self._tracks:
            return
        xy = np.array([t.position for t in self._tracks])
        best = self._best_leg(xy)
        idle = np.array([not t.updated_now for t in self._tracks])
        vis = np.full(len(xy), UNSEEN, dtype=np.int8)
        if idle.any():
            vis[idle] = place_visibility(xy[idle], scan, world, self.existence.place_radius_m,
                                         self.detector.params.no_return_free_m)
            self._remember_hidden_stops(scan, world, vis)
        for t in self._tracks:  # where a track came to stand still: was the place ever empty?
            if t.place is None and t.moved and t.still:
                t.place = self._place_history(t.position, t.last_moving_update)
        for t, b, v in zip(self._tracks, best, vis):
            # nothing leg-like where something person-like updated it: a shape of 0
            leg = float(b) if b == b else (0.0 if t.updated_now else None)
            t.weigh(int(v), leg)

    def _remember_hidden_stops(self, scan: Scan, world: Pose2D, vis: np.ndarray) -> None:
        """A confirmed walker coasting out of sight whose predicted place comes out into the
        open, and is seen empty, did not walk on there: they turned, or stopped somewhere on
        the hidden stretch of their path, from where they were last seen to the last
        predicted place that was hidden. The part of that stretch not seen empty now goes to
        the memory of where people stood (if some of it is still hidden), with their id and
        the evidence they had when last seen (what a hidden walker loses is no sign of
        absence), so they are found there again once the view clears; the track itself goes
        on as before (a walker who turned is found by it). Every other coasting track notes
        where its prediction is hidden."""
        walkers = []
        for i, t in enumerate(self._tracks):
            if t.updated_now:
                continue
            if vis[i] == OCCLUDED:
                t.hidden_position = t.position.copy()
            elif vis[i] == SEEN_THROUGH and t.hidden_position is not None and t.confirmed and t.moved and not t.still:
                walkers.append(t)
        if not walkers:
            return
        stretches = [t.hidden_stretch(self.assoc.support_radius_m) for t in walkers]
        codes = self._visibility_of(stretches, scan, world)
        for t, along, c in zip(walkers, stretches, codes):
            if (c == OCCLUDED).any():
                e = StoodPlace.hidden_stop(t, along, scan.stamp)
                e.narrow(c != SEEN_THROUGH)
                self._stood.append(e)
            t.hidden_position = None  # once per spell out of sight

    def _visibility_of(self, groups: list[np.ndarray], scan: Scan, world: Pose2D) -> list[np.ndarray]:
        """:func:`place_visibility` of several groups of places (world frame, m), one call."""
        return _per_group(place_visibility(np.concatenate(groups), scan, world, self.existence.place_radius_m,
                                           self.detector.params.no_return_free_m), groups)

    def _remember_standing(self, scan: Scan, world: Pose2D) -> None:
        """Remember where reported people who walked in (or arrived) stand still (world frame),
        with their id and evidence, until the place is seen empty or ``place_memory_s`` has
        passed."""
        stamp = scan.stamp
        stood = [e for e in self._stood if e.stamp >= stamp - self.existence.place_memory_s]
        if stood:  # a place seen empty is forgotten (of a guess's stretch, the part seen empty)
            kept = []
            for e, v in zip(stood, self._visibility_of([e.places for e in stood], scan, world)):
                if (v != SEEN_THROUGH).any():
                    e.narrow(v != SEEN_THROUGH)
                    kept.append(e)
            stood = kept
        alive = {t.track_id for t in self._tracks}
        for t in self._tracks:
            if t.reported and t.existence.walked_or_arrived and t.still and t.place != PlaceMemory.OCCUPIED_ONLY:
                # their own place, else one near them whose track is gone (a track taken up
                # here again, below, has a new id); never the place of someone still tracked,
                # however close they stand (face to face, one hidden, the other's track slides)
                e = next((e for e in stood if e.track_id == t.track_id), None) or \
                    next((e for e in stood if e.track_id not in alive and
                          np.hypot(*(e.xy - t.position)) <= self.assoc.support_anchor_m), None)
                if e is not None:
                    # keep when they first came: a track taken up here again (below) began
                    # standing, so its last move is that re-take, not their arrival
                    e.xy, e.stamp, e.track_id, e.l_dyn, e.guess, e.along = (t.position.copy(), stamp, t.track_id,
                                                                            t.existence.l_dyn, False, None)
                    e.came = min(e.came, t.last_moving_update)
                else:
                    stood.append(StoodPlace(t.position.copy(), stamp, t.track_id, t.existence.l_dyn, False,
                                             t.last_moving_update))
        self._stood = stood[-1000:]

    def _walked_off_unseen(self, stamp: float) -> None:
        """Someone remembered where they stood (:meth:`_remember_standing`; not a guess of
        where a walker lost out of sight stopped), whose track is gone, walks off from there
        unseen: hidden while they stood, they are first found walking. A walking track
        confirmed this scan whose first place lies within ``association.recover_radius_m`` of
        such a place (the reach of someone's first steps, as for a standing track,
        :meth:`_born_beside`) takes their id before it is first reported, and the place is
        forgotten (they left it); of several, the nearest place. None does when a confirmed
        track lies nearer where the walking one began, or the walking one has taken the id
        of someone standing already (:meth:`_hand_over`): that person's first steps."""
        if not self._stood:
            return
        self._take_remembered_ids(stamp, self._stood, lambda e, u: np.inf if e.guess or stamp - u.born > SET_OFF_S
                                  else float(np.hypot(*(e.xy - u.origin))))

    def _take_remembered_ids(self, stamp: float, records: list, distance) -> list:
        """Each walking track confirmed this scan, not born standing and still under the id it
        began with, takes the id of the nearest of ``records`` (``distance(record, track)``:
        from where the track began, m; inf where the record does not apply) that no track
        holds, within ``association.recover_radius_m``; none when a confirmed track lies
        nearer where it began (a tracked person's own steps explain it better). The records
        taken are removed from ``records`` and returned."""
        alive = {t.track_id for t in self._tracks}
        r = self.assoc.recover_radius_m
        taken = []
        for u in self._tracks:
            if u.confirmed_at != stamp or u.born_standing or u.track_id != u.born_id:
                continue
            near = [(distance(e, u), k) for k, e in enumerate(records) if e.track_id not in alive]
            d, k = min(near, default=(np.inf, -1))
            if d > r or any(t is not u and t.confirmed and np.hypot(*(t.position - u.origin)) <= d
                            for t in self._tracks):
                continue
            e = records.pop(k)
            u.track_id = e.track_id
            alive.add(e.track_id)
            taken.append(e)
        return taken

    def _walked_on_unseen(self, stamp: float) -> None:
        """A walker whose track ended while their place was not seen empty (hidden, or
        glimpsed behind furniture on a reading or two: too little to be seen moving, so the
        track lost its evidence and ended), found walking on: a walking track confirmed this
        scan, born within ``SET_OFF_S`` of the old track's last update, heading the same way
        (within 90°), whose first place lies within ``association.recover_radius_m`` of where
        the old one would have been by then, walking on as it was, takes its id before it is
        first reported. Of several, the nearest; none when a confirmed track lies nearer
        where the walking one began (it explains it better), or the walking one has taken
        an id already (:meth:`_hand_over`, :meth:`_walked_off_unseen`).
        Not while following someone (``follow``): the selector re-locks on the followed
        person by its own rules, and on the development following runs it gained nothing for
        them and put the target on someone else more often (docs/track_evidence.md)."""
        # a track born within SET_OFF_S of their last update may be confirmed up to
        # max_tentative_s later: the window counts to when they are seen again, not confirmed
        self._vanished = [e for e in self._vanished
                          if stamp - e.seen <= SET_OFF_S + self.track_params.max_tentative_s]
        if not self._vanished or self.selector is not None:
            return
        taken = self._take_remembered_ids(
            stamp, self._vanished, lambda e, u: float(np.hypot(*(e.at(u.born) - u.origin)))
            if u.born - e.seen <= SET_OFF_S and e.velocity @ u.velocity > 0 else np.inf)
        # they walked on: not stopped where their track ended (_remember_ended_out_of_sight)
        ids = {e.track_id for e in taken}
        self._stood = [g for g in self._stood if not (g.guess and g.track_id in ids)]

    def _reacquire_standing(self, scan: Scan, world: Pose2D) -> None:
        """A person-sized object where someone stood, and no track there: that person, seen
        again after their track was lost (someone walked between, the track went with the
        passer-by). They get their id back when it is free, and their evidence. Where they
        were only guessed to stand (:meth:`_remember_hidden_stops`), the object must look like
        a leg (on the hidden stretch of their path, the one nearest its middle); what the
        laser saw there before they came, and never saw empty, is furniture, and the place
        is forgotten."""
        if not self._stood:
            return
        places = [e.places for e in self._stood]
        clear = _per_group(self._clear_of_tracks(np.concatenate(places)), places)
        lost = [(e, p[c]) for e, p, c in zip(self._stood, places, clear) if c.any()]
        if not lost:
            return
        searched = [p for _, p in lost]
        found = _per_group(self._static_support(np.concatenate(searched), scan, world), searched)
        used = {t.track_id for t in self._tracks}
        R = np.eye(2) * self.assoc.support_sigma_m ** 2
        furniture = []
        for (e, p), zs in zip(lost, found):
            near = [z for z, q in zip(zs, p)
                    if z is not None and np.hypot(*(z - q)) <= self.assoc.support_anchor_m]
            if not near:
                continue
            z = min(near, key=lambda z: np.hypot(*(z - e.xy)))
            # the object found lies within the spawn exclusion of a track (the place was clear
            # of tracks; what stands near it now may not be): a tracked person's leg, walking past
            # where someone stood; a track there would be that person twice
            if not self._clear_of_tracks(z[None])[0]:
                continue
            # where they were only guessed to stand (lost out of sight), the thing found must
            # look at least as leg-like as the leg model's base rate (as for any track back in
            # view): clutter the view clears on is not them
            if e.guess and not np.nan_to_num(self._best_leg(z[None]))[0] >= self.leg_model.base_rate:
                continue
            # what the laser saw there, and never saw empty, before they came is furniture (a
            # table leg beside where someone stood keeps the place occupied after they leave)
            if self._place_history(z, e.came) == PlaceMemory.OCCUPIED_ONLY:
                furniture.append(e)
                continue
            e.guess = False
            ex = Existence(self.existence, scan.stamp, True, True, None, self.leg_model.base_rate)
            ex.l_dyn = e.l_dyn
            track_id = e.track_id if e.track_id not in used else self._next_id
            if track_id == self._next_id:
                self._next_id += 1
            t = TrackState(track_id, float(z[0]), float(z[1]), R, scan.stamp, self.track_params, ex, standing=True)
            t.confirmed, t.moved, t.place = True, True, PlaceMemory.UNKNOWN
            t.retaken_beside = None if track_id == e.track_id else e.track_id
            t.last_moving_update = t.last_update - self.track_params.still_after_s  # standing still
            self._tracks.append(t)
            used.add(track_id)
            e.track_id, e.xy, e.along = track_id, z.copy(), None
        if furniture:
            self._stood = [e for e in self._stood if e not in furniture]  # by identity (eq=False)

    def _place_histories(self, xy: np.ndarray, since: float, **options) -> list[str]:
        """:meth:`PlaceMemory.histories` of places (world frame, m, shape (k, 2)): the keyframes
        up to ``existence.place_before_s`` before ``since`` (s), over a disc of
        ``existence.place_radius_m``; ``options`` as that method takes them."""
        e = self.existence
        return self.places.histories(xy, since - e.place_before_s, e.place_radius_m,
                                     self.detector.params.no_return_free_m, **options)

    def _place_history(self, xy: np.ndarray, since: float) -> str:
        return self._place_histories(xy, since)[0]

    def _usable(self, pose: Pose2D | None, stamp: float) -> Pose2D | None:
        """The pose, or None when it is not finite (counted; the first one is a warning)."""
        if pose is None or (math.isfinite(pose.x) and math.isfinite(pose.y) and math.isfinite(pose.yaw)):
            return pose
        self.bad_poses += 1
        if self.bad_poses == 1:
            logging.getLogger("people_tracker").warning(
                "the pose given with the scan at stamp %.3f s is not finite; such scans are used without a pose "
                "(PeopleTracker.bad_poses counts them)", stamp)
        return None

    def _candidates(self, detection: Detection, world: Pose2D, legs: LegCandidates,
                    leg_scores: np.ndarray) -> list[PersonCandidate]:
        objs = detection.objects
        if not objs:
            return []
        if self.pairing.max_leg_radius_m > 0:  # leg centres, behind the readings
            means, widths = means_and_chords([o.points for o in objs])
            xy = world.transform_points(leg_centres(means, widths, self.pairing.max_leg_radius_m))
        else:
            xy = world.transform_points(np.array([(o.x, o.y) for o in objs]))
        # legs near a tracked walking person are that person's: never paired with another
        # person's. A person standing still owns no moving legs: those are a passer-by's.
        walking = [t for t in self._tracks if t.confirmed and not t.still]
        predicted = np.array([t.position for t in walking]).reshape(-1, 2)
        groups = owners(xy, predicted, self.pairing.half_stride_m)
        out = pair_legs(xy, np.array([o.length for o in objs]), [o.object_id for o in objs], self.pairing, groups,
                        np.array([o.width for o in objs]), predicted, _headings(walking))
        return self._stance_partners(out, detection, world, legs, leg_scores, xy, groups, walking)

    def _stance_partners(self, candidates: list[PersonCandidate], detection: Detection, world: Pose2D,
                         legs: LegCandidates, leg_scores: np.ndarray, xy: np.ndarray, groups: np.ndarray,
                         walking: list[TrackState]) -> list[PersonCandidate]:
        """A walker's lone moving leg, paired with their standing leg.

        While one leg swings the other stands on the floor, still, and is no moving object:
        the swinging leg alone lies up to half a stride from the torso. A lone moving leg
        owned by a walking track (see :func:`owners`), with a still leg-shaped segment of
        this scan (leg probability at least ``start_leg_probability``) between two leg
        radii and a stride from it, owned by nobody else (walking or standing: a standing
        person's legs are theirs), whose midpoint with the leg
        lies nearer the track's prediction than the leg does, is that person's leg pair:
        the candidate moves to the midpoint, with a leg pair's uncertainty. Nothing else
        changes: a leg no walking track owns is left alone (furniture beside a passer-by
        starts nobody).

        The other leg of someone walking away from the laser is revealed (``OCCLUDED``)
        behind where the earlier scans saw them, and partly hidden or sparse it often looks
        less leg-like: without odometry (the world frame stays with the sensor) their near
        leg, which comes towards the laser, is the lone moving one. So a still segment
        holding revealed readings, at least as leg-like as the leg model's base rate, is a
        partner too, when it lies at least a leg radius (``max_leg_radius_m``) farther
        from the laser than the lone leg: behind it, not beside it."""
        lone = [k for k, c in enumerate(candidates) if c.kind == "leg"] if self.pairing.stance_partner else []
        if not lone or not walking:
            return candidates
        strong = leg_scores >= self.assoc.start_leg_probability
        keep = strong | ((leg_scores >= self.leg_model.base_rate) & legs.touching(detection.labels == L.OCCLUDED))
        if not keep.any():
            return candidates
        still = keep & ~legs.touching(self._object_readings(detection))
        if not still.any():
            return candidates
        widths = legs.width_m[still]
        s_xy = world.transform_points(leg_centres(legs.xy[still], widths, self.pairing.max_leg_radius_m))
        # a standing person's legs are theirs: the owner among everyone confirmed, walking or not
        everyone = [t for t in self._tracks if t.confirmed]
        s_own = owners(s_xy, np.array([t.position for t in everyone]).reshape(-1, 2), self.pairing.half_stride_m)
        index = {o.object_id: i for i, o in enumerate(detection.objects)}
        out = list(candidates)
        # lone legs take partners counter-clockwise (by bearing, not by beam order), so that
        # a clockwise laser pairs the same legs as a counter-clockwise one
        seen = world.inverse().transform_points(xy)  # the legs in the sensor frame
        lone.sort(key=lambda k: math.atan2(*seen[index[candidates[k].object_ids[0]]][::-1]))
        at = {id(t): n for n, t in enumerate(everyone)}
        leg = np.array([index[candidates[k].object_ids[0]] for k in lone], dtype=np.int64)
        walker = [walking[groups[i]] if groups[i] >= 0 else None for i in leg]
        # how much farther from the laser than the lone leg each partner must lie: a revealed,
        # less leg-like one a leg radius (behind it), a leg-shaped one any distance
        behind = np.where(strong[still], -np.inf, self.pairing.max_leg_radius_m)
        partner, mids = (_stance_kernel if compiled.on else _stance_partner_choice)(
            np.ascontiguousarray(s_xy), np.asarray(s_own, dtype=np.int64), np.ascontiguousarray(xy), leg,
            np.array([-2 if w is None else at.get(id(w), -1) for w in walker], dtype=np.int64),
            np.array([(np.nan, np.nan) if w is None else w.position for w in walker], dtype=float).reshape(-1, 2),
            2.0 * self.pairing.max_leg_radius_m, float(self.pairing.max_leg_separation_m),
            np.ascontiguousarray(behind), float(world.x), float(world.y))
        for n, k in enumerate(lone):
            if partner[n] >= 0:
                out[k] = PersonCandidate(float(mids[n, 0]), float(mids[n, 1]), self.pairing.sigma_pair_m, "pair",
                                         candidates[k].object_ids)
        return out

    def _receding(self, detection: Detection, scan: Scan, world: Pose2D) -> list[PersonCandidate]:
        """Candidates (world frame, kind ``receding``) for walkers moving away from the laser.

        Someone walking straight away from the laser (a robot following them) is seen behind
        where an earlier scan saw them, so the detector labels their readings revealed
        (``OCCLUDED``), not moving, and their legs often give no moving object; a passer-by
        coming the other way beside them does, and would take their track. For each
        confirmed walking track whose velocity points away from the sensor at ``PASSING_MPS``
        or faster, a person-sized group of the readings at its prediction (no moving
        object's; as static support finds it) holding at least ``support_min_points``
        revealed readings is a candidate, with a single leg's σ, when a leg candidate the leg
        model finds at least ``standing.min_leg_probability`` leg-like lies within half a
        person's size (``pairing.max_person_size_m``) of it: a surface seen at a grazing angle
        behind a moving robot is revealed too, step by step, but has no leg's shape. Not where
        the place memory only ever saw the place occupied (furniture). These candidates start
        no track, re-join no turn and update nobody standing still (``association.receding``):
        someone standing is not revealed behind themselves."""
        if not self.assoc.receding:
            return []
        walkers = [t for t in self._tracks if t.confirmed and t.moved and not t.still]
        if walkers:  # walking away from the laser: only then is a walker revealed behind where they were
            sensor = np.array([world.x, world.y])
            away = [float(np.dot(t.velocity, t.position - sensor)) / max(float(np.hypot(*(t.position - sensor))), 1e-6)
                    for t in walkers]
            walkers = [t for t, v in zip(walkers, away) if v >= PASSING_MPS]
        if not walkers:
            return []
        found = self._static_support(np.array([t.position for t in walkers]), scan, world,
                                     self._object_readings(detection), detection.labels == L.OCCLUDED)
        out, seen = [], set()
        for z in found:
            if z is None or (round(z[0], 6), round(z[1], 6)) in seen:
                continue
            leg = self._best_leg(z[None], self.pairing.max_person_size_m / 2)[0]
            if not leg >= self.standing.params.min_leg_probability:  # nan: no leg candidate near
                continue  # nothing leg-shaped: a surface revealed at a grazing angle
            if self._place_history(z, scan.stamp) == PlaceMemory.OCCUPIED_ONLY:
                continue  # furniture: only ever seen occupied
            seen.add((round(z[0], 6), round(z[1], 6)))
            out.append(PersonCandidate(float(z[0]), float(z[1]), self.pairing.sigma_single_leg_m, "receding"))
        return out

    def _stopping_at_own_readings(self, candidates: list[PersonCandidate], detection: Detection, scan: Scan,
                                  world: Pose2D) -> dict[int, np.ndarray]:
        """For each confirmed walker slowing to a stop (``association.stopping_speed_mps``) whose
        prediction still holds a person-sized group of readings no moving object holds: which
        candidates it may not take this scan (by index into ``candidates``, a mask), those
        lying more than ``tracks.min_person_separation_m`` farther from its prediction than
        that group. Also notes, for every track, when it was last that fast."""
        v_stop = self.assoc.stopping_speed_mps
        if v_stop <= 0:
            return {}
        slowing = []
        for i, t in enumerate(self._tracks):
            if float(np.hypot(*t.velocity)) >= v_stop:
                t.brisk_at = scan.stamp
            elif t.confirmed and not t.still and scan.stamp - t.brisk_at <= self.track_params.still_after_s:
                slowing.append(i)
        if not slowing or not candidates:
            return {}
        places = np.array([self._tracks[i].position for i in slowing])
        found = self._static_support(places, scan, world, self._object_readings(detection))
        z = np.array([(c.x, c.y) for c in candidates])
        d = pairwise_distances(places, z)
        out = {}
        for k, (i, group) in enumerate(zip(slowing, found)):
            if group is not None:
                far = d[k] > float(np.hypot(*(group - places[k]))) + self.track_params.min_person_separation_m
                if far.any():
                    out[i] = far
        return out

    def _associate(self, candidates: list[PersonCandidate]) -> list[tuple[int, int]]:
        if not self._tracks or not candidates:
            return []
        means = np.array([t.position for t in self._tracks])
        covs = np.array([t.position_cov for t in self._tracks])
        z = np.array([(c.x, c.y) for c in candidates])
        R = np.array([c.R for c in candidates])
        cost = mahalanobis_costs(means, covs, z, R)
        for i, far in self._stopping.items():  # slowing to a stop: not a candidate beyond their own readings
            cost[i, far] = np.inf
        # someone seen standing still sets off from where they stand, with a leg beside them:
        # anything moving farther away is somebody else passing by (or facing them). One
        # never seen moving (found standing) sets off from where they were found.
        still = np.array([t.still for t in self._tracks])
        if still.any():
            moved = np.array([t.moved for t in self._tracks])
            d_here = pairwise_distances(means, z)
            d_found = pairwise_distances(np.array([t.moving_position for t in self._tracks]), z)
            far = np.where(moved[:, None], d_here > self.track_params.min_person_separation_m,
                           d_found > self.assoc.recover_radius_m)
            cost[still[:, None] & far] = np.inf
            # a walker's revealed readings are theirs: someone standing is not revealed behind themselves
            receding = np.array([c.kind == "receding" for c in candidates])
            cost[still[:, None] & receding[None, :]] = np.inf
            # a moving leg that a confirmed walker's gate holds as well is more likely theirs
            # than someone standing's first step: a walker passing close by someone standing
            # (their legs seen together in one segment) must not carry the standing person's
            # track off with them. It costs the standing track -2 ln P(a first step).
            p_set_off = self.assoc.contested_set_off_probability
            walking = ~still & np.array([t.confirmed for t in self._tracks])
            if p_set_off < 1.0 and walking.any():
                held = (cost[walking] <= self.assoc.gate_chi2).any(axis=0)
                cost[np.ix_(still, held)] -= 2.0 * math.log(max(p_set_off, 1e-12))
        # one assignment for every track; a tentative track pays -2 ln P(it exists) on top of
        # the squared Mahalanobis distance (a pairing's negative log-likelihood), so a new
        # track on someone's second leg gives way to their confirmed track, while a passer-by's
        # new track keeps a candidate that is clearly theirs when a confirmed track lost its own
        doubt = np.array([0.0 if t.confirmed else -2.0 * math.log(max(t.existence.probability, 1e-9))
                          for t in self._tracks])
        cost = np.where(cost <= self.assoc.gate_chi2, cost + doubt[:, None], np.inf)
        return associate(cost, float(np.max(doubt, initial=0.0)) + self.assoc.gate_chi2, self.assoc.method)

    def _recover(self, candidates: list[PersonCandidate], matched: list[tuple[int, int]]) -> list[tuple[int, int]]:
        """Leftover candidates for confirmed tracks the gate left alone: first tracks that lost
        their walking person within the last second (sharp turns), within
        ``association.recover_radius_m`` of where they were last seen moving; then people
        standing still who set off, whose first step lands beyond a standing track's gate,
        within half a stride (``pairing.max_leg_separation_m``) of where they stand. A
        candidate within ``recover_radius_m`` of a walking track is never given to someone
        standing: it is more likely the walker's."""
        r = self.assoc.recover_radius_m
        if r <= 0:
            return []
        taken_t, taken_c = {t for t, _ in matched}, {c for _, c in matched}
        ts = self._tracks
        lost = self._lost_walkers(i for i in range(len(ts)) if i not in taken_t and i not in self._stopping)
        pairs = self._recover_to(candidates, lost, [ts[i].moving_position for i in lost], taken_c, r)
        taken_c |= {c for _, c in pairs}
        walkers = np.array([t.position for t in ts if t.confirmed and not t.still]).reshape(-1, 2)
        if len(walkers):
            z = np.array([(c.x, c.y) for c in candidates]).reshape(-1, 2)
            taken_c |= set(np.flatnonzero(pairwise_distances(z, walkers).min(axis=1) <= r).tolist())
        standing = [i for i, t in enumerate(ts) if t.confirmed and i not in taken_t and t.still]
        # the stepping leg lands within half a stride of them
        return pairs + self._recover_to(candidates, standing, [ts[i].position for i in standing], taken_c,
                                        self.pairing.half_stride_m)

    def _lost_walkers(self, indices) -> list[int]:
        """Of the tracks at ``indices``, the confirmed walkers whose legs were last seen
        moving within ``TURN_S``: perhaps turned sharply where the prediction walks on."""
        ts = self._tracks
        return [i for i in indices
                if ts[i].confirmed and not ts[i].still and ts[i].stamp - ts[i].last_moving_update <= TURN_S]

    def _recover_to(self, candidates: list[PersonCandidate], idle: list[int], anchors: list[np.ndarray],
                    taken_c: set[int], radius_m: float) -> list[tuple[int, int]]:
        """Give the free candidates within ``radius_m`` of each idle track's anchor (world
        frame, m) to the nearest, one each; those tracks forget their velocity. A candidate
        lying nearer another track (where it is now) than the idle track's anchor is that
        other track's: a passer-by's second leg, not the lost person turning."""
        free = [k for k in range(len(candidates)) if k not in taken_c and candidates[k].kind != "receding"]
        if not idle or not free:
            return []
        z = np.array([(candidates[k].x, candidates[k].y) for k in free])
        cost = pairwise_distances(np.array(anchors), z)
        here = pairwise_distances(np.array([t.position for t in self._tracks]), z)  # every track to every candidate
        for a, i in enumerate(idle):
            nearest_other = np.delete(here, i, axis=0).min(axis=0, initial=np.inf)
            cost[a, nearest_other < cost[a]] = np.inf
        pairs = associate(cost, radius_m, "gnn")
        for a, _ in pairs:
            self._tracks[idle[a]].forget_velocity()
        return [(idle[a], free[b]) for a, b in pairs]

    def _static_support(self, places: np.ndarray, scan: Scan, world: Pose2D, explained: np.ndarray | None = None,
                        needed: np.ndarray | None = None) -> list[np.ndarray | None]:
        """A person-sized group of this scan's readings near each place (world frame), or None;
        without the readings of ``explained`` (per beam; default: those of the moving
        candidates given to tracks this scan), and holding ``needed`` ones if given (see
        :func:`static_support`)."""
        d = self.detector.params
        if self._segments[0] is not scan:  # one segmentation a scan, for the several calls
            self._segments = (scan, scan_segments(scan, d.k_segment, d.segment_floor_m) if scan.n_valid else None)
        return static_support(places, world, scan, d.k_segment, d.segment_floor_m, self.assoc.support_radius_m,
                              self.pairing.max_person_size_m, self.assoc.support_min_points,
                              self.pairing.max_leg_radius_m, self._explained if explained is None else explained,
                              needed, self._segments[1], self.assoc.support_min_width_m)

    def _clear_of_tracks(self, xy: np.ndarray, radius_m: float | None = None) -> np.ndarray:
        """Whether each place (world frame) is at least ``radius_m`` (default
        ``spawn_exclusion_m``) from every track."""
        known = np.array([t.position for t in self._tracks]).reshape(-1, 2)
        if not len(known) or not len(xy):
            return np.ones(len(xy), dtype=bool)
        return pairwise_distances(xy, known).min(axis=1) >= (self.assoc.spawn_exclusion_m if radius_m is None
                                                              else radius_m)

    def _support(self, scan: Scan, world: Pose2D, matched: set[int]) -> None:
        """Static support (a person-sized group of readings near the track) updates the
        confirmed tracks no candidate reached this scan, and the tentative ones that began
        standing where someone arrived (their place seen empty before): someone who stands
        with their legs together, one segment the leg model scores low, earns their
        confirmation by staying (``existence.present_lr``), as a confirmed person keeps it.
        A walking track (not still) is not held by readings where the place memory says the
        laser only ever saw something for 10 s or more (``OCCUPIED_ONLY``, without the
        shortcut for places occupied since the first scan: a crowd standing from the start
        is not the room): a walker hidden beside furniture walks on, and someone who stops
        stands where it was empty before."""
        idle = [i for i, t in enumerate(self._tracks) if i not in matched and (
            t.confirmed or (t.born_standing and not t.moved and t.existence.walked_or_arrived))]
        if not idle:
            return
        found = self._static_support(np.array([self._tracks[i].position for i in idle]), scan, world)
        self._support_without_walkers_legs(idle, found, scan, world)
        # someone who stops stands where their legs were last seen moving, while the
        # prediction walks on: look there too
        again = [k for k, z in enumerate(found) if z is None and
                 np.hypot(*(self._tracks[idle[k]].position - self._tracks[idle[k]].moving_position)) > 0.1]
        if again:
            places = np.array([self._tracks[idle[k]].moving_position for k in again])
            for k, z in zip(again, self._static_support(places, scan, world)):
                found[k] = z
        R = np.eye(2) * self.assoc.support_sigma_m ** 2
        held = [(i, z) for i, z in zip(idle, found)
                if z is not None and np.hypot(*(z - self._tracks[i].moving_position)) <= self.assoc.support_anchor_m]
        walking = [k for k, (i, _) in enumerate(held) if not self._tracks[i].still]
        if walking:  # one pass over the place memory's keyframes for every walking track
            room = self._place_histories(np.array([held[k][1] for k in walking]), scan.stamp,
                                         min_occupied_from_first_s=np.inf)
            # a walker hidden beside furniture: the readings are the room's, not theirs
            furniture = {k for k, h in zip(walking, room) if h == PlaceMemory.OCCUPIED_ONLY}
            held = [h for k, h in enumerate(held) if k not in furniture]
        for i, z in held:
            self._tracks[i].update(z, R, moving=False)

    def _walkers_now(self) -> np.ndarray:
        """Where the confirmed tracks that took a moving candidate this scan are (world frame,
        m), shape (w, 2)."""
        return np.array([t.position for t in self._tracks if t.confirmed and t.update_kind == "moving"]).reshape(-1, 2)

    def _nearer_a_walker(self, idx: list[int], xy: np.ndarray) -> np.ndarray:
        """Whether each place of ``xy`` (world frame, m) lies nearer another confirmed track
        that took a moving candidate this scan than the track ``idx[a]``: shape
        (len(idx), len(xy)). A walker's standing leg beside someone is the walker's. (A
        track of ``idx`` that is such a walker itself lies no nearer than itself: the strict
        comparison leaves it out.)"""
        walkers = self._walkers_now()
        if not len(walkers) or not len(xy) or not len(idx):
            return np.zeros((len(idx), len(xy)), dtype=bool)
        mine = pairwise_distances(np.array([self._tracks[i].position for i in idx]), xy)
        return pairwise_distances(walkers, xy).min(axis=0)[None, :] < mine

    def _support_without_walkers_legs(self, idle: list[int], found: list, scan: Scan, world: Pose2D) -> None:
        """Static support found for ``idle`` tracks, again without the readings that lie
        nearer a walker (:meth:`_nearer_a_walker`), for each supported track standing still
        with such a walker within two support radii: a visitor's standing leg beside someone
        standing is the visitor's. Not for a walker's track (in stance phase or hidden, its
        prediction may lag behind their legs, nearer someone passing them)."""
        reach = 2.0 * self.assoc.support_radius_m
        walkers = self._walkers_now()
        near = [k for k, i in enumerate(idle) if found[k] is not None and self._tracks[i].still and
                np.any(np.hypot(*(walkers - self._tracks[i].position).T) <= reach)]
        if not near:
            return
        theirs = self._nearer_a_walker([idle[k] for k in near], world.transform_points(scan.valid_points))
        base = np.zeros(scan.n_beams, dtype=bool) if self._explained is None else self._explained
        for k, mask in zip(near, theirs):
            explained = base.copy()
            explained[scan.valid_index[mask]] = True
            found[k] = self._static_support(self._tracks[idle[k]].position[None], scan, world, explained)[0]

    def _still_legs(self, legs: LegCandidates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every leg candidate's centre (sensor frame, m) and width (m, first to last
        reading), and whether no passer-by explains it (a passer-by's leg pairs with nobody
        standing)."""
        widths = legs.width_m
        xy = leg_centres(legs.xy, widths, self.pairing.max_leg_radius_m) if self.pairing.max_leg_radius_m > 0 \
            else legs.xy
        free = ~legs.touching(self._explained) if self._explained is not None else np.ones(len(legs), dtype=bool)
        return xy, widths, free

    def _standing_candidates(self, still: tuple, scores: np.ndarray, world: Pose2D) -> list[PersonCandidate]:
        """Leg pairs a stance apart (world frame) among ``still`` (:meth:`_still_legs`) legs
        the leg model finds at least ``standing.min_leg_probability`` likely."""
        p = self.standing.params
        if not p.enabled:
            return []
        xy, _, free = still
        mids, pair_legs_xy = standing_pairs(xy[free & (scores >= p.min_leg_probability)], p)
        if not len(mids):
            return []
        xy = world.transform_points(mids)
        legs_w = world.transform_points(pair_legs_xy.reshape(-1, 2)).reshape(-1, 2, 2)
        return [PersonCandidate(float(x), float(y), self.pairing.sigma_pair_m, "standing",
                                legs=tuple(map(tuple, lw.tolist()))) for (x, y), lw in zip(xy, legs_w)]

    def _arrival_candidates(self, still: tuple, scores: np.ndarray, world: Pose2D) -> np.ndarray:
        """Single segments that may be someone who arrived and stands (world frame, m), among
        ``still`` (:meth:`_still_legs`) legs: at least as leg-like as the leg model's base
        rate, no wider than the widest stance plus a leg (two legs merged into one segment)."""
        p = self.standing.params
        if not (p.enabled and p.arrivals):
            return np.zeros((0, 2))
        xy, widths, free = still
        xy = xy[free & (scores >= self.leg_model.base_rate) &
                (widths <= p.max_leg_separation_m + 2.0 * self.pairing.max_leg_radius_m)]
        return world.transform_points(xy) if len(xy) else np.zeros((0, 2))

    def _update_standing(self, standing: list[PersonCandidate]) -> set[int]:
        """Standing pairs update confirmed tracks no moving candidate reached; their indices."""
        idle = [i for i, t in enumerate(self._tracks) if (t.confirmed or t.born_standing) and not t.updated_now]
        if not idle or not standing:
            return set()
        means = np.array([self._tracks[i].position for i in idle])
        covs = np.array([self._tracks[i].position_cov for i in idle])
        z = np.array([(c.x, c.y) for c in standing])
        cost = mahalanobis_costs(means, covs, z, np.array([c.R for c in standing]))
        # like static support, a pair must lie near where the track last moved (or was born standing)
        anchors = np.array([self._tracks[i].moving_position for i in idle])
        far = pairwise_distances(anchors, z) > self.assoc.support_anchor_m
        cost[far] = np.inf
        # a pair with a leg nearer a walker is not this one's: it is the walker's standing leg
        of = np.repeat(np.arange(len(standing)), [len(c.legs) for c in standing])
        theirs = self._nearer_a_walker(idle, np.array([leg for c in standing for leg in c.legs]).reshape(-1, 2))
        for b in np.unique(of[theirs.any(axis=0)]):
            cost[theirs[:, of == b].any(axis=1), b] = np.inf
        out, used = set(), set()
        for a, b in associate(cost, self.assoc.gate_chi2, self.assoc.method):
            self._tracks[idle[a]].update(z[b], standing[b].R, moving=False)
            out.add(idle[a])
            used.add(b)
        # a walker lost within the last second (a sharp turn the prediction missed) takes a
        # leftover pair within reach of where they last moved, as they would a moving candidate,
        # unless the laser saw that place occupied, and never empty, before: furniture
        ts = self._tracks
        lost = self._lost_walkers(i for i in idle if i not in out)
        for i, b in self._recover_to(standing, lost, [ts[i].moving_position for i in lost], used,
                                     self.assoc.recover_radius_m):
            if self._place_history(z[b], ts[i].stamp) != PlaceMemory.OCCUPIED_ONLY:
                ts[i].update(z[b], standing[b].R, moving=False)
                out.add(i)
        return out

    def _initiate_standing(self, standing: list[PersonCandidate], stamp: float) -> None:
        if not self.standing.params.enabled:
            return
        xy = np.array([(c.x, c.y) for c in standing]).reshape(-1, 2)
        persistent = self.standing.persistent(xy, stamp)
        self._spawn([standing[k] for k in np.flatnonzero(persistent)], stamp, standing=True)

    def _initiate_arrivals(self, xy: np.ndarray, world: Pose2D, stamp: float) -> None:
        """A standing track for each single segment (world frame, m) that persisted as a
        pair must, away from tracks and furniture, where the place memory saw the floor
        empty before from about where the laser is now (within ``existence.place_radius_m``:
        the same view, so no drift of the world frame between the two scans, nor a wall
        seen edge-on from afar, passes for an arrival): someone walked in and stands there,
        legs merged or one hidden. It must lie farther from every track than a new track's
        exclusion plus half the widest stance (it may be a tracked person's leg). Places
        found never seen empty from here are remembered and not looked up again from here."""
        if not len(xy):
            return
        xy = xy[self._arrivals.persistent(xy, stamp)]
        # one segment may be one leg of someone tracked, half the widest stance from their torso
        clear_m = self.assoc.spawn_exclusion_m + 0.5 * self.standing.params.max_leg_separation_m
        xy = xy[self._clear_of_tracks(xy, clear_m)]
        view = np.array([world.x, world.y])
        e = self.existence
        if len(xy) and len(self._judged):  # judged before, from about here
            near = np.hypot(*(self._judged[:, 2:] - view).T) <= e.place_radius_m
            if near.any():
                d = pairwise_distances(xy, self._judged[near, :2]).min(axis=1)
                xy = xy[d > self.standing.params.confirm_radius_m]
        if not len(xy):
            return
        places = self._place_histories(xy, stamp, viewpoint=view, viewpoint_radius_m=e.place_radius_m)
        empty = np.array([place == PlaceMemory.EMPTY for place in places])
        if not empty.all():
            rows = np.hstack([xy[~empty], np.broadcast_to(view, (int((~empty).sum()), 2))])
            self._judged = np.vstack([self._judged, rows])[-1000:]
        arrived = np.flatnonzero(empty)
        sigma = self.pairing.sigma_single_leg_m
        self._spawn([PersonCandidate(float(xy[k, 0]), float(xy[k, 1]), sigma, "standing", legs=(tuple(xy[k]),))
                     for k in arrived], stamp, standing=True)

    def _seen_empty(self, xy: np.ndarray, stamp: float) -> np.ndarray:
        """Whether a scan about ½, 1 or 1½ free-space lookbacks ago saw past each place."""
        seen = np.zeros(len(xy), dtype=bool)
        lookback = self.assoc.free_space_lookback_s
        if len(xy) == 0 or lookback <= 0:
            return seen
        for scan, pose, moving in self.detector.earlier_scans(stamp, (0.5 * lookback, lookback, 1.5 * lookback)):
            seen |= seen_through(xy, scan, pose, self.assoc.free_space_margin_m, moving,
                                 self.detector.params.no_return_free_m)
        return seen

    def _spawn(self, candidates: list[PersonCandidate], stamp: float, standing: bool = False) -> None:
        """A new track for each candidate not within the spawn exclusion of any track.

        A moving candidate's place was seen empty just before (``_initiate`` only offers
        those); a standing pair's place is looked up: seen empty lately or in the place
        memory, someone arrived there."""
        best = self._best_leg(np.array([(c.x, c.y) for c in candidates]).reshape(-1, 2))
        for k, c in enumerate(candidates):
            xy = np.array([c.x, c.y])
            if not self._clear_of_tracks(xy[None])[0]:  # also clear of the tracks just started
                continue
            place, arrived = None, True
            if standing:
                place = self._place_history(xy, stamp)
                # where the legs stand now was seen through lately (not the gap between them,
                # which a laser sees through whoever stands there): someone arrived
                legs = np.array(c.legs).reshape(-1, 2) if c.legs else xy[None]
                arrived = place == PlaceMemory.EMPTY or bool(self._seen_empty(legs, stamp).all())
            ex = Existence(self.existence, stamp, standing, arrived, None if best[k] != best[k] else float(best[k]),
                           self.leg_model.base_rate)
            self._tracks.append(TrackState(self._next_id, c.x, c.y, c.R, stamp, self.track_params, ex, standing))
            self._tracks[-1].place = place
            self._next_id += 1

    def _initiate(self, candidates: list[PersonCandidate], used: set[int], stamp: float, world: Pose2D) -> None:
        used = used | {ci for ci, c in enumerate(candidates) if c.kind == "receding"}
        fresh = [ci for ci in range(len(candidates)) if ci not in used]
        free = np.ones(len(candidates), dtype=bool)
        if fresh and self.assoc.free_space_lookback_s > 0:
            xy = np.array([(candidates[ci].x, candidates[ci].y) for ci in fresh])
            # a leg-shaped candidate needs no empty place: someone walking away in their own
            # shadow, with nothing behind them to see past, was never seen arriving; nor does
            # one far ahead where the followed person, lost, may be: back in view round a
            # corner, walking away, too far for their legs to look like legs
            free[fresh] = (self._seen_empty(xy, stamp)
                           | (np.nan_to_num(self._best_leg(xy)) >= self.assoc.start_leg_probability)
                           | self._lost_person_far_ahead(xy, stamp, world))
        self._spawn([c for ci, c in enumerate(candidates) if ci not in used and free[ci]], stamp)

    def _lost_person_far_ahead(self, xy: np.ndarray, stamp: float, world: Pose2D) -> np.ndarray:
        """Whether each place (world frame, m) is where the followed person, lost, may be back
        in view far ahead (:meth:`TargetSelector.back_far_ahead`)."""
        sel = self.selector
        if sel is None or not sel.looking:  # nobody lost: no transform of the candidates
            return np.zeros(len(xy), dtype=bool)
        return np.array([sel.back_far_ahead(stamp, q) for q in world.inverse().transform_points(xy)], dtype=bool)

    def _duplicates(self, stamp: float) -> set[int]:
        """Indices of tracks that are a person who has a track already: slid onto someone
        standing still, or walking with someone for ``tracks.same_person_after_s``.

        Two people's torsos are never closer than ``tracks.min_person_separation_m``; when a
        track born beside one standing still comes that close, it is the same person twice:
        the one that stood there longer keeps the place (with both still, the one that moved
        less over the last ``tracks.still_after_s``: a track that slid over from where
        someone hidden stands goes).
        A track that started farther from them than one of their legs can be (half of
        ``pairing.max_leg_separation_m``) and walks on (seen moving within
        ``tracks.still_after_s``, at ``PASSING_MPS`` or faster; passing in front of or behind
        the standing person hides one of them for a moment) is someone passing close by, and
        stays.
        Two walking tracks that close for ``tracks.same_person_after_s`` are one person twice
        (a track on each leg, or one that slid onto them from a passer-by): the one whose
        place is less certain (the larger trace of its position covariance) goes, unless it
        is the followed person's.
        When the followed person's track goes by one of the two rules for a track standing
        still, the one that stays takes their id (:meth:`_heir_of_target`)."""
        sep, after_s = self.track_params.min_person_separation_m, self.track_params.same_person_after_s
        idx = [i for i, t in enumerate(self._tracks) if t.confirmed]
        close_since, self._close_since = self._close_since, {}
        if len(idx) < 2 or sep <= 0:
            return set()
        xy = np.array([self._tracks[i].position for i in idx])
        d = pairwise_distances(xy, xy)
        out = set()
        rows, cols = np.nonzero(d < sep)
        upper = rows < cols  # each pair once, in np.triu's (row-major) order
        target = self.selector.target if self.selector is not None else None
        for a, b in zip(rows[upper].tolist(), cols[upper].tolist()):
            ta, tb = self._tracks[idx[a]], self._tracks[idx[b]]
            if idx[a] in out or idx[b] in out:
                continue
            if not (ta.still or tb.still):  # two walking: one person twice once they stay this close
                if after_s <= 0:
                    continue
                since = self._close_since[(ta, tb)] = close_since.get((ta, tb), stamp)
                if stamp - since >= after_s:
                    goes, stays = (idx[a], idx[b]) if np.trace(ta.position_cov) > np.trace(tb.position_cov) \
                        else (idx[b], idx[a])
                    out.add(stays if self._tracks[goes].track_id == target else goes)
                continue
            if ta.still != tb.still:
                walker, stander, k = (tb, ta, idx[b]) if ta.still else (ta, tb, idx[a])
                passing = (np.hypot(*(walker.origin - stander.position)) > self.pairing.half_stride_m
                           and walker.stamp - walker.last_moving_update <= self.track_params.still_after_s
                           and np.hypot(*walker.velocity) >= PASSING_MPS)
                if not passing:  # born at their leg (their own leg's track), or sliding onto them
                    out.add(k)
                    self._heir_of_target(walker, stander, target)
            else:  # the one that moved more over the last still_after_s slid there: it goes
                da, db = (float(np.hypot(*(t.position - t.recent_position))) for t in (ta, tb))
                goes, stays, k = (tb, ta, idx[b]) if (da, ta.born) <= (db, tb.born) else (ta, tb, idx[a])
                out.add(k)
                self._heir_of_target(goes, stays, target)
        return out

    @staticmethod
    def _heir_of_target(goes: TrackState, stays: TrackState, target: int | None) -> None:
        """``goes`` and ``stays`` are one person twice and ``goes`` is deleted: when it holds
        the followed person's id (``target``), ``stays`` takes it (the two swap ids; the
        deleted one's is never reported again). Traced outdoors (development seeds 3 and 5,
        laser ``wide``): the person stopped, a track born standing on them stayed and their
        walking track went; the selector, its target gone, looks for the person only in the
        zone ahead, and they stood beside the robot, unmarked, for 8 s."""
        if target is not None and goes.track_id == target:
            goes.track_id, stays.track_id = stays.track_id, goes.track_id

    def _born_beside(self, t: TrackState, tracks: list[TrackState], stamp: float) -> list[TrackState]:
        """The tracks of ``tracks`` born within ``SET_OFF_S`` before ``stamp`` whose first
        place lies within reach of ``t``: someone standing there who set off, perhaps. The
        reach is ``association.recover_radius_m``, and as far again as they could have
        walked at ``set_off_speed_mps`` between ``t``'s last update and the walking track's
        birth (a walker the detector did not see move at once, revealed from behind
        something nearer, is first found farther on), while that time is within
        ``existence.report_unseen_s``: of someone unseen for longer nothing says where
        they went."""
        a, unseen_s = self.assoc, self.existence.report_unseen_s
        return [u for u in tracks if stamp - u.born <= SET_OFF_S and np.hypot(*(u.origin - t.position)) <=
                a.recover_radius_m + a.set_off_speed_mps * _within(u.born - t.last_update, unseen_s)]

    def _first_steps(self, stamp: float) -> list[TrackState]:
        """Young walking tracks that may be the first steps of someone still reported
        standing beside them (born beside them, within ``association.recover_radius_m`` of
        their place still): not reported yet. Either the standing one is gone (its place
        seen empty, or its track dies) and the walking one takes its id (:meth:`_set_off`,
        :meth:`_hand_over`), or the standing one takes the step and the walking one goes as
        the same person twice; reported meanwhile, it showed the person under another id for
        a few scans. Also the tracks of :meth:`_left_behind`: the reverse case, someone's
        trailing leg taken up again where they stood while their own track walks on."""
        standing = [t for t in self._tracks if t.reported and t.still and t.existence.walked_or_arrived]
        r = self.assoc.recover_radius_m
        return self._left_behind(stamp) + [
            u for t in standing for u in self._born_beside(t, self._tracks, stamp)
            if u.track_id > t.track_id and not u.still and np.hypot(*(u.position - t.position)) <= r]

    def _left_behind(self, stamp: float) -> list[TrackState]:
        """Tracks taken up again where someone stood (:meth:`_reacquire_standing`) under a new
        id, because that person's id lives on a walking track, while that track (where it is,
        or where it was last updated: a track that set off on the swinging leg runs ahead of
        them) is still within ``association.recover_radius_m`` of the place or of the new
        track, for ``SET_OFF_S`` at most: not reported yet. Someone standing who sets off
        leaves their trailing leg on the spot for a step, and it is taken up as them again
        while their track walks on (and the new track may walk on beside it, until one goes as
        the same person twice: :meth:`_delete` gives it their id if theirs goes); a person
        whose track went off with a passer-by is reported once the passer-by is beyond reach."""
        walking = {t.track_id: t for t in self._tracks if t.confirmed and not t.still}
        r = self.assoc.recover_radius_m
        def within_reach(u: TrackState, w: TrackState) -> bool:
            return pairwise_distances(np.array([w.position, w.seen_position]),
                                      np.array([u.origin, u.position])).min() <= r

        return [u for u in self._tracks if u.retaken_beside in walking and u.retaken_beside != u.track_id
                and stamp - u.born <= SET_OFF_S and within_reach(u, walking[u.retaken_beside])]

    def _hand_over(self, t: TrackState, living: list[TrackState], stamp: float) -> bool:
        """A person who stood still and set off: their place empties (the standing track
        dies) while a new track starts beside it, which takes the standing one's id. So too
        when the standing track took a first step (set off within ``SET_OFF_S``) but the new
        one took the steps after it, and the old one dies behind them."""
        if not (t.confirmed and t.existence.walked_or_arrived and (t.still or stamp - t.set_off_at <= SET_OFF_S)):
            return False
        young = [u for u in self._born_beside(t, living, stamp) if u.track_id > t.track_id]
        if not young:
            return False
        min(young, key=lambda u: np.hypot(*(u.origin - t.position))).track_id = t.track_id
        return True

    def _set_off(self, t: TrackState, stamp: float) -> bool:
        """Someone standing still who set off with a first step beyond reach: a walking
        track was born beside them and their standing track has had no update since it was
        confirmed (walked off; the trailing leg stays on the spot for the first step, so an
        update or two after its birth is no sign that they stayed), or the scan saw through
        the place they stood (they are gone: their track would die of it within a few
        scans, and hand its id over then, while the walking one is reported under its own).
        Walking away along the line of sight hides the place they left, so its emptiness
        may never be seen."""
        if not (t.confirmed and t.existence.walked_or_arrived and t.still) or t.updated_now:
            return False
        gone = t.visibility == SEEN_THROUGH
        return any(u.confirmed and not u.still and (gone or u.confirmed_at >= t.last_update)
                   for u in self._born_beside(t, self._tracks, stamp))

    def _delete(self, stamp: float) -> None:
        duplicates = self._duplicates(stamp)
        dying = [t for i, t in enumerate(self._tracks) if i not in duplicates and (t.dead() or self._set_off(t, stamp))]
        keep = [t for i, t in enumerate(self._tracks) if i not in duplicates and not (t in dying)]
        self._left_behind_inherit([self._tracks[i] for i in sorted(duplicates)], keep, stamp)
        for t in dying:
            if t.furniture() and t.existence.probability >= self.existence.delete:
                self.standing.furniture(t.position)
            if not self._hand_over(t, keep, stamp) and t.confirmed and t.moved and not t.still \
                    and t.visibility != SEEN_THROUGH:
                self._vanished.append(VanishedWalker(t.track_id, t.position.copy(), t.velocity.copy(), stamp,
                                                     t.last_update))
            self._remember_ended_out_of_sight(t, stamp)
        self._tracks = keep

    def _left_behind_inherit(self, goes: list[TrackState], keep: list[TrackState], stamp: float) -> None:
        """A track of ``goes`` (the same person twice, :meth:`_duplicates`) whose person was
        taken up again behind them (:meth:`_left_behind`, within ``SET_OFF_S``) by a track of
        ``keep`` closer to it than ``tracks.min_person_separation_m``: that track walked on
        with them, and takes their id."""
        sep = self.track_params.min_person_separation_m
        for t in goes:
            heirs = [u for u in keep if u.retaken_beside == t.track_id and stamp - u.born <= SET_OFF_S
                     and np.hypot(*(u.position - t.position)) < sep]
            if heirs:
                heirs[0].track_id, heirs[0].retaken_beside = t.track_id, None

    def _remember_ended_out_of_sight(self, t: TrackState, stamp: float) -> None:
        """A confirmed walker whose track ends out of sight (its predicted place was hidden
        since its last update, and is hidden or occupied now: not seen empty) may have
        stopped somewhere behind whoever hides them: the hidden stretch of their path goes to
        the memory of where people stood, as a guess, with their id and the evidence the
        track had when last updated (as :meth:`_remember_hidden_stops` does for a walker
        whose predicted place comes out into the open). When the view clears, someone
        leg-like found on it takes their id back (:meth:`_reacquire_standing`); the part of
        it seen empty is forgotten."""
        along = t.hidden_stretch(self.assoc.support_radius_m)
        if not (along is not None and t.confirmed and t.moved and not t.still and t.visibility in (OCCLUDED, OCCUPIED)):
            return
        if any(e.track_id == t.track_id for e in self._stood):
            return
        self._stood.append(StoodPlace.hidden_stop(t, along, stamp))

    def _follow(self, world: Pose2D, stamp: float, unreported: list[TrackState] = ()) -> int | None:
        """The followed person's track id (see :mod:`people_tracker.tracker.following`);
        the tracks of ``unreported`` are not offered to it. None while the target's track has
        had no update for the selector's ``coast_s`` (s): the selector keeps the id, but a
        prediction carried on that long is a guess, most often off the person by the time they
        are seen again (a turn out of view, a passer-by between), so the person is reported
        lost rather than somewhere they are not."""
        sel = self.selector
        if sel is None:
            return None
        inv = world.inverse()
        sel.yaw = world.yaw
        sel.moved(stamp, world.x, world.y)

        for u, q in zip(self._tracks, inv.transform_points(np.array([u.position for u in self._tracks]).reshape(-1, 2))):
            trail = self._trails.setdefault(u, deque())
            trail.append((stamp, q))
            while len(trail) > 1 and trail[1][0] <= stamp - sel.trail_s:
                trail.popleft()  # trail[0]: where it was trail_s ago, or where it began

        def here(tracks) -> dict[int, np.ndarray]:  # id -> place in the sensor frame (m), as just put in its trail
            return {u.track_id: self._trails[u][-1][1] for u in tracks}

        def before(tracks) -> dict[int, np.ndarray]:  # id -> place in the sensor frame then (m), trail_s ago or where it began
            return {u.track_id: self._trails[u][0][1] for u in tracks}

        if sel.target is not None:
            t = next((u for u in self._tracks if u.track_id == sel.target), None)
            q = here([t])[t.track_id] if t is not None else None
            why = "track ended" if t is None else "track not reported"
            if t is not None and t.reported and not sel.within_reach(stamp, q):
                t = self._retire(t)  # it is somewhere the person cannot be: on someone or something else
                why = "out of reach"
            if t is not None and t.reported and t.updated_now and sel.slid(q):
                # moved off where the person has been while another track is there: it slid onto a passer-by,
                # unless that one has just come there from elsewhere (a passer-by where the person was),
                # or only the sensor moved (the target stood still in the world: the robot closed in)
                now = [u for u in self._tracks if u is not t and u.updated_now]
                there = sel.only_one_near(stamp, here(now), steady=True)
                other = next((u for u in now if u.track_id == there), None)
                if (other is not None and not sel.came_from_elsewhere(self._trails[other][0][1])
                        and not sel.only_the_sensor_moved(stamp, t.position, other.born)):
                    t = self._retire(t)
                    sel.lost(stamp, "slid onto someone")
            if t is not None and t.reported and t.updated_now:
                sel.seen(stamp, q, t.velocity, t.position)
            elif t is None or not t.reported:
                sel.lost(stamp, why)
            elif sel.coasting(stamp, t.last_update):
                # coasting, while a track is updated where the person should be: that one is them
                if sel.only_one_near(stamp, here(u for u in self._tracks if u is not t and u.updated_now)) is not None:
                    t = self._retire(t)
                    sel.lost(stamp, "coasting, another track where they should be")
            if sel.lost_since is not None:
                others = [u for u in self._tracks if u.track_id != sel.target and u.reported and u not in unreported]
                pending = [u for u in self._tracks if u.track_id != sel.target and not u.reported and u.updated_now]
                new_id = sel.reacquire(stamp, here(others), {u.track_id: u.velocity for u in others + pending},
                                       here(pending), before(others + pending))
                if new_id is not None:
                    for u in self._tracks:  # the id's old track, if it lives on unreported, is not them
                        if u.track_id == sel.target:
                            self._retire(u)
                    new = next(u for u in self._tracks if u.track_id == new_id)
                    new.track_id = sel.target  # the person keeps their id
        reported = here(u for u in self._tracks if u.reported and u not in unreported)
        closing = {}  # while choosing whom to follow: how fast each reported track comes nearer along the sensor's axis (m/s)
        if sel.choosing(stamp):
            for u in self._tracks:
                (s0, q0), (s1, q1) = self._trails[u][0], self._trails[u][-1]
                if u.track_id in reported and s1 - s0 >= 0.5 * sel.trail_s:
                    closing[u.track_id] = float(q0[0] - q1[0]) / (s1 - s0)
        target = sel.choose(reported, stamp, before(u for u in self._tracks if u.track_id in reported), closing)
        t = next(u for u in self._tracks if u.track_id == target) if target in reported else None  # ids are unique
        if t is not None and sel.expected(stamp) is None:
            sel.seen(stamp, reported[target], t.velocity, t.position)
        if t is not None and sel.coasting(stamp, t.last_update):
            return None  # coasting: where the person is now is a guess; reported lost, not marked
        return target

    def _retire(self, t: TrackState) -> None:
        """The track ``t`` goes on under a new id (it is no longer the followed person)."""
        t.track_id, self._next_id = self._next_id, self._next_id + 1
        return None


def _per_group(values, groups: list[np.ndarray]) -> list:
    """``values`` (an array or a list), one per row of the ``groups`` concatenated, split back
    into one slice per group."""
    ends = np.cumsum([len(g) for g in groups])
    return [values[end - len(g):end] for g, end in zip(groups, ends)]


def _within(gap_s: float, limit_s: float) -> float:
    """``gap_s`` (s) when it lies in [0, ``limit_s``], else 0."""
    return gap_s if 0.0 <= gap_s <= limit_s else 0.0


def _headings(tracks: list[TrackState]) -> np.ndarray:
    """(n, 2) unit vectors along each track's velocity (world frame); zero where it is slower
    than ``HEADING_MPS``, not known to twice its standard deviation, or estimated for less
    than ``TURN_S`` since it was last forgotten (someone who just set off or turned sharply
    spreads their legs across their path)."""
    v = np.array([t.velocity for t in tracks], dtype=float).reshape(-1, 2)
    v_std = np.array([math.sqrt(t.kf.P[1, 1] + t.kf.P[3, 3]) for t in tracks], dtype=float)
    steady = np.array([t.stamp - t.velocity_since >= TURN_S for t in tracks], dtype=bool)
    speed = np.hypot(v[:, 0], v[:, 1])
    fast = (speed >= HEADING_MPS) & (speed >= 2.0 * v_std) & steady
    return np.where(fast[:, None], v / np.where(fast, speed, 1.0)[:, None], 0.0)


def tracks_in_sensor_frame(tracks: list[Track], pose: Pose2D) -> np.ndarray:
    """Positions of tracks in the sensor frame, shape (t, 2), metres."""
    if not tracks:
        return np.zeros((0, 2))
    return pose.inverse().transform_points(np.array([(t.x, t.y) for t in tracks]))


def _stance_partner_choice(s_xy, s_own, xy, leg, walker_at, walker_xy, min_d, max_d, behind, sensor_x, sensor_y):
    """Which still leg each lone moving leg of :meth:`PeopleTracker._stance_partners` pairs
    with, in the order given: for lone leg ``n`` (reading set ``leg[n]`` at ``xy[leg[n]]``,
    world frame, m; its walker at ``walker_xy[n]``, index ``walker_at[n]`` among the
    confirmed tracks, -1 when not among them, -2 when no walking track owns the leg), the
    nearest still leg ``s_xy[j]`` not taken by an earlier one, ``min_d``..``max_d`` metres
    away, at least ``behind[j]`` metres farther than the leg from the sensor at
    (``sensor_x``, ``sensor_y``) (``-inf``: anywhere), owned by nobody (``s_own[j]`` -1) or
    that walker, whose midpoint with the leg lies nearer the walker than the leg does; -1
    for none. Returns the partners and the pairs' midpoints (the numpy reference of
    :func:`_stance_loop`)."""
    partner = np.full(len(leg), -1, np.int64)
    mids_out = np.zeros((len(leg), 2))
    taken: set[int] = set()
    s_range = np.hypot(s_xy[:, 0] - sensor_x, s_xy[:, 1] - sensor_y)
    for n, i in enumerate(leg):
        if walker_at[n] == -2:
            continue
        d = np.hypot(*(s_xy - xy[i]).T)
        ok = (d >= min_d) & (d <= max_d) & ((s_own < 0) | (s_own == walker_at[n]))
        ok &= s_range - np.hypot(xy[i, 0] - sensor_x, xy[i, 1] - sensor_y) >= behind
        mids = 0.5 * (s_xy + xy[i])
        ok &= np.hypot(*(mids - walker_xy[n]).T) < np.hypot(*(xy[i] - walker_xy[n]))
        ok[list(taken)] = False
        if not ok.any():
            continue
        j = int(np.flatnonzero(ok)[np.argmin(d[ok])])
        taken.add(j)
        partner[n], mids_out[n] = j, mids[j]
    return partner, mids_out


def _stance_loop(s_xy, s_own, xy, leg, walker_at, walker_xy, min_d, max_d, behind, sensor_x, sensor_y):
    """:func:`_stance_partner_choice` in one compiled loop (numba), the same choices."""
    n_lone, n_still = len(leg), len(s_xy)
    partner = np.full(n_lone, -1, np.int64)
    mids = np.zeros((n_lone, 2))
    taken = np.zeros(n_still, np.bool_)
    for n in range(n_lone):
        if walker_at[n] == -2:
            continue
        x, y = xy[leg[n], 0], xy[leg[n], 1]
        wx, wy = walker_xy[n, 0], walker_xy[n, 1]
        reach = np.hypot(x - wx, y - wy)
        leg_range = np.hypot(x - sensor_x, y - sensor_y)
        best, best_d = -1, np.inf
        for j in range(n_still):
            if taken[j] or not (s_own[j] < 0 or s_own[j] == walker_at[n]):
                continue
            if not np.hypot(s_xy[j, 0] - sensor_x, s_xy[j, 1] - sensor_y) - leg_range >= behind[j]:
                continue
            d = np.hypot(s_xy[j, 0] - x, s_xy[j, 1] - y)
            if not (d >= min_d and d <= max_d):
                continue
            if not np.hypot(0.5 * (s_xy[j, 0] + x) - wx, 0.5 * (s_xy[j, 1] + y) - wy) < reach:
                continue
            if d < best_d:  # the first of equal distances, as argmin
                best, best_d = j, d
        if best >= 0:
            partner[n] = best
            taken[best] = True
            mids[n, 0], mids[n, 1] = 0.5 * (s_xy[best, 0] + x), 0.5 * (s_xy[best, 1] + y)
    return partner, mids


_stance_kernel = compiled.njit(_stance_loop)


def warm_up_kernels(config=None) -> float:
    """Compile the compiled kernels (the first time on a machine, about half a minute) or
    load them from numba's cache (well under a second), by tracking four seconds of the
    simulated ``crossing`` scene with odometry and without, so that every kernel meets the
    argument types the pipeline gives it. A live node calls it before it subscribes: left
    to the first scans, the loading would queue and drop them. Returns the seconds it took
    (0 without the kernels)."""
    from people_tracker.models.scenario import build_simulation, load_scenario
    from people_tracker.tracker.config import load_config

    if not compiled.ENABLED:
        return 0.0
    t0 = time.perf_counter()
    config = config or load_config()
    for odometry in (True, False):
        sim, n = build_simulation({**load_scenario("crossing"), "duration_s": 4.0})
        tracker = PeopleTracker.from_config(config)
        for _ in range(n):
            st = sim.step()
            tracker.step(st.scan, st.odom_pose if odometry else None, st.odom_pose_last_beam if odometry else None)
        last = tracker.last  # where no track coasted: the place test on its own
        place_visibility(np.array([[1.0, 0.5], [3.0, -1.0]]), last.scan, last.pose, config.existence.place_radius_m,
                         tracker.detector.params.no_return_free_m)
        # and static support, which a short scene may never ask for (no confirmed track idle)
        near = last.pose.transform_points(last.scan.valid_points[:1])
        tracker._static_support(near, last.scan, last.pose, np.zeros(last.scan.n_beams, dtype=bool),
                                np.ones(last.scan.n_beams, dtype=bool))
    return time.perf_counter() - t0


__all__ = ["AssociationParams", "PeopleTracker", "StepResult", "tracks_in_sensor_frame", "warm_up_kernels"]
