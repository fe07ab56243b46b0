"""Decomposition: clip-to-vector transformers from the clips' singular vectors."""

from skmotion.decomposition._svd_features import SVDFeatureExtractor

__all__ = ["SVDFeatureExtractor"]
