"""Neighbors: the similarity psi, the interval index, and search inside long takes
(frames for motion matching, occurrences of a clip)."""

from skmotion.neighbors._interval_index import IntervalIndex
from skmotion.neighbors._interval_neighbors import IntervalIndexNeighbors
from skmotion.neighbors._occurrences import find_occurrences
from skmotion.neighbors._psi import pairwise_psi, psi
from skmotion.neighbors._sharded import ShardedIntervalIndex

__all__ = [
    "IntervalIndex",
    "IntervalIndexNeighbors",
    "ShardedIntervalIndex",
    "find_occurrences",
    "pairwise_psi",
    "psi",
]
