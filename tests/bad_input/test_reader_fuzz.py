"""Mutations of the real files, per reader (``tests/bad_input/reader_fuzz.py``), with a fixed
seed and a small budget; ``benchmarks/bench_fuzz.py --per-reader 10000`` runs the issue's
budget. Below it, the failures the long run found, each rebuilt by its test."""

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_keypoints
from tests.bad_input import reader_fuzz

N_CASES = 24  # per reader


@pytest.mark.parametrize("reader", reader_fuzz.READERS)
def test_real_files_per_reader(tmp_path, shared_data, reader):
    counts, failures = reader_fuzz.fuzz_reader(
        reader, shared_data, tmp_path, n_cases=N_CASES, seed=3
    )
    assert not failures, "\n".join(f"{s}: {o}: {d}" for s, o, d, _ in failures[:10])
    total = {k: sum(row[k] for row in counts.values()) for k in reader_fuzz.OUTCOMES}
    assert (
        total["tried"] == N_CASES and total["rejected"] > 0 and total["agrees"] + total["equal"] > 0
    )


def test_the_keypoint_judge_can_fail(tmp_path, shared_data):
    """A read that differs from the plain split of the text, or that takes a column named
    for one axis as another, is called wrong."""
    source = next(s for s in reader_fuzz.sources("keypoints", shared_data, tmp_path))
    path = tmp_path / f"o{source.suffix}"
    path.write_bytes(source.data)
    original = source.read(path)
    assert source.judge(original, original, source.data, "text") == ("agrees", "")
    shifted = source.read(path)
    shifted.channels[3, 4] += 1e-9
    assert source.judge(shifted, original, source.data, "text")[0] == "wrong"
    values, names = reader_fuzz.keypoint_text_reference("a_x,a_y,a_z,a_c\r\n0,nan,2,1\n")
    assert names == ["a_x", "a_y", "a_z", "a_c"]
    np.testing.assert_array_equal(values, [[0, np.nan, 2, 1]])
    for bad in ("0,1\xa0,2,1", "0,1_0,2,1", "0,inf,2,1", "0,1,2\n0,1"):
        with pytest.raises(ValueError):
            reader_fuzz.keypoint_text_reference(bad)


def _keypoint_text(tmp_path, text, name="k.csv"):
    path = tmp_path / name
    path.write_bytes(text.encode("utf-8"))
    return path


@pytest.mark.parametrize("blank", ["\u00a0", "\u2007", "\u3000", "\x85"])
def test_a_unicode_blank_inside_a_number_is_refused_with_its_line(tmp_path, blank):
    """Found by the run: ``2.94868<NBSP>`` was read as 2.94868 (numpy strips Unicode
    blanks); the one text rule of every reader takes spaces and tabs only."""
    text = "h_x,h_y,h_z\n0.5,1,2\n0.25,2.94868" + blank + ",3\n"
    with pytest.raises(MotionFileError, match=r"k\.csv, line 3: not a finite number"):
        read_keypoints(_keypoint_text(tmp_path, text), columns="xyz", frame_rate=30)
    spaced = "0.5 1 2\n0.25" + blank + "2 3\n"  # between numbers: no separator either
    with pytest.raises(MotionFileError, match="line 2"):
        read_keypoints(_keypoint_text(tmp_path, spaced, "k.txt"), columns="xyz", frame_rate=30)


def test_a_control_byte_is_refused_with_its_line(tmp_path):
    text = "0.5 1 2\n0.25 2\x0c 3\n"
    with pytest.raises(MotionFileError, match=r"k\.txt, line 2"):
        read_keypoints(_keypoint_text(tmp_path, text, "k.txt"), columns="xyz", frame_rate=30)


def test_crlf_cr_and_a_byte_order_mark_read_as_lf(tmp_path):
    text = "h_x,h_y,h_z\n0.5,1,2\n0.25,2,3\n"
    expected = [[0.5, 1, 2], [0.25, 2, 3]]
    for variant in (text.replace("\n", "\r\n"), text.replace("\n", "\r"), "\ufeff" + text):
        motion = read_keypoints(_keypoint_text(tmp_path, variant), columns="xyz", frame_rate=30)
        assert motion.channels.tolist() == expected and list(motion.marker_names) == ["h"]


def test_a_column_named_for_another_axis_is_refused(tmp_path):
    """Found by the run: a header ``h_y,h_x,h_z`` was read with x and y swapped, silently."""
    text = "# take 1\nh_y,h_x,h_z,h_c\n0.5,1,2,0.9\n"
    with pytest.raises(MotionFileError, match=r"k\.csv, line 2: column 'h_y' where x belongs"):
        read_keypoints(_keypoint_text(tmp_path, text), columns="xyzc", frame_rate=30)
    # Confidence columns may be named anything; axis names in order are read.
    ok = text.replace("h_y,h_x,h_z,h_c", "h_x,h_y,h_z,h_score")
    motion = read_keypoints(_keypoint_text(tmp_path, ok), columns="xyzc", frame_rate=30)
    np.testing.assert_array_equal(motion.channels, [[0.5, 1, 2]])
    assert motion.extras["confidence"].tolist() == [[0.9]]


@pytest.mark.parametrize("units", ["", "furlongs"])
def test_a_c3d_parameter_error_comes_before_the_positions_are_decoded(tmp_path, rng, units):
    """Found by the run: a Plug-in Gait file whose POINT:UNITS byte was zeroed decoded every
    position (3.4x the file's size) before refusing the unit. The parameters are now
    checked first: the refusal costs a fraction of the file's size."""
    import tracemalloc

    from skmotion.io import read_c3d
    from tests.io.c3d_files import c3d_bytes

    path = tmp_path / "trial.c3d"
    path.write_bytes(c3d_bytes(rng.normal(size=(2000, 60, 3)), units=units))
    size = path.stat().st_size
    tracemalloc.start()
    try:
        with pytest.raises(MotionFileError, match=r"trial\.c3d: POINT:UNITS"):
            read_c3d(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1.5 * size, (peak, size)  # the file's bytes and the parameters only
