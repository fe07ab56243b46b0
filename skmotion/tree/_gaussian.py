"""Gaussian statistics of tree nodes: well-conditioned covariances and log densities.

A node may hold fewer frames than there are channels, or channels that never
change; its covariance must still be invertible. Three estimators are offered:

- ``"diag"``: per-channel variances plus ``reg``;
- ``"spherical"``: the mean per-channel variance plus ``reg``, one number;
- ``"full"``: the Ledoit-Wolf shrinkage of the sample covariance towards a
  scaled identity (closed form, well defined for any number of frames), plus
  ``reg`` on the diagonal.
"""

import numpy as np
from scipy.linalg import solve_triangular

__all__ = [
    "COVARIANCE_TYPES",
    "Gaussians",
    "centred_moments",
    "estimate_covariance",
    "ledoit_wolf_shrinkage",
    "low_rank_covariance",
]

#: The covariance estimators of :func:`estimate_covariance`.
COVARIANCE_TYPES = ("diag", "full", "spherical")

_LOG_2PI = np.log(2.0 * np.pi)
# Elements of the temporary (frames x nodes x channels) block of one chunk.
_CHUNK_ELEMENTS = 1 << 22


def centred_moments(frames, chunk_rows=None):
    """Mean, scatter ``sum (x - m)(x - m)^T`` and squared norms ``|x - m|^2`` of frames.

    Computed in row chunks, so no centred copy of a large node is ever made.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
    chunk_rows : int, default=None
        Rows per chunk; by default about four million values a chunk.

    Returns
    -------
    mean : ndarray of shape (n_channels,)
    scatter : ndarray of shape (n_channels, n_channels)
    sq_norms : ndarray of shape (n_frames,)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import centred_moments
    >>> mean, scatter, sq_norms = centred_moments(np.array([[0.0, 1.0], [2.0, 1.0]]))
    >>> mean.tolist(), scatter.tolist(), sq_norms.tolist()
    ([1.0, 1.0], [[2.0, 0.0], [0.0, 0.0]], [1.0, 1.0])
    """
    n, d = frames.shape
    step = chunk_rows or max(1, _CHUNK_ELEMENTS // d)
    mean = frames.mean(axis=0)
    scatter = np.zeros((d, d))
    sq_norms = np.empty(n)
    for start in range(0, n, step):
        centred = frames[start : start + step] - mean
        scatter += centred.T @ centred
        sq_norms[start : start + step] = np.einsum("ij,ij->i", centred, centred)
    return mean, scatter, sq_norms


def ledoit_wolf_shrinkage(scatter, sq_norms):
    """Ledoit and Wolf's optimal shrinkage of a sample covariance to a scaled identity.

    Parameters
    ----------
    scatter : ndarray of shape (n_channels, n_channels)
        ``sum (x - m)(x - m)^T`` over the frames.
    sq_norms : ndarray of shape (n_frames,)
        ``|x - m|^2`` of each frame.

    Returns
    -------
    shrinkage : float
        In ``[0, 1]``; the covariance is ``(1 - s) S + s mu I`` with ``S`` the
        sample covariance and ``mu`` its mean eigenvalue.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import centred_moments, ledoit_wolf_shrinkage
    >>> _, scatter, sq_norms = centred_moments(np.random.default_rng(0).normal(size=(5, 20)))
    >>> 0 < ledoit_wolf_shrinkage(scatter, sq_norms) <= 1
    True
    """
    n, d = len(sq_norms), len(scatter)
    trace = sq_norms.sum() / n
    mu = trace / d
    frob = np.sum(scatter * scatter) / (n * n)  # ||S||_F^2
    beta = (np.dot(sq_norms, sq_norms) / n - frob) / (d * n)
    delta = (frob - 2.0 * mu * trace + d * mu * mu) / d
    beta = min(beta, delta)
    return 1.0 if delta <= 0 else float(beta / delta)


def estimate_covariance(scatter, n, kind, reg, sq_norms=None):
    """The covariance of one node's frames, by the chosen estimator.

    Parameters
    ----------
    scatter : ndarray of shape (n_channels, n_channels)
        The node's scatter (see :func:`centred_moments`).
    n : int
        The node's number of frames.
    kind : {"diag", "full", "spherical"}
        The estimator (see the module's description).
    reg : float
        Added to every variance (the diagonal), so no covariance is singular.
    sq_norms : ndarray of shape (n,), default=None
        Each frame's squared centred norm (see :func:`centred_moments`); only
        ``"full"`` (Ledoit-Wolf) needs them.

    Returns
    -------
    covariance : float or ndarray of shape (n_channels,) or (n_channels, n_channels)
        A variance (``"spherical"``), variances (``"diag"``) or a matrix (``"full"``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import centred_moments, estimate_covariance
    >>> _, scatter, sq_norms = centred_moments(np.array([[0.0, 1.0], [2.0, 1.0]]))
    >>> estimate_covariance(scatter, 2, "diag", 0.5).tolist()
    [1.5, 0.5]
    """
    d = len(scatter)
    if kind == "diag":
        return np.diag(scatter) / n + reg
    if kind == "spherical":
        return float(np.trace(scatter) / (n * d) + reg)
    if kind == "full":
        if sq_norms is None or len(sq_norms) != n:
            raise ValueError("the 'full' estimate needs each of the n frames' squared norm.")
        scale, floor = _ledoit_wolf_parts(scatter, sq_norms, reg)
        covariance = scale * scatter
        covariance[np.diag_indices_from(covariance)] += floor
        return covariance
    raise ValueError(f"covariance_type must be one of {COVARIANCE_TYPES}, got {kind!r}.")


def _ledoit_wolf_parts(scatter, sq_norms, reg):
    """The full estimate as ``scale * scatter + floor * I``: ``(1 - s) / n`` and ``s mu + reg``."""
    n, d = len(sq_norms), len(scatter)
    shrink = ledoit_wolf_shrinkage(scatter, sq_norms)
    return (1.0 - shrink) / n, shrink * np.trace(scatter) / (n * d) + reg


def low_rank_covariance(centred, scatter, sq_norms, reg):
    """The ``"full"`` estimate of a node as an isotropic part plus a low-rank one.

    The shrunk sample covariance is ``floor I + scale X^T X`` with ``X`` the
    node's centred frames, whose rank is below the frame count: with fewer
    frames than channels, ``floor I + V^T diag(values) V`` with ``r`` rows of
    ``V`` is the same matrix, and a density costs ``O(r d)`` instead of ``O(d^2)``.

    Parameters
    ----------
    centred : ndarray of shape (n_frames, n_channels)
        The node's frames minus their mean.
    scatter, sq_norms : ndarray
        Their centred moments (see :func:`centred_moments`).
    reg : float
        As for :func:`estimate_covariance`.

    Returns
    -------
    floor : float
        The isotropic part.
    vectors : ndarray of shape (r, n_channels)
        Orthonormal rows: the directions the frames span.
    values : ndarray of shape (r,)
        The covariance's excess over ``floor`` along each of them.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import (
    ...     centred_moments, estimate_covariance, low_rank_covariance)
    >>> frames = np.random.default_rng(0).normal(size=(4, 10))
    >>> mean, scatter, sq_norms = centred_moments(frames)
    >>> floor, vectors, values = low_rank_covariance(frames - mean, scatter, sq_norms, 1e-3)
    >>> vectors.shape
    (3, 10)
    >>> full = estimate_covariance(scatter, len(sq_norms), "full", 1e-3, sq_norms)
    >>> np.allclose(floor * np.eye(10) + vectors.T @ np.diag(values) @ vectors, full)
    True
    """
    scale, floor = _ledoit_wolf_parts(scatter, sq_norms, reg)
    _, singular, vectors = np.linalg.svd(centred, full_matrices=False)
    # the centred frames' rank is below their count: their last singular values are rounding
    keep = singular > singular[:1].max(initial=0.0) * 1e-12
    return floor, vectors[keep], scale * singular[keep] ** 2


class Gaussians:
    """A set of Gaussians (one per node) with their log densities.

    Parameters
    ----------
    means : ndarray of shape (n_nodes, n_channels)
        Mean of each Gaussian.
    covariances : ndarray
        ``(n_nodes,)`` variances for ``"spherical"``, ``(n_nodes, n_channels)``
        for ``"diag"``, ``(n_nodes, n_channels, n_channels)`` for ``"full"``;
        positive definite.
    kind : {"diag", "full", "spherical"}
        How ``covariances`` is laid out.
    low_rank : list, default=None
        For ``"full"``, per Gaussian the ``(floor, vectors, values)`` of
        :func:`low_rank_covariance` or None: the compiled decoder evaluates a
        Gaussian whose rank is small against the channels in that form.
        ``log_pdf`` always uses the Cholesky factor (the reference).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import Gaussians
    >>> g = Gaussians(np.zeros((1, 2)), np.ones((1, 2)), "diag")
    >>> round(float(g.log_pdf(np.zeros((1, 2)))[0, 0]), 4)  # -log(2 pi)
    -1.8379
    """

    def __init__(self, means, covariances, kind, low_rank=None):
        if kind not in COVARIANCE_TYPES:
            raise ValueError(f"kind must be one of {COVARIANCE_TYPES}, got {kind!r}.")
        self.means = np.asarray(means, dtype=np.float64)
        self.covariances = np.asarray(covariances, dtype=np.float64)
        self.kind = kind
        self.low_rank = low_rank
        n_nodes, d = self.means.shape
        if kind == "full":
            chol = np.linalg.cholesky(self.covariances)
            eye = np.eye(d)
            self._prec_chol = np.stack([solve_triangular(c, eye, lower=True).T for c in chol])
            self._shifts = np.einsum("kd,kde->ke", self.means, self._prec_chol)
            log_det = 2.0 * np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(axis=1)
        elif kind == "diag":
            self._precisions = 1.0 / self.covariances
            log_det = np.log(self.covariances).sum(axis=1)
        else:
            self._precisions = 1.0 / self.covariances
            log_det = d * np.log(self.covariances)
        self._const = -0.5 * (log_det + d * _LOG_2PI)

    def __len__(self):
        return len(self.means)

    def precision_factors(self):
        """``(prec, shifts, const)``: what the log densities are computed from.

        ``"full"``: the upper factors ``U`` ``(n, d, d)`` with ``U U^T`` the
        precision, and ``mean @ U`` ``(n, d)``; the other kinds: the precisions
        (laid out as the covariances) and None. ``const`` ``(n,)``: the log
        normalising constants.
        """
        if self.kind == "full":
            return self._prec_chol, self._shifts, self._const
        return self._precisions, None, self._const

    def log_pdf(self, X, nodes=None):
        """Log density of every frame under every (or the chosen) Gaussian.

        Parameters
        ----------
        X : ndarray of shape (n_frames, n_channels)
            Frames.
        nodes : array-like of int, default=None
            Which Gaussians; all by default.

        Returns
        -------
        log_pdf : ndarray of shape (n_frames, n_selected)
        """
        X = np.asarray(X, dtype=np.float64)
        nodes = np.arange(len(self)) if nodes is None else np.asarray(nodes, dtype=np.intp)
        width = len(nodes) * (X.shape[1] if self.kind == "full" else 1)
        step = max(1, _CHUNK_ELEMENTS // max(width, 1))
        out = np.empty((len(X), len(nodes)))
        for start in range(0, len(X), step):
            out[start : start + step] = self._log_pdf_block(X[start : start + step], nodes)
        return out

    def _log_pdf_block(self, X, nodes):
        means = self.means[nodes]
        if self.kind == "full":
            chol = self._prec_chol[nodes]
            d = X.shape[1]
            y = (X @ chol.transpose(1, 0, 2).reshape(d, -1)).reshape(len(X), len(nodes), d)
            y -= self._shifts[nodes]
            maha = np.einsum("mkd,mkd->mk", y, y)
        elif self.kind == "diag":
            prec = self._precisions[nodes]
            maha = (X * X) @ prec.T - 2.0 * (X @ (means * prec).T)
            maha += np.einsum("kd,kd->k", means * means, prec)
        else:
            prec = self._precisions[nodes]
            sq = np.einsum("md,md->m", X, X)[:, None] - 2.0 * (X @ means.T)
            sq += np.einsum("kd,kd->k", means, means)
            maha = sq * prec
        # Rounding in the expanded squares can dip a hair below zero.
        np.maximum(maha, 0.0, out=maha)
        return self._const[nodes] - 0.5 * maha
