"""IntervalIndexNeighbors: similarity search over clips with the interval index.

The estimator, whole: reading its input (clips or feature vectors), learning
the tree's layout and building it (``fit``, ``insert``, ``partial_fit``), and the
queries. The tree is an :class:`~skmotion.neighbors._interval_index.IntervalIndex`;
the stored clips and their ranking are a
:class:`~skmotion.neighbors._stored_clips.StoredClips` it holds; the entry widths
are learned by the free functions of ``_widths`` and a clip's spectra come from
``_index_features``.
"""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.utils import check_random_state
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, column_or_1d, validate_data

from skmotion.base import ClipEstimatorMixin, MotionTags
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.decomposition._svd_projection import fit_svd_projection, svd_project
from skmotion.neighbors._index_features import (
    clip_level_limit,
    index_spectra,
    input_kind,
    resolve_levels,
)
from skmotion.neighbors._interval_index import IntervalIndex, entry_edges
from skmotion.neighbors._psi import signatures_from_spectra
from skmotion.neighbors._ranking import nearest_in_leaves
from skmotion.neighbors._stored_clips import GrowableStore, StoredClips
from skmotion.neighbors._widths import learn_delta, radius_for_recall
from skmotion.utils._clips import check_clips
from skmotion.utils._labels import check_label_types
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["IntervalIndexNeighbors", "learn_delta"]

# Leaves ranked per parallel task: fixed, so results do not depend on n_jobs.
_LEAVES_PER_TASK = 32
# Levels of the tree when neither n_levels nor features.n_components is given.
_DEFAULT_LEVELS = 7
# The recall the entry widths are learned for when neither rule is given.
_DEFAULT_RECALL = 0.99
# Feature components the discriminant axes are learned from (at most what the data allows):
# on MSRC-12's development people, 20, 40 and 60 (all) components gave held-out pruning
# 0.92, 0.94 and 0.95 at recall 0.96 (benchmarks/bench_neighbors_msrc12.py).
_DISCRIMINANT_INPUTS = 64


class IntervalIndexNeighbors(ClipEstimatorMixin, ClassifierMixin, BaseEstimator):
    """Similarity search and k-NN classification of clips through an interval index.

    Fit computes each clip's SVD feature vector (the projection of
    :func:`~skmotion.decomposition.fit_svd_projection`, with ``n_levels_``
    components) and inserts it into an interval tree with one
    level per component (Li & Prabhakaran). ``delta_i``, how far apart component
    ``i`` of two clips with the same label can be, is learned from ``y``; level
    ``i`` cuts the component's range into entries of width ``epsilon * delta_i``
    (at most ``max_entries``), and a clip is inserted into every entry that
    overlaps ``[c_i - epsilon * delta_i, c_i + epsilon * delta_i]``. A query follows
    one node per level to a leaf; the leaf's clips are its candidates, which are
    then ranked by the similarity :func:`psi` (distance ``1 - psi``).

    ``X`` may also be a 2-D array of feature vectors: the tree indexes its first
    ``n_levels_`` columns and candidates are ranked by Euclidean distance.

    Parameters
    ----------
    n_levels : int or None, default=None
        Levels of the tree, i.e. feature components indexed. None means
        ``features.n_components`` when that is set, else 7 capped at what the
        data allows (the feature columns, or for clips the number of training
        clips and the composite vector's length: 6 on 6-channel clips with
        ``weighting="first"``); ``n_levels_`` holds the value used. An explicit
        value the data cannot give is an error naming the limit.
    target_recall : float in (0, 1] or None, default=None
        Learn each level's radius (and entry width) so that this share of the
        training clips' similar pairs survives the tree, pruning as much as
        possible (see Notes). None means 0.99 unless ``epsilon`` is given.
    epsilon : float or None, default=None
        The paper's rule instead: entry width and covering radius are
        ``epsilon * delta_i``. With ``epsilon >= 1`` and ``delta_quantile=1``
        every stored clip with the query's label is a candidate when the query
        is a stored clip (recall 1 by construction). Giving both ``epsilon``
        and ``target_recall`` is an error.
    similar : {"labels", "psi"}, default="labels"
        Which training pairs ``target_recall`` keeps: clips with the same label,
        or each clip and its nearest other clip by psi (for clips whose labels
        are classes rather than repetitions: then the pairs are the repetitions
        psi finds, and the recall is that of the exact psi 1-NN).
    width_factor : float, default=1.0
        Entry width over covering radius. 1 is the paper's layout; wider
        entries (2) put each clip into fewer leaves (about ``2**n_levels``
        instead of ``3**n_levels``: less memory, faster insertion) at some cost
        in pruning, which ``target_recall`` takes into account.
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
    axes : {"svd", "discriminant"}, default="svd"
        What the tree's levels index. ``"svd"``: the leading feature
        components (the paper). ``"discriminant"``: the leading discriminant
        axes of the first 64 feature components (all the data allows when
        fewer: 60 for 60-channel clips with the first vector), learned from
        ``y``: Fisher's discriminant, between-label over within-label
        variance, with the within-label covariance shrunk by Ledoit-Wolf
        (sklearn's ``LinearDiscriminantAnalysis(solver="eigen",
        shrinkage="auto")``). Levels then spread the labels apart and the
        widths cover the within-label spread only: on MSRC-12 repetitions
        (similar = same gesture by the same person) this raises the held-out
        pruning at recall 0.95 from about 0.8 to 0.9 or more. It needs
        labels that are repetitions with several clips each: with few clips
        per label the axes fit the training clips' spread and held-out recall
        falls (see the user guide). The ranking (psi, or Euclidean on the
        feature columns) is unchanged.
    features : SVDFeatureExtractor, default=None
        Its ``weighting`` chooses the feature vectors; None means
        ``SVDFeatureExtractor(weighting="first")``. Use
        ``SVDFeatureExtractor(weighting="first_two")`` for the weighted first
        two singular vectors. The tree has one level per feature component, so
        its ``n_components`` (when not None) sets the number of levels; giving
        both ``n_levels`` and a different ``features.n_components`` is an error.
    n_jobs : int, default=None
        Number of jobs for the SVDs and the ranking; results do not depend on it.
    verbose : int, default=0
        Print a line per stage of fit (decomposition, widths, tree) on
        standard error when 1 or more; fit takes minutes at 10^5 clips.
    random_state : int, RandomState instance or None, default=None
        Draws the pairs ``target_recall`` learns from when there are more than
        50,000 (and the anchors of ``similar="psi"``, at most 2,000).

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Class labels.
    n_levels_ : int
        Levels of the tree (= feature components or axes indexed).
    axes_ : ndarray of shape (n_inputs, n_levels_) or None
        With ``axes="discriminant"``: the tree's axes, applied to the first
        ``n_inputs`` feature components (or columns); None with ``"svd"``.
    delta_ : ndarray of shape (n_levels_,)
        The learned ``delta_i`` (the paper's rule).
    radius_ : ndarray of shape (n_levels_,)
        Covering radius (and entry width) of each level: ``epsilon * delta_``,
        or learned for ``target_recall``.
    width_rule_ : {"target_recall", "epsilon"}
        Which rule set ``radius_``.
    training_survival_ : float
        With ``target_recall``: the share of random pairs of training clips
        that survive the tree (1 - the pruning expected on such pairs).
    index_ : IntervalIndex
        The tree; stored clip ``j`` has id ``j``.
    projection_ : SVDProjection or None
        The fitted feature projection (None for feature-vector input); with
        ``axes="discriminant"`` it has the ``n_inputs`` components the axes read.
    feature_extractor_ : SVDFeatureExtractor or None
        An extractor applying ``projection_`` (None for feature-vector input):
        the SVD feature vectors, whose first ``n_levels_`` components the tree
        indexes (or, with ``axes="discriminant"``, their product with ``axes_``).
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
    Entry widths. ``target_recall`` (the default, 0.99) learns the radii from
    the training clips' similar pairs (same label, or psi nearest neighbours):
    for a few shapes of the radii (per-level quantiles of the pairs'
    component distances) the common scale is the smallest at which that share
    of the pairs survives the tree (computed exactly, with the entries the tree
    will have), and the shape that lets the fewest random training pairs
    through is kept (``training_survival_``). The held-out recall is close to,
    not guaranteed at, the target. ``epsilon`` gives the paper's rule instead.
    Measured on held-out queries (``benchmarks/bench_neighbors_pruning.py``),
    the learned widths prune more than ``epsilon=1.0`` at the same recall on
    every development set.

    Every clip is divided by its largest absolute value before its SVD: the
    singular vectors, their energy shares and so psi and the feature vectors do
    not depend on a clip's scale, and clips of any finite magnitude (1e-300 to
    1e300) are described alike.

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
    >>> index.n_samples_fit_, index.n_levels_, len(index.candidates(clips[:3]))
    (42, 5, 3)
    >>> distances, neighbours = index.kneighbors(n_neighbors=2)
    >>> neighbours.shape
    (42, 2)
    >>> index.score(clips, data.target)
    1.0
    """

    _parameter_constraints = {
        "n_levels": [Interval(Integral, 1, None, closed="left"), None],
        "target_recall": [Interval(Real, 0, 1, closed="right"), None],
        "epsilon": [Interval(Real, 0, None, closed="neither"), None],
        "similar": [StrOptions({"labels", "psi"})],
        "width_factor": [Interval(Real, 0, None, closed="neither")],
        "max_entries": [Interval(Integral, 1, None, closed="left")],
        "delta_quantile": [Interval(Real, 0, 1, closed="right")],
        "axes": [StrOptions({"svd", "discriminant"})],
        "n_neighbors": [Interval(Integral, 1, None, closed="left")],
        "k": [Interval(Integral, 1, None, closed="left")],
        "features": [SVDFeatureExtractor, None],
        "n_jobs": [Integral, None],
        "verbose": ["verbose"],
        "random_state": ["random_state"],
    }
    _motion_tags = MotionTags(output_kind="labels")

    def __init__(
        self,
        n_levels=None,
        *,
        target_recall=None,
        epsilon=None,
        similar="labels",
        width_factor=1.0,
        max_entries=64,
        delta_quantile=1.0,
        axes="svd",
        n_neighbors=1,
        k=6,
        features=None,
        n_jobs=None,
        verbose=0,
        random_state=None,
    ):
        self.n_levels = n_levels
        self.target_recall = target_recall
        self.epsilon = epsilon
        self.similar = similar
        self.width_factor = width_factor
        self.max_entries = max_entries
        self.delta_quantile = delta_quantile
        self.axes = axes
        self.n_neighbors = n_neighbors
        self.k = k
        self.features = features
        self.n_jobs = n_jobs
        self.verbose = verbose
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = True  # feature vectors are accepted too
        return tags

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
        say(self.verbose, f"{type(self).__name__}: decomposing the clips")
        inputs, ranking = self._describe(X, reset=True)
        y = self._check_labels(y, len(inputs))
        if self.input_kind_ == "table":
            self.projection_ = None
        self.effective_metric_ = "euclidean" if self.input_kind_ == "table" else "psi"
        self.classes_ = np.unique(y if classes is None else classes)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
        self.axes_ = self._learn_axes(inputs, encoded)
        tree_features = self._to_tree(inputs)
        say(self.verbose, f"{type(self).__name__}: learning the entry widths")
        self.index_ = IntervalIndex(*self._layout(tree_features, encoded, ranking))
        say(self.verbose, f"{type(self).__name__}: building the tree ({self.n_levels_} levels)")
        self.index_.insert(tree_features)
        self._stored = StoredClips(self.effective_metric_)
        self._store(tree_features, ranking, encoded)
        return self

    def _learn_axes(self, inputs, encoded):
        """The discriminant axes (see ``axes``), or None for the leading components."""
        if self.axes == "svd":
            return None
        if len(np.unique(encoded)) < 2:
            raise ValueError(
                'axes="discriminant" needs two or more labels in y; got one. '
                'Use axes="svd" for a collection of one label.'
            )
        inputs = inputs[:, : self._n_inputs(inputs.shape[1])]
        lda = LinearDiscriminantAnalysis(solver="eigen", shrinkage="auto").fit(inputs, encoded)
        return lda.scalings_[:, : self.n_levels_]

    def _to_tree(self, inputs):
        """What the tree indexes: the first ``n_levels_`` components, or the axes."""
        axes = getattr(self, "axes_", None)  # pickles from before axes hold none
        if axes is None:
            return inputs[:, : self.n_levels_]
        return inputs[:, : len(axes)] @ axes

    def _n_inputs(self, limit):
        """Feature components (or columns) read: ``n_levels_``, or up to 64 for the axes."""
        if self.axes == "svd":
            return self.n_levels_
        return max(self.n_levels_, min(limit, _DISCRIMINANT_INPUTS))

    def _layout(self, tree_features, encoded, ranking):
        """Learn ``delta_`` and ``radius_``; return the tree's (edges, radius).

        The layout depends on the training feature vectors and labels only (and
        on psi signatures for ``similar="psi"``), so a sharded index learns it
        once and every shard uses it.
        """
        self.delta_ = learn_delta(tree_features, encoded, self.delta_quantile)
        radius = self.radius_ = self._radius(tree_features, encoded, ranking)
        low, high = tree_features.min(axis=0), tree_features.max(axis=0)
        edges = [
            entry_edges(low[i], high[i], self.width_factor * radius[i], self.max_entries)
            for i in range(len(radius))
        ]
        return edges, radius

    def _radius(self, tree_features, encoded, ranking):
        """Each level's radius by the paper's rule or learned for the recall asked."""
        if self.epsilon is not None and self.target_recall is not None:
            raise ValueError(
                f"epsilon={self.epsilon} and target_recall={self.target_recall}: give one rule "
                "for the entry widths (epsilon: the paper's epsilon * delta_i; target_recall: "
                "learned from the similar pairs)."
            )
        if self.epsilon is not None:
            self.width_rule_ = "epsilon"
            return self.epsilon * self.delta_
        if self.similar == "psi" and self.effective_metric_ != "psi":
            raise ValueError('similar="psi" needs clips; X is a table of feature vectors.')
        self.width_rule_ = "target_recall"
        radius, self.training_survival_ = radius_for_recall(
            tree_features,
            encoded if self.similar == "labels" else ranking,
            _DEFAULT_RECALL if self.target_recall is None else self.target_recall,
            check_random_state(self.random_state),
            max_entries=self.max_entries,
            width_factor=self.width_factor,
            n_jobs=self.n_jobs,
        )
        return radius

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
        inputs, ranking = self._describe(X, reset=False)
        y = self._check_labels(y, len(inputs), known=True)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
        tree_features = self._to_tree(inputs)
        self.index_.insert(tree_features)
        self._store(tree_features, ranking, encoded)
        return self

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

    def _store(self, tree_features, ranking, encoded):
        """Append clips to the stored ones."""
        self._stored.append_clips(tree_features, ranking, encoded, self.classes_[encoded])
        self.n_samples_fit_ = len(self._stored)
        self.labels_ = self._stored["labels"]  # a view: O(1) per insertion

    def __setstate__(self, state):
        super().__setstate__(state)
        self.__dict__.setdefault("axes", "svd")  # pickled before the parameter existed
        # an unfitted index has no store; one pickled before StoredClips holds a GrowableStore
        if type(getattr(self, "_stored", None)) is GrowableStore:
            self._stored = StoredClips.adopt(self._stored)

    # -- input -------------------------------------------------------------------

    def _describe(self, X, *, reset, ranking=True):
        """Validate ``X`` once; return (feature vectors, ranking data or None).

        The feature vectors hold what the tree's levels are made of (see
        :meth:`_to_tree`): the SVD components the projection gives (``n_levels_``,
        or more for the axes), or the table's columns.

        Without ranking (candidate sets only) a clip needs only its first
        singular vector(s), not the ``k`` eigenvectors of psi.
        """
        kind = input_kind(X)
        if reset:
            self.input_kind_ = kind
        elif kind != self.input_kind_:
            expected = "a 2-D array of feature vectors" if self.input_kind_ == "table" else "clips"
            raise ValueError(
                f"X: {type(self).__name__} was fitted on {expected}; pass the same kind."
            )
        if self.input_kind_ == "table":
            table = None if reset else self._checked_table(X)
            if table is None:
                table = validate_data(self, X, reset=reset, dtype=np.float64)
            if reset:
                self.n_levels_ = self._resolve_levels(table.shape[1], "feature(s) of X")
            return table, table
        clips = check_clips(X, estimator=self, reset=reset)
        weighting = self._weighting()
        spectra = index_spectra(clips, weighting, self.k if ranking else 0, n_jobs=self.n_jobs)
        if reset:
            limit, what = clip_level_limit(clips, weighting)
            self.n_levels_ = self._resolve_levels(limit, what)
            self.projection_ = fit_svd_projection(*spectra, self._n_inputs(limit), weighting)
        tree = svd_project(self.projection_, *spectra)
        return tree, signatures_from_spectra(*spectra, self.k) if ranking else None

    def _checked_table(self, X):
        """``X`` itself when it is what ``validate_data`` would return unchanged, else None.

        A 2-D float64 array of the fitted width with finite values, fitted
        without feature names: sklearn's validation of one query costs several
        times the search (it looks for DataFrames, converts, checks names).
        """
        if (
            type(X) is np.ndarray
            and X.dtype == np.float64
            and X.ndim == 2
            and X.shape[0] > 0
            and X.shape[1] == self.n_features_in_
            and "feature_names_in_" not in vars(self)
            and np.isfinite(X).all()
        ):
            return X
        return None

    def _weighting(self):
        return "first" if self.features is None else self.features.weighting

    def _resolve_levels(self, limit, what):
        """``n_levels_``: the levels asked for, or the capped default (see ``n_levels``)."""
        from_features = None if self.features is None else self.features.n_components
        return resolve_levels(self.n_levels, from_features, limit, what, _DEFAULT_LEVELS)

    @property
    def feature_extractor_(self):
        """A fitted :class:`SVDFeatureExtractor` giving this index's feature vectors."""
        check_is_fitted(self)
        if self.input_kind_ == "table":
            return None
        return SVDFeatureExtractor.from_projection(
            self.projection_, self.n_features_in_, n_jobs=self.n_jobs
        )

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

    def _check_known(self, y):
        unseen = np.setdiff1d(y, self.classes_)
        if unseen.size:
            raise ValueError(
                f"y: labels {unseen.tolist()} are not among the classes "
                f"{self.classes_.tolist()}; refit (or pass classes to the first partial_fit) "
                "to add classes."
            )

    def _queries(self, X, ranking=True):
        """(tree features, ranking data, self ids or None) of the queries."""
        if "index_" not in vars(self):  # fitted: skip check_is_fitted's tags (~10 us a call)
            check_is_fitted(self)
        if X is None:
            return self._stored["tree"], self._stored.ranking, np.arange(self.n_samples_fit_)
        inputs, ranking = self._describe(X, reset=False, ranking=ranking)
        return self._to_tree(inputs), ranking, None

    # -- queries -------------------------------------------------------------------

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
        features, _, self_ids = self._queries(X, ranking=False)
        found = self.index_.candidates(features)
        if self_ids is not None:
            found = [c[c != i] for c, i in zip(found, self_ids)]
        return found

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
        distances, indices = nearest_in_leaves(
            self.index_.leaf_of(features),
            lambda leaf, rows: self._stored.rank_leaf(
                self.index_.leaf_items(leaf).astype(np.intp), rows, ranking, self_ids, n_neighbors
            ),
            n_neighbors,
            leaves_per_task=_LEAVES_PER_TASK,
            n_jobs=self.n_jobs,
        )
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
        np.add.at(
            votes, (np.arange(len(neighbours))[:, None], self._stored["encoded"][neighbours]), 1.0
        )
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
