"""Structure-aware mutations of binary motion files (C3D, .npy, .npz), for the fuzz test
and benchmarks/bench_fuzz.py.

Each mutation edits what real damage edits: a C3D header field (point count, analog
words per frame, first and last frame, scale, data block, rate, the parameter block
byte), a byte of the parameter section (a name length, a type, a dimension, an
offset), a byte of the data block, or the end of the file (truncation); an .npy
header (shape, dtype, order, header length, magic, version) or data; a byte of an
.npz archive's zip structure, or a forged member shape.

Every mutated file is read with a time limit and Python's allocation tracing, and the
outcome is one of:

- ``rejected``: the reader's own :class:`MotionFileError`, naming the file;
- ``agrees``: read, and equal to an independent reference: for a C3D data-block byte,
  the original with that frame decoded again from the mutated bytes by a plain NumPy
  view of the writer's known layout; for an .npy/.npz file, ``numpy.load`` of the
  same bytes (run only when the header's size fits the file); for a truncation that
  only cut the zero padding, the original;
- ``by the file``: read, and different from the original after a header or
  parameter edit (another rate, point count or frame range that the data still
  backs), or a truncation that the file's own counts allow: there is no independent
  truth for these, so they are counted apart and judged only for crashes, hangs and
  allocations;

and a **failure** is anything else: another exception type (a crash), no answer in
the time limit (a hang), a peak allocation past twice the file's size (plus 1 MB),
or a read that disagrees with its reference (a silent wrong read).
"""

import ast
import io
import signal
import struct
import tracemalloc
import zipfile
from dataclasses import dataclass, field

import numpy as np

from skmotion.io import MotionFileError, read_c3d, read_keypoints
from tests.io.c3d_files import c3d_bytes

OUTCOMES = ("tried", "rejected", "agrees", "by the file", "crash", "hang", "allocation", "wrong")
_HEADER_FIELDS = {  # byte offset, struct format
    "parameter block": (0, "<B"),
    "points": (2, "<H"),
    "analog words": (4, "<H"),
    "first frame": (6, "<H"),
    "last frame": (8, "<H"),
    "scale": (12, "<f"),
    "data block": (16, "<H"),
    "rate": (20, "<f"),
}
_EXTREMES = [0, 1, 2, 255, 256, 32767, 32768, 65535]
_FLOATS = [0.0, -0.0, 1e-40, -1.0, 1.0, 1e30, float("nan"), float("inf"), -1e9]


class _Timeout(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Timeout()


@dataclass
class Tally:
    counts: dict = field(default_factory=dict)
    failures: list = field(default_factory=list)

    def add(self, source, outcome, description=""):
        row = self.counts.setdefault(source, dict.fromkeys(OUTCOMES, 0))
        row["tried"] += 1
        row[outcome] += 1
        if outcome in ("crash", "hang", "allocation", "wrong"):
            self.failures.append(f"{source}: {outcome}: {description}")


# -- C3D -----------------------------------------------------------------------------
def written_c3d(rng):
    """A float32 C3D file of 40 frames, 5 points (with gaps), 3 analog channels, events."""
    xyz = rng.normal(scale=500.0, size=(40, 5, 3))
    residuals = rng.integers(0, 5, size=(40, 5)).astype(float)
    residuals[10:14, 2] = -1
    analog = rng.integers(-1000, 1000, size=(80, 3)).astype(float)
    events = [
        ("EVENT", "USED", [1]),
        ("EVENT", "LABELS", ["Foot Strike"]),
        ("EVENT", "CONTEXTS", ["Left"]),
        ("EVENT", "TIMES", np.array([[0.0, 0.2]])),
    ]
    return c3d_bytes(
        xyz, residuals, analog=analog, analog_per_frame=2, parameters=events, rate=100.0
    )


def _c3d_layout(data):
    """(data start byte, frame bytes, n_frames) of a file the writer made (float32)."""
    n_points, n_analog = struct.unpack_from("<HH", data, 2)
    data_start = (struct.unpack_from("<H", data, 16)[0] - 1) * 512
    first, last = struct.unpack_from("<HH", data, 6)
    return data_start, 4 * (4 * n_points + n_analog), last - first + 1


def mutate_c3d(data, rng, layout=None):
    """(description, mutated bytes, kind) with kind in {"header", "parameter", "data", "cut"}.

    ``layout`` is the (data start byte, frame bytes, n_frames) of a file that the
    writer did not make (default: the writer's float32 layout).
    """
    data = bytearray(data)
    start, frame_bytes, n_frames = layout or _c3d_layout(data)
    kind = rng.choice(["header", "parameter", "data", "cut"], p=[0.35, 0.3, 0.2, 0.15])
    if kind == "header":
        name = str(rng.choice(list(_HEADER_FIELDS)))
        offset, fmt = _HEADER_FIELDS[name]
        if fmt == "<f":
            value = float(rng.choice(_FLOATS)) if rng.random() < 0.7 else float(rng.normal(0, 100))
        else:
            value = int(rng.choice(_EXTREMES)) if rng.random() < 0.6 else int(rng.integers(0, 600))
            value = min(value, 255) if fmt == "<B" else value
        struct.pack_into(fmt, data, offset, value)
        return f"header {name} = {value!r}", bytes(data), kind
    if kind == "parameter":
        at = int(rng.integers(512, start))
        value = int(rng.choice([0, 1, 0x7F, 0x80, 0xFF, int(rng.integers(0, 256))]))
        data[at] = value
        return f"parameter byte {at} = {value}", bytes(data), kind
    if kind == "data":
        at = int(rng.integers(start, start + n_frames * frame_bytes))
        data[at] ^= 1 << int(rng.integers(0, 8))
        return f"data byte {at} flipped", bytes(data), kind
    cut = int(rng.integers(0, len(data)))
    return f"cut at byte {cut} of {len(data)}", bytes(data[:cut]), kind


def _c3d_reference(original, mutated):
    """The data-block mutation decoded independently: the writer's float32 layout."""
    start, frame_bytes, n_frames = _c3d_layout(mutated)
    n_points = struct.unpack_from("<H", mutated, 2)[0]
    block = np.frombuffer(mutated, dtype="<f4", count=n_frames * frame_bytes // 4, offset=start)
    words = block.reshape(n_frames, -1)[:, : 4 * n_points].reshape(n_frames, n_points, 4)
    xyz = words[:, :, :3].astype(float)
    fourth = words[:, :, 3]
    invalid = ~(np.abs(fourth) < 2.0**31) | (np.where(np.abs(fourth) < 2.0**31, fourth, -1) < 0)
    invalid |= ~np.isfinite(xyz).all(axis=2)
    xyz[invalid] = np.nan
    return xyz.reshape(n_frames, -1) / 1000.0


def judge_c3d(result, original, data, kind, mutated, *, decode=None):
    """The outcome of a C3D read that did not raise.

    ``decode(mutated)`` is the independent decode of the data block (by default the plain
    float32 one of the files this module writes).
    """
    same = result.channels.shape == original.channels.shape and np.array_equal(
        result.channels, original.channels, equal_nan=True
    )
    if kind == "data":
        expected = _c3d_reference(data, mutated) if decode is None else decode(mutated)
        if result.channels.shape == expected.shape and np.allclose(
            result.channels, expected, rtol=1e-12, atol=0, equal_nan=True
        ):
            return "agrees", ""
        return "wrong", "a data byte flip read differently from the plain decode"
    if same:
        return "agrees", ""
    if kind == "cut":
        return "wrong", f"a truncated file read as {result.channels.shape}, not refused"
    # A header or parameter edit changes what the file states (a rate, a count, a frame
    # range the data still backs): no independent truth, so no claim beyond crash, hang
    # and allocation; counted apart.
    return "by the file", ""


# -- .npy / .npz ---------------------------------------------------------------------
def npy_bytes(values):
    buffer = io.BytesIO()
    np.save(buffer, values)
    return buffer.getvalue()


def npz_bytes(values, names=None, compressed=False):
    buffer = io.BytesIO()
    arrays = {"keypoints": values}
    if names is not None:
        arrays["joint_names"] = np.array(names)
    (np.savez_compressed if compressed else np.savez)(buffer, **arrays)
    return buffer.getvalue()


def written_npy(rng):
    return npy_bytes(rng.normal(size=(30, 4, 3)))


def written_npz(rng):
    return npz_bytes(rng.normal(size=(30, 4, 3)), list("abcd"))


def _new_header(header, rng):
    """An .npy header dict text with one field edited."""
    fields = ast.literal_eval(header.strip())
    shape, rest = fields["shape"], fields["shape"][1:]
    choice = rng.integers(0, 4)
    if choice == 0:
        new = [
            shape,
            (10**9, *rest),
            (2**62, 2**62),
            (-1, *rest),
            (*shape, 1000000),
            (),
            (0, *rest),
            (shape[0] + 1, *rest),
            (shape[0] // 2, *rest),
        ][int(rng.integers(0, 9))]
        return header.replace(repr(shape), repr(new)), f"shape {new}"
    if choice == 1:
        descr = str(rng.choice(["|O", "<c16", ">f8", "<f4", "|V8", "<M8[s]", "|b1", "<U2", "xyz"]))
        return header.replace(repr(fields["descr"]), repr(descr)), f"descr {descr}"
    if choice == 2:
        return header.replace("False", "True"), "fortran_order True"
    return header.replace("}", ", 'extra': (((}"), "garbled dict"


def mutate_npy(data, rng):
    header_len = int.from_bytes(data[8:10], "little")
    header = data[10 : 10 + header_len].decode("latin-1")
    kind = rng.choice(["header", "prefix", "data", "cut"], p=[0.45, 0.15, 0.2, 0.2])
    if kind == "header":
        new, what = _new_header(header.rstrip(), rng)
        new = new[: header_len - 1].ljust(header_len - 1) + "\n"
        return what, data[:10] + new.encode("latin-1") + data[10 + header_len :], kind
    if kind == "prefix":
        at = int(rng.integers(0, 10))
        value = int(rng.integers(0, 256))
        mutated = bytearray(data)
        mutated[at] = value
        return f"prefix byte {at} = {value}", bytes(mutated), kind
    if kind == "data":
        mutated = bytearray(data)
        at = int(rng.integers(10 + header_len, len(data)))
        mutated[at] ^= 1 << int(rng.integers(0, 8))
        return f"data byte {at} flipped", bytes(mutated), kind
    cut = int(rng.integers(0, len(data)))
    return f"cut at byte {cut} of {len(data)}", data[:cut], kind


def mutate_npz(data, rng):
    kind = rng.choice(["zip", "member", "cut"], p=[0.5, 0.3, 0.2])
    if kind == "zip":
        mutated = bytearray(data)
        for _ in range(int(rng.integers(1, 4))):
            at = int(rng.integers(0, len(data)))
            mutated[at] = int(rng.integers(0, 256))
        return "zip bytes changed", bytes(mutated), kind
    if kind == "member":
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            members = {n: archive.read(n) for n in archive.namelist()}
        what, members["keypoints.npy"], _ = mutate_npy(members["keypoints.npy"], rng)
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as archive:
            for name, body in members.items():
                archive.writestr(name, body)
        return f"member keypoints.npy: {what}", buffer.getvalue(), kind
    cut = int(rng.integers(0, len(data)))
    return f"cut at byte {cut} of {len(data)}", data[:cut], kind


def _numpy_reference(path, size):
    """numpy.load of the file, only when no header claims more than the file holds."""
    from skmotion.io._keypoints import _read_array

    try:
        _read_array(path)  # raises before any allocation a forged header would cause
    except MotionFileError:
        return None
    loaded = np.load(path, allow_pickle=False)
    if isinstance(loaded, np.lib.npyio.NpzFile):
        with loaded:
            return loaded["keypoints"]
    return loaded


def judge_array(result, original, data, kind, mutated, path):
    try:
        reference = _numpy_reference(path, len(mutated))
    except Exception as exc:  # noqa: BLE001 - numpy refusing is a fine answer for us too
        return "wrong", f"read, but numpy.load refuses the bytes ({type(exc).__name__}: {exc})"
    if reference is None:
        return "wrong", "read, though its header claims more than the file holds"
    with np.errstate(invalid="ignore"):
        values = np.asarray(reference, dtype=float)
    expected = values.reshape(len(values), -1) if values.ndim == 3 else values
    if expected.shape == result.channels.shape and np.array_equal(
        expected, result.channels, equal_nan=True
    ):
        same = np.array_equal(result.channels, original.channels, equal_nan=True)
        return ("agrees", "") if same or kind != "cut" else ("by the file", "")
    return "wrong", "read differently from numpy.load of the same bytes"


# -- keypoint text (the text mutations of the reader fuzz test) ---------------------
def written_csv(rng):
    values = np.round(rng.normal(size=(30, 9)), 4)
    header = ",".join(f"{j}_{a}" for j in "abc" for a in "xyz")
    return (header + "\n" + "\n".join(",".join(map(str, row)) for row in values) + "\n").encode()


def mutate_csv(data, rng):
    from tests.bad_input.fuzz import mutate

    description, mutated, neutral = mutate(data, rng)
    return description, mutated, "neutral" if neutral else "text"


def judge_csv(result, original, data, kind, mutated):
    """A text edit that still reads: equal to the original after a layout-only change,
    otherwise what the edited text says (counted apart)."""
    same = result.channels.shape == original.channels.shape and np.array_equal(
        result.channels, original.channels, equal_nan=True
    )
    if kind == "neutral":
        return ("agrees", "") if same else ("wrong", "a layout-only change changed the values")
    return ("agrees", "") if same else ("by the file", "")


# -- the engine ----------------------------------------------------------------------
def real_c3d(shared_data):
    """A real Plug-in Gait file (Intel, float32, 97 points, 34 analog channels)."""
    return lambda rng: (shared_data / "c3d" / "PiG_Motion3_noFF.c3d").read_bytes()


SOURCES = {
    "written-c3d": (written_c3d, mutate_c3d, lambda p: read_c3d(p), judge_c3d),
    "written-npy": (written_npy, mutate_npy, lambda p: read_keypoints(p, frame_rate=30.0), None),
    "written-npz": (written_npz, mutate_npz, lambda p: read_keypoints(p, frame_rate=30.0), None),
    "written-csv": (
        written_csv,
        mutate_csv,
        lambda p: read_keypoints(p, columns="xyz", frame_rate=30.0),
        judge_csv,
    ),
}


def _read_traced(read, path, time_limit):
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, time_limit)
    tracemalloc.start()
    try:
        return read(path), None, tracemalloc.get_traced_memory()[1]
    except BaseException as exc:  # noqa: BLE001 - classified by the caller
        return None, exc, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def run_case(source, path, mutated, description, kind, original, data, tally, time_limit):
    _, _, read, judge = SOURCES[source]
    path.write_bytes(mutated)
    result, error, peak = _read_traced(read, path, time_limit)
    if peak > 2 * len(mutated) + (1 << 20):
        return tally.add(source, "allocation", f"{description}: peak {peak} bytes")
    if isinstance(error, _Timeout):
        return tally.add(source, "hang", description)
    if isinstance(error, MotionFileError):
        if str(error).startswith(str(path)):
            return tally.add(source, "rejected")
        return tally.add(source, "crash", f"{description}: error not naming the file: {error}")
    if error is not None:
        return tally.add(source, "crash", f"{description}: {type(error).__name__}: {error}")
    if judge is None:
        outcome, why = judge_array(result, original, data, kind, mutated, path)
    else:
        outcome, why = judge(result, original, data, kind, mutated)
    return tally.add(source, outcome, f"{description}: {why}")


def fuzz(folder, shared_data=None, *, n_cases=100, seed=0, time_limit=5.0):
    """Mutate every binary source ``n_cases`` times; the Tally of outcomes per source."""
    rng = np.random.default_rng(seed)
    tally = Tally()
    if shared_data is not None and (shared_data / "c3d").is_dir():
        SOURCES["real-c3d"] = (
            real_c3d(shared_data),
            mutate_c3d,
            SOURCES["written-c3d"][2],
            judge_c3d,
        )
    for source in SOURCES:
        make, mutate, read, _ = SOURCES[source]
        data = make(np.random.default_rng(0))
        suffix = source.rsplit("-", 1)[1]
        original_path = folder / f"original.{suffix}"
        original_path.write_bytes(data)
        original = read(original_path)
        path = folder / f"mutated-{source}.{suffix}"
        for _ in range(n_cases):
            description, mutated, kind = mutate(data, rng)
            run_case(source, path, mutated, description, kind, original, data, tally, time_limit)
    return tally
