"""Neighbors: the similarity psi, the interval index, and search inside long takes
(frames for motion matching, occurrences of a clip)."""

import sys

from skmotion.neighbors import _stored_clips
from skmotion.neighbors._interval_index import IntervalIndex
from skmotion.neighbors._interval_neighbors import IntervalIndexNeighbors
from skmotion.neighbors._motion_matcher import MotionMatcher, floor_frames
from skmotion.neighbors._occurrences import find_occurrences
from skmotion.neighbors._psi import pairwise_psi, psi
from skmotion.neighbors._sharded import ShardedIntervalIndex

# Pickles made before _store.py joined _stored_clips.py name its GrowableStore there.
sys.modules["skmotion.neighbors._store"] = _stored_clips

__all__ = [
    "IntervalIndex",
    "IntervalIndexNeighbors",
    "MotionMatcher",
    "ShardedIntervalIndex",
    "find_occurrences",
    "floor_frames",
    "pairwise_psi",
    "psi",
]
