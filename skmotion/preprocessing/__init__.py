"""Preprocessing: clip-to-clip transformers and the steps that bridge to sklearn."""

from skmotion.preprocessing._filter import LowPassFilter, filter_min_frames, lowpass_filter
from skmotion.preprocessing._flatten import FlattenClips
from skmotion.preprocessing._resample import ResampleClips, resample_clip
from skmotion.preprocessing._segment import (
    SEGMENTATION_RULES,
    energy_segments,
    movement_energy,
    segment_clip,
    zero_velocity_crossings,
    zvc_segments,
)

__all__ = [
    "FlattenClips",
    "LowPassFilter",
    "ResampleClips",
    "SEGMENTATION_RULES",
    "energy_segments",
    "filter_min_frames",
    "lowpass_filter",
    "movement_energy",
    "resample_clip",
    "segment_clip",
    "zero_velocity_crossings",
    "zvc_segments",
]
