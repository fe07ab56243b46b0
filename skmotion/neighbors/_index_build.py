"""How IntervalIndexNeighbors builds its tree and grows it: entry widths, insertion.

A mixin of :class:`~skmotion.neighbors.IntervalIndexNeighbors` (the class stays
in ``_interval_neighbors``, where pickles look for it): learning ``delta_`` and
the radii, building the :class:`IntervalIndex`; ``insert`` and ``partial_fit``.
"""

import numpy as np
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from skmotion.neighbors._interval_index import IntervalIndex, entry_edges
from skmotion.neighbors._store import GrowableStore
from skmotion.neighbors._widths import learn_delta, radius_for_recall
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import _fit_context

__all__ = []

# The recall the entry widths are learned for when neither rule is given.
_DEFAULT_RECALL = 0.99


class _IndexBuildMixin:
    """Fitting the tree's layout (``_fit``, behind ``fit``), and ``insert``, ``partial_fit``."""

    def _fit(self, X, y, classes=None):
        say(self.verbose, f"{type(self).__name__}: decomposing the clips")
        tree_features, ranking = self._describe(X, reset=True)
        y = self._check_labels(y, len(tree_features))
        if self.input_kind_ == "table":
            self.projection_ = None
        self.effective_metric_ = "euclidean" if self.input_kind_ == "table" else "psi"
        self.classes_ = np.unique(y if classes is None else classes)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
        say(self.verbose, f"{type(self).__name__}: learning the entry widths")
        self.index_ = IntervalIndex(*self._layout(tree_features, encoded, ranking))
        say(self.verbose, f"{type(self).__name__}: building the tree ({self.n_levels_} levels)")
        self.index_.insert(tree_features)
        names = ("weights", "vectors") if self.effective_metric_ == "psi" else ("table",)
        self._stored = GrowableStore(("tree", "encoded", "labels") + names)
        self._store(tree_features, ranking, encoded)
        return self

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
        tree_features, ranking = self._describe(X, reset=False)
        y = self._check_labels(y, len(tree_features), known=True)
        self._check_known(y)
        encoded = np.searchsorted(self.classes_, y)
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
