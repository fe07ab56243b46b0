"""Inputs that used to give a wrong answer without a word: a hole in a DataFrame's frame
labels, an AMC file that says both :DEGREES and :RADIANS."""

import numpy as np
import pandas as pd
import pytest

from skmotion.io import MotionFileError, read_amc
from skmotion.preprocessing import FillGaps
from skmotion.utils import check_clips, insert_missing_frames
from tests.io.test_asf_amc import ASF, _amc, _frames


def _frame_table(frames_a, frames_b):
    index = pd.MultiIndex.from_tuples(
        [("a", f) for f in frames_a] + [("b", f) for f in frames_b], names=["clip", "frame"]
    )
    values = np.arange(3.0 * len(index)).reshape(-1, 3)  # one 3-D point
    return pd.DataFrame(values, index=index, columns=["x", "y", "z"])


def test_a_hole_in_the_frame_labels_is_refused_with_the_way_out():
    df = _frame_table([0, 1, 4, 5], [0, 1, 2])
    with pytest.raises(ValueError, match=r"clip 'a' jumps from frame 1 to frame 4 \(2 frames"):
        check_clips(df)
    with pytest.raises(ValueError, match="insert_missing_frames"):
        FillGaps().fit_transform(df)
    # Timestamps (not integers) only need to increase; whole clips may start anywhere.
    check_clips(_frame_table([0.0, 0.5, 2.0], [0.0]))
    check_clips(_frame_table([10, 11, 12], [3, 4]))


def test_insert_missing_frames_then_fill_gaps():
    """Position x = frame: the filled frames 2 and 3 of clip a are 2 and 3 again."""
    df = _frame_table([0, 1, 4, 5], [7, 8, 9])
    df["x"] = df.index.get_level_values(1).astype(float)
    filled = insert_missing_frames(df)
    assert filled.index.tolist()[:6] == [("a", 0), ("a", 1), ("a", 2), ("a", 3), ("a", 4), ("a", 5)]
    assert filled.loc["a"].iloc[2:4].isna().all().all() and len(filled) == 9
    assert filled.loc["b", "y"].tolist() == df.loc["b", "y"].tolist()
    out = FillGaps(method="linear").fit_transform(filled)
    np.testing.assert_allclose(out.loc["a", "x"].to_numpy(), np.arange(6.0))
    with pytest.raises(ValueError, match="frame labels must be integers"):
        insert_missing_frames(_frame_table([0.0, 0.5], [0.0]))


@pytest.mark.parametrize("order", [(":DEGREES", ":RADIANS"), (":RADIANS", ":DEGREES")])
def test_amc_with_both_angle_units_is_refused(tmp_path, rng, order):
    from skmotion.io import read_asf

    (tmp_path / "s.asf").write_text(ASF)
    body = _amc(_frames(rng, 3)).replace(":DEGREES", "\r\n".join(order))
    (tmp_path / "t.amc").write_text(body, newline="")
    with pytest.raises(MotionFileError, match=r"t\.amc, line 3: both :DEGREES and :RADIANS"):
        read_amc(tmp_path / "t.amc", read_asf(tmp_path / "s.asf"))
    # Saying the same unit twice is no contradiction.
    (tmp_path / "u.amc").write_text(body.replace(order[1], order[0]), newline="")
    assert read_amc(tmp_path / "u.amc", read_asf(tmp_path / "s.asf")).n_frames == 3
