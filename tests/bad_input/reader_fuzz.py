"""Mutations of real files, counted per reader: the engine of ``benchmarks/bench_fuzz.py
--per-reader`` (10,000 cases per reader) and of a small CI test.

The readers and the real files each one gets:

- ``c3d`` (:func:`~skmotion.io.read_c3d`): the four files of ``c3d/`` in the shared
  data (Intel float32 Plug-in Gait exports, a DEC int16 file, a file with no unit),
  mutated by :func:`binary_fuzz.mutate_c3d` (header fields, parameter bytes, data
  bytes, truncation);
- ``bvh``: the header and first frames of a CMU BVH file and of a non-CMU one
  (``bvh-samples``);
- ``asf``: the three CMU skeletons; ``amc``: the first frames of one trial of each,
  read with its skeleton; the text mutations of :mod:`tests.bad_input.fuzz`;
- ``keypoints`` (:func:`~skmotion.io.read_keypoints`): the first frames of an MSRC-12
  Kinect recording as ``.txt`` (its own layout, one frame per line, ``x y z
  confidence`` per joint) and as a ``.csv`` with a header, and the MSRC-12 positions as
  ``.npy`` and compressed ``.npz``.

Each case is read in this process with a time limit (``signal.setitimer``) and
allocation tracing (``tracemalloc``); its outcome is one of
``rejected`` (the reader's MotionFileError, naming the file, and for text a line inside
it), ``agrees`` (read, equal to an independent reference of the mutated bytes),
``equal`` (a layout-only change read equal to the original), ``by the file`` (a C3D
header or parameter edit or a CSV header edit that the data still backs: no independent
truth, judged for the failures only), or a failure: ``crash`` (any other exception),
``hang`` (no answer in the limit), ``allocation`` (a traced peak past twice the file's
size plus its answer's arrays, plus 1 MB, or an answer past 4x the file's size, which
no format needs: int16 becoming float64 is the largest growth) and ``wrong`` (read,
and different from the reference). The answer is counted apart because a Motion holds
float64 copies: a float32 C3D file's positions and residuals alone are twice its size.
"""

import re
import struct
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from skmotion.io import Motion, MotionFileError, read_c3d, read_keypoints
from skmotion.io._c3d_parameters import read_metadata
from tests.bad_input import binary_fuzz, files, fuzz
from tests.bad_input.test_file_mutations import CHECKS

READERS = ("c3d", "bvh", "asf", "amc", "keypoints")
OUTCOMES = (
    "tried",
    "rejected",
    "agrees",
    "equal",
    "by the file",
    "crash",
    "hang",
    "allocation",
    "wrong",
)
FAILURES = ("crash", "hang", "allocation", "wrong")
_MSRC12_FRAMES = 12


@dataclass
class Source:
    """One real file of a reader: its bytes, how to mutate, read and judge it."""

    name: str
    suffix: str
    data: bytes
    read: object  # path -> result
    mutate: object  # (data, rng) -> (description, mutated bytes, kind)
    judge: object  # (result, original, mutated bytes, kind) -> (outcome, why)
    text: bool = False


# -- C3D -----------------------------------------------------------------------------
def _c3d_decode(data, layout, shape):
    """The points of ``data`` by a plain NumPy view of the known storage (no library code).

    ``layout`` is (word dtype, |scale|, unit factor, points, analog words, data start).
    """
    word_type, scale, factor, n_points, n_analog, start = layout
    n_frames = shape[0]
    size = np.dtype(word_type).itemsize
    count = n_frames * (4 * n_points + n_analog)
    words = np.frombuffer(data, dtype=word_type, count=count, offset=start)
    words = words.reshape(n_frames, -1)[:, : 4 * n_points].reshape(n_frames, n_points, 4)
    fourth = words[:, :, 3].astype(float)
    xyz = words[:, :, :3].astype(float)
    if size == 2:
        xyz = xyz * scale
        invalid = fourth < 0
    else:
        invalid = ~(np.abs(fourth) < 2.0**31) | ~(fourth >= 0)
    invalid |= ~np.isfinite(xyz).all(axis=2)
    xyz = xyz * factor
    xyz[invalid] = np.nan
    return xyz.reshape(n_frames, -1)


def _c3d_source(path):
    data = path.read_bytes()
    meta = read_metadata(path, np.frombuffer(data, dtype=np.uint8))
    scale = float(meta.number("POINT:SCALE", meta.header["scale"]))
    unit = (meta.strings("POINT:UNITS") or [""])[0].strip(" \x00")
    units = "m" if unit else None

    def read(p):
        return read_c3d(p, units=units)

    original = read(path)
    word_type = ("<f4" if scale < 0 else "<i2") if meta.processor != "MIPS" else None
    assert word_type is not None and meta.processor in ("INTEL", "DEC")
    assert meta.processor == "INTEL" or scale > 0, "a DEC float file: no plain decode"
    n_points = original.channels.shape[1] // 3
    layout = (
        word_type,
        abs(scale),
        1e-3 if units else 1.0,
        n_points,
        struct.unpack_from("<H", data, 4)[0],
        (struct.unpack_from("<H", data, 16)[0] - 1) * 512,
    )
    # The reference must read the untouched file as the reader does.
    np.testing.assert_allclose(
        _c3d_decode(data, layout, original.channels.shape), original.channels, rtol=1e-12
    )

    frame_bytes = np.dtype(word_type).itemsize * (4 * n_points + layout[4])
    where = (layout[5], frame_bytes, len(original.channels))

    def mutate(data, rng):
        return binary_fuzz.mutate_c3d(data, rng, layout=where)

    def judge(result, original, mutated, kind):
        decode = partial(_c3d_decode, layout=layout, shape=original.channels.shape)
        return binary_fuzz.judge_c3d(result, original, data, kind, mutated, decode=decode)

    return Source(path.name, path.suffix.lower(), data, read, mutate, judge)


# -- text formats (BVH, ASF, AMC) ------------------------------------------------------
def _text_judge(kind):
    def judge(result, original, mutated, neutral):
        if neutral == "neutral":
            if fuzz._same(kind, result, original):
                return "equal", ""
            return "wrong", "a layout-only change changed the result"
        try:
            CHECKS[kind](result, fuzz._normalised(mutated))
        except (ValueError, AttributeError, IndexError, AssertionError, KeyError) as exc:
            return "wrong", f"read, but the reference disagrees ({exc!r})"
        return "agrees", ""

    return judge


def _text_mutate(data, rng):
    description, mutated, neutral = fuzz.mutate(data, rng)
    return description, mutated, "neutral" if neutral else "text"


def _cut_bvh(path, n_frames=6):
    text = path.read_bytes()
    head, body = text.split(b"Frame Time:", 1)
    frame_time, *frames = re.split(rb"\r?\n", body)[: n_frames + 1]
    head = re.sub(rb"Frames:\s*\d+", b"Frames: %d" % n_frames, head)
    return head + b"Frame Time:" + frame_time + b"\n" + b"\n".join(frames) + b"\n"


def _cut_amc(path, n_frames=3):
    lines = path.read_bytes().split(b"\n")
    frame_lines = [k for k, line in enumerate(lines) if line.strip().isdigit()]
    return b"\n".join(lines[: frame_lines[n_frames]]) + b"\n"


def _text_sources(kind, shared, folder):
    out = []
    if kind == "bvh":
        for path in (shared / "cmu-bvh" / "07" / "07_01.bvh", *(shared / "bvh-samples").glob("*")):
            out.append((path.name, _cut_bvh(path), files.reader_for("bvh", folder)))
    for subject in ("01", "02", "03"):
        asf = (shared / "cmu-asfamc" / subject / f"{subject}.asf").read_bytes()
        if kind == "asf":
            out.append((f"{subject}.asf", asf, files.reader_for("asf", folder)))
        if kind == "amc":
            amc = shared / "cmu-asfamc" / subject / f"{subject}_01.amc"
            (folder / subject).mkdir(exist_ok=True)
            read = files.reader_for("amc", folder / subject, asf)
            out.append((amc.name, _cut_amc(amc), read))
    suffix = "." + kind
    return [
        Source(name, suffix, data, read, _text_mutate, _text_judge(kind), text=True)
        for name, data, read in out
    ]


# -- keypoints -------------------------------------------------------------------------
_KEYPOINT_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan")


def keypoint_text_reference(text):
    """(values, header or None) of a keypoint table, by plain splitting: LF, CRLF or CR
    end a line, ``#`` starts a comment, a comma or spaces and tabs separate the values,
    every value is an ASCII number or ``nan``, and every row has as many as the first."""
    if text.startswith("\ufeff"):
        text = text[1:]
    rows = []
    for line in text.replace("\r\n", "\n").replace("\r", "\n").split("\n"):
        line = line.split("#", 1)[0].strip(" \t")
        if line:
            split = line.split(",") if "," in line else re.split(r"[ \t]+", line)
            rows.append([w.strip(" \t") for w in split])
    header = None
    if rows and not any(_KEYPOINT_NUMBER.fullmatch(w.lower()) for w in rows[0]):
        header, rows = rows[0], rows[1:]
    if not rows or any(len(r) != len(rows[0]) for r in rows):
        raise ValueError("rows of different lengths, or no rows")
    bad = [w for r in rows for w in r if not _KEYPOINT_NUMBER.fullmatch(w.lower())]
    if bad:
        raise ValueError(f"not a number: {bad[0]!r}")
    values = np.array([[float(w) for w in r] for r in rows])
    if np.isinf(values).any():
        raise ValueError("an infinite value")
    return values, header


def _decoded(data):
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:  # the readers' rule: UTF-8, else Latin-1 (older tools)
        return data.decode("latin-1")


def _keypoint_text_judge(result, original, mutated, kind):
    try:
        values, header = keypoint_text_reference(_decoded(mutated))
    except ValueError as exc:
        return "wrong", f"read, but the reference refuses the text ({exc})"
    frames = values.reshape(len(values), -1, 4)
    read = np.concatenate(
        [result.channels.reshape(frames.shape[:2] + (3,)), result.extras["confidence"][..., None]],
        axis=2,
    )
    if not np.array_equal(read, frames, equal_nan=True):
        return "wrong", "read differently from the plain split of the text"
    if header is not None:
        names = [h.rsplit("_", 1)[0] for h in header[::4]]
        axes = [h.rsplit("_", 1)[-1].lower() for h in header]
        if names != list(result.marker_names):
            return "wrong", f"joints {result.marker_names[:3]}... are not the header's"
        if any(a in ("x", "y", "z") and a != "xyzc"[k % 4] for k, a in enumerate(axes)):
            return "wrong", "a column named for one axis was read as another"
    if kind == "neutral":
        same = np.array_equal(result.channels, original.channels, equal_nan=True)
        return ("equal", "") if same else ("wrong", "a layout-only change changed the result")
    return "agrees", ""


def _keypoint_array_judge(result, original, mutated, kind, path):
    outcome, why = binary_fuzz.judge_array(result, original, None, kind, mutated, path)
    return outcome, why


def _keypoint_sources(shared):
    csv = sorted((shared / "msrc12" / "original").glob("*.csv"))[0]
    lines = csv.read_bytes().split(b"\n")[40 : 40 + _MSRC12_FRAMES]  # the first are zeros
    table = np.array([[float(w) for w in line.split()[1:]] for line in lines])  # no time
    txt = "".join(" ".join(f"{v:.6g}" for v in row) + "\n" for row in table).encode()
    header = ",".join(f"joint{j}_{a}" for j in range(table.shape[1] // 4) for a in "xyzc")
    csv_text = header + "\n" + "".join(",".join(f"{v:.6g}" for v in row) + "\n" for row in table)
    with np.load(shared / "msrc12" / "msrc12_sequences.npz") as archive:
        positions = archive["positions"][:30]
    npy, npz = binary_fuzz.npy_bytes(positions), binary_fuzz.npz_bytes(positions, compressed=True)

    def read_text(p):
        return read_keypoints(p, columns="xyzc", frame_rate=30.0)

    def read_array(p):
        return read_keypoints(p, columns="xyz", frame_rate=30.0)

    return [
        Source(csv.stem + ".txt", ".txt", txt, read_text, _text_mutate, _keypoint_text_judge),
        Source(
            csv.stem + ".csv",
            ".csv",
            csv_text.encode(),
            read_text,
            _text_mutate,
            _keypoint_text_judge,
        ),  # fmt: skip
        Source("msrc12.npy", ".npy", npy, read_array, binary_fuzz.mutate_npy, None),
        Source("msrc12.npz", ".npz", npz, read_array, binary_fuzz.mutate_npz, None),
    ]


def sources(reader, shared, folder):
    """The real sources of one reader (:data:`READERS`)."""
    if reader == "c3d":
        return [_c3d_source(p) for p in sorted((shared / "c3d").iterdir())]
    if reader == "keypoints":
        return _keypoint_sources(shared)
    return _text_sources(reader, shared, folder)


# -- the engine ------------------------------------------------------------------------
def answer_bytes(result):
    """The bytes of the arrays a read returns (a Motion's channels and extras)."""
    if not isinstance(result, Motion):
        return 0
    extras = [v for v in result.extras.values() if isinstance(v, np.ndarray)]
    return result.channels.nbytes + sum(v.nbytes for v in extras)


def run_case(source, path, mutated, description, kind, original, counts, failures, limit):
    """Read one mutated file and add its outcome to ``counts``."""
    path.write_bytes(mutated)
    result, error, peak = binary_fuzz._read_traced(source.read, path, limit)
    outcome, why = "crash", ""
    answer = answer_bytes(result)
    if peak > 2 * (len(mutated) + answer) + (1 << 20) or answer > 4 * len(mutated) + (1 << 20):
        outcome, why = "allocation", f"peak {peak} bytes, answer {answer} bytes"
    elif isinstance(error, binary_fuzz._Timeout):
        outcome, why = "hang", f"no answer in {limit} s"
    elif isinstance(error, MotionFileError):
        lines = mutated.count(b"\n") + mutated.count(b"\r") + 1
        inside = not source.text or error.line is None or 1 <= error.line <= lines
        if str(error).startswith(str(path)) and inside:
            outcome = "rejected"
        else:
            why = f"an error outside the file: {error}"
    elif error is not None:
        why = f"{type(error).__name__}: {error}"
    elif source.judge is None:
        outcome, why = _keypoint_array_judge(result, original, mutated, kind, path)
    else:
        outcome, why = source.judge(result, original, mutated, kind)
    counts[outcome] += 1
    counts["tried"] += 1
    if outcome in FAILURES:
        failures.append((source.name, outcome, f"{description}: {why}", mutated))
    return outcome


def fuzz_reader(reader, shared, folder, *, n_cases, seed, chunk=0, time_limit=5.0):
    """Mutate the real files of ``reader`` ``n_cases`` times in all (round robin).

    ``chunk`` selects an independent random stream, so that one budget can be split
    over processes and stay reproducible. Returns ``(counts per source, failures)``;
    each failure is (source, outcome, description, mutated bytes).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng([seed, READERS.index(reader), chunk])
    chosen = sources(reader, shared, folder)
    originals, counts, failures = [], {}, []
    for source in chosen:
        original_path = folder / f"original{source.suffix}"
        original_path.write_bytes(source.data)
        originals.append(source.read(original_path))
        counts[source.name] = dict.fromkeys(OUTCOMES, 0)
    for case in range(n_cases):
        k = case % len(chosen)
        source = chosen[k]
        description, mutated, kind = source.mutate(source.data, rng)
        path = folder / f"mutated{source.suffix}"
        run_case(
            source,
            path,
            mutated,
            description,
            kind,
            originals[k],
            counts[source.name],
            failures,
            time_limit,
        )
    return counts, failures
