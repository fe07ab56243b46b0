"""Utilities: the clip validator, container conversion, frame stacking, parallelism, progress."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.utils._clip_dataframes": ["insert_missing_frames"],
        "skmotion.utils._clips": [
            "Clips",
            "Container",
            "check_clips",
            "split_frames",
            "stack_clips",
            "to_container",
        ],
        "skmotion.utils._parallel": ["parallel_map"],
        "skmotion.utils._progress": ["progress", "say"],
        "skmotion.utils._bridges": ["from_aeon", "from_tslearn", "to_aeon", "to_tslearn"],
    },
)

__all__ = [
    "Clips",
    "Container",
    "check_clips",
    "from_aeon",
    "from_tslearn",
    "insert_missing_frames",
    "parallel_map",
    "progress",
    "say",
    "split_frames",
    "stack_clips",
    "to_aeon",
    "to_container",
    "to_tslearn",
]
