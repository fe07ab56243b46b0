"""Decomposition: low-dimensional codes of clips and of their segments."""

from skmotion.decomposition._eigenmovements import EigenMovementPCA
from skmotion.decomposition._svd_features import SVDFeatureExtractor
from skmotion.decomposition._svd_projection import (
    SVDProjection,
    fit_svd_projection,
    max_svd_components,
    svd_project,
)

__all__ = [
    "EigenMovementPCA",
    "SVDFeatureExtractor",
    "SVDProjection",
    "fit_svd_projection",
    "max_svd_components",
    "svd_project",
]
