"""Neighbors: the similarity psi and the interval index for fast similarity search."""

from skmotion.neighbors._psi import pairwise_psi, psi

__all__ = ["pairwise_psi", "psi"]
