"""Tracker accuracy against ground truth: CLEAR MOT (Leigh et al., ICRA 2015), IDF1, OSPA.

Protocols (Leigh et al.):

* ``general``: every person. A track within ``threshold`` metres of a person can match it
  (CLEAR MOT's assignment, keeping last frame's matches while they stay in range);
  ``MOTA = 1 - (misses + false positives + id switches) / ground-truth people``, ``MOTP``
  the mean distance of the matches in metres.
* ``following``: Leigh et al.'s figures for the followed person over all tracks — the
  ground truth holds only them (Leigh's recordings), or everyone with the person named
  (``target_person``, or the simulator's ``target`` column). False positives are counted but
  do not lower MOTA: ``MOTA = 1 - (misses + id switches) / ground truth``. From the rows the
  tracker marked ``target``, target continuity (:func:`target_continuity`): the share of the
  person's visible scans after the first lock with the target within ``threshold`` of them,
  the scans with the target on someone or something else, the target changes and the time
  to the first lock.

Every scan is a frame, including scans where nobody is annotated (a reported person
there is a false positive). Positions are compared in the sensor frame.

Hidden people (simulated scenes, where the simulator knows who is there but out of sight,
fewer than 3 points) follow the MOTChallenge convention for ignored ground truth: a track
that lies within ``threshold`` of a hidden person, and is not needed for a visible one
(a joint nearest assignment per frame), is left out of that frame: neither a match nor a
false positive. A tracker that keeps an occluded person is not punished for it, and gets
no credit either.

A bearing window (Leigh et al.'s ``constrain_to_specific_angle``) drops the ground-truth
people and the tracks whose sensor-frame bearing ``atan2(y, x)`` lies outside it before
matching, in every frame. Their published moving-robot figures use −80°..12°: the part of
the left laser's view that the annotators labelled (ahead of the robot).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from people_tracker.models.pose import pairwise_distances
from people_tracker.tracker.errors import InputError, require
from people_tracker.tracker.io.ground_truth import GroundTruth


@dataclass(frozen=True, eq=False)
class TrackRows:
    """Reported tracks: one row per track per scan, sensor frame, metres."""

    scan_index: np.ndarray
    track_id: np.ndarray
    x: np.ndarray
    y: np.ndarray
    target: np.ndarray | None = None  # 1 for the followed person, when the file says
    stamp: np.ndarray | None = None  # the scan's stamp (s), when the file says

    def __len__(self) -> int:
        return int(self.scan_index.shape[0])

    @classmethod
    def of(cls, rows) -> "TrackRows":
        """From rows ``(scan_index, track_id, x, y)``, or ``(…, target, stamp)`` with the
        followed person's flag and the scan's stamp (s)."""
        a = np.array(rows, dtype=float)
        a = a.reshape(-1, a.shape[1] if a.ndim == 2 else 4)
        full = a.shape[1] >= 6
        return cls(a[:, 0].astype(np.int64), a[:, 1].astype(np.int64), a[:, 2], a[:, 3],
                   a[:, 4].astype(np.int64) if full else None, a[:, 5] if full else None)


def frame_mismatches(gt: GroundTruth, tracks: TrackRows) -> list[str]:
    """Reasons to doubt that ``tracks`` and ``gt`` come from one recording, one line each.

    The ground truth's frames are its scans ``0..n-1`` (its last annotated scan when it
    does not say how many there are); the tracks' frames run from scan 0 (every message
    of the topic counts) to their last row. Said when the tracks go beyond the ground
    truth (by more than a quarter when it does not say how many frames it has: nobody may
    be visible in the last scans), or when the two overlap on fewer than half of either's
    frames.
    """
    if not len(tracks.scan_index):
        return []
    n_gt = gt.n_frames if gt.n_frames is not None else (int(gt.scan_index.max()) + 1 if len(gt.scan_index) else 0)
    n_tracks = int(tracks.scan_index.max()) + 1
    out = []
    if n_tracks > (n_gt if gt.n_frames is not None else 1.25 * n_gt):
        out.append(f"the tracks hold scan indices up to {n_tracks - 1}, beyond the ground truth's {n_gt} frames "
                   f"(0..{n_gt - 1}): are both from the same recording and topic?")
    overlap = min(n_gt, n_tracks)
    if overlap < 0.5 * n_gt or overlap < 0.5 * n_tracks:
        out.append(f"the tracks (scans 0..{n_tracks - 1}) and the ground truth ({n_gt} frames) overlap on "
                   f"{overlap} frames only, fewer than half of "
                   + ("either's" if overlap < 0.5 * n_gt and overlap < 0.5 * n_tracks
                      else "the ground truth's" if overlap < 0.5 * n_gt else "the tracks'"))
    return out


def _by_frame(index: np.ndarray, n_frames: int) -> list[np.ndarray]:
    """Row numbers of each frame 0..n_frames-1."""
    order = np.argsort(index, kind="stable")
    bounds = np.searchsorted(index[order], np.arange(n_frames + 1))
    return [order[bounds[k]:bounds[k + 1]] for k in range(n_frames)]


def ospa(gt_xy: np.ndarray, tr_xy: np.ndarray, cutoff: float, order: float) -> float:
    """OSPA distance (Schuhmacher et al. 2008) between two point sets, metres."""
    m, n = len(gt_xy), len(tr_xy)
    if m == 0 and n == 0:
        return 0.0
    if m == 0 or n == 0:
        return cutoff
    d = np.minimum(pairwise_distances(gt_xy, tr_xy), cutoff)
    cost = d ** order
    rows, cols = linear_sum_assignment(cost)
    # (1/n (Σ d_c^p over the assignment + c^p |m - n|))^(1/p)
    total = cost[rows, cols].sum() + cutoff ** order * abs(m - n)
    return float((total / max(m, n)) ** (1.0 / order))


def without_hidden(gt: GroundTruth, hidden: GroundTruth, tracks: TrackRows, threshold: float) -> tuple[TrackRows, int]:
    """The tracks without those on hidden people (see the module docstring), and how many
    track rows were left out."""
    keep = np.ones(len(tracks), dtype=bool)
    frames = max(int(tracks.scan_index.max(initial=-1)), int(hidden.scan_index.max(initial=-1))) + 1
    g_rows, h_rows, t_rows = (_by_frame(a.scan_index, frames) for a in (gt, hidden, tracks))
    for k in range(frames):
        h, t = h_rows[k], t_rows[k]
        if not len(h) or not len(t):
            continue
        g = g_rows[k]
        people = np.vstack([np.column_stack([gt.x[g], gt.y[g]]), np.column_stack([hidden.x[h], hidden.y[h]])])
        d = pairwise_distances(people, np.column_stack([tracks.x[t], tracks.y[t]]))
        rows, cols = linear_sum_assignment(np.where(d <= threshold, d, 1e6))
        for r, c in zip(rows, cols):
            if r >= len(g) and d[r, c] <= threshold:
                keep[t[c]] = False
    return _rows_where(tracks, keep), int((~keep).sum())


def followed_person(gt: GroundTruth, target_person: int | None = None) -> int:
    """The id of the followed person: ``target_person``, the one the ground truth marks, or
    the only one in it; an :class:`InputError` when it cannot say."""
    ids = np.unique(gt.person_id)
    if target_person is not None:
        if target_person not in ids:
            raise InputError(f"--target-person {target_person} is not in the ground truth "
                             f"(it holds {', '.join(map(str, ids[:10].tolist())) or 'nobody'})")
        return int(target_person)
    if gt.target is not None and (gt.target == 1).any():
        marked = np.unique(gt.person_id[gt.target == 1])
        if len(marked) == 1:
            return int(marked[0])
    if len(ids) == 1:
        return int(ids[0])
    raise InputError(f"the ground truth holds {len(ids)} people and does not say whom the robot follows: "
                     "name them with --target-person ID")


def target_continuity(person: GroundTruth, others: GroundTruth, tracks: TrackRows, threshold: float) -> dict:
    """How well the tracker's target stays on the followed person.

    ``person`` holds the followed person's visible scans, ``others`` everyone else's; the
    target is the track rows marked ``target == 1`` (one per scan). The first lock is the
    first visible scan with the target within ``threshold`` of the person. After it:
    ``target_on_person`` is the share of the person's visible scans with the target on them;
    ``target_wrong_scans`` counts scans with the target farther than ``threshold`` from the
    visible person, or, while they are not visible, within ``threshold`` of someone else;
    ``target_changes`` counts changes of the target's track id (over the whole run);
    ``first_lock_s`` is the time from the person's first visible scan to the first lock,
    seconds (from the tracks' stamps; NaN without them or without a lock).
    """
    nan = float("nan")
    out = {"target_person_scans": int(len(person)), "first_lock_scan": None, "first_lock_s": nan,
           "target_on_person": nan, "target_wrong_scans": None, "target_changes": None}
    if tracks.target is None:
        return out
    sel = np.flatnonzero(tracks.target == 1)
    sel = sel[np.argsort(tracks.scan_index[sel], kind="stable")]
    scans, first = np.unique(tracks.scan_index[sel], return_index=True)
    sel = sel[first]  # one target row per scan
    ids = tracks.track_id[sel]
    out["target_changes"] = int((ids[1:] != ids[:-1]).sum())
    where = {int(k): (float(x), float(y)) for k, x, y in zip(scans, tracks.x[sel], tracks.y[sel])}
    p_scan = person.scan_index
    d = np.array([np.hypot(where[k][0] - x, where[k][1] - y) if k in where else np.inf
                  for k, x, y in zip(p_scan.tolist(), person.x, person.y)])
    on = d <= threshold
    if not on.any():
        out["target_on_person"], out["target_wrong_scans"] = 0.0, int(len(scans))
        return out
    lock = int(p_scan[np.argmax(on)])
    after = p_scan >= lock
    out["first_lock_scan"] = lock
    out["target_on_person"] = float(on[after].mean())
    visible = set(p_scan.tolist())
    wrong = int((~on[after] & np.isfinite(d[after])).sum())
    o_rows = _by_frame(others.scan_index, int(max(scans.max(initial=-1), others.scan_index.max(initial=-1))) + 1)
    for k in scans[scans >= lock].tolist():
        if k in visible or k >= len(o_rows) or not len(o_rows[k]):
            continue
        r = o_rows[k]
        if (np.hypot(others.x[r] - where[k][0], others.y[r] - where[k][1]) <= threshold).any():
            wrong += 1
    out["target_wrong_scans"] = wrong
    if tracks.stamp is not None and len(np.unique(tracks.scan_index)) >= 2:
        slope = np.polyfit(tracks.scan_index.astype(float), tracks.stamp, 1)[0]  # s per scan
        out["first_lock_s"] = float(slope * (lock - int(p_scan[0])))
    return out


def evaluate(gt: GroundTruth, tracks: TrackRows, protocol: str = "general", threshold: float = 0.75,
             ospa_cutoff: float = 1.0, ospa_order: float = 1.0, n_frames: int | None = None,
             bearing_window_deg: tuple[float, float] | None = None, hidden: GroundTruth | None = None,
             target_person: int | None = None) -> dict:
    """Score ``tracks`` against ``gt``.

    Parameters
    ----------
    gt : GroundTruth
    tracks : TrackRows
    protocol : {'general', 'following'}
    threshold : float
        Largest distance of a match, metres.
    ospa_cutoff, ospa_order : float
        OSPA's cut-off c (metres) and order p.
    n_frames : int, optional
        Number of frames; default ``gt.n_frames`` or the largest index seen plus one.
    bearing_window_deg : (float, float), optional
        Keep only people and tracks whose sensor-frame bearing lies in [min, max], degrees.
    hidden : GroundTruth, optional
        People who are there but hidden: tracks on them are ignored (see the module docstring).
    target_person : int, optional
        The followed person's id (``following``), when the ground truth holds everyone.

    Returns
    -------
    dict
        frames, ground_truth, matches, misses, false_positives, id_switches, mota, motp (m),
        idf1, ospa (m, mean over frames), and the protocol and parameters used; for
        ``following`` also target_person and the figures of :func:`target_continuity`.
    """
    # imported here: pandas is slow to import and only evaluation needs it
    mm = require("motmetrics", "eval", "evaluation (CLEAR MOT, IDF1)")

    if protocol not in ("general", "following"):
        raise ValueError(f"protocol must be general or following, got {protocol!r}")
    following = {}
    if protocol == "following":
        pid = followed_person(gt, target_person)
        others = _rows_where(gt, gt.person_id != pid)
        gt = _rows_where(gt, gt.person_id == pid)
        following = {"target_person": pid, **target_continuity(gt, others, tracks, threshold)}
    ignored = 0
    if hidden is not None and len(hidden) and protocol == "general":
        tracks, ignored = without_hidden(gt, hidden, tracks, threshold)
    if bearing_window_deg is not None:
        gt, tracks = _in_window(gt, bearing_window_deg), _in_window(tracks, bearing_window_deg)
    last = max(int(gt.scan_index.max(initial=-1)), int(tracks.scan_index.max(initial=-1)))
    frames = n_frames if n_frames is not None else (gt.n_frames if gt.n_frames is not None else last + 1)
    frames = max(frames, last + 1)
    gt_rows = _by_frame(gt.scan_index, frames)
    tr_rows = _by_frame(tracks.scan_index, frames)
    acc = mm.MOTAccumulator(auto_id=True)
    ospas = np.empty(frames)
    for k in range(frames):
        g, t = gt_rows[k], tr_rows[k]
        gxy = np.column_stack([gt.x[g], gt.y[g]])
        txy = np.column_stack([tracks.x[t], tracks.y[t]])
        # Euclidean distances (not squared: MOTP is then in metres); beyond the threshold: no match
        d = pairwise_distances(gxy, txy) if len(g) and len(t) \
            else np.zeros((len(g), len(t)))
        d[d > threshold] = np.nan
        acc.update(gt.person_id[g].tolist(), tracks.track_id[t].tolist(), d)
        ospas[k] = ospa(gxy, txy, ospa_cutoff, ospa_order)
    summary = mm.metrics.create().compute(
        acc, metrics=["num_objects", "num_detections", "num_misses", "num_false_positives", "num_switches",
                      "motp", "idf1"], name="all")
    row = summary.loc["all"]
    n_gt = int(row["num_objects"])
    misses, fps, switches = int(row["num_misses"]), int(row["num_false_positives"]), int(row["num_switches"])
    errors = misses + switches + (0 if protocol == "following" else fps)
    return {
        "protocol": protocol,
        "threshold_m": threshold,
        "frames": int(frames),
        "ground_truth": n_gt,
        "tracks_reported": int(len(tracks)) + ignored,
        "tracks_on_hidden_people": ignored,
        "matches": int(row["num_detections"]),  # CLEAR MOT correspondences, switches included
        "misses": misses,
        "false_positives": fps,
        "id_switches": switches,
        "mota": (1.0 - errors / n_gt) if n_gt else float("nan"),
        "motp_m": float(row["motp"]) if int(row["num_detections"]) else float("nan"),
        "idf1": float(row["idf1"]) if n_gt + len(tracks) else float("nan"),
        "ospa_m": float(ospas.mean()) if frames else float("nan"),
        "ospa_cutoff_m": ospa_cutoff,
        "ospa_order": ospa_order,
        "bearing_window_deg": None if bearing_window_deg is None else [float(b) for b in bearing_window_deg],
        **following,
    }


def _in_window(rows, window_deg: tuple[float, float]):
    """The rows (GroundTruth or TrackRows) whose sensor-frame bearing is inside the window."""
    lo, hi = np.radians(window_deg[0]), np.radians(window_deg[1])
    bearing = np.arctan2(rows.y, rows.x)
    return _rows_where(rows, (bearing >= lo) & (bearing <= hi))


def _rows_where(rows, keep: np.ndarray):
    """The rows (GroundTruth or TrackRows) where ``keep`` (bool, one per row) is true."""
    return replace(rows, **{f.name: getattr(rows, f.name)[keep] for f in fields(rows)
                            if isinstance(getattr(rows, f.name), np.ndarray) and getattr(rows, f.name).shape == keep.shape})


def format_table(result: dict) -> str:
    """The result as an aligned, readable table."""
    pct = lambda v: "n/a" if v != v else f"{100 * v:.1f} %"  # noqa: E731
    metres = lambda v: "n/a" if v != v else f"{v:.3f} m"  # noqa: E731
    lines = [
        ("protocol", f"{result['protocol']} (match within {result['threshold_m']:g} m)"),
        ("frames", f"{result['frames']}"
                   + ("" if result.get("bearing_window_deg") is None else
                      " (people and tracks with bearing {:g}°..{:g}° only)".format(*result["bearing_window_deg"]))),
        ("ground-truth people", f"{result['ground_truth']}"),
        ("reported tracks", f"{result['tracks_reported']}"
                            + (f" ({result['tracks_on_hidden_people']} on hidden people, ignored)"
                               if result.get("tracks_on_hidden_people") else "")),
        ("matches", f"{result['matches']}"),
        ("misses", f"{result['misses']}"),
        ("false positives", f"{result['false_positives']}" + (" (not counted in MOTA)" if result["protocol"] == "following" else "")),
        ("id switches", f"{result['id_switches']}"),
        ("MOTA", pct(result["mota"])),
        ("MOTP", metres(result["motp_m"])),
        ("IDF1", pct(result["idf1"])),
        (f"OSPA (c={result['ospa_cutoff_m']:g} m, p={result['ospa_order']:g})", metres(result["ospa_m"])),
    ]
    if result["protocol"] == "following":
        lock = result.get("first_lock_scan")
        lines += [
            ("followed person", f"{result['target_person']} ({result['target_person_scans']} visible scans)"),
            ("first lock", "never" if lock is None else f"scan {lock}" + (
                "" if result["first_lock_s"] != result["first_lock_s"] else f", {result['first_lock_s']:.2f} s "
                "after they are first visible")),
            ("target on the person", "n/a (no target column)" if result["target_changes"] is None
             else pct(result["target_on_person"]) + " of their visible scans after the first lock"),
            ("target elsewhere", "n/a" if result["target_wrong_scans"] is None
             else f"{result['target_wrong_scans']} scans (on someone or something else)"),
            ("target changes", "n/a" if result["target_changes"] is None else f"{result['target_changes']}"),
        ]
    width = max(len(k) for k, _ in lines)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in lines)
