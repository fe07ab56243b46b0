"""Reading C3D files: optical marker positions, analog channels and events."""

from pathlib import Path

import numpy as np

from skmotion.io._c3d_parameters import dec_to_float, read_metadata
from skmotion.io._errors import MotionFileError
from skmotion.io._motion import METERS_PER_UNIT, Motion
from skmotion.io._recording import AnalogChannels, MotionEvent

__all__ = ["read_c3d"]

# Point words per processor type: (float32 dtype, int16 dtype); DEC floats are converted.
_WORDS = {"INTEL": ("<f4", "<i2"), "DEC": (None, "<i2"), "MIPS": (">f4", ">i2")}


def _labels(meta, group, n):
    """GROUP:LABELS, LABELS2, ... (more than 255 entries), made unique, ``n`` of them."""
    labels = list(meta.strings(f"{group}:LABELS"))
    for k in range(2, 100):
        more = meta.parameters.get(f"{group}:LABELS{k}")
        if more is None:
            break
        labels += list(more) if isinstance(more, list) else []
    labels = labels[:n] + [""] * (n - len(labels))
    # An empty label gets its number; a repeated one its occurrence ("LASI#2"), so that
    # every channel has its own name (documented in docs/motion-files.md).
    out, seen = [], {}
    stem = "point" if group == "POINT" else "analog"
    for i, label in enumerate(labels):
        label = label or f"{stem}{i + 1}"
        seen[label] = seen.get(label, 0) + 1
        out.append(label if seen[label] == 1 else f"{label}#{seen[label]}")
    return out


def _decode_points(raw, processor, scale, n_points):
    """Positions, residuals and validity from the point words of every frame.

    ``raw`` is a uint8 array (n_frames, 4 * n_points * word size): per point
    x, y, z and a fourth word whose low byte is the residual (in units of
    ``|scale|``) and whose sign marks an invalid point (C3D user guide).
    """
    n_frames = len(raw)
    float_type, int_type = _WORDS[processor]
    if scale < 0:
        if float_type is None:
            words = dec_to_float(np.ascontiguousarray(raw))
        else:
            words = np.ascontiguousarray(raw).reshape(-1).view(float_type)
        words = words.reshape(n_frames, n_points, 4)
        xyz = words[:, :, :3].astype(np.float64)
        # A junk fourth word (NaN, huge) counts as invalid rather than overflowing the cast,
        # and so does a negative fraction (-0.5 would truncate to a valid 0).
        fourth = words[:, :, 3]
        usable = (np.abs(fourth) < 2.0**31) & (fourth >= 0)
        last = np.where(usable, fourth, -1.0).astype(np.int32)
    else:
        words = np.ascontiguousarray(raw).reshape(-1).view(int_type)
        words = words.reshape(n_frames, n_points, 4)
        xyz = words[:, :, :3] * abs(scale)
        last = words[:, :, 3].astype(np.int32)
    residuals = (last & 0xFF) * abs(scale)
    invalid = (last < 0) | ~np.isfinite(xyz).all(axis=2)
    return xyz, residuals, invalid


def _announced_counts(meta):
    """The frame counts the header and parameters state (each may be wrong)."""
    header, counts = meta.header, []
    first, last = header["first_frame"], header["last_frame"]
    if last >= first >= 0 and last > 0:
        counts.append(last - first + 1)
    start, end = (
        meta.parameters.get("TRIAL:ACTUAL_START_FIELD"),
        meta.parameters.get("TRIAL:ACTUAL_END_FIELD"),
    )
    if _is_pair(start) and _is_pair(end):
        # Two 16-bit words each (files past 65535 frames): low word first.
        first_long = int(start[0] & 0xFFFF) + 65536 * int(start[1] & 0xFFFF)
        last_long = int(end[0] & 0xFFFF) + 65536 * int(end[1] & 0xFFFF)
        if last_long >= first_long and last_long > 0:
            counts.append(last_long - first_long + 1)
    frames = meta.number("POINT:FRAMES", unsigned=True)
    if frames is not None and np.isfinite(frames) and 0 < frames < 2**31:
        counts.append(int(frames))
    return sorted(set(counts), reverse=True)


def _is_pair(values):
    return values is not None and not isinstance(values, list) and len(values) >= 2


def _frame_count(path, meta, data, frame_bytes):
    """Frames to read: the largest announced count the data holds whole.

    Headers are sometimes wrong (a last frame of 0, or 65535 in long files);
    a count that the data block cannot hold is never used, and a larger count
    whose extra frames are only the zero padding of the last 512-byte block
    gives way to a smaller one. With no count announced, the whole frames of
    the data block without its trailing zero padding.
    """
    held = len(data) // frame_bytes
    counts = _announced_counts(meta)
    fitting = [c for c in counts if c <= held]
    if not fitting and counts:
        raise MotionFileError(
            path,
            None,
            f"truncated: the header announces {counts[-1]} frames of {frame_bytes} bytes, "
            f"the data block holds {held}",
        )
    if not fitting:
        nonzero = np.flatnonzero(data[: held * frame_bytes].reshape(held, frame_bytes).any(axis=1))
        return int(nonzero[-1]) + 1 if len(nonzero) else 0
    n = fitting[0]
    for smaller in fitting[1:]:
        if data[smaller * frame_bytes : n * frame_bytes].any():
            break
        n = smaller
    return n


def _unit_scale(path, file_unit, units):
    """The factor from the file's length unit to ``units`` (None: keep the file's)."""
    if units is None:
        return 1.0, file_unit or "unknown"
    if file_unit not in METERS_PER_UNIT:
        what = "empty" if not file_unit else f"{file_unit!r}, not a known length unit"
        raise MotionFileError(
            path,
            None,
            f"POINT:UNITS is {what}; pass units=None to keep the numbers as stored "
            "(skmotion info --units none)",
        )
    return METERS_PER_UNIT[file_unit] / METERS_PER_UNIT[units], units


def _padded(values, n, fill):
    values = [] if values is None or isinstance(values, list) else list(values[:n])
    return np.array(values + [fill] * (n - len(values)), dtype=float)


def _analog(meta, words, n_frames, point_rate):
    """The analog channels of the data block's analog words (n_frames, bytes), or None."""
    n_used = int(meta.number("ANALOG:USED", 0, unsigned=True))
    total = meta.header["analog_per_frame"]
    if n_used <= 0 or total <= 0 or total % n_used:
        return None
    per_frame = total // n_used
    rate = meta.number("ANALOG:RATE")
    if rate is None or not np.isfinite(rate) or rate <= 0:
        rate = point_rate * per_frame  # BTS files leave ANALOG:RATE out

    def decode():  # on first use of ``values``: the point read does not pay for it
        return _analog_values(meta, words, words.shape[1] == 4 * total, n_used)

    units = meta.strings("ANALOG:UNITS")[:n_used]
    return AnalogChannels(
        decode,
        float(rate),
        _labels(meta, "ANALOG", n_used),
        units + [""] * (n_used - len(units)),
    )


def _analog_values(meta, words, floats, n_used):
    """Analog samples (n_samples, n_used) from the analog bytes of every frame."""
    flat = np.ascontiguousarray(words).reshape(-1)
    if floats:
        if meta.processor == "DEC":
            values = dec_to_float(flat).astype(np.float64)
        else:
            values = flat.view(meta.order + "f4").astype(np.float64)
    else:
        unsigned = meta.strings("ANALOG:FORMAT")[:1] == ["UNSIGNED"]
        values = flat.view(meta.order + ("u2" if unsigned else "i2")).astype(np.float64)
    values = values.reshape(-1, n_used)
    offset = _padded(meta.parameters.get("ANALOG:OFFSET"), n_used, 0.0)
    if meta.strings("ANALOG:FORMAT")[:1] == ["UNSIGNED"]:
        offset = offset % 65536
    scale = _padded(meta.parameters.get("ANALOG:SCALE"), n_used, 1.0)
    general = meta.number("ANALOG:GEN_SCALE", 1.0)
    values -= offset
    values *= scale * general
    return values


def _events(meta, rate):
    """The EVENT group's labelled instants; ``frame`` counts from the motion's first row."""
    times = meta.parameters.get("EVENT:TIMES")
    n = int(meta.number("EVENT:USED", 0, unsigned=True))
    if times is None or isinstance(times, list) or n <= 0:
        return ()
    n = min(n, len(times) // 2)
    seconds = times[: 2 * n].reshape(n, 2) @ np.array([60.0, 1.0])  # (minutes, seconds)
    start = meta.parameters.get("TRIAL:ACTUAL_START_FIELD")
    first = (
        int(start[0] & 0xFFFF) + 65536 * int(start[1] & 0xFFFF)
        if _is_pair(start)
        else meta.header["first_frame"]
    )
    columns = [meta.strings(f"EVENT:{k}") for k in ("LABELS", "CONTEXTS", "SUBJECTS")]
    columns = [c[:n] + [""] * (n - len(c[:n])) for c in columns]
    return tuple(
        # The file's clock counts trial frame 1 as time 0.
        MotionEvent(label, context, float(t), int(round(t * rate)) + 1 - first, subject)
        for label, context, subject, t in zip(*columns, seconds)
        if np.isfinite(t)
    )


def read_c3d(path, *, units="m"):
    """Read a C3D file: marker positions, analog channels and events.

    C3D is the binary format of optical motion capture (Vicon, Qualisys,
    Motion Analysis, BTS, ...). The header and parameter section are parsed
    from the file's bytes, and the data block is decoded in one NumPy step,
    for Intel, DEC and MIPS files with int16 or float32 storage; no
    optional package is needed.

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.
    units : {"m", "cm", "mm", "in", "ft"} or None, default="m"
        Length unit of the returned positions and residuals, converted from
        the file's ``POINT:UNITS`` (NUL bytes and spaces stripped, any
        case); None keeps the numbers as stored, with the file's unit (or
        ``"unknown"`` when ``POINT:UNITS`` is empty, as in BTS and
        PhaseSpace files).

    Returns
    -------
    motion : Motion
        A position motion (``skeleton=None``): ``marker_names`` from
        ``POINT:LABELS`` (an empty label becomes ``point<k>``, a repeated one
        ``<label>#2``), channels ``<label>_x``, ``_y``, ``_z`` in the lab
        frame of the file (usually Z up), ``frame_rate`` from ``POINT:RATE``,
        ``units``. A point whose residual is negative (invalid, not seen) is
        NaN. ``motion.extras["residuals"]`` holds the residual of each point
        (n_frames, n_markers) in ``units``, NaN where invalid; 0 means the
        point was interpolated or modelled. ``motion.analog`` holds the
        analog channels (:class:`AnalogChannels`: values after the file's
        offsets and scales, ``ANALOG:RATE``, labels, units), None when the
        file has none; ``motion.events`` the ``EVENT`` group's labelled
        instants (:class:`MotionEvent`: label, context, time, row).

    Raises
    ------
    MotionFileError
        A file that is not C3D, a damaged parameter section, a data block
        shorter than every frame count the file announces, an unknown or
        empty length unit when converting; the message names the file.

    See Also
    --------
    skmotion.io.read_keypoints : positions from trackers and pose estimators.

    Notes
    -----
    The number of frames is the largest count the file announces (header
    first and last frame, ``TRIAL:ACTUAL_START_FIELD``/``ACTUAL_END_FIELD``,
    ``POINT:FRAMES``) that the data block holds whole: a header whose last
    frame is 0 or off by one does not cut the motion short. A parameter
    defined twice keeps its last definition, as ezc3d does.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> import pytest; c3d = pytest.importorskip("c3d")  # pip install "skmotion[c3d]"
    >>> from skmotion.io import read_c3d
    >>> writer = c3d.Writer(point_rate=100.0, point_scale=-1.0)  # float32 storage, mm
    >>> writer.set_point_labels(["LASI", "RASI"])
    >>> points = np.zeros((2, 5), np.float32)
    >>> points[:, :3] = [[100.0, 200.0, 900.0], [300.0, 200.0, 900.0]]
    >>> points[1, 3] = -1.0  # RASI unseen in this frame
    >>> writer.add_frames([(points, np.zeros((0, 0)))] * 3)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "trial.c3d")
    ...     with open(path, "wb") as handle:
    ...         writer.write(handle)
    ...     motion = read_c3d(path)
    >>> motion.marker_names, motion.frame_rate, motion.units
    (('LASI', 'RASI'), 100.0, 'm')
    >>> motion.channels[0]
    array([0.1, 0.2, 0.9, nan, nan, nan])
    """
    path = Path(path)
    if units is not None and units not in METERS_PER_UNIT:
        raise ValueError(f"units must be None or one of {sorted(METERS_PER_UNIT)}; got {units!r}.")
    raw = np.fromfile(path, dtype=np.uint8)  # a missing file: the OSError names it
    meta = read_metadata(path, raw)
    n_points = int(meta.number("POINT:USED", meta.header["n_points"], unsigned=True))
    scale = float(meta.number("POINT:SCALE", meta.header["scale"]))
    rate = float(meta.number("POINT:RATE", meta.header["rate"]))
    if not scale or not np.isfinite(scale):
        raise MotionFileError(path, None, f"POINT:SCALE {scale!r} is not usable")
    if not rate > 0 or not np.isfinite(rate):
        raise MotionFileError(path, None, f"POINT:RATE is {rate!r}, not a frame rate")
    if n_points == 0:
        raise MotionFileError(path, None, "no 3-D points (POINT:USED is 0)")
    n_analog = int(meta.number("ANALOG:USED", 0, unsigned=True))
    if n_analog > 0 and meta.header["analog_per_frame"] % n_analog:
        raise MotionFileError(
            path,
            None,
            f"the header's {meta.header['analog_per_frame']} analog samples per frame are not "
            f"a whole number per channel of ANALOG:USED={n_analog}",
        )
    # What the parameters say is checked before the data block is decoded: a bad
    # unit or event fails fast, without first allocating the positions.
    file_unit = (meta.strings("POINT:UNITS") or [""])[0].lower()
    factor, units = _unit_scale(path, file_unit, units)
    labels = _labels(meta, "POINT", n_points)
    events = _events(meta, rate)
    word = 4 if scale < 0 else 2
    point_bytes = 4 * n_points * word
    frame_bytes = point_bytes + meta.header["analog_per_frame"] * word
    data = raw[max(meta.header["data_start"] - 1, 0) * 512 :]
    n_frames = _frame_count(path, meta, data, frame_bytes)
    block = data[: n_frames * frame_bytes].reshape(n_frames, frame_bytes)
    xyz, residuals, invalid = _decode_points(
        block[:, :point_bytes], meta.processor, scale, n_points
    )
    if factor != 1.0:
        xyz *= factor
    xyz[invalid] = np.nan
    residuals = np.where(invalid, np.nan, residuals * factor)
    return Motion(
        None,
        xyz.reshape(n_frames, 3 * n_points),
        frame_rate=rate,
        source=str(path),
        marker_names=labels,
        units=units,
        extras={"residuals": residuals},
        analog=_analog(meta, block[:, point_bytes:], n_frames, rate),
        events=events,
    )
