"""Decomposition: low-dimensional codes of clips and of their segments."""

from skmotion.decomposition._eigenmovements import EigenMovementPCA
from skmotion.decomposition._svd_features import SVDFeatureExtractor

__all__ = ["EigenMovementPCA", "SVDFeatureExtractor"]
