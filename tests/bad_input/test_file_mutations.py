"""Hypothesis-generated mutations of motion files: an error naming file and line, or a
result that agrees with the mutated file's own text.

The independent references below read a file with plain string splitting; they
are strict (any word where a number belongs raises), so a reader that accepts a
file they reject has silently guessed.
"""

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from skmotion.io import MotionFileError
from tests.bad_input import files

# A deadline catches a reader that hangs on a mutated file (a read takes milliseconds;
# the bound is generous for a loaded 2-core CI machine).
MUTATION_SETTINGS = settings(
    max_examples=40,
    deadline=10_000,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
_NUMBER = re.compile(rb"(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])")


@st.composite
def mutations(draw, data):
    """(description, mutated bytes) of one random edit of ``data``."""
    lines = data.split(b"\n")
    kind = draw(
        st.sampled_from(
            ["truncate", "delete line", "duplicate line", "number to word", "drop brace"]
        )
    )
    if kind == "truncate":
        cut = draw(st.integers(0, len(data) - 1))
        return f"truncate at byte {cut}", data[:cut]
    if kind in ("delete line", "duplicate line"):
        i = draw(st.integers(0, len(lines) - 1))
        edited = lines[:i] + lines[i + 1 :] if kind == "delete line" else lines[: i + 1] + lines[i:]
        return f"{kind} {i + 1}", b"\n".join(edited)
    spans = (
        [m.span() for m in _NUMBER.finditer(data)]
        if kind == "number to word"
        else [(m.start(), m.end()) for m in re.finditer(rb"[{}]", data)]
    )
    if not spans:
        return "unchanged", data
    start, end = draw(st.sampled_from(spans))
    word = b"walk" if kind == "number to word" else b""
    return f"{kind} at byte {start}", data[:start] + word + data[end:]


def _words(text):
    """Words separated by spaces, tabs and line breaks only (not Python's Unicode blanks)."""
    return [w for w in re.split(r"[ \t\r\n]+", text) if w]


def _floats(words):
    values = np.array([float(w) for w in words], dtype=float)  # a word raises ValueError
    assert np.isfinite(values).all(), "the reference read a non-finite value"
    return values


def bvh_reference(text):
    """(n_frames, n_channels, values) of a BVH file, by plain splitting."""
    header, motion = re.split(r"^\s*MOTION\b", text, maxsplit=1, flags=re.M | re.I)
    n_channels = sum(int(n) for n in re.findall(r"CHANNELS\s+(\d+)", header, flags=re.I))
    found = re.match(r"\s*Frames:[ \t]*(\d+)[ \t]*\r?\n\s*Frame Time:[^\n]*", motion, flags=re.I)
    values = _floats(_words(motion[found.end() :]))
    return int(found.group(1)), n_channels, values


def check_bvh(motion, text):
    n_frames, n_channels, values = bvh_reference(text)
    assert motion.channels.shape == (n_frames, n_channels) and values.size == n_frames * n_channels
    rotations = np.array([name.endswith("rotation") for name in motion.channel_names])
    read = motion.channels.copy()
    read[:, rotations] = np.rad2deg(read[:, rotations])
    np.testing.assert_allclose(read, values.reshape(n_frames, n_channels), rtol=1e-12, atol=1e-9)


def check_amc(motion, text):
    """Every bone line's values in its frame's row and the bone's columns."""
    skeleton = motion.skeleton
    counts = [len(c) for c in skeleton.channels]
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    rotations = np.array([name.endswith("rotation") for name in skeleton.channel_names])
    degrees = ":RADIANS" not in text.upper()
    frame, n_values = -1, 0
    for line in text.split("\n"):  # the readers' rule: LF ends a line, blanks are space and tab
        words = _words(line)
        if not words or words[0].startswith((":", "#")):
            continue
        if len(words) == 1 and words[0].isdigit():
            frame += 1
            continue
        j = skeleton.joints.index(words[0])
        values = _floats(words[1:])
        assert len(values) == counts[j]
        columns = slice(starts[j], starts[j] + counts[j])
        read = motion.channels[frame, columns]
        read = np.where(rotations[columns] & degrees, np.rad2deg(read), read)
        np.testing.assert_allclose(read, values, rtol=1e-12, atol=1e-9)
        n_values += len(values)
    assert motion.channels.shape == (frame + 1, skeleton.n_channels)
    assert n_values == motion.channels.size, "values were dropped or invented"


def check_asf(skeleton, text):
    bones = re.findall(r"^\s*name\s+(\S+)", text.split(":hierarchy")[0], flags=re.M)
    assert set(bones) <= set(skeleton.joints), f"bones dropped: {set(bones) - set(skeleton.joints)}"
    assert np.isfinite(skeleton.offsets).all()


def check_ts(result, text):
    clips, labels = result
    body = re.split(r"^[ \t]*@data", text, maxsplit=1, flags=re.I | re.M)[1]  # tags: any case
    data = [line.strip(" \t\r") for line in body.split("\n")]
    data = [line for line in data if line and not line.startswith("#")]
    assert len(clips) == len(data)
    for clip, line in zip(clips, data):
        fields = line.split(":")[: clip.shape[1]]
        expected = np.array(
            [[float(v.replace("?", "nan")) for v in f.split(",")] for f in fields]
        ).T
        np.testing.assert_array_equal(clip, expected)
        assert not np.isinf(clip).any()
    if labels is not None:
        assert len(labels) == len(clips)


CHECKS = {"bvh": check_bvh, "amc": check_amc, "asf": check_asf, "ts": check_ts}


def read_mutated(tmp_path, kind, read, description, data):
    """Read the mutated file; an error must name the file and a line inside it."""
    path = tmp_path / f"mutated.{kind}"
    path.write_bytes(data)
    try:
        result = read(path)
    except MotionFileError as error:
        assert str(error).startswith(str(path)), error
        assert error.line is None or 1 <= error.line <= data.count(b"\n") + 1, (
            f"{description}: line {error.line}"
        )
        return "MotionFileError"
    text = data.decode("latin-1")
    try:
        CHECKS[kind](result, text)
    except (ValueError, AttributeError, IndexError) as exc:  # the reference cannot read it
        raise AssertionError(
            f"{description}: the reader accepted a file the reference rejects ({exc!r})"
        ) from None
    return "read, agrees with the reference"


def _mutation_test(kind, source, asf_source=None):
    @MUTATION_SETTINGS
    @given(data=st.data())
    def test(tmp_path, shared, data):
        base = source(shared, tmp_path)
        read = files.reader_for(
            kind, tmp_path, asf_source(shared, tmp_path) if asf_source else None
        )
        description, mutated = data.draw(mutations(base), label="mutation")
        event(read_mutated(tmp_path, kind, read, description, mutated))

    return test


@pytest.fixture
def shared(request):
    """The real data folder for the 'real' sources (skips without it), else None."""
    return request.getfixturevalue("shared_data") if "real" in request.node.name else None


SOURCES = {
    "written-bvh": ("bvh", lambda s, tmp: files.written_bvh(tmp), None),
    "written-asf": ("asf", lambda s, tmp: files.written_asf(), None),
    "written-amc": ("amc", lambda s, tmp: files.written_amc(), lambda s, tmp: files.written_asf()),
    "written-ts": ("ts", lambda s, tmp: files.written_ts(), None),
    "real-bvh": ("bvh", lambda s, tmp: files.real_bvh(s), None),
    "real-asf": ("asf", lambda s, tmp: files.real_asf(s), None),
    "real-amc": ("amc", lambda s, tmp: files.real_amc(s), lambda s, tmp: files.real_asf(s)),
    "real-ts": ("ts", lambda s, tmp: files.real_ts(s), None),
}

for _name, (_kind, _source, _asf) in SOURCES.items():
    globals()[f"test_mutated_{_name.replace('-', '_')}"] = _mutation_test(_kind, _source, _asf)


@pytest.mark.parametrize("name", list(SOURCES))
def test_unmutated_sources_read_and_agree_with_the_references(tmp_path, request, name):
    kind, source, asf_source = SOURCES[name]
    shared = request.getfixturevalue("shared_data") if name.startswith("real") else None
    base = source(shared, tmp_path)
    read = files.reader_for(kind, tmp_path, asf_source(shared, tmp_path) if asf_source else None)
    path = tmp_path / f"base.{kind}"
    path.write_bytes(base)
    CHECKS[kind](read(path), base.decode("latin-1"))


@pytest.mark.parametrize("name", list(SOURCES))
def test_every_line_deleted_or_duplicated(tmp_path, request, name):
    """Systematically, not by chance: each line deleted, then duplicated (every line of
    the written files; of the longer real excerpts, lines spread evenly, ~100)."""
    kind, source, asf_source = SOURCES[name]
    shared = request.getfixturevalue("shared_data") if name.startswith("real") else None
    base = source(shared, tmp_path)
    read = files.reader_for(kind, tmp_path, asf_source(shared, tmp_path) if asf_source else None)
    lines = base.split(b"\n")
    outcomes = []
    for i in range(0, len(lines), max(1, len(lines) // 100) if name.startswith("real") else 1):
        outcomes.append(
            read_mutated(
                tmp_path, kind, read, f"delete line {i + 1}", b"\n".join(lines[:i] + lines[i + 1 :])
            )
        )
        outcomes.append(
            read_mutated(
                tmp_path,
                kind,
                read,
                f"duplicate line {i + 1}",
                b"\n".join(lines[: i + 1] + lines[i:]),
            )
        )
    assert "MotionFileError" in outcomes
    print(f"{name}: {len(outcomes)} files, {outcomes.count('MotionFileError')} MotionFileErrors")
