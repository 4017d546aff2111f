import numpy as np

from people_tracker.models.scan import Scan
from people_tracker.tracker.scan_checks import ScanChecker


def scan(stamp, n=100, ranges=None):
    r = np.full(n, 2.0) if ranges is None else ranges
    return Scan(r, -1.0, 2.0 / n, 0.1, 10.0, stamp=stamp)


def run(checker, scans):
    return [checker.check(s) for s in scans]


def test_good_stream_is_all_used():
    v = run(ScanChecker(5.0, 3), [scan(0.1 * i) for i in range(20)])
    assert all(x.use and not x.restart and x.reason is None for x in v)


def test_all_invalid_scan_is_skipped_with_a_reason():
    bad = scan(0.2, ranges=np.array([np.nan] * 50 + [0.0] * 25 + [np.inf] * 25))
    v = run(ScanChecker(5.0, 3), [scan(0.0), scan(0.1), bad, scan(0.3)])
    assert [x.use for x in v] == [True, True, False, True]
    assert "all 100 readings are invalid" in v[2].reason


def test_stamp_going_backwards_or_repeating_is_skipped():
    v = run(ScanChecker(5.0, 3), [scan(0.0), scan(0.1), scan(0.05), scan(0.1), scan(0.2)])
    assert [x.use for x in v] == [True, True, False, False, True]
    assert "goes back" in v[2].reason and "repeats" in v[3].reason


def test_stamp_jump_restarts_history_but_keeps_the_scan():
    stamps = [0.1 * i for i in range(5)] + [3.0, 3.1]
    v = run(ScanChecker(5.0, 3), [scan(t) for t in stamps])
    assert all(x.use for x in v)
    assert [x.restart for x in v] == [False] * 5 + [True, False]
    assert "jumps" in v[5].reason


def test_a_stray_beam_count_is_skipped_and_a_lasting_change_adopted():
    c = ScanChecker(5.0, 3)
    counts = [100, 100, 50, 100, 60, 60, 60, 60, 100]
    v = [c.check(scan(0.1 * i, n=k)) for i, k in enumerate(counts)]
    assert [x.use for x in v] == [True, True, False, True, False, False, True, True, False]
    assert v[6].restart and "changed from 100 to 60" in v[6].reason
    assert "50 beams" in v[2].reason


def test_undecodable_message_is_skipped():
    v = ScanChecker(5.0, 3).check(None, "cannot be decoded (bad bytes)")
    assert not v.use and "cannot be decoded" in v.reason
