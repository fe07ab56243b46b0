"""Right singular vectors and singular values of every clip, computed in batches.

Both the SVD feature vectors and the similarity psi need, for each clip ``A``
(``n_frames x n_channels``), the singular values and the leading right singular
vectors. For the usual clip (more frames than channels) they come from the
``n_channels x n_channels`` Gram matrix ``A^T A``; for a clip with fewer frames
than channels, from the smaller ``n_frames x n_frames`` matrix ``A A^T``. Clips
whose matrices have one size are decomposed in one batched call. Nothing loops
over frames.
"""

from contextlib import nullcontext

import numpy as np

# threadpoolctl comes with scikit-learn (one of its own dependencies).
from threadpoolctl import ThreadpoolController

from skmotion.decomposition._leading import leading_spectra
from skmotion.utils._parallel import parallel_map

__all__ = ["clip_spectra", "small_blas"]


def small_blas():
    """Context in which BLAS/LAPACK run on one thread.

    Per-clip problems are small (tens of channels): a multithreaded BLAS spends
    far longer synchronising its threads than computing, and on a busy machine
    it slows them a hundredfold. Parallelism comes from ``n_jobs`` instead.
    """
    global _CONTROLLER, _BLAS
    if _CONTROLLER is None:  # finding the loaded BLAS libraries is slow: do it once
        _CONTROLLER = ThreadpoolController()
        _BLAS = _CONTROLLER.select(user_api="blas").lib_controllers
    if all(blas.num_threads == 1 for blas in _BLAS):
        # Already one thread (OMP_NUM_THREADS=1, a joblib worker): nothing to limit, and
        # setting and restoring the limits costs as much as a one-clip query's pairs.
        return nullcontext()
    return _CONTROLLER.limit(limits=1, user_api="blas")


_CONTROLLER = None
_BLAS = []

# Clips per task: fixed, so the tasks (and so the results) do not depend on n_jobs.
_CHUNK = 512
# Subspace iteration: residual tolerance (relative to the largest eigenvalue),
# steps between convergence checks, and the steps before a full eigh takes over.
_TOLERANCE = 1e-9
_CHECK = 4
_MAX_STEPS = 24


def _rank_tolerance(eigenvalues):
    """Eigenvalues of a Gram matrix below this are rounding noise, i.e. zero."""
    n = eigenvalues.shape[-1]
    return eigenvalues.max(axis=-1, keepdims=True) * n * 10 * np.finfo(np.float64).eps


def _unit_scale(clip):
    """The clip divided by its largest absolute value (an all-zero clip unchanged).

    Singular vectors and the shares of the singular values do not change with
    the clip's scale, but its Gram matrix overflows for values near 1e154 and
    underflows near 1e-154: scaled to a maximum of 1 it does neither.
    """
    clip = np.asarray(clip, dtype=np.float64)
    peak = np.abs(clip).max() if clip.size else 0.0
    return clip / peak if peak > 0 else clip


def _spectra_of_chunk(chunk, n_vectors, method):
    if method == "iterative":
        return _leading_pairs(chunk, n_vectors)
    n = chunk[0].shape[1]
    eigenvalues = np.zeros((len(chunk), n))
    vectors = np.zeros((len(chunk), n, n_vectors))
    # The smaller Gram matrix of each clip: A^T A (channels x channels), or A A^T
    # (frames x frames) for a clip with fewer frames than channels. Clips of one
    # length are stacked: their Gram matrices come from one batched product and
    # are decomposed in one batched call.
    lengths = np.array([len(c) for c in chunk])
    for length in np.unique(lengths):
        rows = np.flatnonzero(lengths == length)
        clips = np.stack([np.asarray(chunk[i], dtype=np.float64) for i in rows])
        peak = np.abs(clips).max(axis=(1, 2), keepdims=True)
        clips = clips / np.where(peak > 0, peak, 1.0)  # see _unit_scale
        tall = length >= n
        grams = np.swapaxes(clips, 1, 2) @ clips if tall else clips @ np.swapaxes(clips, 1, 2)
        values, vecs = np.linalg.eigh(grams)
        values, vecs = values[:, ::-1], vecs[:, :, ::-1][:, :, :n_vectors]  # decreasing
        if not tall:
            # Right singular vectors from the left ones: v = A^T w / |A^T w|.
            vecs = np.swapaxes(clips, 1, 2) @ vecs
            norms = np.linalg.norm(vecs, axis=1, keepdims=True)
            vecs = np.divide(vecs, norms, out=np.zeros_like(vecs), where=norms > 0)
        eigenvalues[rows, : values.shape[1]] = values
        vectors[rows, :, : vecs.shape[2]] = vecs
    return _zero_beyond_rank(eigenvalues, vectors)


def _leading_pairs(chunk, n_vectors):
    """The leading pairs of each clip by the compiled kernel (any lengths, one call).

    Power steps (one pair) or subspace iteration (a block of ``n_vectors + 4``,
    two products per QR, a Rayleigh-Ritz step every ``_CHECK`` steps) on the
    smaller Gram matrix, each pair's residual ``|G v - lambda v|`` within
    ``_TOLERANCE * lambda_1``, and LAPACK's ``dsyevr`` for the clips not
    converged after ``_MAX_STEPS`` (or whose matrix is small enough that the
    full problem costs no more). Compiled, because numpy's per-call cost on
    small stacked matrices was most of a query's cost.
    """
    n = chunk[0].shape[1]
    clips = [np.ascontiguousarray(c, dtype=np.float64) for c in chunk]
    values, vectors = leading_spectra(clips, n_vectors, _TOLERANCE, _CHECK, _MAX_STEPS)
    eigenvalues = np.zeros((len(chunk), n))
    eigenvalues[:, :n_vectors] = values
    return _zero_beyond_rank(eigenvalues, vectors)


def _zero_beyond_rank(eigenvalues, vectors):
    n, n_vectors = vectors.shape[1:]
    eigenvalues = np.clip(eigenvalues, 0.0, None)
    # Directions beyond a clip's rank are undefined: make them zero vectors, so
    # that every caller treats them the same whichever route computed them.
    null = eigenvalues <= _rank_tolerance(eigenvalues)
    eigenvalues[null] = 0.0
    vectors[null[:, :n_vectors][:, None, :].repeat(n, axis=1)] = 0.0
    return eigenvalues, vectors


def clip_spectra(clips, n_vectors, *, method="exact", n_jobs=None):
    """Squared singular values and leading right singular vectors of each clip.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        Validated clips (see :func:`skmotion.utils.check_clips`).
    n_vectors : int
        How many leading right singular vectors to return (at most ``n_channels``).
    method : {"exact", "iterative"}, default="exact"
        ``"exact"``: a full batched ``eigh`` of each Gram matrix, all eigenvalues.
        ``"iterative"``: the ``n_vectors`` leading pairs only, by a compiled
        loop over the clips (power steps for one pair, subspace iteration for
        several), each within ``1e-9 * lambda_1`` in residual (LAPACK's
        ``dsyevr`` otherwise); the eigenvalues beyond ``n_vectors`` are then
        returned as 0.
    n_jobs : int, default=None
        Number of jobs over chunks of clips; results do not depend on it.

    Returns
    -------
    eigenvalues : ndarray of shape (n_clips, n_channels)
        Eigenvalues of each ``A^T A`` (the squared singular values of ``A``),
        in decreasing order; zero beyond the clip's rank. ``A`` is the clip
        divided by its largest absolute value: the vectors and the shares of the
        eigenvalues are what depend on the clip, not its scale, and the scaled
        Gram matrix neither overflows nor underflows for any finite clip.
    vectors : ndarray of shape (n_clips, n_channels, n_vectors)
        ``vectors[c, :, i]`` is the ``i``-th right singular vector of clip ``c``
        (unit norm, arbitrary sign), or zeros when ``i`` is at or beyond its rank.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.decomposition._clip_svd import clip_spectra
    >>> A = np.array([[3.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    >>> values, vectors = clip_spectra([A], n_vectors=2)
    >>> (values * 3.0**2).tolist()  # A / 3 was decomposed
    [[9.0, 1.0]]
    >>> np.abs(vectors[0]).tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    n_vectors = min(int(n_vectors), clips[0].shape[1])
    chunks = [clips[i : i + _CHUNK] for i in range(0, len(clips), _CHUNK)]
    with small_blas():
        parts = parallel_map(
            lambda chunk: _spectra_of_chunk(chunk, n_vectors, method), chunks, n_jobs=n_jobs
        )
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
