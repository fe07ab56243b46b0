"""How IntervalIndexNeighbors reads its input: clips or feature vectors, and labels.

A mixin of :class:`~skmotion.neighbors.IntervalIndexNeighbors` (the class stays
in ``_interval_neighbors``, where pickles look for it): validating ``X`` once and
turning it into tree features and ranking data, and checking ``y``.
"""

import numpy as np
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, column_or_1d, validate_data

from skmotion.decomposition import SVDFeatureExtractor
from skmotion.decomposition._svd_projection import fit_svd_projection, svd_project
from skmotion.neighbors._describe import clip_level_limit, index_spectra, resolve_levels
from skmotion.neighbors._psi import signatures_from_spectra
from skmotion.neighbors._ranking import input_kind
from skmotion.utils._clips import check_clips
from skmotion.utils._labels import check_label_types

__all__ = []

# Levels of the tree when neither n_levels nor features.n_components is given.
_DEFAULT_LEVELS = 7


class _IndexInputMixin:
    """Validation of queries, clips and labels, and their description for the tree."""

    def _describe(self, X, *, reset, ranking=True):
        """Validate ``X`` once; return (feature vectors, ranking data or None).

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
            table = validate_data(self, X, reset=reset, dtype=np.float64)
            if reset:
                self.n_levels_ = self._resolve_levels(table.shape[1], "feature(s) of X")
            return table[:, : self.n_levels_], table
        clips = check_clips(X, estimator=self, reset=reset)
        weighting = self._weighting()
        spectra = index_spectra(clips, weighting, self.k if ranking else 0, n_jobs=self.n_jobs)
        if reset:
            self.n_levels_ = self._resolve_levels(*clip_level_limit(clips, weighting))
            self.projection_ = fit_svd_projection(*spectra, self.n_levels_, weighting)
        tree = svd_project(self.projection_, *spectra)
        return tree, signatures_from_spectra(*spectra, self.k) if ranking else None

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
            return self._tree_features, self._ranking, np.arange(self.n_samples_fit_)
        tree_features, ranking = self._describe(X, reset=False, ranking=ranking)
        return tree_features, ranking, None
