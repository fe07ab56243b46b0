"""Neighbors: the similarity psi and the interval index for fast similarity search."""

from skmotion.neighbors._interval_index import IntervalIndex
from skmotion.neighbors._interval_neighbors import IntervalIndexNeighbors
from skmotion.neighbors._psi import pairwise_psi, psi
from skmotion.neighbors._sharded import ShardedIntervalIndex

__all__ = ["IntervalIndex", "IntervalIndexNeighbors", "ShardedIntervalIndex", "pairwise_psi", "psi"]
