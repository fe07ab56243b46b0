"""What a stick figure needs, from any description of a body: joint positions and bones.

A body is given in one of three ways:

- a :class:`~skmotion.kinematics.Skeleton` with joint-angle frames (its channels):
  positions come from forward kinematics;
- a layout: any object with joint names (``joints``, ``joint_names`` or ``names``)
  and either ``parents`` (one parent index per joint, -1 for a root) or ``bones``
  (pairs of joint names or indices), with frames of joint positions;
- nothing but ``bones`` (or ``parents``) as arrays, with frames of joint positions.

Frames of positions are ``(n_joints, d)`` for one pose or ``(n_frames, n_joints, d)``,
or flat ``(n_joints * d,)`` / ``(n_frames, n_joints * d)`` as a clip stores them,
with ``d`` 2 or 3.
"""

from dataclasses import dataclass

import numpy as np

_NAME_ATTRIBUTES = ("joints", "joint_names", "names")
_AXES = "xyz"


@dataclass(frozen=True)
class BodyFrames:
    """Joint positions of some frames and the bones joining them.

    Attributes
    ----------
    positions : ndarray of shape (n_frames, n_joints, d)
    bones : ndarray of int of shape (n_bones, 2)
        Pairs of joint indices (parent, child).
    names : list of str
    up : int or None
        Index of the up axis in 3-D (None in 2-D).
    unit : str
        The length unit for axis labels ("" when unknown).
    """

    positions: np.ndarray
    bones: np.ndarray
    names: list
    up: object
    unit: str


def _joint_names(body):
    for attribute in _NAME_ATTRIBUTES:
        names = getattr(body, attribute, None)
        if names is not None and not isinstance(names, str):
            return [str(n) for n in names]
    return None


def _bones_from_parents(parents, n_joints):
    parents = np.asarray(parents)
    if (
        parents.ndim != 1
        or len(parents) != n_joints
        or not np.issubdtype(parents.dtype, np.integer)
    ):
        raise ValueError(
            f"parents must hold one integer per joint ({n_joints}); got shape {parents.shape}."
        )
    bad = (parents < -1) | (parents >= n_joints)
    if bad.any():
        j = int(np.flatnonzero(bad)[0])
        raise ValueError(f"parents[{j}] = {parents[j]} is not a joint index in [-1, {n_joints}).")
    children = np.flatnonzero(parents >= 0)
    return np.column_stack([parents[children], children]).astype(np.intp)


def _bones_from_pairs(pairs, names, n_joints):
    out = []
    for k, pair in enumerate(pairs):
        if len(pair) != 2:
            raise ValueError(f"bone {k} is {pair!r}; a bone is a pair of joints.")
        ends = []
        for end in pair:
            if isinstance(end, str):
                if names is None or end not in names:
                    raise ValueError(f"bone {k} names joint {end!r}, which the body does not have.")
                ends.append(names.index(end))
            else:
                index = int(end)
                if not 0 <= index < n_joints:
                    raise ValueError(f"bone {k} joins joint {index}; joints are 0..{n_joints - 1}.")
                ends.append(index)
        out.append(ends)
    return np.asarray(out, dtype=np.intp).reshape(-1, 2)


def _as_frames(frames, n_joints, dims):
    """Positions as (n_frames, n_joints, d), from nested or flat frames."""
    array = np.asarray(frames, dtype=float)
    if array.ndim == 1:
        if n_joints is None or len(array) % n_joints:
            raise ValueError(
                f"a flat pose of {len(array)} values needs a body that names its joints."
            )
        array = array.reshape(1, n_joints, -1)
    if array.ndim == 2:
        one_pose = array.shape[1] in (2, 3) and (n_joints is None or len(array) == n_joints)
        if one_pose:
            array = array[None]
        elif n_joints is not None and array.shape[1] % n_joints == 0:
            array = array.reshape(len(array), n_joints, -1)  # flat frames, as a clip stores them
        else:
            raise ValueError(
                f"cannot read {array.shape} as joint positions: give (n_joints, d) for one pose, "
                "(n_frames, n_joints, d) for a clip, or a body that names its joints."
            )
    if array.ndim != 3 or array.shape[2] not in (2, 3):
        raise ValueError(
            f"joint positions must be (n_joints, 2 or 3) or (n_frames, n_joints, 2 or 3); "
            f"got shape {np.shape(frames)}."
        )
    if dims is not None and array.shape[2] != dims:
        raise ValueError(f"expected {dims}-D positions; got {array.shape[2]}-D.")
    if not np.isfinite(array).all():
        raise ValueError("joint positions contain NaN or infinity.")
    return array


def body_frames(frames, body=None, *, bones=None, up_axis=None):
    """Joint positions and bones for drawing, from a skeleton, a layout or plain arrays.

    Parameters
    ----------
    frames : array-like
        Joint angles (one frame or a clip) for a Skeleton, else joint positions.
    body : Skeleton, layout object, or None
        See the module docstring.
    bones : array-like, default=None
        Pairs of joints (names or indices), or one parent index per joint;
        needed when ``body`` has neither.
    up_axis : {"x", "y", "z"}, default=None
        The up axis of 3-D positions; by default the body's ``up_axis``, else "z".

    Returns
    -------
    BodyFrames
    """
    names = _joint_names(body) if body is not None else None
    unit = ""
    if body is not None and hasattr(body, "forward_kinematics") and hasattr(body, "channels"):
        channels = np.atleast_2d(np.asarray(frames, dtype=float))
        if channels.shape[1] != body.n_channels:
            raise ValueError(
                f"frames have {channels.shape[1]} channels; the skeleton has {body.n_channels}."
            )
        positions = body.forward_kinematics(channels).positions
        if not np.isfinite(positions).all():
            raise ValueError("joint angles contain NaN or infinity.")
        unit = "" if body.units in (None, "unknown") else str(body.units)
        if body.meters_per_unit:  # draw in metres whatever the file's unit
            positions, unit = positions * float(body.meters_per_unit), "m"
    else:
        n_joints = len(names) if names is not None else None
        if n_joints is None and bones is not None and np.ndim(bones) == 1:
            n_joints = len(bones)  # a parents array gives the joint count
        positions = _as_frames(frames, n_joints, None)
    n_joints = positions.shape[1]
    if names is None:
        names = [f"joint {j}" for j in range(n_joints)]
    if len(names) != n_joints:
        raise ValueError(f"the body names {len(names)} joints; the frames hold {n_joints}.")
    given = bones
    if given is None and body is not None:
        given = getattr(body, "bones", None)
        if given is None:
            given = getattr(body, "parents", None)
    if given is None:
        raise ValueError(
            "no bones: pass a Skeleton, a layout with parents or bones, or bones=[(a, b), ...]."
        )
    if np.ndim(given) == 1 and not isinstance(given[0], (tuple, list, np.ndarray)):
        bone_pairs = _bones_from_parents(given, n_joints)
    else:
        bone_pairs = _bones_from_pairs(given, names, n_joints)
    up = None
    if positions.shape[2] == 3:
        # a Skeleton names its up_axis, a layout its `up` (signed: "-y" for image-like y down)
        axis = up_axis or getattr(body, "up_axis", None) or getattr(body, "up", None) or "z"
        if axis.lstrip("-") not in _AXES:
            raise ValueError(f"up_axis must be 'x', 'y' or 'z'; got {axis!r}.")
        up = _AXES.index(axis.lstrip("-"))
        if axis.startswith("-"):
            positions = positions.copy()
            positions[:, :, up] *= -1
    return BodyFrames(positions, bone_pairs, names, up, unit)
