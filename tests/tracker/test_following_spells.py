"""The spells of ``benchmarks/following_losses.py --spells``: runs of scans with the followed
person's target on someone or something else, and how each began."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from following_losses import _wrong_spells  # noqa: E402


def _marks(spec):
    """Scans 0.1 s apart from (track, on whom, person visible) per scan (None: no target);
    the person is person 1."""
    return [None if s is None else (0.1 * n, s[1] == 1, s[0], s[1], s[2], "lost 1 (track ended)")
            for n, s in enumerate(spec)]


def test_a_track_that_goes_from_the_person_onto_someone_and_an_id_given_to_another():
    a, b = object(), object()
    spec = ([(a, 1, True)] + [(a, 5, True)] * 12  # a slides from the person onto person 5 for 1.2 s
            + [None] * 3
            + [(b, None, True)] * 11  # the id given to b, on nobody, while the person is visible
            + [(a, 1, True)] + [(a, 5, True)] * 5)  # a short one: left out
    lines = _wrong_spells(_marks(spec), 1.0, 0.0)
    assert len(lines) == 2
    assert "12 scans  on person 5 (12); the track last on the person, 0.10 s before" in lines[0]
    assert lines[0].strip().startswith("0.10 s")
    assert "11 scans  on someone or something else (11); another track (the person's id given to it after 'lost 1 (track ended)')" in lines[1]


def test_a_target_on_nothing_while_the_person_is_hidden_is_no_spell():
    a = object()
    spec = [(a, 1, True)] + [(a, None, False)] * 20  # coasting on through the gap: a guess, not wrong
    assert _wrong_spells(_marks(spec), 1.0, 0.0) == []


def test_the_hops_are_counted_by_what_the_person_had_and_did():
    from following_losses import Hop, hop_counts
    hops = [Hop(1.0, "leg", {5: 8}, (), True), Hop(2.0, "pair", {6: 10, -1: 2}, ("pair->C",), False),
            Hop(3.0, "leg", {7: 9}, (), False)]
    lines = hop_counts(hops)
    assert lines[0].endswith(": 3")
    assert "no candidate of their own: 2; they stood still: 1; both: 1" in lines[1]
    assert lines[2].endswith("leg 2, pair 1")
    assert "pair  readings of person 6 (10), surroundings (2); the person's own candidates: pair->C; they walked" \
        in hops[1].line()


def test_a_simulated_run_lists_the_scans_where_the_persons_track_took_someone_elses_candidate():
    """60 s of a development run: the followed person's track takes passers-by's legs."""
    from following_losses import classify
    hops = []
    classify("follow_indoor_crowd", "narrow", 1, 60.0, hops=hops)
    assert hops, "the person's track never took someone else's candidate"
    for h in hops:
        assert 0.0 < h.t_s <= 60.0
        assert h.kind in ("leg", "pair", "blob")
        assert max(h.whose, key=h.whose.get) != 1  # the followed person is the simulator's person 1


def test_the_losses_are_counted_by_reason_where_the_track_given_up_was_and_how_they_ended():
    from following_losses import Loss, loss_counts
    a, b = object(), object()
    losses = [Loss(1.0, "slid onto someone", True, a, "re-acquired by the same track", True, 2.07),
              Loss(5.0, "slid onto someone", False, b, "re-acquired by another track", False, 6.0),
              Loss(9.0, "track ended", None, None, "re-acquired by another track", True, 10.5),
              Loss(20.0, "slid onto someone", True, a)]
    lines = loss_counts(losses)
    assert lines[0].endswith(": 4")
    assert lines[1].strip() == "slid onto someone: 3; the track given up was on the person in 2, off them in 1"
    assert sorted(line.strip() for line in lines[2:5]) == [
        "1  not ended", "1  re-acquired by another track, NOT on the person", "1  re-acquired by the same track, on the person"]
    assert lines[5].strip() == "track ended: 1; the track given up was on the person in 0, off them in 0"
    assert "re-acquired by the same track 1.07 s later, on the person" in losses[0].line()
    assert "the track given up was ended or out of view" in losses[2].line()


def test_a_simulated_run_lists_each_loss_of_the_person_and_its_end():
    """90 s of a development run: the person is lost (their track ends, or slides off them)
    and their id is taken up again."""
    from following_losses import classify
    losses = []
    classify("follow_indoor_crowd", "narrow", 1, 90.0, losses=losses)
    assert losses, "the person was never reported lost"
    for x in losses:
        assert 0.0 < x.t_s <= 90.0
        assert x.why in ("track ended", "track not reported", "slid onto someone", "out of reach",
                         "coasting, another track where they should be")
        if x.why == "track ended":
            assert x.on_person is None  # nothing left to judge
        if x.end_s is not None:
            assert x.end_s > x.t_s
            assert x.end in ("found again", "re-acquired by the same track", "re-acquired by another track", "gave up")
    assert any(x.end.startswith("re-acquired") and x.onto_person for x in losses)


def test_a_loss_not_ended_or_given_up_says_nothing_of_where_the_target_went():
    from following_losses import Loss
    assert Loss(3.0, "track ended", None, None).line().endswith("not ended")
    assert Loss(3.0, "track ended", None, None, "gave up", None, 13.0).line().endswith("gave up 10.00 s later")
