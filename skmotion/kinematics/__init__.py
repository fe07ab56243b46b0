"""Kinematics: the Skeleton, position layouts, rotation conventions, batched forward kinematics."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.kinematics._body_size": ["body_size"],
        "skmotion.kinematics._forward": ["FKResult", "forward_kinematics"],
        "skmotion.kinematics._joint_matching": ["JointMatch", "match_joints"],
        "skmotion.kinematics._layout_check": ["check_layout"],
        "skmotion.kinematics._layouts": ["Layout"],
        "skmotion.kinematics._marker_names": ["MARKER_NAMES"],
        "skmotion.kinematics._named_layouts": ["LAYOUTS", "get_layout"],
        "skmotion.kinematics._rotations": [
            "check_rotation_order",
            "euler_to_matrix",
            "matrix_to_euler",
            "yaw_matrix",
        ],
        "skmotion.kinematics._skeleton": ["CHANNEL_KINDS", "Skeleton"],
    },
)

__all__ = [
    "CHANNEL_KINDS",
    "FKResult",
    "JointMatch",
    "LAYOUTS",
    "Layout",
    "MARKER_NAMES",
    "Skeleton",
    "body_size",
    "check_layout",
    "check_rotation_order",
    "euler_to_matrix",
    "forward_kinematics",
    "get_layout",
    "match_joints",
    "matrix_to_euler",
    "yaw_matrix",
]
