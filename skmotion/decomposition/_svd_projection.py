"""The SVD feature projection of Li & Prabhakaran, as functions on per-clip spectra.

:class:`~skmotion.decomposition.SVDFeatureExtractor` and
:class:`~skmotion.neighbors.IntervalIndexNeighbors` both turn clips into feature
vectors this way; the index also needs the clips' spectra for psi, so the work
is split into functions on spectra already computed by ``clip_spectra``: one
decomposition per clip serves both.
"""

from typing import NamedTuple

import numpy as np

from skmotion.decomposition._clip_svd import small_blas

__all__ = [
    "N_VECTORS",
    "SVDProjection",
    "fit_svd_projection",
    "max_svd_components",
    "svd_project",
]

# Right singular vectors per clip that each weighting uses.
N_VECTORS = {"first": 1, "first_two": 2}


class SVDProjection(NamedTuple):
    """A fitted SVD feature projection (see :func:`fit_svd_projection`)."""

    weighting: str
    axes: np.ndarray  # (n_vectors, n_channels): sign references of each clip's u_i
    components: np.ndarray  # (n_components, n_composite): rows of Z^T
    singular_values: np.ndarray  # (n_components,)


def _orient(vector):
    """Sign making the entry of largest magnitude positive (a fixed convention)."""
    return 1.0 if vector[np.argmax(np.abs(vector))] >= 0 else -1.0


def _right_singular(matrix, n):
    """The ``n`` leading right singular vectors (rows) and singular values of a matrix.

    With more rows (training clips) than columns, from the eigen-decomposition
    of the small ``matrix^T matrix``: the left singular vectors, one entry per
    clip, are never needed. Otherwise an SVD, whose cost follows the rows.
    """
    with small_blas():  # small problems: threads would only wait for each other
        if matrix.shape[0] <= matrix.shape[1]:
            _, singular, vt = np.linalg.svd(matrix, full_matrices=False)
            return vt[:n], singular[:n]
        values, vectors = np.linalg.eigh(matrix.T @ matrix)
    return vectors[:, ::-1][:, :n].T, np.sqrt(np.clip(values[::-1][:n], 0.0, None))


def _principal_axis(vectors):
    """First principal axis (uncentred) of unit vectors, with a fixed sign.

    ``sum_c v_c v_c^T`` does not change when any ``v_c`` flips sign, so the axis
    is a property of the vectors' directions alone.
    """
    axis = _right_singular(vectors, 1)[0][0]
    return axis * _orient(axis)


def max_svd_components(n_clips, n_channels, weighting="first"):
    """The most feature components a projection fitted on these clips can have.

    ``min(n_clips, n_vectors * n_channels)``: the stacked composite vectors
    (one row per clip, ``n_vectors * n_channels`` columns) have no more
    right singular vectors.
    """
    return min(int(n_clips), N_VECTORS[weighting] * int(n_channels))


def _composite(eigenvalues, vectors, axes, weighting):
    """Each clip's composite vector: its ``u_i`` turned along ``axes``, weighted."""
    n_vectors = N_VECTORS[weighting]
    empty = np.flatnonzero(eigenvalues[:, 0] == 0)
    if empty.size:
        raise ValueError(
            f"X: clip {empty[0]} is all zeros; it has no singular vectors, so "
            "it has no SVD feature vector."
        )
    u = vectors[:, :, :n_vectors]
    signs = np.where(np.einsum("cni,in->ci", u, axes) < 0, -1.0, 1.0)
    u = u * signs[:, None, :]
    if n_vectors == 1:
        return u[:, :, 0]
    singular = np.sqrt(eigenvalues)
    weights = singular[:, :n_vectors] / singular.sum(axis=1, keepdims=True)
    return np.concatenate([weights[:, i : i + 1] * u[:, :, i] for i in range(n_vectors)], axis=1)


def fit_svd_projection(eigenvalues, vectors, n_components, weighting="first"):
    """Learn the projection ``Z[:, :n_components]`` from training clips' spectra.

    The training clips' composite vectors (``u_1``, or ``[w_1 u_1, w_2 u_2]``
    with ``w_i = s_i / sum_k s_k``) are stacked; the projection is the first
    ``n_components`` right singular vectors ``Z`` of that matrix (Li &
    Prabhakaran, section IV), each with its largest entry positive.

    Parameters
    ----------
    eigenvalues, vectors : ndarray of shape (n_clips, n_channels) and \
            (n_clips, n_channels, >= n_vectors)
        The clips' spectra from ``clip_spectra`` (``n_vectors`` is 1 for
        ``"first"``, 2 for ``"first_two"``).
    n_components : int
        Length of the feature vectors, at most :func:`max_svd_components`.
    weighting : {"first", "first_two"}, default="first"
        Which singular vectors make the composite vector.

    Returns
    -------
    projection : SVDProjection
        ``(weighting, axes, components, singular_values)``; apply it with
        :func:`svd_project`.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.decomposition import fit_svd_projection, svd_project
    >>> from skmotion.decomposition._clip_svd import clip_spectra
    >>> rng = np.random.default_rng(0)
    >>> clips = [rng.normal(size=(30, 4)) * [4, 3, 2, 1] for _ in range(6)]
    >>> spectra = clip_spectra(clips, 1)
    >>> projection = fit_svd_projection(*spectra, n_components=3)
    >>> svd_project(projection, *spectra).shape
    (6, 3)
    """
    n_vectors = N_VECTORS[weighting]
    n_clips, n_channels = eigenvalues.shape
    limit = max_svd_components(n_clips, n_channels, weighting)
    if not 1 <= n_components <= limit:
        raise ValueError(
            f"n_components={n_components} must be at most {limit}: the number of training "
            f"clips ({n_clips}) and the length of the composite vectors "
            f"({n_vectors * n_channels} = {n_vectors} x {n_channels} channels for "
            f"weighting={weighting!r}). Pass n_components={limit} or fewer, or "
            "n_components=None to use as many as the data allows (up to the default)."
        )
    axes = np.stack([_principal_axis(vectors[:, :, i]) for i in range(n_vectors)])
    components, singular = _right_singular(
        _composite(eigenvalues, vectors, axes, weighting), n_components
    )
    components = components * np.array([_orient(row) for row in components])[:, None]
    return SVDProjection(weighting, axes, components, singular)


def svd_project(projection, eigenvalues, vectors):
    """Feature vectors of clips from their spectra and a fitted projection.

    Parameters
    ----------
    projection : SVDProjection
        From :func:`fit_svd_projection`.
    eigenvalues, vectors : ndarray
        The clips' spectra from ``clip_spectra``, with the training clips' channels.

    Returns
    -------
    features : ndarray of shape (n_clips, n_components)
        Each composite vector times ``Z[:, :n_components]``, negated when its
        first component is negative (the paper's sign rule); in ``[-1, 1]``.
    """
    composite = _composite(eigenvalues, vectors, projection.axes, projection.weighting)
    features = composite @ projection.components.T
    features *= np.where(features[:, :1] < 0, -1.0, 1.0)
    return features
