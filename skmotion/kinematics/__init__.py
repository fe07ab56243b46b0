"""Kinematics: the Skeleton, rotation conventions and batched forward kinematics."""

from skmotion.kinematics._body_size import body_size
from skmotion.kinematics._forward import FKResult, forward_kinematics
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
    "Skeleton",
    "body_size",
    "check_rotation_order",
    "euler_to_matrix",
    "forward_kinematics",
    "matrix_to_euler",
    "yaw_matrix",
]
