"""SVDFeatureExtractor: one fixed-length feature vector per clip from its SVD."""

from numbers import Integral

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.decomposition._clip_svd import clip_spectra, small_blas
from skmotion.utils._clips import check_clips
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["SVDFeatureExtractor"]

_N_VECTORS = {"first": 1, "first_two": 2}


def _orient(vector):
    """Sign making the entry of largest magnitude positive (a fixed convention)."""
    return 1.0 if vector[np.argmax(np.abs(vector))] >= 0 else -1.0


def _right_singular(matrix, n):
    """The ``n`` leading right singular vectors (rows) and singular values of a matrix.

    With more rows (training clips) than columns, from the eigen-decomposition
    of the small ``matrix^T matrix``: the left singular vectors, one entry per
    clip, which an SVD would also compute, are never needed. Otherwise an SVD,
    whose cost then follows the number of rows.
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


class SVDFeatureExtractor(ClipFeatureMixin, BaseEstimator):
    """Feature vectors of clips from their first right singular vectors.

    For a clip ``A`` (``n_frames x n_channels``) with right singular vectors
    ``u_1, u_2, ...`` and singular values ``s_1 >= s_2 >= ...``, its composite
    vector is ``u_1`` (``weighting="first"``) or ``[w_1 u_1, w_2 u_2]`` with
    ``w_i = s_i / sum_k s_k`` (``weighting="first_two"``). Fit stacks the
    training clips' composite vectors into a matrix, takes its SVD ``W S Z^T``
    and keeps the first ``n_components`` columns of ``Z``; a clip's feature
    vector is its composite vector times ``Z[:, :n_components]`` (Li &
    Prabhakaran, section IV). Every component lies in ``[-1, 1]``.

    The SVD is not centred: as in the paper, the first singular vector is the
    direction along which the frames have the largest 2-norm. Clips of any
    length map to vectors of one length, and a clip that repeats the same
    motion several times has the same feature vector as one repetition.

    Parameters
    ----------
    n_components : int, default=8
        Length ``r`` of the feature vectors. At most the composite vector's
        length (``n_channels``, or ``2 * n_channels`` for ``"first_two"``) and
        the number of training clips.
    weighting : {"first", "first_two"}, default="first"
        The first right singular vector alone, or the first two weighted by their
        share of the singular values.
    n_jobs : int, default=None
        Number of jobs for the per-clip SVDs (joblib's meaning); results do not
        depend on it.

    Attributes
    ----------
    components_ : ndarray of shape (n_components, n_composite)
        The rows are ``Z[:, :n_components]^T``.
    singular_values_ : ndarray of shape (n_components,)
        The leading singular values of the stacked composite vectors.
    axes_ : ndarray of shape (n_vectors, n_channels)
        Sign references: each clip's ``u_i`` is flipped so that ``u_i . axes_[i]``
        is non-negative (see Notes).
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    skmotion.neighbors.IntervalIndexNeighbors : indexes these feature vectors.
    skmotion.neighbors.psi : the similarity of two clips from their SVDs.

    Notes
    -----
    Singular vectors have arbitrary signs. The convention here: ``axes_[i]`` is
    the first (uncentred) principal axis of the training clips' ``u_i``, which
    does not depend on their signs, with its largest entry positive; each clip's
    ``u_i`` is turned to point along it. Finally, as in the paper, a feature
    vector whose first component is negative is negated. For ``"first"`` the two
    rules agree; for ``"first_two"`` the first fixes the sign of ``u_2``
    relative to ``u_1``, which the paper leaves open.

    The per-clip SVDs come from the ``n_channels x n_channels`` Gram matrix or,
    for clips with fewer frames than channels, the smaller ``n_frames x
    n_frames`` one (batched eigen-decompositions). An all-zero clip has no
    singular vector and is rejected.

    References
    ----------
    C. Li and B. Prabhakaran, "Indexing of motion capture data for efficient and
    fast similarity search", Journal of Computers 1(3), 2006.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.decomposition import SVDFeatureExtractor
    >>> data = make_motions(n_clips_per_class=4, random_state=0)
    >>> clips = [c[:, 6:] for c in data.clips]  # joint angles without the root
    >>> features = SVDFeatureExtractor(n_components=5).fit_transform(clips)
    >>> features.shape
    (28, 5)
    >>> bool((features[:, 0] >= 0).all() and (abs(features) <= 1).all())
    True
    """

    _parameter_constraints = {
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "weighting": [StrOptions(set(_N_VECTORS))],
        "n_jobs": [Integral, None],
    }
    _motion_tags = MotionTags(output_kind="table")

    def __init__(self, n_components=8, *, weighting="first", n_jobs=None):
        self.n_components = n_components
        self.weighting = weighting
        self.n_jobs = n_jobs

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Learn the projection ``Z[:, :n_components]`` from the training clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray of shape \
                (n_clips, n_frames, n_channels) or DataFrame
            Training clips.
        y : None
            Ignored.

        Returns
        -------
        self : SVDFeatureExtractor
            The fitted transformer.
        """
        clips = check_clips(X, estimator=self, reset=True)
        self._fit_spectra(*clip_spectra(clips, _N_VECTORS[self.weighting], n_jobs=self.n_jobs))
        return self

    def transform(self, X):
        """Feature vectors of clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray of shape \
                (n_clips, n_frames, n_channels) or DataFrame
            Clips with the channels seen in fit.

        Returns
        -------
        features : ndarray of shape (n_clips, n_components)
            Or a DataFrame after ``set_output(transform="pandas")``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        spectra = clip_spectra(clips, _N_VECTORS[self.weighting], n_jobs=self.n_jobs)
        return self._wrap_table(self._transform_spectra(*spectra), clips)

    # -- the work, on precomputed spectra (IntervalIndexNeighbors shares them) --

    def _composite(self, eigenvalues, vectors):
        n_vectors = _N_VECTORS[self.weighting]
        empty = np.flatnonzero(eigenvalues[:, 0] == 0)
        if empty.size:
            raise ValueError(
                f"X: clip {empty[0]} is all zeros; it has no singular vectors, so "
                "SVDFeatureExtractor cannot describe it."
            )
        u = vectors[:, :, :n_vectors]
        signs = np.where(np.einsum("cni,in->ci", u, self.axes_) < 0, -1.0, 1.0)
        u = u * signs[:, None, :]
        if n_vectors == 1:
            return u[:, :, 0]
        singular = np.sqrt(eigenvalues)
        weights = singular[:, :n_vectors] / singular.sum(axis=1, keepdims=True)
        return np.concatenate(
            [weights[:, i : i + 1] * u[:, :, i] for i in range(n_vectors)], axis=1
        )

    def _fit_spectra(self, eigenvalues, vectors):
        n_vectors = _N_VECTORS[self.weighting]
        n_clips, n_channels = eigenvalues.shape
        limit = min(n_clips, n_vectors * n_channels)
        if self.n_components > limit:
            raise ValueError(
                f"n_components={self.n_components} must be at most {limit}: the number "
                f"of training clips ({n_clips}) and the length of the composite vectors "
                f"({n_vectors * n_channels} for weighting={self.weighting!r})."
            )
        self.axes_ = np.stack([_principal_axis(vectors[:, :, i]) for i in range(n_vectors)])
        composite = self._composite(eigenvalues, vectors)
        components, singular = _right_singular(composite, self.n_components)
        self.components_ = components * np.array([_orient(row) for row in components])[:, None]
        self.singular_values_ = singular
        return self

    def _transform_spectra(self, eigenvalues, vectors):
        features = self._composite(eigenvalues, vectors) @ self.components_.T
        features *= np.where(features[:, :1] < 0, -1.0, 1.0)
        return features

    def get_feature_names_out(self, input_features=None):
        """Output feature names ``svdfeatureextractor0, svdfeatureextractor1, ...``.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Ignored; the features are combinations of all channels.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        prefix = type(self).__name__.lower()
        return np.asarray([f"{prefix}{i}" for i in range(self.n_components)], dtype=object)
