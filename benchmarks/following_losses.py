"""Where the followed person's target goes when it is not on them, scan by scan.

Usage::

    python benchmarks/following_losses.py [--scene follow_indoor_crowd] [--laser wide] [--seed 2] [--duration S]
        [--spells] [--hops] [--losses]

Runs the default tracker with ``--follow auto`` on one simulated following run and sorts
every scan where the person is visible, after the first lock, into: the target is on them
(within 0.75 m, sensor frame); on someone or something else; no target while a reported
track is on them (the tracker has them, the target model gave the id to no one: lost for
less than ``relock_s``, or after it, how many reported tracks lay where the re-lock looks
for the person, the zone ahead and beyond it where they could be: with two or more the id
goes to none, and one that walks as the person could not takes no id either);
no target while the person's track coasts (no update for the selector's ``coast_s``: it
is reported as a track, but not marked as the target); no target while only an unreported
track is on them; no target and no track near them. With ``--spells``, also each spell of a
second or more with the target on someone or something else while the person is visible
or the target is on someone: when, how long, on whom, and whether the target's track was the
one last on the person (it went from them onto someone) or another (the id was given to it,
after the loss the selector's event names).
With ``--hops``, also each scan where the target's track, within
``tracks.min_person_separation_m`` of the person the scan before, took a moving candidate
made mostly of someone else's readings (the simulator says whose each reading is): the
candidate's kind, whose readings, whether the person had a candidate of their own that scan
(and who took it), and whether they stood still; then the counts. Candidates made of no
moving object (``receding``) are not judged.
With ``--losses``, also each time the selector reported its person lost (its event's reason),
whether the track it gave up was on the person then (the simulator's truth), and how the
loss ended: their own track found again, the id re-acquired by that same track (a track
judged off the person that was on them, or came back to them) or by another, on the person
or not; then the counts by reason.
The development seeds of the following work are 1 and 2 (``benchmarks/following.py``).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from dataclasses import dataclass

import numpy as np

from people_tracker.tracker.config import load_config
from people_tracker.tracker.io.simulated import SimulatedSource
from people_tracker.tracker.people_tracker import PeopleTracker, tracks_in_sensor_frame

NEAR_M = 0.75  # m: the following protocol's match distance
STILL_MPS = 0.1  # m/s: the person stands still when their torso moves slower than this (simulator's truth)


def classify(scene: str, laser: str, seed: int, duration: float | None,
             spells: list[str] | None = None, min_spell_s: float = 1.0, hops: list | None = None,
             losses: list | None = None) -> Counter:
    """The count of the person's visible scans after the first lock in each class; with a
    ``spells`` list, one line is added to it per spell of ``min_spell_s`` or more with the
    target on someone or something else; with a ``hops`` list, one :class:`Hop` per scan
    where the target's track took someone else's candidate; with a ``losses`` list, one
    :class:`Loss` per time the person was reported lost (see the module's text)."""
    source = SimulatedSource(scene, seed=seed, duration=duration, laser=laser)
    tracker = PeopleTracker.from_config(load_config(), follow="auto")
    person, sel = source.sim.target_id, tracker.selector
    out: Counter = Counter()
    locked, first = False, None  # first: the first scan's stamp (s)
    # per scan: None without a target, else (stamp s, on the person, its track, on whom, person visible,
    # the selector's last 'lost' event)
    marks = []
    on_before, previous = None, None  # the target's id if on the person the scan before; that scan's truth
    n_events, loss = 0, None  # the selector's events read so far; the loss not ended yet
    for record in source.scans():
        # the target's track before this scan (only --losses asks)
        gave_up = None if losses is None else next((u for u in tracker._tracks if u.track_id == sel.target), None)
        tracks = tracker.step(record.scan, record.pose, record.pose_last_beam)
        truth = source.truths[record.index]
        k = np.flatnonzero((truth.person_id == person) & truth.visible)
        if losses is not None:
            for event in sel.events[n_events:]:
                loss = _loss_event(event, loss, losses, gave_up, tracker, truth, person, record.scan.stamp - (first or record.scan.stamp))
            n_events = len(sel.events)
        locked |= any(t.target for t in tracks)
        first = record.scan.stamp if first is None else first
        # the reported tracks' places in the sensor frame (m), and the target's id (None without one)
        here = dict(zip((t.track_id for t in tracks), tracks_in_sensor_frame(tracks, tracker.last.pose)))
        target = next((t.track_id for t in tracks if t.target), None)
        if spells is not None:
            marks.append(_mark(record.scan.stamp, target, here, tracker, truth, person, bool(len(k))))
        if hops is not None:
            if on_before is not None and len(k):
                hop = _hop(tracker, truth, previous, person, int(k[0]), on_before, record.scan.stamp - first)
                if hop is not None:
                    hops.append(hop)
            near = bool(len(k)) and target is not None and \
                float(np.hypot(*(here[target] - truth.torso_sensor[k[0]]))) <= tracker.track_params.min_person_separation_m
            on_before, previous = (target if near else None), truth
        if not len(k) or not locked:
            continue
        dist = {tid: float(np.hypot(*(q - truth.torso_sensor[k[0]]))) for tid, q in here.items()}
        if target is not None:
            out["target on the person" if dist[target] <= NEAR_M else "target on someone or something else"] += 1
            continue
        stamp = record.scan.stamp
        if sel.target is not None and sel.lost_since is None and any(
                u.track_id == sel.target and sel.coasting(stamp, u.last_update) for u in tracker._tracks):
            out[f"no target: the person's track has had no update for {sel.coast_s:g} s (reported lost)"] += 1
        elif any(d <= NEAR_M for d in dist.values()):
            if sel.target is None or sel.lost_since is None:
                why = "no person being looked for"
            elif stamp - sel.lost_since < sel.relock_s:
                why = f"lost for less than {sel.relock_s:g} s"
            else:
                ahead = len(sel.looked_for(stamp, here))
                why = ("they are not where the re-lock looks" if ahead == 0 else
                       "1 reported track where the re-lock looks, walking as the person could not" if ahead == 1 else
                       f"{min(ahead, 3)}{'+' if ahead >= 3 else ''} reported tracks where the re-lock looks")
            out[f"no target, a reported track on them: {why}"] += 1
        elif any(float(np.hypot(*(q - truth.torso_sensor[k[0]]))) <= NEAR_M
                 for q in tracks_in_sensor_frame([u.report() for u in tracker._tracks], tracker.last.pose)):
            out["no target, only an unreported track on them"] += 1
        else:
            out["no target, no track near them"] += 1
    if spells is not None:
        spells += _wrong_spells(marks, min_spell_s, first or 0.0)
    return out


@dataclass
class Loss:
    """One time the selector reported its person lost, and how that ended."""

    t_s: float  # from the first scan, s
    why: str  # the reason the 'lost' event gives
    on_person: bool | None  # the track given up was on the person then (None: it had ended, or they were out of view)
    track: object  # the track given up (its state; it goes on under a new id when retired)
    end: str = "not ended"  # found again | re-acquired by the same track | re-acquired by another track | gave up
    onto_person: bool | None = None  # where it ended: the target on the person (None: out of view, or no target)
    end_s: float | None = None

    def line(self) -> str:
        on = {True: "on the person", False: "off the person", None: "ended or out of view"}[self.on_person]
        took = "" if self.end_s is None else f" {self.end_s - self.t_s:.2f} s later"
        return f"  {self.t_s:7.2f} s  {self.why}; the track given up was {on}; {self.end}{took}{_onto(self)}"


def _onto(loss: Loss) -> str:
    """Where a loss that ended with a target put it ("" for one not ended or given up)."""
    if loss.end in ("gave up", "not ended"):
        return ""
    return ", " + {True: "on the person", False: "NOT on the person", None: "person out of view"}[loss.onto_person]


def _on_person(state, tracker: PeopleTracker, truth, person: int) -> bool | None:
    """Whether the track ``state`` lies within ``NEAR_M`` of the person (sensor frame); None
    when it has ended or the person is out of view."""
    k = np.flatnonzero((truth.person_id == person) & truth.visible)
    if state is None or state not in tracker._tracks or not len(k):
        return None
    q = tracks_in_sensor_frame([state.report()], tracker.last.pose)[0]
    return float(np.hypot(*(q - truth.torso_sensor[k[0]]))) <= NEAR_M


def _loss_event(event: str, loss: Loss | None, losses: list, gave_up, tracker: PeopleTracker, truth, person: int,
                t_s: float) -> Loss | None:
    """Book one selector ``event`` in ``losses``; the loss still open after it (``gave_up``:
    the target's track before this scan)."""
    if event.startswith("lost"):
        why = event[event.find("(") + 1:-1] if "(" in event else "no reason given"
        loss = Loss(t_s, why, _on_person(gave_up, tracker, truth, person), gave_up)
        losses.append(loss)
    elif loss is not None and event.startswith(("re-acquired", "found", "gave up")):
        now = next((u for u in tracker._tracks if u.track_id == tracker.selector.target), None)
        loss.end = ("gave up" if event.startswith("gave up") else "found again" if event.startswith("found") else
                    "re-acquired by the same track" if now is loss.track else "re-acquired by another track")
        loss.onto_person = None if loss.end == "gave up" else _on_person(now, tracker, truth, person)
        loss.end_s, loss = t_s, None
    return loss


def loss_counts(losses: list[Loss]) -> list[str]:
    """The summary lines of ``--losses``: per reason, how often the track given up was on the
    person, and how the losses ended."""
    out = [f"times the person was reported lost: {len(losses)}"]
    for why, n in Counter(x.why for x in losses).most_common():
        mine = [x for x in losses if x.why == why]
        ends = Counter(x.end + _onto(x) for x in mine)
        out.append(f"  {why}: {n}; the track given up was on the person in {sum(x.on_person is True for x in mine)}, "
                   f"off them in {sum(x.on_person is False for x in mine)}")
        out += [f"    {c:4d}  {e}" for e, c in ends.most_common()]
    return out


@dataclass(frozen=True)
class Hop:
    """One scan where the target's track, on the person the scan before, took a candidate
    made mostly of someone else's readings."""

    t_s: float  # from the first scan, s
    kind: str  # the candidate's kind (pair, leg, blob)
    whose: dict  # person id (-1: no one, the surroundings) -> how many of its readings
    own: tuple  # the person's own candidates this scan: "kind->who took it" (C confirmed, t tentative, none)
    still: bool  # the person stood still (slower than STILL_MPS)

    def line(self) -> str:
        whose = ", ".join(f"{'surroundings' if p < 0 else f'person {p}'} ({n})" for p, n in
                          sorted(self.whose.items(), key=lambda kv: -kv[1]))
        own = ", ".join(self.own) if self.own else "none"
        return (f"  {self.t_s:7.2f} s  {self.kind:5s} readings of {whose}; the person's own candidates: {own}; "
                f"they {'stood still' if self.still else 'walked'}")


def hop_counts(hops: list[Hop]) -> list[str]:
    """The summary lines of ``--hops``."""
    n = len(hops)
    kinds = Counter(h.kind for h in hops)
    return [f"scans where the target's track, on the person the scan before, took someone else's candidate: {n}",
            f"  the person had no candidate of their own: {sum(not h.own for h in hops)}; "
            f"they stood still: {sum(h.still for h in hops)}; both: {sum(h.still and not h.own for h in hops)}",
            "  by the candidate's kind: " + (", ".join(f"{k} {c}" for k, c in kinds.most_common()) or "none")]


def _whose(candidate, objects: dict, truth) -> Counter:
    """Whose readings (simulator's person id, -1 for the surroundings) a candidate is made of."""
    return Counter(int(truth.beam_person[b]) for oid in candidate.object_ids for b in objects[oid].beams)


def _hop(tracker: PeopleTracker, truth, previous, person: int, k: int, target_id: int, t_s: float) -> Hop | None:
    """This scan's :class:`Hop` of the track ``target_id``, or None (see :func:`classify`);
    ``k``: the person's index in ``truth``."""
    last = tracker.last
    took = [ci for tid, ci in last.matched if tid == target_id]
    if not took or not last.candidates[took[0]].object_ids:
        return None
    objects = {o.object_id: o for o in last.detection.objects}
    whose = _whose(last.candidates[took[0]], objects, truth)
    if not whose or whose.most_common(1)[0][0] == person:
        return None
    inv = last.pose.inverse()
    taker = dict((ci, tid) for tid, ci in last.matched)
    confirmed = {t.track_id: t.confirmed for t in tracker._tracks}
    own = []
    for j, c in enumerate(last.candidates):
        if j == took[0]:
            continue
        if c.object_ids:
            w = _whose(c, objects, truth)
            mine = bool(w) and w.most_common(1)[0][0] == person
        else:  # no readings of its own to judge: theirs when it lies on them
            q = inv.transform_points(np.array([[c.x, c.y]]))[0]
            mine = float(np.hypot(*(q - truth.torso_sensor[k]))) <= tracker.track_params.min_person_separation_m
        if mine:
            tid = taker.get(j)
            own.append(f"{c.kind}->{'none' if tid is None else ('C' if confirmed.get(tid, True) else 't')}")
    kp = np.flatnonzero(previous.person_id == person)
    dt = truth.stamp - previous.stamp
    still = bool(len(kp)) and dt > 0 and float(np.hypot(*(truth.torso_world[k] - previous.torso_world[kp[0]]))) < STILL_MPS * dt
    return Hop(t_s, last.candidates[took[0]].kind, dict(whose), tuple(own), still)


def _mark(stamp: float, target: int | None, here: dict, tracker: PeopleTracker, truth, person: int, visible: bool):
    """One scan's target for :func:`_wrong_spells`, or None without a target (``here``: the
    reported tracks' places in the sensor frame, m)."""
    if target is None:
        return None
    d = np.hypot(*(truth.torso_sensor - here[target]).T)
    j = int(np.argmin(d)) if len(d) else -1
    whom = int(truth.person_id[j]) if j >= 0 and d[j] <= NEAR_M else None
    state = next(u for u in tracker._tracks if u.track_id == target)
    lost = next((e for e in reversed(tracker.selector.events) if e.startswith("lost")), None)
    return stamp, whom == person, state, whom, visible, lost


def _wrong_spells(marks: list, min_s: float, t0: float) -> list[str]:
    """The lines of :func:`classify`'s ``spells`` from its per-scan marks (times from ``t0``, s)."""
    lines, last_on, n = [], None, 0
    while n < len(marks):
        m = marks[n]
        if m is not None and m[1]:
            last_on = m
        if m is None or m[1] or not (m[4] or m[3] is not None):
            n += 1
            continue
        end = n
        while end + 1 < len(marks) and marks[end + 1] is not None and not marks[end + 1][1]:
            end += 1
        spell = marks[n:end + 1]
        if spell[-1][0] - m[0] >= min_s:
            whom = Counter("someone or something else" if s[3] is None else f"person {s[3]}" for s in spell)
            how = (f"another track (the person's id given to it after '{m[5]}')" if last_on is None or last_on[2] is not m[2] else
                   f"the track last on the person, {m[0] - last_on[0]:.2f} s before")
            lines.append(f"  {m[0] - t0:7.2f} s  {len(spell):4d} scans  on {', '.join(f'{w} ({c})' for w, c in whom.most_common())}; "
                         f"{how}")
        n = end + 1
    return lines


def one_run_arguments(doc: str, scene: str, seed: int, argv=None, listings: bool = False) -> argparse.Namespace:
    """``--scene``, ``--laser``, ``--seed`` and ``--duration`` of one simulated following run
    (with ``listings``, also ``--spells``, ``--hops`` and ``--losses``)."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--scene", default=scene)
    ap.add_argument("--laser", default="wide")
    ap.add_argument("--seed", type=int, default=seed)
    ap.add_argument("--duration", type=float, help="seconds (default: the scene's 10 minutes)")
    if listings:
        ap.add_argument("--spells", action="store_true",
                        help="also list each spell of a second or more with the target on someone or something else")
        ap.add_argument("--hops", action="store_true",
                        help="also list each scan where the target's track went from the person onto someone "
                             "else's candidate, and count them")
        ap.add_argument("--losses", action="store_true",
                        help="also list each time the person was reported lost: why, whether the track given up "
                             "was on them, and how it ended; then the counts")
    return ap.parse_args(argv)


def main(argv=None) -> int:
    args = one_run_arguments(__doc__, "follow_indoor_crowd", 2, argv, listings=True)
    spells: list[str] | None = [] if args.spells else None
    hops: list[Hop] | None = [] if args.hops else None
    losses: list[Loss] | None = [] if args.losses else None
    counts = classify(args.scene, args.laser, args.seed, args.duration, spells, hops=hops, losses=losses)
    total = sum(counts.values())
    print(f"{args.scene}, laser {args.laser}, seed {args.seed}: {total} scans with the person visible after the first lock")
    for what, n in sorted(counts.items(), key=lambda kv: -kv[1]):
        print(f"{100 * n / max(total, 1):6.1f} %  {n:6d}  {what}")
    if spells is not None:
        print("spells of 1 s or more with the target on someone or something else (s from the first scan):")
        print("\n".join(spells) if spells else "  none")
    if hops is not None:
        print("scans where the target's track went from the person onto someone else's candidate "
              "(s from the first scan):")
        print("\n".join(h.line() for h in hops) if hops else "  none")
        print("\n".join(hop_counts(hops)))
    if losses is not None:
        print("each time the person was reported lost (s from the first scan):")
        print("\n".join(x.line() for x in losses) if losses else "  none")
        print("\n".join(loss_counts(losses)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
