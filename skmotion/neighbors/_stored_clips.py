"""The clips an IntervalIndexNeighbors holds, and distances from queries to them.

A mixin of :class:`~skmotion.neighbors.IntervalIndexNeighbors` (the class stays
in ``_interval_neighbors``, where pickles look for it): each stored clip's tree
features, label and ranking data (psi signatures or feature vectors) in a
:class:`GrowableStore`, and the ranking of a leaf's queries against its clips.
"""

import numpy as np
from sklearn.metrics.pairwise import euclidean_distances

from skmotion.neighbors._ranking import psi_distance_block, smallest_k

__all__ = []


class _StoredClipsMixin:
    """The stored clips' arrays, and distances of queries to them."""

    def _store(self, tree_features, ranking, encoded):
        """Append clips' tree features, ranking data and labels to the stored ones."""
        ranking = ranking if isinstance(ranking, tuple) else (ranking,)
        parts = dict(zip(self._stored.names[3:], ranking))
        self._stored.append(
            tree=tree_features, encoded=encoded, labels=self.classes_[encoded], **parts
        )
        self.n_samples_fit_ = len(self._stored)
        self.labels_ = self._stored["labels"]  # a view: O(1) per insertion

    @property
    def _tree_features(self):
        return self._stored["tree"]

    @property
    def _encoded(self):
        return self._stored["encoded"]

    @property
    def _ranking(self):
        """Signatures (weights, vectors) for psi, or the feature vectors."""
        if self.effective_metric_ == "psi":
            return self._stored["weights"], self._stored["vectors"]
        return self._stored["table"]

    def _distances(self, ranking, rows, columns):
        if self.effective_metric_ == "euclidean":
            return euclidean_distances(ranking[rows], self._ranking[columns])
        return psi_distance_block(ranking, self._ranking, rows, columns)

    def _rank_leaf(self, leaf, rows, ranking, self_ids, n_neighbors):
        columns = self.index_.leaf_items(leaf).astype(np.intp)
        n_usable = len(columns) - (1 if self_ids is not None else 0)
        if n_usable < n_neighbors:
            columns = np.arange(self.n_samples_fit_)
        distances = self._distances(ranking, rows, columns)
        if self_ids is not None:
            distances[columns[None, :] == self_ids[rows][:, None]] = np.inf
        chosen, nearest = smallest_k(distances, n_neighbors)
        return nearest, columns[chosen]
