"""Truncated and garbled BVH / ASF / AMC / .ts files.

Two tables: hand-made bad files (what, reader, text, message pattern), and
hypothesis-generated mutations (truncate at a byte, delete or duplicate a line,
replace a number by a word, drop a brace) of files the tests write and of the
first lines of the real files in ``../shared/data``. A mutated file must either
raise a MotionFileError naming the file and a line inside it, or read to a result
that agrees with the file's text as an independent plain-Python parse reads it:
frames times channels equals the values written, each value equal, no NaN.
"""

import re

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_amc, read_asf, read_bvh, read_ts
from tests.bad_input import files
from tests.io.test_asf_amc import ASF, _amc, _frames
from tests.io.test_bvh import LEG

AMC = _amc(_frames(np.random.default_rng(0), 3)).replace("\r\n", "\n")
TS = files.written_ts().decode()


def _amc_reader(path):
    asf = path.parent / "toy.asf"
    asf.write_text(ASF)
    return read_amc(path, read_asf(asf))


READERS = {"bvh": read_bvh, "asf": read_asf, "amc": _amc_reader, "ts": read_ts}

# (what, format, file bytes, message pattern after "<file>, line N: " or "<file>: ")
HAND_MADE = [
    ("empty BVH", "bvh", b"", r"no MOTION block"),
    (
        "binary junk as BVH",
        "bvh",
        bytes(range(256)) * 4,
        r"line 1: not a text file: control byte b'\\x00'",
    ),
    (
        "BVH: no frames",
        "bvh",
        (LEG.split("Frames:")[0] + "Frames: 0\nFrame Time: 0.008333\n").encode(),
        r"line 22: the file holds no frames",
    ),
    (
        "BVH: NaN value",
        "bvh",
        LEG.replace("10 90 0 90", "10 nan 0 90").encode(),
        r"line 25: non-finite value 'nan'",
    ),
    (
        "BVH: inf value",
        "bvh",
        LEG.replace("10 90 0 90", "10 inf 0 90").encode(),
        r"line 25: non-finite value 'inf'",
    ),
    (
        "BVH: negative channel count",
        "bvh",
        LEG.replace("CHANNELS 3", "CHANNELS -3", 1).encode(),
        r"line \d+: channel count of joint 'knee' must be an integer, found '-3'",
    ),
    (
        "BVH: second ROOT",
        "bvh",
        LEG.replace("MOTION", "ROOT b\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION").encode(),
        r"line 21: a second ROOT",
    ),
    (
        "BVH: joint name twice",
        "bvh",
        LEG.replace("JOINT tail", "JOINT knee").encode(),
        r"line \d+: joint name 'knee' appears twice",
    ),
    (
        "BVH: a brace too many",
        "bvh",
        LEG.replace("MOTION", "}\nMOTION").encode(),
        r"line 21: unexpected '}'",
    ),
    ("empty ASF", "asf", b"", r"no :root section: not an ASF file"),
    (
        "binary junk as ASF",
        "asf",
        bytes(range(256)) * 4,
        r"line 1: not a text file: control byte b'\\x00'",
    ),
    (
        "ASF: length a word",
        "asf",
        ASF.replace("length 7.6", "length long").encode(),
        r"line \d+: non-numeric value 'long'",
    ),
    (
        "ASF: direction inf",
        "asf",
        ASF.replace("direction 0.1 -0.9 0.3", "direction 0.1 inf 0.3").encode(),
        r"line 37: non-finite value in direction",
    ),
    (
        "ASF: a bone without axis",
        "asf",
        ASF.replace("     axis 10 -25 20  XYZ\n", "").encode(),
        r"line 23: the bone opened here has no 'axis'",
    ),
    (
        "ASF: a bone twice in the hierarchy",
        "asf",
        ASF.replace("femur tibia", "femur tibia\n    root tibia").encode(),
        r"line \d+: .*tibia",
    ),
    ("empty AMC", "amc", b"", r"no frame number"),
    ("AMC: header only", "amc", b":FULLY-SPECIFIED\n:DEGREES\n", r"no frame number"),
    (
        "AMC: NaN value",
        "amc",
        re.sub(r"(\nfemur )\S+", r"\1nan", AMC, count=1).encode(),
        r"line 5: non-(numeric|finite) value 'nan'",
    ),
    (
        "AMC: inf value",
        "amc",
        re.sub(r"(\nback )\S+", r"\1inf", AMC, count=1).encode(),
        r"line 7: non-(numeric|finite) value 'inf'",
    ),
    (
        "AMC: bone name only",
        "amc",
        re.sub(r"(\nback )\S+", r"\nback", AMC, count=1).encode(),
        r"line 7: bone 'back' has 0 values",
    ),
    ("empty .ts", "ts", b"", r"no @data tag"),
    (
        "binary junk as .ts",
        "ts",
        bytes(range(128, 256)) * 4,
        r"not a text file \(invalid start byte\)",
    ),
    (".ts: no series", "ts", TS.split("@data")[0].encode() + b"@data\n", r"no series after @data"),
    (
        ".ts: undeclared label",
        "ts",
        TS.replace("7,8:9,10:run", "7,8:9,10:jump").encode(),
        r"line 9: class label 'jump' is not declared",
    ),
    (
        ".ts: a word",
        "ts",
        TS.replace("7,8:9,10", "7,eight:9,10").encode(),
        r"line 9: dimension 1: non-numeric value 'eight'",
    ),
    (
        ".ts: one dimension",
        "ts",
        TS.replace("7,8:9,10:run", "7,8:run").encode(),
        r"line 9: 1 dimensions, but the file declares 2",
    ),
    (
        ".ts: ragged dimensions",
        "ts",
        TS.replace("7,8:9,10", "7,8:9,10,11").encode(),
        r"line 9: dimensions of one series differ in length: \[2, 3\]",
    ),
    (
        ".ts: bad dimensions tag",
        "ts",
        TS.replace("@dimensions 2", "@dimensions two").encode(),
        r"line 4: @dimensions must be an integer",
    ),
    (
        ".ts: inf value",
        "ts",
        TS.replace("7,8:9,10", "7,inf:9,10").encode(),
        r"line 9: dimension 1: non-finite value 'inf' at position 2",
    ),
]

# The Frame Time line of LEG (line 23) replaced by each bad value.
HAND_MADE += [
    (
        f"BVH: Frame Time {value}",
        "bvh",
        LEG.replace("Frame Time: 0.008333", f"Frame Time: {value}").encode(),
        f"line 23: {message}",
    )
    for value, message in [
        ("0", "Frame Time must be positive"),
        ("-0.1", "Frame Time must be positive"),
        ("nan", "Frame Time must be positive"),
        ("fast", "non-numeric Frame Time 'fast'"),
    ]
]


@pytest.mark.parametrize(
    "kind, data, pattern", [c[1:] for c in HAND_MADE], ids=[c[0] for c in HAND_MADE]
)
def test_hand_made_bad_file(tmp_path, kind, data, pattern):
    path = tmp_path / f"bad.{kind}"
    path.write_bytes(data)
    with pytest.raises(MotionFileError) as info:
        READERS[kind](path)
    assert str(info.value).startswith(str(path)), info.value
    assert re.search(pattern, str(info.value)), info.value


@pytest.mark.parametrize(
    "reader", [read_bvh, read_asf, read_ts, _amc_reader], ids=["bvh", "asf", "ts", "amc"]
)
def test_folder_instead_of_file(tmp_path, reader):
    with pytest.raises(MotionFileError, match="is a folder, not a file"):
        reader(tmp_path)


@pytest.mark.parametrize("reader", [read_bvh, read_asf, read_ts], ids=["bvh", "asf", "ts"])
def test_missing_file(tmp_path, reader):
    with pytest.raises(FileNotFoundError, match="nothing.here"):
        reader(tmp_path / "nothing.here")


def test_amc_needs_a_frame_rate_that_is_a_number(tmp_path):
    path = tmp_path / "a.amc"
    path.write_text(AMC)
    (tmp_path / "a.asf").write_text(ASF)
    for rate, error in [
        (0, ValueError),
        (-120, ValueError),
        (float("nan"), ValueError),
        ("120", TypeError),
    ]:
        with pytest.raises(error, match="frame_rate"):
            read_amc(path, read_asf(tmp_path / "a.asf"), frame_rate=rate)
