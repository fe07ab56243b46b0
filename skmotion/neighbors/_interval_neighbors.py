"""IntervalIndexNeighbors: similarity search over clips with the interval index."""

from numbers import Integral, Real

import numpy as np
import pandas as pd
import scipy.sparse as sp
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.metrics.pairwise import euclidean_distances
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, column_or_1d, validate_data

from skmotion.base import ClipEstimatorMixin, MotionTags
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.decomposition._clip_svd import clip_spectra, small_blas
from skmotion.decomposition._svd_features import _N_VECTORS
from skmotion.neighbors._interval_index import IntervalIndex, entry_edges
from skmotion.neighbors._psi import psi_from_signatures, signatures_from_spectra
from skmotion.utils._clips import check_clips
from skmotion.utils._labels import check_label_types
from skmotion.utils._parallel import parallel_map
from skmotion.utils._sklearn_compat import Interval, _fit_context

__all__ = ["IntervalIndexNeighbors"]

# Leaves ranked per parallel task: fixed, so results do not depend on n_jobs.
_LEAVES_PER_TASK = 32


def _is_table(X):
    """A 2-D table of feature vectors rather than a clip collection?

    Clips are a list or tuple of 2-D arrays, a 3-D array or a ``(clip, frame)``
    DataFrame; anything else (a 2-D array, a list of 1-D rows, a plain DataFrame)
    is a table.
    """
    if isinstance(X, (list, tuple)):
        # All rows 1-D: a list with one 1-D clip among 2-D ones is a clip collection
        # with a bad clip, which check_clips names.
        return len(X) > 0 and all(np.ndim(x) == 1 for x in X)
    if isinstance(X, np.ndarray):
        return X.ndim != 3
    if isinstance(X, pd.DataFrame):
        return not isinstance(X.index, pd.MultiIndex)
    # Array-likes are tables; anything else (None, a dict, a file name) goes to
    # check_clips, whose TypeError names what was given.
    return sp.issparse(X) or hasattr(X, "__array__")


def learn_delta(features, labels, quantile):
    """Per component, how far apart clips with the same label can be.

    For each label with two or more clips, the range (max - min) of each
    component over its clips; then the ``quantile`` of these ranges over the
    labels. ``quantile=1`` is the maximum, the paper's ``delta_i``.
    """
    # One pass over the clips sorted by label (not one per label: a collection
    # of repeated motions has about as many labels as clips).
    _, codes, counts = np.unique(labels, return_inverse=True, return_counts=True)
    order = np.argsort(codes.ravel(), kind="stable")
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    ordered = features[order]
    spreads = (
        np.maximum.reduceat(ordered, starts, axis=0) - np.minimum.reduceat(ordered, starts, axis=0)
    )[counts > 1]
    if not len(spreads):
        return np.zeros(features.shape[1])
    return np.quantile(spreads, quantile, axis=0)


def _extend(buffer, n, new):
    """Write ``new`` after the first ``n`` rows of ``buffer``, growing it by doubling.

    Insertions then cost amortised O(new rows), not a copy of everything stored.
    """
    need = n + len(new)
    if buffer is None or need > len(buffer):
        grown = np.empty(
            (max(need, 2 * (0 if buffer is None else len(buffer))),) + new.shape[1:],
            dtype=new.dtype,
        )
        if buffer is not None:
            grown[:n] = buffer[:n]
        buffer = grown
    buffer[n:need] = new
    return buffer


class IntervalIndexNeighbors(ClipEstimatorMixin, ClassifierMixin, BaseEstimator):
    """Similarity search and k-NN classification of clips through an interval index.

    Fit computes each clip's SVD feature vector (:class:`SVDFeatureExtractor`
    with ``n_components=n_levels``) and inserts it into an interval tree with one
    level per component (Li & Prabhakaran). ``delta_i``, how far apart component
    ``i`` of two clips with the same label can be, is learned from ``y``; level
    ``i`` cuts the component's range into entries of width ``epsilon * delta_i``
    (at most ``max_entries``), and a clip is inserted into every entry that
    overlaps ``[c_i - epsilon * delta_i, c_i + epsilon * delta_i]``. A query follows
    one node per level to a leaf; the leaf's clips are its candidates, which are
    then ranked by the similarity :func:`psi` (distance ``1 - psi``).

    ``X`` may also be a 2-D array of feature vectors: the tree indexes its first
    ``n_levels`` columns and candidates are ranked by Euclidean distance.

    Parameters
    ----------
    n_levels : int, default=7
        Levels of the tree, i.e. feature components indexed.
    epsilon : float, default=1.0
        Entry interval factor: entry width and covering radius are
        ``epsilon * delta_i``. With ``epsilon >= 1`` and ``delta_quantile=1``
        every stored clip with the query's label is a candidate when the query
        is a stored clip (recall 1 by construction).
    max_entries : int, default=64
        The most entries a node may have; wider entries are used when capped.
    delta_quantile : float, default=1.0
        ``delta_i`` is this quantile, over the labels with two or more clips, of
        the range of component ``i`` within a label. 1.0 is the paper's rule (the
        maximum); lower values resist one noisy label and prune more.
    n_neighbors : int, default=1
        Neighbours for :meth:`kneighbors` and the vote of :meth:`predict`.
    k : int, default=6
        Eigenvectors compared by :func:`psi` (clips only).
    features : SVDFeatureExtractor, default=None
        The feature extractor (cloned, with ``n_components`` set to
        ``n_levels``); None means ``SVDFeatureExtractor(weighting="first")``.
        Use ``SVDFeatureExtractor(weighting="first_two")`` for the weighted
        first two singular vectors.
    n_jobs : int, default=None
        Number of jobs for the SVDs and the ranking; results do not depend on it.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Class labels.
    delta_ : ndarray of shape (n_levels,)
        The learned ``delta_i``.
    index_ : IntervalIndex
        The tree; stored clip ``j`` has id ``j``.
    feature_extractor_ : SVDFeatureExtractor or None
        The fitted extractor (None for feature-vector input).
    input_kind_ : {"clips", "table"}
        What fit was given.
    effective_metric_ : {"psi", "euclidean"}
        How candidates are ranked.
    labels_ : ndarray of shape (n_samples_fit_,)
        Label of each stored clip (grows with :meth:`insert`).
    n_samples_fit_ : int
        Number of stored clips.
    n_features_in_ : int
        Number of channels (or feature columns) seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    SVDFeatureExtractor : the feature vectors indexed.
    skmotion.metrics.pruning_efficiency : how much of the collection a query prunes.

    Notes
    -----
    A query whose leaf holds fewer than ``n_neighbors`` clips is ranked against
    all stored clips instead, so :meth:`kneighbors` always returns
    ``n_neighbors`` neighbours; :meth:`candidates` shows the pruned sets as they
    are. The first and last entries of a level are open-ended, so components
    outside the fitted range (new queries, inserted clips) fall into them.
    Queries that reach the same leaf are ranked together, as one matrix.

    References
    ----------
    C. Li and B. Prabhakaran, "Indexing of motion capture data for efficient and
    fast similarity search", Journal of Computers 1(3), 2006.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.neighbors import IntervalIndexNeighbors
    >>> data = make_motions(n_clips_per_class=6, random_state=0)
    >>> clips = [c[:, 6:] for c in data.clips]  # joint angles without the root
    >>> index = IntervalIndexNeighbors(n_levels=5, epsilon=1.0).fit(clips, data.target)
    >>> index.n_samples_fit_, len(index.candidates(clips[:3]))
    (42, 3)
    >>> distances, neighbours = index.kneighbors(n_neighbors=2)
    >>> neighbours.shape
    (42, 2)
    >>> index.score(clips, data.target)
    1.0
    """

    _parameter_constraints = {
        "n_levels": [Interval(Integral, 1, None, closed="left")],
        "epsilon": [Interval(Real, 0, None, closed="neither")],
        "max_entries": [Interval(Integral, 1, None, closed="left")],
        "delta_quantile": [Interval(Real, 0, 1, closed="right")],
        "n_neighbors": [Interval(Integral, 1, None, closed="left")],
        "k": [Interval(Integral, 1, None, closed="left")],
        "features": [SVDFeatureExtractor, None],
        "n_jobs": [Integral, None],
    }
    _motion_tags = MotionTags(output_kind="labels")

    def __init__(
        self,
        n_levels=7,
        *,
        epsilon=1.0,
        max_entries=64,
        delta_quantile=1.0,
        n_neighbors=1,
        k=6,
        features=None,
        n_jobs=None,
    ):
        self.n_levels = n_levels
        self.epsilon = epsilon
        self.max_entries = max_entries
        self.delta_quantile = delta_quantile
        self.n_neighbors = n_neighbors
        self.k = k
        self.features = features
        self.n_jobs = n_jobs

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = True  # feature vectors are accepted too
        return tags

    # -- input -------------------------------------------------------------------

    def _describe(self, X, *, reset):
        """Validate ``X`` once; return (tree features, ranking data)."""
        if reset:
            self.input_kind_ = "table" if _is_table(X) else "clips"
        elif ("table" if _is_table(X) else "clips") != self.input_kind_:
            expected = "a 2-D array of feature vectors" if self.input_kind_ == "table" else "clips"
            raise ValueError(
                f"X: {type(self).__name__} was fitted on {expected}; pass the same kind."
            )
        if self.input_kind_ == "table":
            table = validate_data(self, X, reset=reset, dtype=np.float64)
            return table, table
        clips = check_clips(X, estimator=self, reset=reset)
        extractor = self._extractor() if reset else self.feature_extractor_
        n_vectors = max(min(self.k, clips.n_channels), _N_VECTORS[extractor.weighting])
        eigenvalues, vectors = clip_spectra(clips, n_vectors, n_jobs=self.n_jobs)
        if reset:
            extractor._fit_spectra(eigenvalues, vectors)
            extractor.n_features_in_ = clips.n_channels
            self.feature_extractor_ = extractor
        features = extractor._transform_spectra(eigenvalues, vectors)
        return features, signatures_from_spectra(eigenvalues, vectors, self.k)

    def _extractor(self):
        base = SVDFeatureExtractor() if self.features is None else self.features
        return clone(base).set_params(n_components=self.n_levels, n_jobs=self.n_jobs)

    def _check_labels(self, y, n, *, known=False):
        # Labels that must be among classes_ (known=True) are checked against
        # them instead: type_of_target costs milliseconds, a clip insertion less.
        check_label_types(y)
        if not known:
            check_classification_targets(y)
        y = column_or_1d(y, warn=True)
        if len(y) != n:
            raise ValueError(f"y has {len(y)} labels, but X has {n} clips.")
        return y

    # -- fitting -----------------------------------------------------------------

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y):
        """Build the index over clips (or feature vectors) and their labels.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray of shape \
                (n_clips, n_frames, n_channels), DataFrame, or ndarray of shape \
                (n_clips, n_features)
            Clips, or one feature vector per clip.
        y : array-like of shape (n_clips,)
            Labels; clips with the same label are similar (``delta_i`` is learned
            from them).

        Returns
        -------
        self : IntervalIndexNeighbors
            The fitted index.
        """
        return self._fit(X, y)

    def _fit(self, X, y, classes=None):
        features, ranking = self._describe(X, reset=True)
        y = self._check_labels(y, len(features))
        if self.input_kind_ == "table" and features.shape[1] < self.n_levels:
            raise ValueError(
                f"n_levels={self.n_levels} needs feature vectors with at least that many "
                f"columns; X has {features.shape[1]} feature(s)."
            )
        self.classes_ = np.unique(y if classes is None else classes)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
        tree_features = features[:, : self.n_levels]
        self.delta_ = learn_delta(tree_features, encoded, self.delta_quantile)
        radius = self.epsilon * self.delta_
        low, high = tree_features.min(axis=0), tree_features.max(axis=0)
        edges = [
            entry_edges(low[i], high[i], radius[i], self.max_entries) for i in range(self.n_levels)
        ]
        self.index_ = IntervalIndex(edges, radius)
        self.index_.insert(tree_features)
        self.effective_metric_ = "euclidean" if self.input_kind_ == "table" else "psi"
        self.n_samples_fit_ = 0
        self._buffers = None
        self._store(tree_features, ranking, encoded)
        return self

    def _store(self, tree_features, ranking, encoded):
        """Append clips' tree features, ranking data and labels to the stored ones."""
        labels = self.classes_[encoded]
        new = (
            tree_features,
            encoded,
            labels,
            *(ranking if isinstance(ranking, tuple) else (ranking,)),
        )
        old = self._buffers or (None,) * len(new)
        n = self.n_samples_fit_
        self._buffers = tuple(_extend(b, n, a) for b, a in zip(old, new))
        self.n_samples_fit_ = n + len(tree_features)
        self.labels_ = self._buffers[2][: self.n_samples_fit_]  # a view: O(1) per insertion

    @property
    def _tree_features(self):
        return self._buffers[0][: self.n_samples_fit_]

    @property
    def _encoded(self):
        return self._buffers[1][: self.n_samples_fit_]

    @property
    def _ranking(self):
        """Signatures (weights, vectors) for psi, or the feature vectors."""
        parts = tuple(b[: self.n_samples_fit_] for b in self._buffers[3:])
        return parts if self.effective_metric_ == "psi" else parts[0]

    def insert(self, X, y):
        """Add clips to the fitted index, without rebuilding it.

        The feature projection, ``delta_`` and the entries stay as fitted.

        Parameters
        ----------
        X : clips or feature vectors, as given to :meth:`fit`
            The clips to add; they get ids ``n_samples_fit_, n_samples_fit_ + 1, ...``.
        y : array-like of shape (n_clips,)
            Their labels, from ``classes_``.

        Returns
        -------
        self : IntervalIndexNeighbors
            The index, now holding the new clips.
        """
        check_is_fitted(self)
        features, ranking = self._describe(X, reset=False)
        y = self._check_labels(y, len(features), known=True)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
        tree_features = features[:, : self.n_levels]
        self.index_.insert(tree_features)
        self._store(tree_features, ranking, encoded)
        return self

    def _check_known(self, y):
        unseen = np.setdiff1d(y, self.classes_)
        if unseen.size:
            raise ValueError(
                f"y: labels {unseen.tolist()} are not among the classes "
                f"{self.classes_.tolist()}; refit (or pass classes to the first partial_fit) "
                "to add classes."
            )

    def partial_fit(self, X, y, classes=None):
        """Fit on the first call, then :meth:`insert`.

        Parameters
        ----------
        X : clips or feature vectors
            Clips to index.
        y : array-like of shape (n_clips,)
            Their labels.
        classes : array-like of shape (n_classes,), default=None
            All the labels later calls may bring; used on the first call only
            (by default the labels of that call).

        Returns
        -------
        self : IntervalIndexNeighbors
            The index.
        """
        if not hasattr(self, "index_"):
            return self._fit_first(X, y, classes)
        return self.insert(X, y)

    @_fit_context(prefer_skip_nested_validation=True)
    def _fit_first(self, X, y, classes):
        return self._fit(X, y, classes)

    # -- queries -------------------------------------------------------------------

    def _queries(self, X):
        """(tree features, ranking data, self ids or None) of the queries."""
        check_is_fitted(self)
        if X is None:
            return self._tree_features, self._ranking, np.arange(self.n_samples_fit_)
        features, ranking = self._describe(X, reset=False)
        return features[:, : self.n_levels], ranking, None

    def candidates(self, X=None):
        """The pruned candidate set of each query: ids of the clips in its leaf.

        Parameters
        ----------
        X : clips or feature vectors, default=None
            Queries; None queries every stored clip, leaving out the clip itself.

        Returns
        -------
        candidates : list of ndarray of int
            Sorted ids of stored clips (positions in the fitted collection, then
            inserted clips), one array per query.
        """
        features, _, self_ids = self._queries(X)
        found = self.index_.candidates(features)
        if self_ids is not None:
            found = [c[c != i] for c, i in zip(found, self_ids)]
        return found

    def _distances(self, ranking, rows, columns):
        if self.effective_metric_ == "euclidean":
            return euclidean_distances(ranking[rows], self._ranking[columns])
        weights, vectors = ranking
        stored_weights, stored_vectors = self._ranking
        return 1.0 - psi_from_signatures(
            weights[rows], vectors[rows], stored_weights[columns], stored_vectors[columns]
        )

    def _rank_leaf(self, leaf, rows, ranking, self_ids, n_neighbors):
        columns = self.index_.leaf_items(leaf).astype(np.intp)
        n_usable = len(columns) - (1 if self_ids is not None else 0)
        if n_usable < n_neighbors:
            columns = np.arange(self.n_samples_fit_)
        distances = self._distances(ranking, rows, columns)
        if self_ids is not None:
            distances[columns[None, :] == self_ids[rows][:, None]] = np.inf
        if columns.size > 4 * n_neighbors:
            part = np.argpartition(distances, n_neighbors - 1, axis=1)[:, :n_neighbors]
            part.sort(axis=1)  # equal distances: the lower id first
        else:
            part = np.broadcast_to(np.arange(columns.size), distances.shape)
        order = np.argsort(np.take_along_axis(distances, part, axis=1), axis=1, kind="stable")[
            :, :n_neighbors
        ]
        chosen = np.take_along_axis(part, order, axis=1)
        return rows, np.take_along_axis(distances, chosen, axis=1), columns[chosen]

    def kneighbors(self, X=None, n_neighbors=None, return_distance=True):
        """The nearest stored clips of each query, among its candidates.

        Parameters
        ----------
        X : clips or feature vectors, default=None
            Queries; None queries every stored clip and leaves the clip itself out.
        n_neighbors : int, default=None
            Number of neighbours; ``self.n_neighbors`` by default.
        return_distance : bool, default=True
            Whether to return the distances.

        Returns
        -------
        distances : ndarray of shape (n_queries, n_neighbors)
            ``1 - psi`` (clips) or Euclidean distances, increasing along each row.
            Only with ``return_distance=True``.
        indices : ndarray of shape (n_queries, n_neighbors)
            Ids of the neighbours; equal distances are ordered by id.
        """
        n_neighbors = self.n_neighbors if n_neighbors is None else n_neighbors
        features, ranking, self_ids = self._queries(X)
        available = self.n_samples_fit_ - (1 if self_ids is not None else 0)
        if not isinstance(n_neighbors, Integral) or not 1 <= n_neighbors <= available:
            raise ValueError(
                f"n_neighbors must be an integer from 1 to {available} (the stored clips"
                f"{' other than the query' if self_ids is not None else ''}); got {n_neighbors!r}."
            )
        leaves = self.index_.leaf_of(features)
        order = np.argsort(leaves, kind="stable")
        bounds = np.flatnonzero(np.r_[True, leaves[order][1:] != leaves[order][:-1], True])
        groups = [(leaves[order[a]], order[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]
        tasks = [groups[i : i + _LEAVES_PER_TASK] for i in range(0, len(groups), _LEAVES_PER_TASK)]

        def rank(task):
            return [
                self._rank_leaf(leaf, rows, ranking, self_ids, n_neighbors) for leaf, rows in task
            ]

        distances = np.empty((len(features), n_neighbors))
        indices = np.empty((len(features), n_neighbors), dtype=np.intp)
        with small_blas():
            ranked = parallel_map(rank, tasks, n_jobs=self.n_jobs)
        for part in ranked:
            for rows, dist, ind in part:
                distances[rows], indices[rows] = dist, ind
        return (distances, indices) if return_distance else indices

    def predict_proba(self, X):
        """Share of each class among the ``n_neighbors`` nearest stored clips.

        Parameters
        ----------
        X : clips or feature vectors
            Queries.

        Returns
        -------
        proba : ndarray of shape (n_queries, n_classes)
            Columns in the order of ``classes_``.
        """
        neighbours = self.kneighbors(X, return_distance=False)
        votes = np.zeros((len(neighbours), len(self.classes_)))
        np.add.at(votes, (np.arange(len(neighbours))[:, None], self._encoded[neighbours]), 1.0)
        return votes / neighbours.shape[1]

    def predict(self, X):
        """Majority label of the ``n_neighbors`` nearest stored clips.

        Parameters
        ----------
        X : clips or feature vectors
            Queries.

        Returns
        -------
        labels : ndarray of shape (n_queries,)
            Ties go to the first class in ``classes_``.
        """
        proba = self.predict_proba(X)
        return self.classes_[proba.argmax(axis=1)]
