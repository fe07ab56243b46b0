"""SVDFeatureExtractor: one fixed-length feature vector per clip from its SVD."""

from numbers import Integral

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.decomposition._clip_svd import clip_spectra
from skmotion.decomposition._svd_projection import (
    N_VECTORS,
    SVDProjection,
    fit_svd_projection,
    max_svd_components,
    svd_project,
)
from skmotion.utils._clips import check_clips
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["SVDFeatureExtractor", "resolve_n_components"]

# The length of the feature vectors when n_components is None (capped by the data).
_DEFAULT_COMPONENTS = 8


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
    n_components : int or None, default=None
        Length ``r`` of the feature vectors. At most the composite vector's
        length (``n_channels``, or ``2 * n_channels`` for ``"first_two"``) and
        the number of training clips; a larger value is an error that names
        the limit. None means 8, capped at that limit (so the default works on
        6-channel data); ``n_components_`` holds the value used.
    weighting : {"first", "first_two"}, default="first"
        The first right singular vector alone, or the first two weighted by their
        share of the singular values.
    n_jobs : int, default=None
        Number of jobs for the per-clip SVDs (joblib's meaning); results do not
        depend on it.

    Attributes
    ----------
    n_components_ : int
        Length of the feature vectors (``n_components``, or the capped default).
    components_ : ndarray of shape (n_components_, n_composite)
        The rows are ``Z[:, :n_components]^T``.
    singular_values_ : ndarray of shape (n_components_,)
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
        "n_components": [Interval(Integral, 1, None, closed="left"), None],
        "weighting": [StrOptions(set(N_VECTORS))],
        "n_jobs": [Integral, None],
    }
    _motion_tags = MotionTags(output_kind="table")

    def __init__(self, n_components=None, *, weighting="first", n_jobs=None):
        self.n_components = n_components
        self.weighting = weighting
        self.n_jobs = n_jobs

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Learn the projection ``Z[:, :n_components_]`` from the training clips.

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
        spectra = self._spectra(clips)
        n_components = resolve_n_components(
            self.n_components, len(clips), clips.n_channels, self.weighting
        )
        self._set_projection(fit_svd_projection(*spectra, n_components, self.weighting))
        return self

    def _spectra(self, clips):
        # "first" needs the leading pair only (the compiled iterative route, the
        # interval index's); "first_two" weighs by all the singular values.
        method = "iterative" if self.weighting == "first" else "exact"
        return clip_spectra(clips, N_VECTORS[self.weighting], method=method, n_jobs=self.n_jobs)

    @classmethod
    def from_projection(cls, projection, n_features_in, *, n_jobs=None):
        """A fitted extractor applying a projection fitted elsewhere.

        Parameters
        ----------
        projection : SVDProjection
            From :func:`~skmotion.decomposition.fit_svd_projection` (for example
            the one :class:`~skmotion.neighbors.IntervalIndexNeighbors` learned).
        n_features_in : int
            Number of channels of the clips it was fitted on.
        n_jobs : int, default=None
            Number of jobs for the per-clip SVDs of :meth:`transform`.

        Returns
        -------
        extractor : SVDFeatureExtractor
            Fitted: its ``transform`` gives the projection's feature vectors.
        """
        extractor = cls(
            n_components=len(projection.components), weighting=projection.weighting, n_jobs=n_jobs
        )
        extractor._set_projection(projection)
        extractor.n_features_in_ = int(n_features_in)
        return extractor

    def _set_projection(self, projection):
        self.axes_ = projection.axes
        self.components_ = projection.components
        self.singular_values_ = projection.singular_values
        self.n_components_ = len(projection.components)

    @property
    def projection_(self):
        """The fitted projection as an :class:`SVDProjection` (for :func:`svd_project`)."""
        check_is_fitted(self)
        return SVDProjection(self.weighting, self.axes_, self.components_, self.singular_values_)

    def transform(self, X):
        """Feature vectors of clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray of shape \
                (n_clips, n_frames, n_channels) or DataFrame
            Clips with the channels seen in fit.

        Returns
        -------
        features : ndarray of shape (n_clips, n_components_)
            Or a DataFrame after ``set_output(transform="pandas")``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        spectra = self._spectra(clips)
        return self._wrap_table(svd_project(self.projection_, *spectra), clips)

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
        return np.asarray([f"{prefix}{i}" for i in range(self.n_components_)], dtype=object)


def resolve_n_components(n_components, n_clips, n_channels, weighting):
    """``n_components``, or for None the default capped at what the data allows."""
    if n_components is None:
        return min(_DEFAULT_COMPONENTS, max_svd_components(n_clips, n_channels, weighting))
    return int(n_components)
