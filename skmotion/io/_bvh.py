"""Reading BVH (Biovision hierarchy) files."""

import dataclasses
import io
import re

import numpy as np

from skmotion.io._bvh_hierarchy import parse_hierarchy
from skmotion.io._errors import MotionFileError
from skmotion.io._motion import Motion
from skmotion.io._text import (
    Tokens,
    decode_text,
    is_special,
    number_bytes_only,
    parse_floats,
    parse_number,
    read_text,
)
from skmotion.kinematics import Skeleton, forward_kinematics, match_joints

__all__ = ["detect_up_axis", "read_bvh"]

_UP_AXES = ("x", "y", "z", None)
_DIGITS = re.compile(r"[0-9]+")
_CHUNK_BYTES = 1 << 22  # the MOTION block is parsed in pieces of about 4 MB


def _frame_rate(path, line, text):
    """1 / Frame Time, rounded to whole Hz when the written value allows it."""
    try:
        frame_time = float(text) if is_special(text) else parse_number(text)
    except ValueError:
        raise MotionFileError(path, line, f"non-numeric Frame Time {text!r}") from None
    if not frame_time > 0 or not np.isfinite(frame_time):
        raise MotionFileError(path, line, f"Frame Time must be positive and finite, got {text!r}")
    rate = 1.0 / frame_time
    if not np.isfinite(rate):
        raise MotionFileError(
            path, line, f"Frame Time {text!r} is too small: its frame rate is not a finite number"
        )
    decimals = len(text.split(".")[1]) if "." in text and "e" not in text.lower() else 17
    whole = round(rate)
    # 0.008333 is 120 Hz written to 6 decimals: keep 120 rather than 120.005
    # (but 0.03 s stays 33.3 Hz).
    if (
        whole > 0
        and abs(1.0 / whole - frame_time) <= 0.5 * 10.0**-decimals
        and abs(rate - whole) < 1e-3 * whole
    ):
        return float(whole)
    return rate


def detect_up_axis(skeleton, channels, *, max_frames=25):
    """The vertical axis of a figure: the axis of its largest extent over the clip.

    A standing, walking or running figure is taller than it is wide or deep
    in most frames; the median extent over (up to ``max_frames`` evenly
    spaced) frames ignores a T-pose at the start. A clip that is lying down,
    or only in a T-pose, needs its up axis given explicitly.

    Parameters
    ----------
    skeleton : Skeleton
    channels : ndarray of shape (n_frames, n_channels)
    max_frames : int, default=25
        How many frames to look at.

    Returns
    -------
    up_axis : {"x", "y", "z"}

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.io import detect_up_axis
    >>> sk = humanoid_skeleton()
    >>> detect_up_axis(sk, np.zeros((1, sk.n_channels)))
    'y'
    """
    channels = np.asarray(channels)
    frames = np.unique(
        np.linspace(0, len(channels) - 1, min(len(channels), max_frames)).round().astype(int)
    )
    positions = forward_kinematics(skeleton, channels[frames]).positions
    extents = np.median(positions.max(axis=1) - positions.min(axis=1), axis=0)
    return "xyz"[int(np.argmax(extents))]


def _up_axis(skeleton, channels):
    """Head above feet in the rest pose; the largest extent over the clip for a non-humanoid."""
    try:
        return match_joints(skeleton).up_axis
    except ValueError:
        return detect_up_axis(skeleton, channels)


_HEADER = re.compile(
    rb"MOTION[ \t]*\n[ \t\n]*Frames:[ \t]*([^ \t\n]*)[ \t]*\n[ \t\n]*"
    rb"Frame Time:[ \t]*([^ \t\n]*)[ \t]*(?:\n|$)",
    flags=re.IGNORECASE,
)


def _motion_block(path, data, start, n_channels):
    """Frames, frame rate and channel values of the MOTION block at byte ``start``."""
    first_line = data.count(b"\n", 0, start) + 1
    header = _HEADER.match(data, start)
    if header is None:
        raise MotionFileError(
            path,
            first_line,
            "expected 'MOTION', 'Frames: N' and 'Frame Time: T' lines (each alone on its line)",
        )
    frames_text = decode_text(header.group(1))
    if not _DIGITS.fullmatch(frames_text):
        raise MotionFileError(
            path,
            data.count(b"\n", 0, header.start(1)) + 1,
            f"Frames must be an integer, found {frames_text!r}",
        )
    n_frames = int(frames_text)
    frame_rate = _frame_rate(
        path, data.count(b"\n", 0, header.start(2)) + 1, decode_text(header.group(2))
    )
    if n_channels == 0:
        raise MotionFileError(path, first_line, "the hierarchy has no channels")
    if n_frames == 0:
        raise MotionFileError(
            path, data.count(b"\n", 0, header.start(1)) + 1, "the file holds no frames"
        )
    body_line = data.count(b"\n", 0, header.end()) + 1
    return _frame_values(path, data, header.end(), body_line, n_frames, n_channels), frame_rate


def _frame_values(path, data, begin, line, n_frames, n_channels):
    """The frame table from byte ``begin`` (at file line ``line``), parsed in ~4 MB pieces.

    Each piece is checked (numeric bytes only, equal rows of ``n_channels`` finite
    values) and parsed at once; only a piece that fails is examined token by token,
    so an error costs about what a valid file does.
    """
    tables, n_read = [], 0
    while begin < len(data):
        cut = data.find(b"\n", begin + _CHUNK_BYTES)
        cut = len(data) if cut < 0 else cut + 1
        piece = data[begin:cut]
        values = None
        if not piece.strip():
            values = np.empty((0, n_channels))
        elif number_bytes_only(piece):
            try:
                values = np.loadtxt(io.BytesIO(piece), dtype=float, ndmin=2, comments=None)
            except ValueError:
                values = None
        if values is None or (
            values.size and (values.shape[1] != n_channels or not np.isfinite(values).all())
        ):
            _explain_piece(path, piece, line, n_channels)
        if values.size:
            if n_read + len(values) > n_frames:
                extra = _filled_lines(piece, line)[n_frames - n_read]
                raise MotionFileError(
                    path, extra, f"more frame lines than the {n_frames} declared by 'Frames:'"
                )
            tables.append(values)
            n_read += len(values)
        line += piece.count(b"\n")
        begin = cut
    if n_read < n_frames:
        raise MotionFileError(
            path,
            data.count(b"\n", 0, len(data.rstrip())) + 1,  # the last line that is not blank
            f"the MOTION block ends after {n_read} frames, but 'Frames: {n_frames}' "
            "was declared (truncated file?)",
        )
    return np.concatenate(tables)


def _filled_lines(piece, first_line):
    """File line numbers of the non-blank lines of ``piece``."""
    tokens = Tokens(piece, first_line=first_line)
    return np.flatnonzero(tokens.per_line()) + first_line


def _explain_piece(path, piece, first_line, n_channels):
    """Raise the MotionFileError naming the first bad line of a piece of the frame table."""
    tokens = Tokens(piece, first_line=first_line)
    per_line = tokens.per_line()
    filled = np.flatnonzero(per_line)
    wrong = filled[per_line[filled] != n_channels]
    if wrong.size:
        raise MotionFileError(
            path,
            int(wrong[0]) + first_line,
            f"{per_line[wrong[0]]} values on a frame line, but the hierarchy has {n_channels} "
            "channels",
        )
    parse_floats(tokens, path)  # names the offending value
    raise MotionFileError(path, first_line, "frame values that cannot be read as numbers")


def read_bvh(path, *, up_axis=None):
    """Read a BVH file: its skeleton and its motion.

    Any joint hierarchy, ``End Site`` blocks, joints with any subset of the six
    channels in any order (hence every rotation order, per joint) are read. The
    MOTION block is parsed as one numeric array. Angles are converted to radians.
    An End Site becomes a joint without channels named ``<parent>_end``.

    Parameters
    ----------
    path : str or path-like
        The ``.bvh`` file.
    up_axis : {"x", "y", "z"}, default=None
        The vertical axis of the file's world. BVH files do not record it; by
        default it is the axis along which the rest pose's head is farthest
        from its feet, when :func:`~skmotion.kinematics.match_joints` finds
        them (the same answer for every file of one skeleton), else the
        axis of the figure's largest extent over the clip
        (:func:`detect_up_axis`).

    Returns
    -------
    motion : Motion
        Lengths are in the file's unit (``units="unknown"``); ``frame_rate`` is
        ``1 / Frame Time``, rounded to whole Hz when the written frame time is
        consistent with it (0.008333 s gives 120 Hz).

    Raises
    ------
    MotionFileError
        For a malformed file (missing braces or keywords, unknown channels,
        non-numeric values, a frame line with the wrong number of values, a
        truncated MOTION block); the message names the file and the line.

    See Also
    --------
    write_bvh : the inverse.

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.io import read_bvh
    >>> text = '''HIERARCHY
    ... ROOT hip
    ... {
    ...   OFFSET 0 0 0
    ...   CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    ...   JOINT knee
    ...   {
    ...     OFFSET 0 -40 0
    ...     CHANNELS 3 Zrotation Xrotation Yrotation
    ...     End Site
    ...     {
    ...       OFFSET 0 -40 0
    ...     }
    ...   }
    ... }
    ... MOTION
    ... Frames: 2
    ... Frame Time: 0.033333
    ... 0 90 0 0 0 0 0 0 0
    ... 0 90 0 0 0 0 0 90 0
    ... '''
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "leg.bvh")
    ...     _ = open(path, "w").write(text)
    ...     motion = read_bvh(path)
    >>> motion.skeleton.joints, motion.frame_rate, motion.skeleton.up_axis
    (('hip', 'knee', 'knee_end'), 30.0, 'y')
    >>> motion.forward_kinematics().positions[1, 2].round(6) + 0.0  # knee turned 90 degrees about X
    array([  0.,  50., -40.])
    """
    if up_axis not in _UP_AXES:
        raise ValueError(f"up_axis must be 'x', 'y', 'z' or None, got {up_axis!r}.")
    data = read_text(path)
    found = re.search(rb"^[ \t]*MOTION\b", data, flags=re.MULTILINE | re.IGNORECASE)
    if found is None:
        raise MotionFileError(path, None, "no MOTION block (not a BVH file, or truncated)")
    joints, parents, offsets, channel_lists = parse_hierarchy(
        path, decode_text(data[: found.start()])
    )
    try:
        skeleton = Skeleton(joints, parents, offsets, channel_lists)
    except ValueError as exc:
        raise MotionFileError(path, None, f"the hierarchy is not a valid skeleton: {exc}") from None
    start = found.start() + len(found.group()) - len(found.group().lstrip())
    channels, frame_rate = _motion_block(path, data, start, skeleton.n_channels)
    rotations = np.array([name.endswith("rotation") for name in skeleton.channel_names])
    channels[:, rotations] = np.deg2rad(channels[:, rotations])
    skeleton = dataclasses.replace(skeleton, up_axis=up_axis or _up_axis(skeleton, channels))
    return Motion(skeleton, channels, frame_rate=frame_rate, source=str(path))
