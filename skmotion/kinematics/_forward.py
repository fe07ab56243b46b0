"""Forward kinematics: all joints, all frames, in one compiled pass."""

from collections import namedtuple
from functools import lru_cache

import numpy as np

from skmotion.kinematics._forward_loops import forward_pass

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
    """Which channel drives each joint's rotation slots and offset, once per skeleton."""
    n_joints = skeleton.n_joints
    rotation_column = np.full((n_joints, 3), -1, dtype=np.intp)
    position_column = np.full((n_joints, 3), -1, dtype=np.intp)
    column = 0
    for j, names in enumerate(skeleton.channels):
        for name in names:
            if name.endswith("rotation"):
                rotation_column[j, skeleton.rotation_orders[j].index(name[0])] = column
            else:
                position_column[j, "XYZ".index(name[0])] = column
            column += 1
    axes = np.zeros((n_joints, 3, 3)) if skeleton.axes is None else skeleton.axes
    return {
        "rotation_column": rotation_column,
        "axis_of_slot": np.array(
            [["XYZ".index(a) for a in skeleton.rotation_orders[j]] for j in range(n_joints)],
            dtype=np.intp,
        ).reshape(n_joints, 3),
        "position_column": position_column,
        "offsets": np.ascontiguousarray(skeleton.offsets, dtype=float),
        "axes": np.ascontiguousarray(axes, dtype=float),
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

    One compiled pass: each frame walks the joints in index order (parents
    first), building each local rotation from its Euler angles and composing it
    with its parent's world pose.

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
    rotations = np.empty((n_frames, n_joints, 3, 3))
    positions = np.empty((n_frames, n_joints, 3))
    forward_pass(
        np.ascontiguousarray(channels),
        plan["rotation_column"],
        plan["axis_of_slot"],
        plan["position_column"],
        plan["offsets"],
        plan["axes"],
        skeleton.axes is not None,
        plan["parents"],
        rotations,
        positions,
    )
    return FKResult(positions, rotations)
