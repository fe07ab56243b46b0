"""Writing BVH files."""

import numpy as np

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
        plan.append(
            {
                "written": positions + rotations,
                "sources": [columns[c] for c in positions]
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
        n_pos = sum(c.endswith("position") for c in step["written"])
        if step["mode"] == "copy":
            block = channels[:, step["sources"]].copy()
            block[:, n_pos:] = np.rad2deg(block[:, n_pos:])
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


def _hierarchy(skeleton, plan, number):
    lines = ["HIERARCHY"]
    children = [skeleton.children(j) for j in range(skeleton.n_joints)]

    def write(j, depth):
        pad = "  " * depth
        offset = " ".join(number(v) for v in skeleton.offsets[j])
        if not children[j] and not skeleton.channels[j] and j != 0:
            lines.extend([f"{pad}End Site", f"{pad}{{", f"{pad}  OFFSET {offset}", f"{pad}}}"])
            return
        keyword = "ROOT" if j == 0 else "JOINT"
        written = plan[j]["written"]
        lines.extend(
            [
                f"{pad}{keyword} {skeleton.joints[j]}",
                f"{pad}{{",
                f"{pad}  OFFSET {offset}",
                f"{pad}  CHANNELS {len(written)}" + "".join(f" {c}" for c in written),
            ]
        )
        for child in children[j]:
            write(child, depth + 1)
        lines.append(f"{pad}}}")

    write(0, 0)
    return lines


def write_bvh(motion, path, *, precision=None):
    """Write a Motion as a BVH file.

    Angles are written in degrees. Joints of skeletons with bone axes (read
    from ASF) are written with three rotation channels holding their whole
    local rotation, so the written file poses every joint exactly as the
    motion does. End sites (joints with neither channels nor children) become
    ``End Site`` blocks.

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
    plan = _joint_plan(skeleton)
    values = _values(skeleton, motion.channels, plan)
    lines = _hierarchy(skeleton, plan, lambda v: fmt % v)
    lines += ["MOTION", f"Frames: {motion.n_frames}", f"Frame Time: {1.0 / motion.frame_rate!r}"]
    with open(path, "w", newline="\n") as fh:
        fh.write("\n".join(lines) + "\n")
        np.savetxt(fh, values, fmt=fmt, delimiter=" ")
