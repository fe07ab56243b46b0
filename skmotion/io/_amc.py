"""Reading Acclaim motion files (AMC), the motion of an ASF skeleton."""

import re

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._motion import Motion
from skmotion.io._text import Tokens, is_special, parse_floats, read_text
from skmotion.kinematics import Skeleton

__all__ = ["read_amc"]

_FIRST_FRAME = re.compile(rb"^[ \t]*\d", flags=re.MULTILINE)


def _header(path, data):
    """Split off the ``:keyword`` / ``#`` header; returns (angle unit, body start, its line)."""
    found = _FIRST_FRAME.search(data)
    if found is None:
        raise MotionFileError(path, None, "no frame number: the file holds no frames")
    unit = None
    for number, line in enumerate(data[: found.start()].decode("latin-1").split("\n"), start=1):
        word = line.strip(" \t")
        if not word or word.startswith("#"):
            continue
        if not word.startswith(":"):
            raise MotionFileError(
                path, number, f"bone data before the first frame number: {word.split(' ')[0]!r}"
            )
        if word.upper() in (":DEGREES", ":RADIANS"):
            said = "deg" if word.upper() == ":DEGREES" else "rad"
            if unit is not None and said != unit:
                # A 57x difference: neither keyword may silently win.
                raise MotionFileError(path, number, "both :DEGREES and :RADIANS: which unit?")
            unit = said
    return unit, found.start(), data.count(b"\n", 0, found.start()) + 1


def _joint_table(skeleton):
    """Per joint: its first column and channel count; and the rotation columns."""
    counts = np.array([len(c) for c in skeleton.channels])
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rotations = np.array([name.endswith("rotation") for name in skeleton.channel_names], dtype=bool)
    return starts, counts, rotations


def _joint_ids(tokens, which, skeleton):
    """Skeleton joint index of each name token (-1 for unknown names).

    The ~30 bone names repeat in every frame, so tokens are grouped by their
    first 16 bytes and length with NumPy and only one token per group is
    looked up; names longer than 16 bytes are looked up one by one.
    """
    index = {name.encode("latin-1"): j for j, name in enumerate(skeleton.joints)}
    starts, ends = tokens.starts[which], tokens.ends[which]
    lengths = ends - starts
    buffer = np.frombuffer(tokens.data + bytes(16), dtype=np.uint8)
    window = np.arange(16)
    chars = np.where(window < lengths[:, None], buffer[starts[:, None] + window], 0).astype(
        np.uint8
    )
    keys = np.ascontiguousarray(chars).view(np.uint64)
    mixed = keys[:, 0] * np.uint64(0x9E3779B97F4A7C15) ^ keys[:, 1] ^ lengths.astype(np.uint64)
    unique, first, inverse = np.unique(mixed, return_index=True, return_inverse=True)
    exact = (
        (keys == keys[first][inverse]).all(axis=1)
        & (lengths == lengths[first][inverse])
        & (lengths <= 16)
    )
    ids = np.array([index.get(tokens.data[starts[k] : ends[k]], -1) for k in first], dtype=np.intp)[
        inverse
    ]
    for k in np.flatnonzero(~exact):
        ids[k] = index.get(tokens.data[starts[k] : ends[k]], -1)
    return ids


def read_amc(path, skeleton, *, frame_rate=120.0):
    """Read an Acclaim motion (AMC) file for a skeleton from :func:`read_asf`.

    Each frame is a frame number followed by one line per bone, ``name v1 v2
    ...``, with the bone's values in the order of its ``dof`` line (the root's
    in the order of its ``order`` line). Bones may come in any order within a
    frame, but each bone with channels must appear exactly once per frame. The
    whole file is parsed with vectorised NumPy operations on its bytes.

    Parameters
    ----------
    path : str or path-like
        The ``.amc`` file.
    skeleton : Skeleton
        The file's skeleton, from :func:`read_asf`.
    frame_rate : float, default=120.0
        Frames per second. AMC files do not record it; the CMU database is
        captured at 120 Hz.

    Returns
    -------
    motion : Motion
        Angles in radians (converted when the file says ``:DEGREES``, or by
        default), positions in the skeleton's length unit.

    Raises
    ------
    MotionFileError
        For an unknown bone, a bone line with the wrong number of values, a
        frame missing a bone or listing it twice (a truncated file), frame
        numbers out of sequence, non-numeric values, a header saying both
        ``:DEGREES`` and ``:RADIANS``; the message names the file and the line.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from skmotion.io import read_amc, read_asf
    >>> asf = '''
    ... :root
    ...   order TX TY TZ RX RY RZ
    ...   axis XYZ
    ... :bonedata
    ...   begin
    ...     name femur
    ...     direction 0 -1 0
    ...     length 10
    ...     axis 0 0 0 XYZ
    ...     dof rx
    ...   end
    ... :hierarchy
    ...   begin
    ...     root femur
    ...   end
    ... '''
    >>> amc = ":FULLY-SPECIFIED\\n:DEGREES\\n1\\nroot 0 20 0 0 0 0\\nfemur 0\\n"
    >>> amc += "2\\nroot 0 20 0 0 0 0\\nfemur 90\\n"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = open(os.path.join(folder, "a.asf"), "w").write(asf)
    ...     _ = open(os.path.join(folder, "a.amc"), "w").write(amc)
    ...     skeleton = read_asf(os.path.join(folder, "a.asf"))
    ...     motion = read_amc(os.path.join(folder, "a.amc"), skeleton)
    >>> motion.channels[:, 6].tolist() == [0.0, np.pi / 2]
    True
    >>> motion.forward_kinematics().positions[:, 2].round(6) + 0.0  # the femur's tip
    array([[ 0., 10.,  0.],
           [ 0., 20., -10.]])
    """
    if not isinstance(skeleton, Skeleton):
        raise TypeError(
            f"skeleton must be a Skeleton (from read_asf), got {type(skeleton).__name__}."
        )
    data = read_text(path)
    unit, start, first_line = _header(path, data)
    tokens = Tokens(data[start:], first_line=first_line)
    buffer = np.frombuffer(tokens.data, dtype=np.uint8)
    first_byte = buffer[tokens.starts]
    lead = np.r_[True, tokens.lines[1:] != tokens.lines[:-1]]  # first token of its line
    named = ((first_byte | 32) >= ord("a")) & ((first_byte | 32) <= ord("z")) | (
        first_byte == ord("_")
    )
    misplaced = np.flatnonzero(named & ~lead)
    if misplaced.size:
        k = misplaced[0]
        word = tokens.text(k)
        problem = "non-finite" if is_special(word) else "non-numeric"
        raise MotionFileError(path, int(tokens.lines[k]), f"{problem} value {word!r}")
    name_tokens = np.flatnonzero(named)
    joints = _joint_ids(tokens, name_tokens, skeleton)
    if (joints < 0).any():
        k = name_tokens[np.flatnonzero(joints < 0)[0]]
        raise MotionFileError(
            path, int(tokens.lines[k]), f"unknown bone {tokens.text(k)!r} (not in the skeleton)"
        )

    # Line structure: frame lines hold a lone number; bone lines a name and its values.
    lead_tokens = np.flatnonzero(lead)
    per_line = np.diff(np.r_[lead_tokens, len(tokens)])
    is_frame = ~named[lead_tokens]
    bad = np.flatnonzero(is_frame & (per_line != 1))
    if bad.size:
        line = int(tokens.lines[lead_tokens[bad[0]]])
        raise MotionFileError(path, line, "a frame number must stand alone on its line")
    starts, counts, rotations = _joint_table(skeleton)
    line_joint = np.full(len(lead_tokens), -1)
    line_joint[~is_frame] = joints
    expected = counts[line_joint[~is_frame]]
    bad = np.flatnonzero(per_line[~is_frame] - 1 != expected)
    if bad.size:
        k = lead_tokens[~is_frame][bad[0]]
        j = line_joint[~is_frame][bad[0]]
        raise MotionFileError(
            path,
            int(tokens.lines[k]),
            f"bone {skeleton.joints[j]!r} has {per_line[~is_frame][bad[0]] - 1} values, "
            f"but its dof has {counts[j]}",
        )

    # Frame numbers, and which frame each bone line belongs to.
    values = parse_floats(tokens, path, which=~named, rows=lead_tokens[is_frame])
    value_index = np.cumsum(~named) - 1  # position of each numeric token in ``values``
    frame_numbers = values[value_index[lead_tokens[is_frame]]]
    frame_lines = tokens.lines[lead_tokens[is_frame]]
    if len(frame_numbers) and not (frame_numbers[0] >= 0 and frame_numbers[0] % 1 == 0):
        raise MotionFileError(
            path, int(frame_lines[0]), f"frame number {frame_numbers[0]:g} is not a whole number"
        )
    steps = np.diff(frame_numbers)
    if (steps != 1).any():
        k = int(np.flatnonzero(steps != 1)[0]) + 1
        raise MotionFileError(
            path,
            int(frame_lines[k]),
            f"frame number {frame_numbers[k]:g} follows {frame_numbers[k - 1]:g}; "
            "frames must count up by one",
        )
    n_frames = len(frame_numbers)
    frame_of_line = np.cumsum(is_frame) - 1
    bone_frames = frame_of_line[~is_frame]
    bone_joints = line_joint[~is_frame]
    animated = np.flatnonzero(counts > 0)
    seen = np.bincount(
        bone_frames * skeleton.n_joints + bone_joints, minlength=n_frames * skeleton.n_joints
    )
    seen = seen.reshape(n_frames, skeleton.n_joints)
    wrong = seen[:, animated] != 1
    if wrong.any():
        f, a = np.argwhere(wrong)[0]
        what = "lacks" if seen[f, animated[a]] == 0 else "lists twice"
        raise MotionFileError(
            path,
            int(frame_lines[f]),
            f"frame {frame_numbers[f]:g} {what} bone {skeleton.joints[animated[a]]!r}"
            + (" (truncated file?)" if what == "lacks" and f == n_frames - 1 else ""),
        )

    # Scatter every bone line's values into its frame's row.
    line_count = counts[bone_joints]
    first_value = value_index[np.minimum(lead_tokens[~is_frame] + 1, len(tokens) - 1)]
    within = np.arange(line_count.sum()) - np.repeat(np.cumsum(line_count) - line_count, line_count)
    channels = np.empty((n_frames, skeleton.n_channels))
    rows = np.repeat(bone_frames, line_count)
    cols = np.repeat(starts[bone_joints], line_count) + within
    channels[rows, cols] = values[np.repeat(first_value, line_count) + within]
    if unit != "rad":
        channels[:, rotations] = np.deg2rad(channels[:, rotations])
    return Motion(skeleton, channels, frame_rate=frame_rate, source=str(path))
