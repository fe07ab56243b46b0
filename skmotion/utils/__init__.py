"""Utilities: the clip validator, container conversion, frame stacking, parallelism, progress."""

from skmotion.utils._clip_dataframes import insert_missing_frames
from skmotion.utils._clips import (
    Clips,
    Container,
    check_clips,
    split_frames,
    stack_clips,
    to_container,
)
from skmotion.utils._parallel import parallel_map
from skmotion.utils._progress import progress, say

__all__ = [
    "Clips",
    "Container",
    "check_clips",
    "insert_missing_frames",
    "parallel_map",
    "progress",
    "say",
    "split_frames",
    "stack_clips",
    "to_container",
]
