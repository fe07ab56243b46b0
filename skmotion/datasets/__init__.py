"""Datasets: the built-in synthetic motions and humanoid skeleton; loaders of real data."""

from skmotion.datasets._home import get_data_home
from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.datasets._repeats import make_repeated_motions
from skmotion.datasets._synthetic import MOTION_CLASSES, make_motions
from skmotion.datasets._uea import load_uea

__all__ = ["MOTION_CLASSES", "get_data_home", "humanoid_skeleton", "load_uea", "make_motions", "make_repeated_motions"]
