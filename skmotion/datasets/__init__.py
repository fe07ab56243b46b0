"""Datasets: the built-in synthetic motions and humanoid skeleton; loaders of real data."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.datasets._cmu_labels": [
            "CMU_MOTION_CLASSES",
            "cmu_motion_class",
            "motion_class_of_name",
        ],
        "skmotion.datasets._fetch": ["fetch_cmu_mocap"],
        "skmotion.datasets._home": ["get_data_home"],
        "skmotion.datasets._humanoid": ["humanoid_skeleton"],
        "skmotion.datasets._labels": ["read_labels"],
        "skmotion.datasets._motion_files": [
            "load_bvh_folder",
            "load_cmu_asfamc",
            "load_motion_folder",
            "read_cmu_index",
            "read_labels",
        ],
        "skmotion.datasets._positions": [
            "EXTRA_LANDMARKS",
            "layout_markers",
            "layout_positions",
            "make_position_motions",
        ],
        "skmotion.datasets._repeats": ["make_repeated_motions"],
        "skmotion.datasets._synthetic": ["MOTION_CLASSES", "make_motions"],
        "skmotion.datasets._uea": ["load_uea"],
        "skmotion.datasets._walks": ["WALK_DIRECTIONS", "make_walks"],
    },
)

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
    "read_labels",
]
