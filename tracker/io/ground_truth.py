"""Ground truth: person positions per scan, in the sensor frame.

From an annotated recording (``leg_tracker/msg/Person`` or ``PersonArray`` messages) with
the scan-index rule of Leigh et al.'s benchmark, or from the ground-truth CSV of the
contract (``scan_index,person_id,x,y``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.bag import LASER_SCAN, PERSON_TYPES, connections_of, open_bag, select_topic, topics_of_type
from people_tracker.tracker.io.csv_table import read_rows

log = logging.getLogger(__name__)

GT_COLUMNS = ("scan_index", "person_id", "x", "y")


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """Visible people per scan.

    Attributes
    ----------
    n_frames : int or None
        Number of scans evaluated (every scan of the topic is a frame, with people or not);
        None when the source does not say (a CSV), so the evaluator takes the last index.
    scan_index, person_id : ndarray of int, shape (m,)
    x, y : ndarray of float, shape (m,)
        Person (torso) position in the scan's sensor frame, metres.
    target : ndarray of int, shape (m,), or None
        1 on the rows of the person the robot follows, when the source says (the
        simulator's ``target`` column).
    """

    n_frames: int | None
    scan_index: np.ndarray
    person_id: np.ndarray
    x: np.ndarray
    y: np.ndarray
    target: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.scan_index.shape[0])


def _make(n_frames, rows) -> GroundTruth:
    rows = sorted(rows, key=lambda r: (r[0], r[1]))
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    return GroundTruth(n_frames, arr[:, 0].astype(np.int64), arr[:, 1].astype(np.int64), arr[:, 2], arr[:, 3])


def read_bag_ground_truth(path: str | Path, scan_topic: str | None = None,
                          gt_topic: str | None = None, required: bool = True) -> GroundTruth | None:
    """Ground truth of an annotated recording.

    Every message of the scan topic is a frame. A person message is stamped (bag time)
    between the scan it annotates and the next one, so it belongs to the last scan whose
    bag time is at or before its own. With ``required=False`` a recording without a
    ground-truth topic gives None instead of an error.
    """
    reader = open_bag(path)
    try:
        if not required and gt_topic is None and not topics_of_type(reader, PERSON_TYPES):
            return None
        scan_topic = select_topic(reader, scan_topic, LASER_SCAN, "LaserScan", "--topic")
        gt_topic = select_topic(reader, gt_topic, PERSON_TYPES, "ground-truth (leg_tracker/Person)", "--gt-topic")
        scan_conns = connections_of(reader, scan_topic)
        scan_ids = {c.id for c in scan_conns}
        scan_times: list[int] = []
        gt_msgs: list[tuple[int, object]] = []
        try:
            for conn, t, raw in reader.messages(connections=scan_conns + connections_of(reader, gt_topic)):
                if conn.id in scan_ids:
                    scan_times.append(t)
                else:
                    gt_msgs.append((t, reader.deserialize(raw, conn.msgtype)))
        except Exception as exc:
            raise InputError(f"ground truth '{path}' cannot be read: {' '.join(str(exc).split())[:200]}") from None
    finally:
        reader.close()
    times = np.asarray(scan_times, dtype=np.int64)
    rows = []
    early = 0
    for t, msg in gt_msgs:
        k = int(np.searchsorted(times, t, side="right")) - 1  # last scan with bag time <= t
        if k < 0:
            early += 1
            continue
        for person in getattr(msg, "people", [msg]):
            rows.append((k, int(person.id), float(person.pose.position.x), float(person.pose.position.y)))
    if early:
        log.warning("%d ground-truth messages come before the first scan and are ignored", early)
    return _make(len(scan_times), rows)


def read_gt_csv(path: str | Path) -> GroundTruth:
    """Ground truth from a CSV with the header ``scan_index,person_id,x,y`` (a ``target``
    column is read when present; other extra columns are ignored)."""
    rows = read_rows(path, "ground truth", GT_COLUMNS, lambda row: (
        int(row["scan_index"]), int(row["person_id"]), float(row["x"]), float(row["y"]),
        int(row["target"]) if row.get("target") not in (None, "") else -1))
    gt = _make(None, [r[:4] for r in rows])
    targets = {(r[0], r[1]) for r in rows if r[4] == 1}
    if not rows or rows[0][4] < 0:
        return gt
    mark = np.array([(k, p) in targets for k, p in zip(gt.scan_index.tolist(), gt.person_id.tolist())], dtype=np.int64)
    return GroundTruth(None, gt.scan_index, gt.person_id, gt.x, gt.y, mark)


def read_ground_truth(path: str | Path, scan_topic: str | None = None, gt_topic: str | None = None) -> GroundTruth:
    """Ground truth from a recording (by its form) or from a CSV file."""
    p = Path(path)
    if p.suffix.lower() == ".csv":
        return read_gt_csv(p)
    return read_bag_ground_truth(p, scan_topic, gt_topic)
