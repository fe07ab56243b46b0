"""Preprocessing: clip-to-clip transformers and the steps that bridge to sklearn."""

from skmotion.preprocessing._flatten import FlattenClips
from skmotion.preprocessing._resample import ResampleClips, resample_clip

__all__ = ["FlattenClips", "ResampleClips", "resample_clip"]
