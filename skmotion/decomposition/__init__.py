"""Decomposition: low-dimensional codes of clips and of their segments."""

from skmotion.decomposition._eigenmovements import EigenMovementPCA

__all__ = ["EigenMovementPCA"]
