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

__all__ = ["COVARIANCE_TYPES", "Gaussians", "centred_moments", "estimate_covariance", "ledoit_wolf_shrinkage"]

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


def estimate_covariance(scatter, sq_norms, kind, reg):
    """The covariance of one node's frames, by the chosen estimator.

    Parameters
    ----------
    scatter, sq_norms : ndarray
        The node's centred moments (see :func:`centred_moments`).
    kind : {"diag", "full", "spherical"}
        The estimator (see the module's description).
    reg : float
        Added to every variance (the diagonal), so no covariance is singular.

    Returns
    -------
    covariance : float or ndarray of shape (n_channels,) or (n_channels, n_channels)
        A variance (``"spherical"``), variances (``"diag"``) or a matrix (``"full"``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import centred_moments, estimate_covariance
    >>> _, scatter, sq_norms = centred_moments(np.array([[0.0, 1.0], [2.0, 1.0]]))
    >>> estimate_covariance(scatter, sq_norms, "diag", 0.5).tolist()
    [1.5, 0.5]
    """
    n, d = len(sq_norms), len(scatter)
    if kind == "diag":
        return np.diag(scatter) / n + reg
    if kind == "spherical":
        return float(np.trace(scatter) / (n * d) + reg)
    if kind == "full":
        sample = scatter / n
        shrink = ledoit_wolf_shrinkage(scatter, sq_norms)
        mu = np.trace(sample) / d
        covariance = (1.0 - shrink) * sample
        covariance[np.diag_indices_from(covariance)] += shrink * mu + reg
        return covariance
    raise ValueError(f"covariance_type must be one of {COVARIANCE_TYPES}, got {kind!r}.")


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

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._gaussian import Gaussians
    >>> g = Gaussians(np.zeros((1, 2)), np.ones((1, 2)), "diag")
    >>> round(float(g.log_pdf(np.zeros((1, 2)))[0, 0]), 4)  # -log(2 pi)
    -1.8379
    """

    def __init__(self, means, covariances, kind):
        if kind not in COVARIANCE_TYPES:
            raise ValueError(f"kind must be one of {COVARIANCE_TYPES}, got {kind!r}.")
        self.means = np.asarray(means, dtype=np.float64)
        self.covariances = np.asarray(covariances, dtype=np.float64)
        self.kind = kind
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
        self._kernel = self._kernel_arrays()

    def __len__(self):
        return len(self.means)

    def kernel_arrays(self):
        """The arrays the compiled decoder reads (:mod:`skmotion.tree._beam`), by tree node id.

        Made once, with the Gaussians.

        Returns
        -------
        arrays : dict
            ``means`` ``(n, d)``; ``prec``: flat per-channel precisions (``"diag"``
            and ``"spherical"``, the latter repeated over channels) or flat upper
            triangular factors ``U`` with ``U U^T`` the precision (``"full"``);
            ``shifts`` ``(n, d)``, ``mean @ U`` (a ``(1, 1)`` placeholder otherwise);
            ``const`` ``(n,)``; ``full``.
        """
        return self._kernel

    def _kernel_arrays(self):
        n, d = self.means.shape
        if self.kind == "full":
            prec, shifts = self._prec_chol, self._shifts
        else:
            prec = np.broadcast_to(self._precisions.reshape(n, -1), (n, d))
            shifts = np.zeros((1, 1))
        return {
            "means": np.ascontiguousarray(self.means),
            "prec": np.ascontiguousarray(prec, dtype=np.float64).ravel(),
            "shifts": np.ascontiguousarray(shifts, dtype=np.float64),
            "const": np.ascontiguousarray(self._const, dtype=np.float64),
            "full": self.kind == "full",
        }

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
