"""Reading C3D files (optical marker positions) through the ``c3d`` package (extra ``c3d``)."""

import warnings
from pathlib import Path

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._motion import METERS_PER_UNIT, Motion

__all__ = ["read_c3d"]

# Point words per processor type: (float32 dtype, int16 dtype); DEC floats are converted.
_WORDS = {"INTEL": ("<f4", "<i2"), "DEC": (None, "<i2"), "MIPS": (">f4", ">i2")}


def _import_c3d():
    try:
        import c3d
    except ImportError:
        raise ImportError(
            "Reading C3D files needs the optional package 'c3d': pip install 'skmotion[c3d]'."
        ) from None
    return c3d


def _labels(reader, n_points):
    """POINT:LABELS, LABELS2, ... (files with more than 255 points), stripped and made unique."""
    labels, key = [], "POINT:LABELS"
    for k in range(2, 100):
        param = reader.get(key)
        if param is None:
            break
        labels += [str(s).strip() for s in param.string_array.ravel()]
        key = f"POINT:LABELS{k}"
    labels = labels[:n_points] + [""] * (n_points - len(labels))
    # An empty label gets its point number; a repeated one its occurrence ("LASI#2"), so that
    # every channel has its own name (documented in docs/motion-files.md).
    out, seen = [], {}
    for i, label in enumerate(labels):
        label = label or f"point{i + 1}"
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
            from c3d.c3d import DEC_to_IEEE_BYTES

            words = DEC_to_IEEE_BYTES(raw.tobytes())
        else:
            words = raw.reshape(-1).view(float_type)
        words = words.reshape(n_frames, n_points, 4)
        xyz = words[:, :, :3].astype(np.float64)
        # A junk fourth word (NaN, huge) counts as invalid rather than overflowing the cast.
        fourth = words[:, :, 3]
        last = np.where(np.abs(fourth) < 2.0**31, fourth, -1.0).astype(np.int32)
    else:
        words = raw.reshape(-1).view(int_type).reshape(n_frames, n_points, 4)
        xyz = words[:, :, :3] * abs(scale)
        last = words[:, :, 3].astype(np.int32)
    residuals = (last & 0xFF) * abs(scale)
    invalid = (last < 0) | ~np.isfinite(xyz).all(axis=2)
    return xyz, residuals, invalid


def _point_block(path, reader):
    """The point words of every frame, as uint8 rows; analog samples are skipped."""
    # The package gives numpy uint16 counts: Python ints, so that the products cannot wrap.
    n_points = int(reader.point_used)
    word = 4 if reader.point_scale < 0 else 2
    point_bytes = 4 * n_points * word
    analog_bytes = int(reader.analog_used) * int(reader.analog_per_frame) * word
    n_frames = int(reader.frame_count)
    start = (int(reader.header.data_block) - 1) * 512
    data = np.fromfile(path, dtype=np.uint8, offset=start)
    frame_bytes = point_bytes + analog_bytes
    if n_frames < 0 or len(data) < n_frames * frame_bytes:
        whole = len(data) // max(frame_bytes, 1)
        raise MotionFileError(
            path,
            None,
            f"truncated: the header announces {n_frames} frames of {frame_bytes} bytes, "
            f"the data block holds {whole}",
        )
    return data[: n_frames * frame_bytes].reshape(n_frames, frame_bytes)[:, :point_bytes]


def _unit_scale(path, file_unit, units):
    """The factor from the file's length unit to ``units`` (None: keep the file's)."""
    if units is None:
        return 1.0, file_unit or "unknown"
    if file_unit not in METERS_PER_UNIT:
        raise MotionFileError(
            path,
            None,
            f"POINT:UNITS is {file_unit!r}, not a known length unit; pass units=None to keep it",
        )
    return METERS_PER_UNIT[file_unit] / METERS_PER_UNIT[units], units


def read_c3d(path, *, units="m"):
    """Read the marker positions of a C3D file as a position :class:`Motion`.

    C3D is the binary format of optical motion capture (Vicon, Qualisys,
    Motion Analysis, ...). The metadata (labels, rate, scale, units,
    processor type) is parsed by the ``c3d`` package (install the extra:
    ``pip install 'skmotion[c3d]'``); the point block is decoded in one
    NumPy step, for Intel, DEC and MIPS files with int16 or float32 storage.
    Analog channels (force plates, EMG) are not read.

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.
    units : {"m", "cm", "mm", "in", "ft"} or None, default="m"
        Length unit of the returned positions and residuals, converted from
        the file's ``POINT:UNITS``; None keeps the file's unit.

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
        point was interpolated or modelled.

    Raises
    ------
    ImportError
        Without the ``c3d`` package.
    MotionFileError
        A file the ``c3d`` package cannot parse, a truncated data block, an
        unknown length unit when converting; the message names the file.

    See Also
    --------
    skmotion.io.read_keypoints : positions from trackers and pose estimators.

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
    c3d = _import_c3d()
    path = Path(path)
    if units is not None and units not in METERS_PER_UNIT:
        raise ValueError(f"units must be None or one of {sorted(METERS_PER_UNIT)}; got {units!r}.")
    with open(path, "rb") as handle:  # a missing file: the OSError names it
        try:
            with warnings.catch_warnings():
                # The package warns about files without analog data; the points are what we read.
                warnings.simplefilter("ignore")
                reader = c3d.Reader(handle)
                n_points, scale = int(reader.point_used), float(reader.point_scale)
                processor, rate = reader.proc_type, float(reader.point_rate)
                labels = _labels(reader, n_points)
                unit = reader.get("POINT:UNITS")
                file_unit = unit.string_value.strip().lower() if unit is not None else ""
                block = _point_block(path, reader)
        except MotionFileError:
            raise
        except Exception as exc:  # the package raises ValueError, struct.error, EOF errors ...
            raise MotionFileError(path, None, f"not a readable C3D file ({exc})") from None
    if processor not in _WORDS or not scale or not np.isfinite(scale):
        raise MotionFileError(
            path, None, f"processor {processor!r} and POINT:SCALE {scale!r} are not usable"
        )
    if not rate > 0 or not np.isfinite(rate):
        raise MotionFileError(path, None, f"POINT:RATE is {rate!r}, not a frame rate")
    if n_points == 0:
        raise MotionFileError(path, None, "no 3-D points (POINT:USED is 0)")
    xyz, residuals, invalid = _decode_points(block, processor, scale, n_points)
    factor, units = _unit_scale(path, file_unit, units)
    if factor != 1.0:
        xyz *= factor
    xyz[invalid] = np.nan
    residuals = np.where(invalid, np.nan, residuals * factor)
    return Motion(
        None,
        xyz.reshape(len(xyz), 3 * n_points),
        frame_rate=rate,
        source=str(path),
        marker_names=labels,
        units=units,
        extras={"residuals": residuals},
    )
