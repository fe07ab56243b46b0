"""Principal axes of segment vectors, with the paper's covariance normalisation."""

import numpy as np
from scipy.linalg import eigh
from sklearn.utils.extmath import svd_flip

__all__ = ["principal_axes"]


def principal_axes(vectors, n_components):
    """Mean, the first eigenvectors (rows) and all eigenvalues of the covariance.

    The covariance divides by the number of segments (the paper's eq. 3), so the
    mean squared error of projecting the training segments on the first ``k``
    eigenvectors is exactly the sum of the other eigenvalues. The symmetric
    eigenproblem is solved on the smaller of the covariance ``(D, D)`` and the
    Gram matrix ``(N, N)`` of the centred vectors; when the segments span fewer
    than ``n_components`` directions, an SVD completes the basis.
    """
    n_segments, n_features = vectors.shape
    mean = vectors.mean(axis=0)
    centred = vectors - mean
    if n_segments >= n_features:
        eigenvalues, axes = eigh(centred.T @ centred)
        eigenvalues, axes = eigenvalues[::-1], axes[:, ::-1].T
    else:
        eigenvalues, u = eigh(centred @ centred.T)
        eigenvalues, u = eigenvalues[::-1], u[:, ::-1]
        rank = int((eigenvalues > eigenvalues[0] * n_segments * np.finfo(float).eps).sum())
        if rank >= n_components:
            axes = (centred.T @ u[:, :n_components] / np.sqrt(eigenvalues[:n_components])).T
        else:
            axes = np.linalg.svd(centred, full_matrices=False)[2]
    axes = axes[:n_components]
    _, axes = svd_flip(np.zeros((1, len(axes))), axes, u_based_decision=False)
    return mean, axes, np.clip(eigenvalues, 0.0, None) / n_segments
