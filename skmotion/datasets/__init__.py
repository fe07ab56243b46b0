"""Datasets: the built-in synthetic motions and humanoid skeleton."""

from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.datasets._synthetic import MOTION_CLASSES, make_motions

__all__ = ["MOTION_CLASSES", "humanoid_skeleton", "make_motions"]
