"""Preprocessing: clip-to-clip transformers and the steps that bridge to sklearn."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.kinematics._layouts": ["Layout"],
        "skmotion.kinematics._named_layouts": ["LAYOUTS", "get_layout"],
        "skmotion.preprocessing._body_frame": ["body_frame_features", "body_size"],
        "skmotion.preprocessing._fill_gaps": ["FillGaps"],
        "skmotion.preprocessing._filter": ["LowPassFilter", "filter_min_frames", "lowpass_filter"],
        "skmotion.preprocessing._flatten": ["FlattenClips"],
        "skmotion.preprocessing._marker_presets": [
            "MARKER_NAMES",
            "MARKER_PRESETS",
            "detect_marker_preset",
            "marker_preset",
        ],
        "skmotion.preprocessing._marker_set": ["Marker", "MarkerSet"],
        "skmotion.preprocessing._resample": ["ResampleClips", "resample_clip"],
        "skmotion.preprocessing._segment": [
            "SEGMENTATION_RULES",
            "energy_segments",
            "movement_energy",
            "segment_clip",
            "zero_velocity_crossings",
            "zvc_segments",
        ],
        "skmotion.preprocessing._to_markers": ["to_markers"],
        "skmotion.preprocessing._virtual_markers": ["SIZE_CHAIN", "VirtualMarkerTransform"],
    },
)

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
