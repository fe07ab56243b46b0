"""MotionTreeHMM's class-score features: ``transform``, their names, out-of-fold training rows.

``transform`` gives a clip's per-layer class scores (the functions of
``_calibration``); ``fit_transform`` gives the training clips' rows from
graphs counted without each clip's fold (``_held_out_scores``, whose class
totals also fit the temperature of ``predict_proba`` in ``fit``).
"""

import numpy as np
from sklearn.utils.validation import check_is_fitted

from skmotion.tree._calibration import class_score_features, class_score_names, layer_class_scores
from skmotion.utils._clips import check_clips
from skmotion.utils._progress import progress
from skmotion.utils._sklearn_compat import _fit_context

__all__ = ["ClassScoreFeaturesMixin"]


class ClassScoreFeaturesMixin:
    """The class-score features of :class:`MotionTreeHMM`, which mixes this class in.

    ``transform``, ``get_feature_names_out`` and ``fit_transform``. Uses the
    model's ``_fit`` and ``_count_graphs`` and its recognition methods
    (``_graph_scores``, ``_class_totals``, ``_layer_log_probs``).
    """

    @_fit_context(prefer_skip_nested_validation=True)
    def fit_transform(self, X, y, groups=None):
        """Fit, and return the training clips' class-score features, out of fold.

        A training clip's transition graphs include its own transitions, so its
        ``transform`` scores are optimistic (its class looks surer than it will
        on new clips) and a model stacked on them learns to trust them too much.
        As sklearn's ``StackingClassifier`` does with ``cross_val_predict``, each
        row here comes from the internal cross-validation's graphs counted
        without the clip's fold (the folds of ``calibration_cv`` and ``groups``;
        the tree, built without labels, is shared). So ``fit_transform(X, y)``
        differs from ``fit(X, y).transform(X)``; ``transform`` of new clips uses
        the graphs of all training clips. When no folds can be made
        (``calibration_cv=None``, a class of one clip) the rows are in-sample.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        y : array-like of shape (n_clips,)
        groups : array-like of shape (n_clips,), default=None
            See ``fit``.

        Returns
        -------
        features : ndarray of shape (n_clips, n_scored_layers * n_classes) or DataFrame
            See ``transform``.
        """
        clips, log_prob = self._fit(X, y, groups)
        if log_prob is None:
            log_prob = self._layer_log_probs(clips)
        return self._wrap_table(class_score_features(log_prob, [len(c) for c in clips]), clips)

    def _held_out_scores(self, clips, labels, offsets, y_index, folds):
        """Scores of every clip by graphs counted without its fold (calibration and stacking).

        The tree is shared (it is built without labels); each fold recounts the
        graphs from its training clips only and scores its held-out clips.
        Returns the class totals ``(n_clips, n_classes)`` (as ``_class_log_probs``)
        and the per-layer scores ``(n_clips, n_classes, n_scored)``.
        """
        lengths = np.diff(offsets)
        totals = np.empty((len(clips), len(self.classes_)))
        layers = np.empty((len(clips), len(self.classes_), len(self.score_layers_)))
        for train, held_out in progress(
            folds, verbose=self.verbose, desc="MotionTreeHMM: calibration folds"
        ):
            keep = np.repeat(np.isin(np.arange(len(lengths)), train), lengths)
            sub_offsets = np.r_[0, np.cumsum(lengths[train])]
            guide, graphs, graph_classes = self._count_graphs(
                self.tree_, [lab[keep] for lab in labels], sub_offsets, y_index[train]
            )
            scores = self._graph_scores(
                [clips[i] for i in held_out], exact=False, graphs=graphs, guide=guide
            )
            totals[held_out] = self._class_totals(scores, graph_classes)
            layers[held_out] = layer_class_scores(
                scores, graph_classes, len(self.classes_), self.graph == "clip"
            )
        return totals, layers

    def transform(self, X):
        """Per-layer class scores: the supervised view of the tree, features for a linear model.

        For each scored layer ``l`` (``score_layers_``) and class ``c``:
        ``log softmax_c(log P_l(clip | c) / n_frames)``, where ``P_l(clip | c)``
        is the clip's generation probability under class ``c``'s graph at layer
        ``l`` (the summed probability of its ``n_paths`` best node sequences, the
        factor of that layer in ``score_samples``). Dividing by the clip's
        length makes clips of any length comparable; the softmax over classes
        within each layer makes each layer's block a log posterior under a
        uniform class prior (at temperature 1). With ``graph="clip"``, a class's
        score at a layer is that of its best training clip at that layer. Use
        it to stack: ``make_pipeline(MotionTreeHMM(), LogisticRegression())``
        learns how much to trust each layer; ``fit_transform`` gives out-of-fold
        rows for the training clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        features : ndarray of shape (n_clips, n_scored_layers * n_classes)
            Layer-major: all classes of the first scored layer, then the next
            (``get_feature_names_out``); a DataFrame after
            ``set_output(transform="pandas")``.

        Examples
        --------
        >>> from sklearn.linear_model import LogisticRegression
        >>> from sklearn.pipeline import make_pipeline
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=3).fit(X, data.target)
        >>> model.transform(X).shape, list(model.get_feature_names_out()[:2])
        ((8, 6), ['layer1_class_0', 'layer1_class_1'])
        >>> stacked = make_pipeline(MotionTreeHMM(max_depth=3), LogisticRegression())
        >>> stacked.fit(X, data.target).score(X, data.target)
        1.0
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        features = class_score_features(self._layer_log_probs(clips), [len(c) for c in clips])
        return self._wrap_table(features, clips)

    def get_feature_names_out(self, input_features=None):
        """Column names of ``transform``: ``layer<l>_class_<label>``, layer-major.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Ignored (the columns do not follow the input channels); accepted
            for sklearn's API.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return class_score_names(self.score_layers_, self.classes_)
