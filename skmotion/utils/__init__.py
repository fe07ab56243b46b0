"""Utilities: the clip validator, container conversion, frame stacking, parallelism, progress."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
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
    },
)

__all__ = [
    "Clips",
    "Container",
    "check_clips",
    "parallel_map",
    "progress",
    "say",
    "split_frames",
    "stack_clips",
    "to_container",
]
