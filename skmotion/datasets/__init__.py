"""Datasets: the built-in synthetic motions and humanoid skeleton; loaders of real data."""

from skmotion.datasets._cmu_labels import CMU_MOTION_CLASSES, cmu_motion_class, motion_class_of_name
from skmotion.datasets._fetch import fetch_cmu_mocap
from skmotion.datasets._home import get_data_home
from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.datasets._motion_files import (
    load_bvh_folder,
    load_cmu_asfamc,
    load_motion_folder,
    read_cmu_index,
)
from skmotion.datasets._positions import (
    EXTRA_LANDMARKS,
    layout_markers,
    layout_positions,
    make_position_motions,
)
from skmotion.datasets._repeats import make_repeated_motions
from skmotion.datasets._synthetic import MOTION_CLASSES, make_motions
from skmotion.datasets._uea import load_uea
from skmotion.datasets._walks import WALK_DIRECTIONS, make_walks

__all__ = [
    "CMU_MOTION_CLASSES",
    "EXTRA_LANDMARKS",
    "MOTION_CLASSES",
    "WALK_DIRECTIONS",
    "cmu_motion_class",
    "fetch_cmu_mocap",
    "get_data_home",
    "humanoid_skeleton",
    "layout_markers",
    "layout_positions",
    "load_bvh_folder",
    "load_cmu_asfamc",
    "load_motion_folder",
    "load_uea",
    "make_motions",
    "make_position_motions",
    "make_repeated_motions",
    "make_walks",
    "motion_class_of_name",
    "read_cmu_index",
]
