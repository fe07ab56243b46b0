"""Kinematics: the Skeleton, position layouts, rotation conventions, batched forward kinematics."""

from skmotion.kinematics._body_size import body_size
from skmotion.kinematics._forward import FKResult, forward_kinematics
from skmotion.kinematics._joint_matching import JointMatch, match_joints
from skmotion.kinematics._layouts import Layout
from skmotion.kinematics._marker_names import MARKER_NAMES
from skmotion.kinematics._named_layouts import LAYOUTS, get_layout
from skmotion.kinematics._rotations import (
    check_rotation_order,
    euler_to_matrix,
    matrix_to_euler,
    yaw_matrix,
)
from skmotion.kinematics._skeleton import CHANNEL_KINDS, Skeleton

__all__ = [
    "CHANNEL_KINDS",
    "FKResult",
    "JointMatch",
    "LAYOUTS",
    "Layout",
    "MARKER_NAMES",
    "Skeleton",
    "body_size",
    "check_rotation_order",
    "euler_to_matrix",
    "forward_kinematics",
    "get_layout",
    "match_joints",
    "matrix_to_euler",
    "yaw_matrix",
]
