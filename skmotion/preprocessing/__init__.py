"""Preprocessing: clip-to-clip transformers and the steps that bridge to sklearn."""

from skmotion.kinematics._layouts import Layout
from skmotion.kinematics._named_layouts import LAYOUTS, get_layout
from skmotion.preprocessing._body_frame import body_frame_features, body_size
from skmotion.preprocessing._fill_gaps import FillGaps
from skmotion.preprocessing._filter import LowPassFilter, filter_min_frames, lowpass_filter
from skmotion.preprocessing._flatten import FlattenClips
from skmotion.preprocessing._marker_presets import (
    MARKER_NAMES,
    MARKER_PRESETS,
    detect_marker_preset,
    marker_preset,
)
from skmotion.preprocessing._marker_set import Marker, MarkerSet
from skmotion.preprocessing._resample import ResampleClips, resample_clip
from skmotion.preprocessing._segment import (
    SEGMENTATION_RULES,
    energy_segments,
    movement_energy,
    segment_clip,
    zero_velocity_crossings,
    zvc_segments,
)
from skmotion.preprocessing._to_markers import to_markers
from skmotion.preprocessing._virtual_markers import SIZE_CHAIN, VirtualMarkerTransform

__all__ = [
    "FillGaps",
    "FlattenClips",
    "LAYOUTS",
    "Layout",
    "LowPassFilter",
    "MARKER_NAMES",
    "MARKER_PRESETS",
    "Marker",
    "MarkerSet",
    "ResampleClips",
    "SEGMENTATION_RULES",
    "SIZE_CHAIN",
    "VirtualMarkerTransform",
    "body_frame_features",
    "body_size",
    "detect_marker_preset",
    "energy_segments",
    "filter_min_frames",
    "get_layout",
    "lowpass_filter",
    "marker_preset",
    "movement_energy",
    "resample_clip",
    "segment_clip",
    "to_markers",
    "zero_velocity_crossings",
    "zvc_segments",
]
