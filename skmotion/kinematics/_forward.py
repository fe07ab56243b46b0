"""Batched forward kinematics: all joints, all frames, no loop over frames."""

from collections import namedtuple
from functools import lru_cache

import numpy as np

from skmotion.kinematics._rotations import euler_to_matrix

__all__ = ["FKResult", "forward_kinematics"]

FKResult = namedtuple("FKResult", ["positions", "rotations"])
FKResult.__doc__ = """World pose of every joint in every frame.

Attributes
----------
positions : ndarray of shape (n_frames, n_joints, 3)
    Joint positions in the world frame, in the skeleton's length unit.
rotations : ndarray of shape (n_frames, n_joints, 3, 3)
    Joint orientations in the world frame (the rotation that turns the joint's
    children); column vectors, ``world = R @ local``.
"""


@lru_cache(maxsize=64)
def _channel_plan(skeleton):
    """Where each channel column goes, computed once per skeleton."""
    rot_cols, rot_joints, rot_slots = [], [], []
    pos_cols, pos_joints, pos_axes = [], [], []
    col = 0
    for j, chans in enumerate(skeleton.channels):
        order = skeleton.rotation_orders[j]
        for c in chans:
            axis = c[0]
            if c.endswith("rotation"):
                rot_cols.append(col)
                rot_joints.append(j)
                rot_slots.append(order.index(axis))
            else:
                pos_cols.append(col)
                pos_joints.append(j)
                pos_axes.append("XYZ".index(axis))
            col += 1
    rotating = sorted(set(rot_joints))
    by_order = {}
    for j in rotating:
        by_order.setdefault(skeleton.rotation_orders[j], []).append(j)
    depths = skeleton.depths
    levels = [np.flatnonzero(depths == d) for d in range(1, int(depths.max()) + 1)]
    as_idx = lambda v: np.asarray(v, dtype=np.intp)  # noqa: E731
    return {
        "rot": (as_idx(rot_cols), as_idx(rot_joints), as_idx(rot_slots)),
        "pos": (as_idx(pos_cols), as_idx(pos_joints), as_idx(pos_axes)),
        "by_order": {o: as_idx(js) for o, js in by_order.items()},
        "levels": levels,
        "parents": np.asarray(skeleton.parents, dtype=np.intp),
    }


def _check_channels(skeleton, channels):
    channels = np.asarray(channels, dtype=float)
    if channels.ndim == 1:
        channels = channels[None, :]
    if channels.ndim != 2 or channels.shape[1] != skeleton.n_channels:
        raise ValueError(
            f"channels must have shape (n_frames, {skeleton.n_channels}) for this "
            f"skeleton; got {channels.shape}."
        )
    return channels


def forward_kinematics(skeleton, channels):
    """World positions and rotations of every joint for every frame.

    Local rotations are built per rotation order in one vectorised call each;
    world poses are composed one tree level at a time, so the only Python loops
    run over rotation orders and tree depth, never over frames.

    Parameters
    ----------
    skeleton : Skeleton
        The joint hierarchy.
    channels : array-like of shape (n_frames, n_channels)
        One clip's channels (angles in radians), in ``skeleton.channel_names``
        order. A 1-D array is one frame.

    Returns
    -------
    result : FKResult
        ``positions`` of shape (n_frames, n_joints, 3) and ``rotations`` of
        shape (n_frames, n_joints, 3, 3), both in the world frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import Skeleton, forward_kinematics
    >>> arm = Skeleton(["shoulder", "elbow", "hand"], [-1, 0, 1],
    ...                [[0, 0, 0], [1, 0, 0], [1, 0, 0]],
    ...                [["Zrotation"], ["Zrotation"], []])
    >>> fk = forward_kinematics(arm, [[np.pi / 2, -np.pi / 2]])
    >>> fk.positions[0].round(6) + 0.0
    array([[0., 0., 0.],
           [0., 1., 0.],
           [1., 1., 0.]])
    """
    channels = _check_channels(skeleton, channels)
    plan = _channel_plan(skeleton)
    n_frames, n_joints = channels.shape[0], skeleton.n_joints

    # Joint-major arrays, (n_joints, n_frames, ...): a tree level is then a gather
    # of whole per-joint blocks rather than a strided gather across frames.
    angles = np.zeros((n_joints, n_frames, 3))
    cols, joints, slots = plan["rot"]
    angles[joints, :, slots] = channels[:, cols].T
    local = np.empty((n_joints, n_frames, 3, 3))
    local[:] = np.eye(3)
    for order, idx in plan["by_order"].items():
        local[idx] = euler_to_matrix(angles[idx], order)
    if skeleton.axes is not None:
        axes = np.asarray(skeleton.axes)[:, None]
        local = axes @ local @ np.swapaxes(axes, -1, -2)

    translations = np.empty((n_joints, n_frames, 3))
    translations[:] = np.asarray(skeleton.offsets)[:, None, :]
    cols, joints, axis = plan["pos"]
    translations[joints, :, axis] = channels[:, cols].T

    rotations = np.empty_like(local)
    positions = np.empty_like(translations)
    rotations[0] = local[0]
    positions[0] = translations[0]
    parents = plan["parents"]
    for idx in plan["levels"]:
        parent_rot = rotations[parents[idx]]
        rotations[idx] = parent_rot @ local[idx]
        positions[idx] = (
            positions[parents[idx]] + (parent_rot @ translations[idx][..., None])[..., 0]
        )
    positions = np.ascontiguousarray(positions.transpose(1, 0, 2))
    rotations = np.ascontiguousarray(rotations.transpose(1, 0, 2, 3))
    return FKResult(positions, rotations)
