"""A small C3D writer for tests: any parameter (repeated ones too), any header field.

The layout follows the C3D user guide: a 512-byte header, parameter blocks
(a 4-byte preamble, group and parameter entries), then frames of point words
(x, y, z and a residual word per point) followed by the frame's analog words.
Intel byte order; float32 storage when ``scale < 0``, int16 otherwise.
"""

import struct

import numpy as np

GROUPS = {"POINT": 1, "ANALOG": 2, "EVENT": 3, "TRIAL": 4, "PROCESSING": 5}


def _entry(group_id, name, payload):
    name = name.encode()
    return (
        struct.pack("<bb", len(name), group_id)
        + name
        + struct.pack("<h", len(payload) + 2)
        + payload
    )


def _parameter(group, name, value):
    """One parameter entry: text (str or list of str), int16 (ints) or float32 (floats)."""
    if isinstance(value, (str, bytes)) or (
        isinstance(value, list) and value and isinstance(value[0], (str, bytes))
    ):
        items = [value] if isinstance(value, (str, bytes)) else value
        items = [v.encode("latin-1") if isinstance(v, str) else v for v in items]
        width = max(len(v) for v in items) or 1
        data = b"".join(v.ljust(width, b" ") for v in items)
        dims = [width] if isinstance(value, (str, bytes)) else [width, len(items)]
        head = struct.pack("<bB", -1, len(dims)) + bytes(dims)
    else:
        array = np.atleast_1d(np.asarray(value))
        kind, dtype = (4, "<f4") if array.dtype.kind == "f" else (2, "<i2")
        dims = list(array.shape[::-1])  # the file's first index runs fastest: C order reversed
        data = array.astype(dtype).tobytes()
        head = struct.pack("<bB", kind, len(dims)) + bytes(dims)
    return _entry(GROUPS[group], name, head + data + b"\x00")


def c3d_bytes(
    xyz,
    residuals=None,
    *,
    labels=None,
    rate=100.0,
    scale=-1.0,
    units="mm",
    analog=None,
    analog_per_frame=1,
    header_frames=None,
    parameters=(),
    frames_parameter=True,
):
    """The bytes of a C3D file of points ``xyz`` (n_frames, n_points, 3).

    ``residuals`` (n_frames, n_points): < 0 marks an invalid point. ``analog``
    (n_frames * analog_per_frame, n_channels): raw analog words. ``units`` goes
    into ``POINT:UNITS`` as given (``b"mm\\x00\\x00"``, ``""``; None leaves it out).
    ``header_frames`` = (first, last) overrides the header's frame range;
    ``parameters`` adds (group, name, value) entries after the standard ones
    (the same name twice is written twice).
    """
    xyz = np.asarray(xyz, dtype=float)
    n_frames, n_points = xyz.shape[:2]
    residuals = np.zeros((n_frames, n_points)) if residuals is None else np.asarray(residuals)
    labels = labels if labels is not None else [f"M{k}" for k in range(n_points)]
    n_analog = 0 if analog is None else analog.shape[1]
    params = [
        ("POINT", "USED", [n_points]),
        ("POINT", "RATE", [float(rate)]),
        ("POINT", "SCALE", [float(scale)]),
        ("POINT", "LABELS", list(labels)),
        ("ANALOG", "USED", [n_analog]),
    ]
    if frames_parameter:
        params.append(("POINT", "FRAMES", [n_frames]))
    if units is not None:
        params.append(("POINT", "UNITS", units))
    section = b"".join(_entry(-gid, name, b"\x00") for name, gid in GROUPS.items())
    section += b"".join(_parameter(*p) for p in [*params, *parameters]) + b"\x00\x00"
    n_blocks = (len(section) + 4 + 511) // 512
    section = bytes([1, 0x50, n_blocks, 84]) + section
    section = section.ljust(512 * n_blocks, b"\x00")
    first, last = header_frames if header_frames is not None else (1, n_frames)
    header = bytearray(512)
    header[0], header[1] = 2, 0x50
    struct.pack_into(
        "<HHHHHfHHf",
        header,
        2,
        n_points,
        n_analog * analog_per_frame,
        first,
        last,
        0,
        scale,
        2 + n_blocks,
        analog_per_frame,
        rate,
    )
    word = np.where(residuals < 0, -1, np.round(residuals / abs(scale)))
    points = np.concatenate([xyz if scale < 0 else np.round(xyz / scale), word[:, :, None]], axis=2)
    points = points.reshape(n_frames, 4 * n_points)
    dtype = "<f4" if scale < 0 else "<i2"
    frames = points.astype(dtype)
    if n_analog:
        words = np.asarray(analog).reshape(n_frames, analog_per_frame * n_analog).astype(dtype)
        frames = np.concatenate([frames.view(np.uint8), words.view(np.uint8)], axis=1)
    data = np.ascontiguousarray(frames).tobytes()
    data = data.ljust(-(-len(data) // 512) * 512, b"\x00")
    return bytes(header) + section + data
