"""Neighbors: the similarity psi and the interval index for fast similarity search."""

import sys

from skmotion.neighbors import _stored_clips
from skmotion.neighbors._interval_index import IntervalIndex
from skmotion.neighbors._interval_neighbors import IntervalIndexNeighbors
from skmotion.neighbors._psi import pairwise_psi, psi
from skmotion.neighbors._sharded import ShardedIntervalIndex

# Pickles made before _store.py joined _stored_clips.py name its GrowableStore there.
sys.modules["skmotion.neighbors._store"] = _stored_clips

__all__ = ["IntervalIndex", "IntervalIndexNeighbors", "ShardedIntervalIndex", "pairwise_psi", "psi"]
