"""Reading BVH (Biovision hierarchy) files."""

import dataclasses
import io
import re

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._motion import Motion
from skmotion.io._text import Tokens, parse_floats, read_bytes
from skmotion.kinematics import CHANNEL_KINDS, Skeleton, forward_kinematics

__all__ = ["detect_up_axis", "read_bvh"]

_CHANNELS = {c.lower(): c for c in CHANNEL_KINDS}
_UP_AXES = ("x", "y", "z", None)
_WORD = re.compile(r"[{}]|[^\s{}]+")


class _HeaderParser:
    """Recursive-descent parser of the HIERARCHY block, one token at a time."""

    def __init__(self, path, text):
        self.path = path
        words, starts = [], []
        for match in _WORD.finditer(text):
            words.append(match.group())
            starts.append(match.start())
        newlines = np.flatnonzero(np.frombuffer(text.encode("latin-1"), dtype=np.uint8) == 10)
        lines = (np.searchsorted(newlines, starts) + 1).tolist()
        self.tokens = list(zip(words, lines))
        self.pos = 0
        self.joints, self.parents, self.offsets, self.channels = [], [], [], []

    def error(self, message, line=None):
        if line is None:
            line = self.tokens[min(self.pos, len(self.tokens) - 1)][1] if self.tokens else 1
        return MotionFileError(self.path, line, message)

    def next(self, what):
        if self.pos >= len(self.tokens):
            raise self.error(f"file ends where {what} was expected")
        word, line = self.tokens[self.pos]
        self.pos += 1
        return word, line

    def expect(self, keyword, context):
        word, line = self.next(f"{keyword!r}")
        if word.upper() != keyword.upper():
            raise self.error(f"expected {keyword!r} {context}, found {word!r}", line)
        return line

    def number(self, context):
        word, line = self.next(f"a number ({context})")
        try:
            value = float(word)
        except ValueError:
            raise self.error(f"non-numeric value {word!r} in {context}", line) from None
        if not np.isfinite(value):
            raise self.error(f"non-finite value {word!r} in {context}", line)
        return value

    def offset(self, context):
        """Three numbers; the fast path converts them at once."""
        chunk = self.tokens[self.pos : self.pos + 3]
        try:
            values = [float(word) for word, _ in chunk]
        except ValueError:
            values = []
        if len(values) == 3 and np.isfinite(values).all():
            self.pos += 3
            return values
        return [self.number(context) for _ in range(3)]  # names the offending token

    def parse(self):
        self.expect("HIERARCHY", "at the start of a BVH file")
        self.expect("ROOT", "after HIERARCHY")
        self.joint(parent=-1)
        if self.pos < len(self.tokens):
            word, line = self.tokens[self.pos]
            if word.upper() == "ROOT":
                raise self.error(
                    "a second ROOT: files with several hierarchies are not supported", line
                )
            raise self.error(f"unexpected {word!r} after the hierarchy (a '}}' too many?)", line)

    def joint(self, parent):
        name, line = self.next("a joint name")
        if name in ("{", "}"):
            raise self.error(f"expected a joint name, found {name!r}", line)
        if name in self.joints:
            raise self.error(f"joint name {name!r} appears twice", line)
        index = len(self.joints)
        self.joints.append(name)
        self.parents.append(parent)
        opened = self.expect("{", f"after joint {name!r}")
        self.expect("OFFSET", f"in joint {name!r}")
        self.offsets.append(self.offset(f"OFFSET of {name!r}"))
        self.channels.append(self.channel_list(name))
        while True:
            word, line = self.next(f"'}}' closing joint {name!r} (opened at line {opened})")
            key = word.upper()
            if word == "}":
                return
            if key == "JOINT":
                self.joint(index)
            elif key == "END":
                self.end_site(index, line)
            else:
                raise self.error(
                    f"expected JOINT, End Site or '}}' in joint {name!r} (opened at line {opened}), found {word!r}",
                    line,
                )

    def channel_list(self, name):
        self.expect("CHANNELS", f"in joint {name!r}")
        word, line = self.next("the channel count")
        if not word.isdigit():
            raise self.error(
                f"channel count of joint {name!r} must be an integer, found {word!r}", line
            )
        channels = []
        for _ in range(int(word)):
            word, line = self.next(f"a channel name of joint {name!r}")
            if word.lower() not in _CHANNELS:
                raise self.error(
                    f"unknown channel {word!r} of joint {name!r} (expected one of {list(CHANNEL_KINDS)})",
                    line,
                )
            channels.append(_CHANNELS[word.lower()])
        return channels

    def end_site(self, parent, line):
        self.expect("Site", "after 'End'")
        name = f"{self.joints[parent]}_end"
        suffix = 2
        while name in self.joints:
            name, suffix = f"{self.joints[parent]}_end{suffix}", suffix + 1
        opened = self.expect("{", "after End Site")
        self.expect("OFFSET", "in End Site")
        offset = self.offset(f"OFFSET of the End Site of {self.joints[parent]!r}")
        self.expect("}", f"closing the End Site opened at line {opened}")
        self.joints.append(name)
        self.parents.append(parent)
        self.offsets.append(offset)
        self.channels.append([])


def _frame_rate(path, line, text):
    """1 / Frame Time, rounded to whole Hz when the written value allows it."""
    try:
        frame_time = float(text)
    except ValueError:
        raise MotionFileError(path, line, f"non-numeric Frame Time {text!r}") from None
    if not frame_time > 0 or not np.isfinite(frame_time):
        raise MotionFileError(path, line, f"Frame Time must be positive, got {text!r}")
    rate = 1.0 / frame_time
    decimals = len(text.split(".")[1]) if "." in text and "e" not in text.lower() else 17
    whole = round(rate)
    # 0.008333 is 120 Hz written to 6 decimals: keep 120 rather than 120.005 (but 0.03 s stays 33.3 Hz).
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


def _motion_block(path, data, start, n_channels):
    """Frames, frame rate and channel values of the MOTION block at byte ``start``."""
    first_line = data.count(b"\n", 0, start) + 1
    header = re.match(
        rb"MOTION[ \t]*\r?\n\s*Frames:[ \t]*(\S*)[ \t]*\r?\n\s*Frame Time:[ \t]*(\S*)[^\n]*(\n|$)",
        data[start:],
        flags=re.IGNORECASE,
    )
    if header is None:
        raise MotionFileError(
            path, first_line, "expected 'MOTION', 'Frames: N' and 'Frame Time: T' lines"
        )
    line_of = lambda offset: data.count(b"\n", 0, start + offset) + 1  # noqa: E731
    frames_text = header.group(1).decode("latin-1")
    if not frames_text.isdigit():
        raise MotionFileError(
            path, line_of(header.start(1)), f"Frames must be an integer, found {frames_text!r}"
        )
    n_frames = int(frames_text)
    frame_rate = _frame_rate(path, line_of(header.start(2)), header.group(2).decode("latin-1"))
    body = data[start + header.end() :]
    if n_channels == 0:
        raise MotionFileError(path, first_line, "the hierarchy has no channels")
    if n_frames == 0:
        raise MotionFileError(path, line_of(header.start(1)), "the file holds no frames")
    try:
        values = np.loadtxt(io.BytesIO(body), dtype=float, ndmin=2, comments=None)
    except ValueError:
        values = None
    if values is not None and values.shape == (n_frames, n_channels) and np.isfinite(values).all():
        return values, frame_rate
    # Something is wrong: locate it exactly, token by token.
    tokens = Tokens(body, first_line=line_of(header.end()))
    per_line = tokens.per_line()
    filled = np.flatnonzero(per_line)
    wrong = filled[per_line[filled] != n_channels]
    if wrong.size:
        line = int(wrong[0]) + tokens.first_line
        raise MotionFileError(
            path,
            line,
            f"{per_line[wrong[0]]} values on a frame line, but the hierarchy has {n_channels} channels",
        )
    if len(filled) != n_frames:
        if len(filled) < n_frames:
            last = int(filled[-1]) + tokens.first_line if len(filled) else tokens.first_line - 1
            raise MotionFileError(
                path,
                last,
                f"the MOTION block ends after {len(filled)} frames, but 'Frames: {n_frames}' "
                "was declared (truncated file?)",
            )
        raise MotionFileError(
            path,
            int(filled[n_frames]) + tokens.first_line,
            f"more frame lines than the {n_frames} declared by 'Frames:'",
        )
    values = parse_floats(tokens, path)  # names the offending line
    return values.reshape(n_frames, n_channels), frame_rate


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
        default it is detected as the axis of the figure's largest extent in
        the first frame (see :func:`detect_up_axis`).

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
    data = read_bytes(path)
    found = re.search(rb"^[ \t]*MOTION\b", data, flags=re.MULTILINE | re.IGNORECASE)
    if found is None:
        raise MotionFileError(path, None, "no MOTION block (not a BVH file, or truncated)")
    parser = _HeaderParser(path, data[: found.start()].decode("latin-1"))
    parser.parse()
    skeleton = Skeleton(parser.joints, parser.parents, parser.offsets, parser.channels)
    channels, frame_rate = _motion_block(path, data, found.start(), skeleton.n_channels)
    rotations = np.array([name.endswith("rotation") for name in skeleton.channel_names])
    channels[:, rotations] = np.deg2rad(channels[:, rotations])
    skeleton = dataclasses.replace(skeleton, up_axis=up_axis or detect_up_axis(skeleton, channels))
    return Motion(skeleton, channels, frame_rate=frame_rate, source=str(path))
