"""Marker-set presets: the same 32 marker names on four skeleton families.

Each preset places every marker of :data:`MARKER_NAMES` on the joints of one
skeleton family. Offsets are derived from the skeleton's own bone vectors
(a point part-way along a bone), so a preset follows the size of each
subject. Clips of different skeletons then share one feature space.
"""

import numpy as np

from skmotion.kinematics._joint_matching import match_joints
from skmotion.kinematics._marker_names import MARKER_NAMES
from skmotion.preprocessing._marker_matching import matched_marker_set
from skmotion.preprocessing._marker_set import MarkerSet

__all__ = ["MARKER_NAMES", "MARKER_PRESETS", "detect_marker_preset", "marker_preset"]


# Marker specs. ("at", j): the joint's position. ("along", j, child, t): t of the way
# along the bone from j to its child. ("beyond", j, t, ref): past j, continuing the
# bone that ends at j, by t times the length of the bone ending at ``ref`` (for a
# head top on skeletons without a head end site; their bones run along the
# parent-to-joint direction in the joint's frame).
def _limbs(joint, side):
    """The 13 per-side specs from a joint-name function ``joint(part, side)``."""
    j = lambda part: joint(part, side)  # noqa: E731
    return {
        "clavicle": ("along", j("clavicle"), j("shoulder"), 0.5),
        "shoulder": ("at", j("shoulder")),
        "upper_arm": ("along", j("shoulder"), j("elbow"), 0.5),
        "elbow": ("at", j("elbow")),
        "forearm": ("along", j("elbow"), j("wrist"), 0.5),
        "wrist": ("at", j("wrist")),
        "hand": j("hand"),
        "hip": ("at", j("hip")),
        "thigh": ("along", j("hip"), j("knee"), 0.5),
        "knee": ("at", j("knee")),
        "shin": ("along", j("knee"), j("ankle"), 0.5),
        "ankle": ("at", j("ankle")),
        "toe": ("at", j("toe")),
    }


_CMU_PARTS = {
    "clavicle": "clavicle",
    "shoulder": "humerus",
    "elbow": "radius",
    "wrist": "wrist",
    "hip": "femur",
    "knee": "tibia",
    "ankle": "foot",
    "toe": "toes",
}


def _cmu(part, side):
    s = side[0]
    if part == "hand":
        return ("at", f"{s}hand")
    return f"{s}{_CMU_PARTS[part]}"


_CC_PARTS = {
    "clavicle": "Clavicle",
    "shoulder": "Upperarm",
    "elbow": "Forearm",
    "wrist": "Hand",
    "hip": "Thigh",
    "knee": "Calf",
    "ankle": "Foot",
    "toe": "ToeBase",
}


def _cc(part, side):
    s = side[0].upper()
    if part == "hand":
        return ("at", f"CC_Base_{s}_Mid1")
    return f"CC_Base_{s}_{_CC_PARTS[part]}"


_BVH_PARTS = {
    "clavicle": "Shoulder",
    "shoulder": "Arm",
    "elbow": "ForeArm",
    "wrist": "Hand",
    "hip": "UpLeg",
    "knee": "Leg",
    "ankle": "Foot",
}


def _common_bvh(part, side):
    s = side.capitalize()
    if part == "hand":
        return ("at", f"{s}Hand_End")
    if part == "toe":
        return f"{s}ToeBase"
    return f"{s}{_BVH_PARTS[part]}"


def _humanoid(part, side):
    s = side.capitalize()
    if part == "hand":
        return ("along", f"{s}Hand", f"{s}Hand_end", 0.5)
    if part == "toe":
        return f"{s}Toe"
    return f"{s}{_BVH_PARTS[part]}"


def _table(centre, joint):
    specs = dict(centre)
    for side in ("left", "right"):
        specs.update({f"{side}_{part}": spec for part, spec in _limbs(joint, side).items()})
    return specs


_PRESETS = {
    "cmu_asf": _table(
        {
            "head_top": ("at", "head_end"),
            "head": ("along", "head", "head_end", 0.5),
            "neck": ("at", "head"),
            "chest": ("at", "lowerneck"),
            "spine": ("along", "upperback", "thorax", 0.5),
            "pelvis": ("at", "root"),
        },
        _cmu,
    ),
    "character_creator": _table(
        {
            "head_top": ("beyond", "CC_Base_Head", 0.375, "CC_Base_NeckTwist01"),
            "head": ("beyond", "CC_Base_Head", 0.19, "CC_Base_NeckTwist01"),
            "neck": ("at", "CC_Base_Head"),
            "chest": ("along", "CC_Base_Spine02", "CC_Base_NeckTwist01", 0.75),
            "spine": ("at", "CC_Base_Spine02"),
            "pelvis": ("at", "CC_Base_Hip"),
        },
        _cc,
    ),
    "common_bvh": _table(
        {
            "head_top": ("at", "Head_end"),
            "head": ("along", "Head", "Head_end", 0.5),
            "neck": ("at", "Head"),
            "chest": ("at", "LeftShoulder"),
            "spine": ("at", "Spine"),
            "pelvis": ("at", "Hips"),
        },
        _common_bvh,
    ),
    "humanoid": _table(
        {
            "head_top": ("at", "Head_end"),
            "head": ("along", "Head", "Head_end", 0.5),
            "neck": ("at", "Head"),
            "chest": ("at", "Neck"),
            "spine": ("at", "Chest"),
            "pelvis": ("at", "Hips"),
        },
        _humanoid,
    ),
}
#: Preset names, in the order :func:`detect_marker_preset` tries them; ``"matched"`` places
#: the markers on the joints :func:`~skmotion.kinematics.match_joints` finds (any humanoid).
MARKER_PRESETS = ("cmu_asf", "character_creator", "humanoid", "common_bvh", "matched")


def _spec_joints(spec):
    kind = spec[0]
    if kind == "at":
        return [spec[1]]
    if kind == "along":
        return [spec[1], spec[2]]
    return [spec[1], spec[3]]


def _required_joints(preset):
    return {j for spec in _PRESETS[preset].values() for j in _spec_joints(spec)}


def detect_marker_preset(skeleton):
    """The name of the first preset whose joints the skeleton has all of.

    A skeleton of no known family gets ``"matched"`` when
    :func:`~skmotion.kinematics.match_joints` finds its head, trunk and
    limbs by joint names and topology.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    preset : str
        One of :data:`MARKER_PRESETS`.

    Raises
    ------
    ValueError
        When no preset fits and the matcher finds no humanoid; give a
        :class:`MarkerSet` then.

    Examples
    --------
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.preprocessing import detect_marker_preset
    >>> detect_marker_preset(humanoid_skeleton())
    'humanoid'
    """
    joints = set(skeleton.joints)
    tables = [p for p in MARKER_PRESETS if p in _PRESETS]
    for preset in tables:
        if _required_joints(preset) <= joints:
            return preset
    try:
        match_joints(skeleton)
    except ValueError as exc:
        raise ValueError(f"No marker preset fits this skeleton: {exc}") from None
    return "matched"


def _offset(skeleton, spec):
    kind = spec[0]
    if kind == "at":
        return spec[1], np.zeros(3)
    if kind == "along":
        joint, child, fraction = spec[1:]
        if skeleton.parents[skeleton.joint_index(child)] != skeleton.joint_index(joint):
            raise ValueError(
                f"Marker preset: {child!r} is not a child of {joint!r} in this skeleton."
            )
        return joint, fraction * np.asarray(skeleton.offsets[skeleton.joint_index(child)])
    joint, fraction, reference = spec[1:]
    bone = np.asarray(skeleton.offsets[skeleton.joint_index(joint)])
    length = np.linalg.norm(skeleton.offsets[skeleton.joint_index(reference)])
    return joint, fraction * length * bone / np.linalg.norm(bone)


def marker_preset(skeleton, preset=None):
    """The 32 standard markers (:data:`MARKER_NAMES`) placed on a skeleton.

    Parameters
    ----------
    skeleton : Skeleton
        A skeleton of one of the preset families: the CMU ASF skeleton
        (``cmu_asf``), the Character Creator ``CC_Base_*`` skeleton
        (``character_creator``), the built-in humanoid (``humanoid``) or the
        common ``Hips/Spine/LeftUpLeg`` BVH naming (``common_bvh``); any
        other humanoid through the joint matcher (``matched``).
    preset : str, default=None
        The preset; by default detected from the joint names
        (:func:`detect_marker_preset`).

    Returns
    -------
    markers : MarkerSet
        Offsets follow the skeleton's bone lengths.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.preprocessing import marker_preset
    >>> sk = humanoid_skeleton()
    >>> markers = marker_preset(sk)
    >>> len(markers), markers.names[:4]
    (32, ('head_top', 'head', 'neck', 'chest'))
    >>> rest = markers.positions(sk, np.zeros((1, sk.n_channels)))[0]
    >>> knee, ankle = markers.names.index("left_knee"), markers.names.index("left_ankle")
    >>> round(float(rest[knee, 1] - rest[ankle, 1]), 6)  # the shin, in metres
    0.4
    """
    if preset is None:
        preset = detect_marker_preset(skeleton)
    if preset == "matched":
        return matched_marker_set(skeleton, match_joints(skeleton))
    if preset not in _PRESETS:
        raise ValueError(
            f"Unknown marker preset {preset!r}; expected one of {list(MARKER_PRESETS)}."
        )
    specs = _PRESETS[preset]
    missing = sorted(_required_joints(preset) - set(skeleton.joints))
    if missing:
        raise ValueError(
            f"Marker preset {preset!r} needs joints {missing} that the skeleton does not have."
        )
    return MarkerSet([(name, *_offset(skeleton, specs[name])) for name in MARKER_NAMES])
