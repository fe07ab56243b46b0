"""One text rule for every reader (BVH, ASF, AMC, .ts): the same edit of the same
number gives the same answer in all four formats (docs/errors.md, "The text rule")."""

import re

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_asf, read_bvh
from tests.bad_input import files

# One number per format, on a line the test knows: (pattern whose group 1 is the number).
TARGETS = {
    "bvh": rb"\n(-?[0-9.]+) [^\n]*\n$",  # the first value of the last frame line
    "amc": rb"\nfemur (\S+)",
    "asf": rb"length (7\.6)",
    "ts": rb"\n(7),8",
}
KINDS = list(TARGETS)


def _base(kind, tmp_path):
    return {
        "bvh": lambda: files.written_bvh(tmp_path),
        "amc": files.written_amc,
        "asf": files.written_asf,
        "ts": files.written_ts,
    }[kind]()


def _edited(kind, data, new):
    """``data`` with the target number replaced by ``new(number)``; and the line it is on."""
    found = list(re.finditer(TARGETS[kind], data))[-1 if kind == "bvh" else 0]
    start, end = found.span(1)
    return data[:start] + new(data[start:end]) + data[end:], data.count(b"\n", 0, start) + 1


def _read(kind, tmp_path, data, name="edited"):
    path = tmp_path / f"{name}.{kind}"
    path.write_bytes(data)
    read = files.reader_for(kind, tmp_path, files.written_asf() if kind == "amc" else None)
    return read(path), path


def _same(kind, a, b):
    """Do two reads agree exactly?"""
    if kind == "asf":
        return a == b
    if kind == "ts":
        return all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a[0], b[0])) and list(
            a[1]
        ) == list(b[1])
    return a.skeleton == b.skeleton and np.array_equal(a.channels, b.channels)


EDITS = {
    "NUL inside a number": (lambda v: v[:1] + b"\x00" + v[1:], "control byte b'\\\\x00'"),
    "\\x05 inside a number": (lambda v: v[:1] + b"\x05" + v[1:], "control byte b'\\\\x05'"),
    "form feed between numbers": (lambda v: v + b"\x0c", "control byte b'\\\\x0c'"),
    "underscore 9_0 style": (lambda v: v[:1] + b"_0" + v[1:], "non-numeric value"),
    "Arabic-Indic digit": (lambda v: "\u0661".encode() + v, "non-numeric value"),
    "no-break space as a separator": (lambda v: v + "\u00a0".encode() + b"1", "non-numeric"),
    "no-break space before a number": (lambda v: "\u00a0".encode() + v, "non-numeric"),
    "infinity spelled out": (lambda v: b"infinity", "non-finite value"),
    "overflow 1e400": (lambda v: b"1e400", "non-finite value"),
}


@pytest.mark.parametrize("edit", list(EDITS))
@pytest.mark.parametrize("kind", KINDS)
def test_one_rule_for_numbers_in_every_reader(tmp_path, kind, edit):
    new, message = EDITS[edit]
    data, line = _edited(kind, _base(kind, tmp_path), new)
    with pytest.raises(MotionFileError) as info:
        _read(kind, tmp_path, data)
    assert info.value.line == line, info.value
    assert re.search(message, str(info.value)), info.value
    assert not isinstance(info.value, AssertionError)


@pytest.mark.parametrize("kind", KINDS)
def test_underscores_are_not_digit_separators(tmp_path, kind):
    """Python's float('1_000') is 1000.0 (and NumPy's string conversion agrees); the readers
    reject it in the frame table as well as in single values."""
    assert float("1_000") == 1000.0  # why the rule needs stating
    data, line = _edited(kind, _base(kind, tmp_path), lambda v: b"1_000")
    with pytest.raises(MotionFileError, match="non-numeric value '1_000'") as info:
        _read(kind, tmp_path, data)
    assert info.value.line == line


LAYOUTS = {
    "UTF-8 byte-order mark": lambda d: b"\xef\xbb\xbf" + d,
    "CRLF line breaks": lambda d: d.replace(b"\n", b"\r\n"),
    "CR-only line breaks (classic Mac)": lambda d: d.replace(b"\n", b"\r"),
    "BOM and CR-only": lambda d: b"\xef\xbb\xbf" + d.replace(b"\n", b"\r"),
    "tabs for spaces": lambda d: re.sub(rb"(?<=[0-9]) (?=[-0-9])", b"\t", d),
}


@pytest.mark.parametrize("layout", list(LAYOUTS))
@pytest.mark.parametrize("kind", KINDS)
def test_layouts_that_do_not_change_the_numbers_read_the_same(tmp_path, kind, layout):
    base = _base(kind, tmp_path)
    original, _ = _read(kind, tmp_path, base, "original")
    changed, _ = _read(kind, tmp_path, LAYOUTS[layout](base))
    assert _same(kind, original, changed)


@pytest.mark.parametrize("kind", KINDS)
def test_errors_name_the_same_line_with_cr_only_line_breaks(tmp_path, kind):
    data, line = _edited(kind, _base(kind, tmp_path), lambda v: b"walk")
    with pytest.raises(MotionFileError) as info:
        _read(kind, tmp_path, data.replace(b"\n", b"\r"))
    assert info.value.line == line


@pytest.mark.parametrize("kind", KINDS)
def test_utf16_is_refused_with_a_clear_message(tmp_path, kind):
    data = _base(kind, tmp_path).decode("latin-1").encode("utf-16")
    with pytest.raises(MotionFileError, match="UTF-16/32 byte-order mark"):
        _read(kind, tmp_path, data)


# -- errors of item 6: each names the file and its line --


def _bvh(tmp_path, text):
    path = tmp_path / "clip.bvh"
    path.write_bytes(text.encode())
    return path


@pytest.mark.parametrize(
    "old, new, line, message",
    [
        ("Frame Time: 0.1", "Frame Time: 1e-320", 14, "Frame Time '1e-320' is too small"),
        ("Frame Time: 0.1", "Frame Time: 1e400", 14, "must be positive and finite"),
        ("Frame Time: 0.1", "Frame Time: 0.1 0.2", 12, "expected 'MOTION', 'Frames: N'"),
        ("Frames: 2", "Frames: \u00b2", 13, "Frames must be an integer, found '\u00b2'"),
        ("Frames: 2", "Frames: 2_0", 13, "Frames must be an integer"),
        ("Frames: 2", "Frames: \u0662", 13, "Frames must be an integer"),
        (
            "CHANNELS 3 Zrotation Xrotation Yrotation",
            "CHANNELS 3 Zrotation Xrotation Zrotation",
            9,
            "joint 'knee' lists channel 'Zrotation' twice",
        ),
        ("CHANNELS 3 Zrotation", "CHANNELS \u00b3 Zrotation", 9, "must be an integer"),
        ("OFFSET 0 -1 0", "OFFSET 0 -1_0 0", 8, "non-numeric value '-1_0'"),
    ],
)
def test_bvh_errors_name_file_and_line(tmp_path, old, new, line, message):
    text = SMALL.replace(old, new, 1)
    assert text != SMALL
    with pytest.raises(MotionFileError) as info:
        read_bvh(_bvh(tmp_path, text))
    assert str(info.value).startswith(str(tmp_path / "clip.bvh"))
    assert info.value.line == line and message in str(info.value), info.value


SMALL = """HIERARCHY
ROOT hip
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT knee
  {
    OFFSET 0 -1 0
    CHANNELS 3 Zrotation Xrotation Yrotation
  }
}
MOTION
Frames: 2
Frame Time: 0.1
0 1 0 0 0 0 10 20 30
0 1 0 0 0 0 11 21 31
"""


def test_asf_huge_direction_is_a_direction(tmp_path):
    """``direction 1e308 ...`` overflowed the norm; scaled first, it is the unit vector."""
    text = files.written_asf().decode()
    path = tmp_path / "a.asf"
    path.write_text(text.replace("direction 0.6 -0.7 0.2", "direction 1e308 1e308 0"))
    huge = read_asf(path)
    path.write_text(text.replace("direction 0.6 -0.7 0.2", "direction 1 1 0"))
    np.testing.assert_allclose(huge.offsets, read_asf(path).offsets, rtol=1e-15)
    path.write_text(text.replace("direction 0.6 -0.7 0.2", "direction 1e-320 0 0"))
    np.testing.assert_allclose(read_asf(path).offsets[2], [2.5, 0, 0])


def test_asf_length_that_overflows_names_the_bone(tmp_path):
    text = files.written_asf().decode()
    lines = text.split("\n")
    line = next(i for i, t in enumerate(lines, 1) if "name femur" in t) - 2  # its 'begin'
    path = tmp_path / "a.asf"
    path.write_text(
        text.replace("length 2.5", "length 1.7e308").replace("length 7.6", "length 1.7e308")
    )
    with pytest.raises(
        MotionFileError, match="bone 'femur': its length 1.7e\\+308 overflows"
    ) as info:
        read_asf(path)
    assert info.value.line == line


def test_ts_header_tags_separated_by_tabs(tmp_path):
    """Tabs separate tokens in every reader, .ts header tags included."""
    base = files.written_ts()
    original, _ = _read("ts", tmp_path, base, "original")
    tabbed = re.sub(rb"(?m)^(@\w+) ", rb"\1\t", base).replace(b"true walk", b"true\twalk")
    assert tabbed != base
    changed, _ = _read("ts", tmp_path, tabbed)
    assert _same("ts", original, changed)
