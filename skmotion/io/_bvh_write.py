"""Writing BVH files."""

import numpy as np

from skmotion.io._atomic import atomic_writer
from skmotion.io._motion import Motion
from skmotion.kinematics import euler_to_matrix, matrix_to_euler

__all__ = ["write_bvh"]


def _rotation_axes(channels):
    return [c[0] for c in channels if c.endswith("rotation")]


def _joint_plan(skeleton):
    """Per joint: the channels to write, and how to get their values.

    BVH has no bone axis and takes the rotation order from the order of the
    rotation channels. A joint whose rotation channels already follow its
    rotation order is written as it is (values reordered only); a joint with a
    bone axis ``C`` (ASF) gets three rotation channels holding the Euler
    angles of its whole local rotation ``C @ M @ C.T``.
    """
    plan = []
    column = 0
    for j, channels in enumerate(skeleton.channels):
        order = skeleton.rotation_orders[j]
        columns = {c: column + k for k, c in enumerate(channels)}
        column += len(channels)
        positions = [c for c in channels if c.endswith("position")]
        axes = _rotation_axes(channels)
        has_axis = skeleton.axes is not None and not np.allclose(
            skeleton.axes[j], np.eye(3), atol=1e-12
        )
        if axes and has_axis:
            rotations = [f"{a}rotation" for a in order]
            mode = "matrix"
        else:
            rotations = [f"{a}rotation" for a in order if a in axes]
            mode = "copy"
        # Channels already in rotation order are written as listed (positions may come last).
        verbatim = mode == "copy" and [f"{a}rotation" for a in axes] == rotations
        plan.append(
            {
                "written": list(channels) if verbatim else positions + rotations,
                "sources": [columns[c] for c in channels]
                if verbatim
                else [columns[c] for c in positions]
                + ([] if mode == "matrix" else [columns[c] for c in rotations]),
                "mode": mode,
                "angles": [columns.get(f"{a}rotation") for a in order],
            }
        )
    return plan


def _preorder(skeleton):
    """Joints in the depth-first order in which BVH lists them (and their channels)."""
    order, stack = [], [0]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(skeleton.children(j)))
    return order


def _values(skeleton, channels, plan):
    """The channel table to write, in hierarchy order, angles in degrees."""
    blocks = []
    for j in _preorder(skeleton):
        step = plan[j]
        if step["mode"] == "copy":
            block = channels[:, step["sources"]].copy()
            angles = [c.endswith("rotation") for c in step["written"]]
            block[:, angles] = np.rad2deg(block[:, angles])
        else:
            angles = np.zeros((len(channels), 3))
            for k, col in enumerate(step["angles"]):
                if col is not None:
                    angles[:, k] = channels[:, col]
            order = skeleton.rotation_orders[j]
            axis = skeleton.axes[j]
            local = axis @ euler_to_matrix(angles, order) @ axis.T
            block = np.hstack(
                [channels[:, step["sources"]], np.rad2deg(matrix_to_euler(local, order))]
            )
        blocks.append(block)
    return np.hstack(blocks) if blocks else np.empty((len(channels), 0))


def _end_site_names(skeleton):
    """Joints to write as ``End Site``: channel-less leaves whose name read_bvh would give.

    read_bvh names an End Site ``<parent>_end`` (``_end2``, ... when taken); any other
    channel-less leaf is written as a JOINT with ``CHANNELS 0`` so it keeps its name.
    """
    sites, seen = set(), set()
    for j in _preorder(skeleton):
        name = skeleton.joints[j]
        if j and not skeleton.channels[j] and not skeleton.children(j):
            parent = skeleton.joints[skeleton.parents[j]]
            expected, suffix = f"{parent}_end", 2
            while expected in seen:
                expected, suffix = f"{parent}_end{suffix}", suffix + 1
            if name == expected:
                sites.add(j)
        seen.add(name)
    return sites


def _hierarchy(skeleton, plan, number):
    """The HIERARCHY lines, written with an explicit stack (any depth)."""
    lines = ["HIERARCHY"]
    sites = _end_site_names(skeleton)
    stack = [(0, 0, False)]
    while stack:
        j, depth, closing = stack.pop()
        pad = "  " * min(depth, 32)  # deep chains: indentation is capped, not the depth
        if closing:
            lines.append(f"{pad}}}")
            continue
        offset = " ".join(number(v) for v in skeleton.offsets[j])
        if j in sites:
            lines.extend([f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET {offset}", f"{pad}}}"])
            continue
        written = plan[j]["written"]
        lines.extend(
            [
                f"{pad}{'ROOT' if j == 0 else 'JOINT'} {skeleton.joints[j]}",
                f"{pad}{{",
                f"{pad}  OFFSET {offset}",
                f"{pad}  CHANNELS {len(written)}" + "".join(f" {c}" for c in written),
            ]
        )
        stack.append((j, depth, True))
        stack.extend((child, depth + 1, False) for child in reversed(skeleton.children(j)))
    return lines


def _check_names(skeleton):
    """Names read_bvh reads back verbatim: a line's rest, no braces or blanks at the ends."""
    for j, name in enumerate(skeleton.joints):
        problem = None
        if not name.strip(" \t"):
            problem = "is empty"
        elif name != name.strip(" \t"):
            problem = "starts or ends with a blank"
        elif "{" in name or "}" in name:
            problem = "contains a brace"
        elif any(ord(c) < 32 or ord(c) == 127 for c in name if c != "\t"):
            problem = "contains a line break or a control character"
        if problem:
            raise ValueError(
                f"Joint {j} name {name!r} {problem}: BVH cannot store it (read_bvh takes a "
                "joint's name as the rest of its line)."
            )


def _check_values(values, names):
    """Every value to write is finite (in the file's unit: degrees for angles)."""
    if not len(values):
        raise ValueError("The motion has no frames: a BVH file needs at least one.")
    if not values.shape[1]:
        raise ValueError("The skeleton has no channels: a BVH file needs at least one.")
    bad = ~np.isfinite(values)
    if bad.any():
        frame, column = np.argwhere(bad)[0]
        raise ValueError(
            f"Frame {frame}, channel {names[column]!r} is {float(values[frame, column])!r} "
            "when written "
            f"({int(bad.sum())} non-finite values): BVH files hold finite numbers only."
        )


def _written_names(skeleton, plan):
    return [f"{skeleton.joints[j]}_{c}" for j in _preorder(skeleton) for c in plan[j]["written"]]


def _write_frames(fh, values, fmt):
    """The frame lines (a function of its own so tests can make it fail midway)."""
    np.savetxt(fh, values, fmt=fmt, delimiter=" ")


def write_bvh(motion, path, *, precision=None):
    """Write a Motion as a BVH file.

    Angles are written in degrees. Joints of skeletons with bone axes (read
    from ASF) are written with three rotation channels holding their whole
    local rotation, so the written file poses every joint exactly as the
    motion does. End sites (joints with neither channels nor children) named
    as :func:`read_bvh` names them (``<parent>_end``) become ``End Site``
    blocks; other channel-less leaves are written as joints with
    ``CHANNELS 0``, so every name reads back unchanged.

    The file is written to a temporary name in the same folder and renamed
    over ``path`` at the end: an interrupted write (disk full, an exception)
    leaves any previous file intact.

    Parameters
    ----------
    motion : Motion
        The motion to write.
    path : str or path-like
        The file to create (overwritten if it exists).
    precision : int, default=None
        Decimals of the written values; ``None`` writes every value with 17
        significant digits, so that reading the file back gives the channels
        to within rounding of the degree conversion.

    Raises
    ------
    ValueError
        Before anything is written, for what BVH cannot store or read_bvh would
        read back differently: an empty joint name, one with a brace, a line
        break or blanks at its ends (spaces inside a name are kept); a NaN or
        infinite channel value (naming its frame and channel); no frames; no
        channels.
    PermissionError
        ``path`` is a read-only file: it is not overwritten (write elsewhere,
        or make it writable first).
    OSError
        The folder is missing or not writable, the disk is full, ...; the
        message names ``path``. ``path`` keeps its old content. A symlink is
        written through: its target gets the new content.

    See Also
    --------
    read_bvh : the inverse.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import Motion, read_bvh, write_bvh
    >>> data = make_motions(n_clips_per_class=1, classes=["wave"], random_state=0)
    >>> motion = Motion(data.skeletons[0], data.clips[0], frame_rate=data.frame_rate)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "wave.bvh")
    ...     write_bvh(motion, path)
    ...     back = read_bvh(path)
    >>> bool(np.allclose(back.channels, motion.channels)), back.frame_rate
    (True, 30.0)
    """
    if not isinstance(motion, Motion):
        raise TypeError(f"motion must be a Motion, got {type(motion).__name__}.")
    if precision is not None and (int(precision) != precision or precision < 0):
        raise ValueError(f"precision must be a non-negative integer or None, got {precision!r}.")
    fmt = "%.17g" if precision is None else f"%.{int(precision)}f"
    skeleton = motion.skeleton
    _check_names(skeleton)
    plan = _joint_plan(skeleton)
    with np.errstate(over="ignore", invalid="ignore"):
        values = _values(skeleton, motion.channels, plan)
    _check_values(values, _written_names(skeleton, plan))
    frame_time = 1.0 / motion.frame_rate
    if not np.isfinite(frame_time) or not frame_time > 0:
        raise ValueError(f"frame_rate {motion.frame_rate!r} has no finite positive frame time.")
    lines = _hierarchy(skeleton, plan, lambda v: fmt % v)
    lines += ["MOTION", f"Frames: {motion.n_frames}", f"Frame Time: {frame_time!r}"]
    with atomic_writer(path) as fh:
        fh.write("\n".join(lines) + "\n")
        _write_frames(fh, values, fmt)
