"""Bad folders given to the dataset loaders: missing, empty, a garbled file, no skeleton."""

import pytest

from skmotion.datasets import load_bvh_folder, load_cmu_asfamc, load_motion_folder, load_uea
from skmotion.io import MotionFileError


def _garbled_bvh(folder):
    (folder / "walk").mkdir()
    (folder / "walk" / "a.bvh").write_text("HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\nMOTION\n")


def _amc_without_asf(folder):
    (folder / "01").mkdir()
    (folder / "01" / "01_01.amc").write_text("1\nroot 0 0 0 0 0 0\n")


def _garbled_ts(folder):
    (folder / "Toy_TRAIN.ts").write_text("@dimensions 1\n@classLabel true a\n@data\n1,2:b\n")
    (folder / "Toy_TEST.ts").write_text("@dimensions 1\n@classLabel true a\n@data\n1,2:a\n")


# (what, prepare the folder, load it, exception, message pattern)
LOADER_CASES = [
    (
        "bvh: no folder",
        None,
        lambda d: load_bvh_folder(d / "missing"),
        FileNotFoundError,
        r"No folder at .*missing",
    ),
    ("bvh: empty folder", None, load_bvh_folder, FileNotFoundError, r"No \.bvh files under"),
    (
        "bvh: garbled file",
        _garbled_bvh,
        load_bvh_folder,
        MotionFileError,
        r"a\.bvh, line 5: non-numeric value '}'",
    ),
    ("asf/amc: empty folder", None, load_cmu_asfamc, FileNotFoundError, r"No \.amc trials under"),
    (
        "asf/amc: no skeleton",
        _amc_without_asf,
        load_cmu_asfamc,
        FileNotFoundError,
        r"No skeleton for .*01_01\.amc",
    ),
    (
        "any: empty folder",
        None,
        load_motion_folder,
        FileNotFoundError,
        r"No motion files \(\.bvh, \.amc, \.c3d\) under",
    ),
    (
        "uea: unknown name",
        None,
        lambda d: load_uea("Nope", data_home=d),
        FileNotFoundError,
        r"Dataset 'Nope' not found",
    ),
    (
        "uea: bad subset",
        None,
        lambda d: load_uea("Toy", subset="dev", data_home=d),
        ValueError,
        r"subset must be one of",
    ),
    (
        "uea: garbled file",
        _garbled_ts,
        lambda d: load_uea("Toy", data_home=d),
        MotionFileError,
        r"Toy_TRAIN\.ts, line 4: class label 'b' is not declared",
    ),
]


@pytest.mark.parametrize(
    "prepare, load, error, pattern", [c[1:] for c in LOADER_CASES], ids=[c[0] for c in LOADER_CASES]
)
def test_bad_folder(tmp_path, prepare, load, error, pattern):
    if prepare is not None:
        prepare(tmp_path)
    with pytest.raises(error, match=pattern):
        load(tmp_path)
