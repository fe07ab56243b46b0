"""The 32 standard markers on any humanoid, from the joints the matcher found.

:func:`~skmotion.kinematics.match_joints` says which joint is the head, the
chest, each shoulder, knee, ...; here every marker of :data:`MARKER_NAMES`
gets the same place as in the fixed presets (at a joint, half way along a
bone, past the head), computed in the rest pose and stored in the carrying
joint's frame, so it follows the subject's size and the rig's own axes.
"""

import numpy as np

from skmotion.kinematics import forward_kinematics
from skmotion.kinematics._marker_names import MARKER_NAMES
from skmotion.preprocessing._marker_set import MarkerSet

__all__ = ["matched_marker_set"]


def _places(roles):
    """Per marker: (carrying role, target) with target ("at", role), ("mid", a, b) or
    ("past", role, fraction) (past the joint along the bone that ends there)."""
    base = "neck_base" if "neck_base" in roles else "chest"
    places = {
        "head_top": ("head", ("at", "head_end"))
        if "head_end" in roles
        else ("head", ("past", "head", 0.5)),
        "head": ("head", ("mid", "head", "head_end"))
        if "head_end" in roles
        else ("head", ("past", "head", 0.25)),
        "neck": ("head", ("at", "head")),
        "chest": (base, ("at", base)),
        "spine": ("spine", ("at", "spine"))
        if roles.get("spine") not in (None, roles["pelvis"])
        else ("pelvis", ("mid", "pelvis", base)),
        "pelvis": ("pelvis", ("at", "pelvis")),
    }
    for s in ("left", "right"):
        clavicle = f"{s}_clavicle" if f"{s}_clavicle" in roles else "chest"
        hand = ("at", f"{s}_hand_end") if f"{s}_hand_end" in roles else ("past", f"{s}_wrist", 0.3)
        toe = ("at", f"{s}_toe") if f"{s}_toe" in roles else ("past", f"{s}_ankle", 0.3)
        places.update(
            {
                f"{s}_clavicle": (clavicle, ("mid", clavicle, f"{s}_shoulder")),
                f"{s}_shoulder": (f"{s}_shoulder", ("at", f"{s}_shoulder")),
                f"{s}_upper_arm": (f"{s}_shoulder", ("mid", f"{s}_shoulder", f"{s}_elbow")),
                f"{s}_elbow": (f"{s}_elbow", ("at", f"{s}_elbow")),
                f"{s}_forearm": (f"{s}_elbow", ("mid", f"{s}_elbow", f"{s}_wrist")),
                f"{s}_wrist": (f"{s}_wrist", ("at", f"{s}_wrist")),
                f"{s}_hand": (f"{s}_wrist", hand),
                f"{s}_hip": (f"{s}_hip", ("at", f"{s}_hip")),
                f"{s}_thigh": (f"{s}_hip", ("mid", f"{s}_hip", f"{s}_knee")),
                f"{s}_knee": (f"{s}_knee", ("at", f"{s}_knee")),
                f"{s}_shin": (f"{s}_knee", ("mid", f"{s}_knee", f"{s}_ankle")),
                f"{s}_ankle": (f"{s}_ankle", ("at", f"{s}_ankle")),
                f"{s}_toe": (f"{s}_ankle", toe),
            }
        )
    return places


def matched_marker_set(skeleton, match):
    """The 32 markers of :data:`MARKER_NAMES` on the joints of ``match``.

    Parameters
    ----------
    skeleton : Skeleton
    match : JointMatch
        From :func:`~skmotion.kinematics.match_joints` on ``skeleton``.

    Returns
    -------
    markers : MarkerSet

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.kinematics import match_joints
    >>> from skmotion.preprocessing import marker_preset
    >>> from skmotion.preprocessing._marker_matching import matched_marker_set
    >>> sk = humanoid_skeleton()
    >>> matched = matched_marker_set(sk, match_joints(sk))
    >>> preset = marker_preset(sk, "humanoid")
    >>> rest = np.zeros((1, sk.n_channels))
    >>> moved = np.abs(matched.positions(sk, rest) - preset.positions(sk, rest)).max(axis=2)[0]
    >>> [(name, round(float(d), 2)) for name, d in zip(matched.names, moved) if d > 1e-9]
    [('left_hand', 0.09), ('right_hand', 0.09)]
    """
    index = {role: skeleton.joint_index(joint) for role, joint in match.roles.items()}
    fk = forward_kinematics(skeleton, np.zeros((1, skeleton.n_channels)))
    positions, rotations = fk.positions[0], fk.rotations[0]
    parents = skeleton.parents

    def point(target):
        if target[0] == "at":
            return positions[index[target[1]]]
        if target[0] == "mid":
            return 0.5 * (positions[index[target[1]]] + positions[index[target[2]]])
        j = index[target[1]]
        bone = positions[j] - positions[parents[j]] if parents[j] >= 0 else np.zeros(3)
        return positions[j] + target[2] * bone

    markers = []
    for name in MARKER_NAMES:
        role, target = _places(match.roles)[name]
        j = index[role]
        offset = rotations[j].T @ (point(target) - positions[j])
        markers.append((name, skeleton.joints[j], np.where(np.abs(offset) < 1e-12, 0.0, offset)))
    return MarkerSet(markers)
