import numpy as np
import pytest

from skmotion.datasets import load_uea
from skmotion.io import MotionFileError, read_ts

HEADER = (
    "# a comment\n@problemName toy\n@timeStamps false\n@missing true\n@univariate false\n"
    "@dimensions 2\n"
)


def _write(tmp_path, body, header=HEADER, name="toy.ts"):
    path = tmp_path / name
    path.write_text(header + body)
    return path


def test_unequal_lengths_missing_values_and_labels(tmp_path):
    path = _write(
        tmp_path,
        "@equalLength false\n@classLabel true walk run\n@data\n"
        "1,2,3:4,?,6:walk\n\n7,8:9,1e-3:run\n",
    )
    clips, labels = read_ts(path)
    np.testing.assert_array_equal(clips[0], [[1, 4], [2, np.nan], [3, 6]])
    np.testing.assert_array_equal(clips[1], [[7, 9], [8, 0.001]])
    assert labels.tolist() == ["walk", "run"]


def test_equal_length_without_labels(tmp_path):
    path = _write(
        tmp_path, "@equalLength true\n@seriesLength 2\n@classLabel false\n@data\n1,2:3,4\n5,6:7,8\n"
    )
    clips, labels = read_ts(path)
    assert labels is None
    np.testing.assert_array_equal(np.stack(clips), [[[1, 3], [2, 4]], [[5, 7], [6, 8]]])


@pytest.mark.parametrize(
    "body, line, message",
    [
        ("@classLabel true a b\n1,2:3,4:a\n", 8, "data before the @data tag"),
        ("@classLabel true a b\n@data\n1,2:3,4:c\n", 9, "label 'c' is not declared"),
        (
            "@classLabel true a b\n@data\n1,2:3,4:a\n1,2:a\n",
            10,
            "1 dimensions, but the file declares 2",
        ),
        ("@classLabel true a b\n@data\n1,2:3:a\n", 9, r"differ in length: \[2, 1\]"),
        ("@classLabel true a b\n@data\n1,x:3,4:a\n", 9, "dimension 1: non-numeric value 'x'"),
        (
            "@equalLength true\n@seriesLength 3\n@classLabel true a\n@data\n1,2:3,4:a\n",
            11,
            "@seriesLength is 3",
        ),
        ("@classLabel maybe a\n@data\n", 7, "must start with true or false"),
        ("@dimensions two\n@data\n", 7, "must be an integer"),
    ],
)
def test_malformed_files_name_file_and_line(tmp_path, body, line, message):
    path = _write(tmp_path, body)
    with pytest.raises(MotionFileError, match=f"toy.ts, line {line}: .*{message}") as exc:
        read_ts(path)
    assert exc.value.line == line and exc.value.path == str(path)


@pytest.mark.parametrize(
    "body, message",
    [
        ("@classLabel true a\n", "no @data tag"),
        ("@classLabel true a\n@data\n", "no series"),
        ("@timeStamps true\n@data\n(0,1),(1,2):a\n", "timestamped"),
    ],
)
def test_structurally_empty_or_unsupported(tmp_path, body, message):
    with pytest.raises(MotionFileError, match=message):
        read_ts(_write(tmp_path, body))


def test_binary_file_is_rejected(tmp_path):
    path = tmp_path / "noise.ts"
    path.write_bytes(b"\xff\xfe\x00\x81" * 10)
    with pytest.raises(MotionFileError, match="noise.ts: not a text file"):
        read_ts(path)


def test_load_uea_subsets_and_errors(tmp_path):
    header = "@problemName Toy\n@dimensions 1\n@classLabel true up down\n@data\n"
    (tmp_path / "Toy_TRAIN.ts").write_text(header + "1,2,3:up\n3,2,1:down\n")
    (tmp_path / "Toy_TEST.ts").write_text(header + "1,2:up\n")
    assert load_uea("Toy", subset="test", data_home=tmp_path).target.tolist() == ["up"]
    assert len(load_uea(tmp_path / "Toy_TRAIN.ts").clips) == 2
    with pytest.raises(FileNotFoundError, match="does not download"):
        load_uea("Missing", data_home=tmp_path)
    with pytest.raises(ValueError, match="subset"):
        load_uea("Toy", subset="validation", data_home=tmp_path)


def test_uea_archive_files(shared_data):
    basic = load_uea("BasicMotions", data_home=shared_data)
    assert (basic.subset == "train").sum() == 40 and (basic.subset == "test").sum() == 40
    assert {c.shape for c in basic.clips} == {(100, 6)}
    assert basic.target_names.tolist() == ["Badminton", "Running", "Standing", "Walking"]
    vowels = load_uea("JapaneseVowels", data_home=shared_data)
    assert (vowels.subset == "train").sum() == 270 and (vowels.subset == "test").sum() == 370
    lengths = [len(c) for c in vowels.clips]
    assert min(lengths) == 7 and max(lengths) == 29
    assert {c.shape[1] for c in vowels.clips} == {12}
    assert len(vowels.target_names) == 9
