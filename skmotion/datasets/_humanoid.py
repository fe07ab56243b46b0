"""The built-in humanoid skeleton used by the synthetic motions."""

from skmotion.kinematics import Skeleton

__all__ = ["humanoid_skeleton"]

# (joint, parent, offset in metres for a 1.75 m adult, channels). Y is up, the
# figure faces +Z and its left side is +X. The rest pose stands with the arms
# hanging, so zero angles mean a neutral stance.
_ROT = ("Zrotation", "Xrotation", "Yrotation")
_ROOT = ("Xposition", "Yposition", "Zposition", "Yrotation", "Xrotation", "Zrotation")
_LAYOUT = [
    ("Hips", None, (0.0, 0.95, 0.0), _ROOT),
    ("Spine", "Hips", (0.0, 0.10, 0.0), _ROT),
    ("Chest", "Spine", (0.0, 0.20, 0.0), _ROT),
    ("Neck", "Chest", (0.0, 0.22, 0.0), _ROT),
    ("Head", "Neck", (0.0, 0.10, 0.0), _ROT),
    ("Head_end", "Head", (0.0, 0.18, 0.0), ()),
]
for _side, _x in (("Left", 1.0), ("Right", -1.0)):
    _LAYOUT += [
        (f"{_side}Shoulder", "Chest", (0.04 * _x, 0.17, 0.0), _ROT),
        (f"{_side}Arm", f"{_side}Shoulder", (0.15 * _x, 0.0, 0.0), _ROT),
        (f"{_side}ForeArm", f"{_side}Arm", (0.0, -0.29, 0.0), _ROT),
        (f"{_side}Hand", f"{_side}ForeArm", (0.0, -0.26, 0.0), _ROT),
        (f"{_side}Hand_end", f"{_side}Hand", (0.0, -0.18, 0.0), ()),
    ]
for _side, _x in (("Left", 1.0), ("Right", -1.0)):
    _LAYOUT += [
        (f"{_side}UpLeg", "Hips", (0.09 * _x, -0.05, 0.0), _ROT),
        (f"{_side}Leg", f"{_side}UpLeg", (0.0, -0.42, 0.0), _ROT),
        (f"{_side}Foot", f"{_side}Leg", (0.0, -0.40, 0.0), _ROT),
        (f"{_side}Toe", f"{_side}Foot", (0.0, -0.06, 0.12), _ROT),
        (f"{_side}Toe_end", f"{_side}Toe", (0.0, -0.02, 0.06), ()),
    ]


def humanoid_skeleton(scale=1.0):
    """The built-in 26-joint humanoid (21 with channels, 5 end sites), in metres.

    Y is up and the figure faces +Z. The root ``Hips`` has six channels
    (``Xposition Yposition Zposition Yrotation Xrotation Zrotation``, yaw first);
    every other joint has three rotations in intrinsic ``ZXY`` order, as in
    many BVH exports: 66 channels in all. At zero angles the figure stands with
    its arms hanging.

    Parameters
    ----------
    scale : float, default=1.0
        Multiplies every bone length; 1.0 is a 1.75 m adult.

    Returns
    -------
    skeleton : Skeleton

    Examples
    --------
    >>> from skmotion.datasets import humanoid_skeleton
    >>> sk = humanoid_skeleton()
    >>> sk.n_joints, sk.n_channels, round(sk.height(), 2)
    (26, 66, 1.75)
    """
    rows = _LAYOUT  # listed depth first, parents before children, as in a BVH file
    names = [r[0] for r in rows]
    return Skeleton(
        joints=names,
        parents=[-1 if r[1] is None else names.index(r[1]) for r in rows],
        offsets=[[scale * v for v in r[2]] for r in rows],
        channels=[r[3] for r in rows],
        units="m",
        meters_per_unit=1.0,
        up_axis="y",
    )
