import pytest

from people_tracker.tracker.errors import InputError
from people_tracker.tracker.io.ground_truth import read_ground_truth, read_gt_csv


def test_csv_ground_truth_reads_and_sorts(tmp_path):
    f = tmp_path / "gt.csv"
    f.write_text("scan_index,person_id,x,y,extra\n3,7,1.5,-2.0,a\n0,2,0.5,0.25,b\n3,1,4.0,1.0,c\n")
    gt = read_ground_truth(f)
    assert gt.n_frames is None and len(gt) == 3
    assert gt.scan_index.tolist() == [0, 3, 3] and gt.person_id.tolist() == [2, 1, 7]
    assert gt.x.tolist() == [0.5, 4.0, 1.5]


@pytest.mark.parametrize("text,words", [
    ("", "empty"),
    ("scan_index,person_id,x\n1,2,3\n", "lacks the column(s) y"),
    ("scan_index,person_id,x,y\n1,2,abc,4\n", "line 2"),
    ("scan_index,person_id,x,y\n-1,2,3,4\n", "line 2"),
    ("scan_index,person_id,x,y\n1,2,nan,4\n", "line 2"),
])
def test_bad_csv_names_the_problem(tmp_path, text, words):
    f = tmp_path / "gt.csv"
    f.write_text(text)
    with pytest.raises(InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        read_gt_csv(f)


def test_missing_csv():
    with pytest.raises(InputError, match="does not exist"):
        read_gt_csv("/no/such/gt.csv")
