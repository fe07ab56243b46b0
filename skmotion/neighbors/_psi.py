"""The motion similarity psi of two clips, from the eigenvectors of ``A^T A``."""

from numbers import Integral

import numpy as np

from skmotion.decomposition._clip_svd import clip_spectra
from skmotion.utils._clips import check_clips
from skmotion.utils._parallel import parallel_map
from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = [
    "pairwise_psi",
    "psi",
    "psi_from_signatures",
    "psi_signatures",
    "signatures_from_spectra",
]

# Rows of the similarity matrix per task: bounds memory, independent of n_jobs.
_ROWS = 1024


def psi_signatures(clips, k, *, n_jobs=None):
    """What psi needs of each clip: the first ``k`` eigenvectors and their weights.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        Validated clips.
    k : int
        Number of eigenvectors; more than ``n_channels`` means all of them.
    n_jobs : int, default=None
        Number of jobs for the per-clip eigen-decompositions.

    Returns
    -------
    weights : ndarray of shape (n_clips, k_eff)
        ``lambda_i / sum_{j <= k} lambda_j`` with ``lambda`` the eigenvalues of
        ``A^T A``; ``k_eff = min(k, n_channels)``.
    vectors : ndarray of shape (n_clips, k_eff, n_channels)
        The matching unit eigenvectors (zeros beyond a clip's rank).
    """
    k = min(int(k), clips[0].shape[1])
    return signatures_from_spectra(*clip_spectra(clips, k, n_jobs=n_jobs), k)


def signatures_from_spectra(eigenvalues, vectors, k):
    """:func:`psi_signatures` from spectra already computed by ``clip_spectra``.

    ``vectors`` must hold at least ``min(k, n_channels)`` vectors per clip.
    """
    k = min(int(k), eigenvalues.shape[1])
    top = eigenvalues[:, :k]
    total = top.sum(axis=1, keepdims=True)
    empty = np.flatnonzero(total[:, 0] == 0)
    if empty.size:
        raise ValueError(f"clip {empty[0]} is all zeros; psi is not defined for it.")
    return top / total, np.ascontiguousarray(vectors[:, :, :k].transpose(0, 2, 1))


def psi_from_signatures(weights_a, vectors_a, weights_b, vectors_b):
    """The psi matrix between two sets of signatures (see :func:`psi_signatures`).

    Parameters
    ----------
    weights_a, vectors_a : ndarray of shape (n_a, k) and (n_a, k, n_channels)
    weights_b, vectors_b : ndarray of shape (n_b, k) and (n_b, k, n_channels)

    Returns
    -------
    similarity : ndarray of shape (n_a, n_b)
        Values in ``[0, 1]``.
    """
    out = np.zeros((len(weights_a), len(weights_b)))
    for i in range(weights_a.shape[1]):
        dots = np.abs(vectors_a[:, i, :] @ vectors_b[:, i, :].T)
        out += (weights_a[:, i, None] + weights_b[None, :, i]) * dots
    out *= 0.5
    # Rounding can push a perfect match a hair above 1.
    return np.clip(out, 0.0, 1.0, out=out)


@validate_params(
    {"Q": ["array-like"], "P": ["array-like"], "k": [Interval(Integral, 1, None, closed="left")]},
    prefer_skip_nested_validation=True,
)
def psi(Q, P, k=6):
    """Similarity of two clips from the eigenvectors of ``Q^T Q`` and ``P^T P``.

    ``psi(Q, P) = 1/2 * sum_{i<=k} (s_i / sum(s) + l_i / sum(l)) * |u_i . v_i|``
    where ``s, l`` are the eigenvalues of ``Q^T Q`` and ``P^T P`` (decreasing),
    ``u_i, v_i`` their unit eigenvectors, and the sums run over the first ``k``
    eigenvalues. 1 means the same shape: the same principal directions with the
    same shares of energy. The clips may differ in length.

    Parameters
    ----------
    Q, P : array-like of shape (n_frames_q, n_channels) and (n_frames_p, n_channels)
        Two clips with the same channels.
    k : int, default=6
        Number of eigenvectors compared (the paper's choice for body motion);
        more than ``n_channels`` means all of them.

    Returns
    -------
    similarity : float
        In ``[0, 1]``; ``psi(Q, Q) == 1``; symmetric.

    Notes
    -----
    Li & Prabhakaran divide by the sum of all ``n_channels`` eigenvalues; here the
    sums run over the ``k`` used, so that a clip's similarity with itself is
    exactly 1 (with all eigenvalues it is the share of the first ``k``, slightly
    below 1). Eigenvectors beyond a clip's rank are undefined and count as zero.
    Repeating a clip (stacking it on itself) scales ``Q^T Q`` and leaves psi
    unchanged, so psi ignores how many times a motion is repeated.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors import psi
    >>> rng = np.random.default_rng(0)
    >>> Q = rng.normal(size=(50, 8)) * np.arange(8, 0, -1)
    >>> round(psi(Q, Q), 6), round(psi(Q, np.vstack([Q, Q, Q])), 6)
    (1.0, 1.0)
    >>> 0 <= psi(Q, rng.normal(size=(30, 8))) < 1
    True
    """
    clips = check_clips([Q, P], input_name="[Q, P]")
    signatures = psi_signatures(clips, k)
    return float(
        psi_from_signatures(*(s[:1] for s in signatures), *(s[1:] for s in signatures))[0, 0]
    )


@validate_params(
    {
        "X": ["array-like"],
        "Y": ["array-like", None],
        "k": [Interval(Integral, 1, None, closed="left")],
        "n_jobs": [Integral, None],
    },
    prefer_skip_nested_validation=True,
)
def pairwise_psi(X, Y=None, k=6, *, n_jobs=None):
    """psi between every clip of ``X`` and every clip of ``Y``.

    A similarity matrix: use it as a precomputed kernel, or ``1 - psi`` as a
    precomputed distance (``KNeighborsClassifier(metric="precomputed")``).

    Parameters
    ----------
    X : list of ndarray of shape (n_frames_i, n_channels), ndarray of shape \
            (n_clips, n_frames, n_channels) or DataFrame
        Clips.
    Y : same kinds as X, default=None
        Other clips with the same channels; ``None`` means ``X``.
    k : int, default=6
        Number of eigenvectors compared (see :func:`psi`).
    n_jobs : int, default=None
        Number of jobs (joblib's meaning); results do not depend on it.

    Returns
    -------
    similarity : ndarray of shape (n_clips_X, n_clips_Y)
        Values in ``[0, 1]``; symmetric with ones on the diagonal when ``Y`` is None.

    Examples
    --------
    >>> from sklearn.neighbors import KNeighborsClassifier
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.neighbors import pairwise_psi
    >>> data = make_motions(n_clips_per_class=4, random_state=0)
    >>> clips = [c[:, 6:] for c in data.clips]  # joint angles without the root
    >>> S = pairwise_psi(clips)
    >>> S.shape, bool(abs(S - S.T).max() < 1e-12), round(float(S.diagonal().min()), 6)
    ((28, 28), True, 1.0)
    >>> knn = KNeighborsClassifier(n_neighbors=1, metric="precomputed")
    >>> knn.fit(1 - S, data.target).predict(1 - S)[:7].tolist()
    [0, 0, 0, 0, 1, 1, 1]
    """
    clips_x = check_clips(X, input_name="X")
    a = psi_signatures(clips_x, k, n_jobs=n_jobs)
    if Y is None:
        b = a
    else:
        clips_y = check_clips(Y, input_name="Y")
        if clips_y.n_channels != clips_x.n_channels:
            raise ValueError(
                f"Y: clips have {clips_y.n_channels} channels, but the clips of X have "
                f"{clips_x.n_channels}; psi compares clips with the same channels."
            )
        b = psi_signatures(clips_y, k, n_jobs=n_jobs)
    starts = range(0, len(a[0]), _ROWS)
    rows = parallel_map(
        lambda s: psi_from_signatures(a[0][s : s + _ROWS], a[1][s : s + _ROWS], *b),
        starts,
        n_jobs=n_jobs,
    )
    return np.concatenate(rows, axis=0)
