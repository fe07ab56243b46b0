"""MotionTreeHMM's recognition: clips decoded under the class graphs, and the answers per clip.

The decoding every readout of the model shares (``_decode``: the top-down beam
search of ``decode_clips``, one shared beam on the global graph), the per-class
log generation probabilities built on it, and the classifier's answers:
``predict``, ``predict_proba``, ``predict_log_proba``, ``decision_function``,
``score_samples``, and ``novelty_score`` (the nodes' density).
"""

import numpy as np
from sklearn.utils.validation import check_is_fitted

from skmotion.tree._batch import decode_clips
from skmotion.tree._calibration import (
    layer_class_scores,
    log_softmax_rows,
    mixture_log_density,
    per_frame,
    sum_of_paths,
)
from skmotion.utils._clips import check_clips, stack_clips

__all__ = ["RecognitionMixin"]


_NOVELTY_CHUNK = 4096  # frames per block of node densities in novelty_score


class RecognitionMixin:
    """Decoding and the classifier's answers per clip, mixed into :class:`MotionTreeHMM`.

    Reads the fitted model (``tree_``, ``global_graph_``, ``graphs_``,
    ``graph_classes_``, ``classes_``, ``layer_``, ``score_layers_``,
    ``center_``, ``scale_``, ``temperature_``, ``log_node_weights_``) and its
    parameters ``graph``, ``node_prior``, ``n_paths`` and ``n_jobs``.
    """

    def _decode(
        self,
        clips,
        graphs,
        layer,
        n_graphs,
        *,
        score_layers=1,
        exact=True,
        prune=False,
        paths=True,
        guide=None,
    ):
        """Beam-decode every clip under every graph: paths and scores per clip (``decode_clips``).

        Without ``exact``, and when the normaliser of ``Ps`` is the same for
        every graph (``node_prior="layer"``), scores skip it: rankings are equal.
        With ``prune``, graphs that cannot score a clip best get ``-inf`` (for ``predict``).
        ``guide`` replaces the global graph in the shared search (calibration folds).
        """
        normalise = exact or self.node_prior != "layer"
        # One beam search per clip on the global graph, shared by all graphs. Under
        # node_prior="graph" a graph may have no candidate left in the shared beam,
        # so each graph then searches on its own (and nothing is pruned: pruning
        # compares the graphs of a clip within its shared search).
        guide = self.global_graph_ if guide is None else guide
        guide = guide if self.node_prior == "layer" else None
        frames, offsets = stack_clips(clips)
        return decode_clips(
            self.tree_,
            graphs,
            (frames - self.center_) / self.scale_,
            offsets,
            n_graphs=n_graphs,
            layer=layer,
            n_paths=self.n_paths,
            node_prior=self.node_prior,
            score_layers=score_layers,
            guide=guide,
            normalise=normalise,
            prune=prune and guide is not None,
            return_paths=paths,
            n_jobs=self.n_jobs,
        )

    def _graph_scores(self, clips, exact=True, prune=False, graphs=None, guide=None):
        """The decoder's K-best log scores ``(n_clips, n_graphs, n_scored, n_paths)``.

        Without ``exact``, up to a constant per clip and layer (enough to rank
        classes). With ``prune``, ``-inf`` for graphs that provably do not score
        best. ``graphs`` and ``guide`` replace the fitted ones (calibration folds).
        """
        graphs = self.graphs_ if graphs is None else graphs
        _, scores = self._decode(
            clips,
            graphs,
            self.layer_,
            graphs.n_graphs,
            score_layers=len(self.score_layers_),
            exact=exact,
            prune=prune,
            paths=False,
            guide=guide,
        )
        return scores

    def _class_totals(self, scores, graph_classes):
        """Per-class log generation probability, the product over the scored layers."""
        per_graph = sum_of_paths(scores).sum(axis=2)
        if self.graph == "class":
            return per_graph
        out = np.full((len(scores), len(self.classes_)), -np.inf)
        np.maximum.at(out.T, graph_classes, per_graph.T)
        return out

    def _class_log_probs(self, clips, exact=True, prune=False):
        """Log generation probability of each clip under each class, ``(n_clips, n_classes)``.

        The product over the scored layers. Without ``exact``, up to a constant
        per clip (enough to rank classes). With ``prune``, ``-inf`` for classes
        that provably do not score best.
        """
        scores = self._graph_scores(clips, exact=exact, prune=prune)
        return self._class_totals(scores, self.graph_classes_)

    def _layer_log_probs(self, clips):
        """Per-layer class log generation probabilities ``(n_clips, n_classes, n_scored)``."""
        return layer_class_scores(
            self._graph_scores(clips, exact=False),
            self.graph_classes_,
            len(self.classes_),
            self.graph == "clip",
        )

    def score_samples(self, X):
        """Log generation probability of each clip under each class.

        With ``graph="clip"`` a class's value is that of its best training clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        log_prob : ndarray of shape (n_clips, n_classes)
            ``log`` of the summed probability of the ``n_paths`` best node
            sequences at ``layer_`` (summed over ``score_layers_`` when there
            are several); columns follow ``classes_``.
        """
        check_is_fitted(self)
        return self._class_log_probs(check_clips(X, estimator=self))

    def decision_function(self, X):
        """Per-frame log generation probability of each clip under each class, over the temperature.

        ``log P(clip | class) / (n_frames * temperature_)``, up to a constant per
        clip: the softmax of a row is ``predict_proba``; its argmax is
        ``predict`` (which prunes, with the same labels).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        scores : ndarray of shape (n_clips, n_classes) or (n_clips,)
            Columns follow ``classes_``; with two classes, as sklearn expects,
            one column: the second class's score minus the first's.
        """
        scores = self._scores(X)
        if len(self.classes_) == 2:
            with np.errstate(invalid="ignore"):
                return scores[:, 1] - scores[:, 0]
        return scores

    def _scores(self, X):
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        log_prob = self._class_log_probs(clips, exact=False)
        return per_frame(log_prob, [len(c) for c in clips]) / self.temperature_

    def predict_log_proba(self, X):
        """Log class probabilities: a softmax of ``decision_function`` (see ``predict_proba``).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        log_proba : ndarray of shape (n_clips, n_classes)
        """
        return log_softmax_rows(self._scores(X))

    def predict_proba(self, X):
        """Class probabilities from per-frame generation probabilities and a fitted temperature.

        ``softmax(log P(clip | class) / (n_frames * temperature_))``: dividing by
        the clip's length keeps a long clip from making every answer certain
        (the plain normalised generation probabilities are near 0 or 1 for
        nearly every clip, the wrong ones included); ``temperature_`` is fitted
        by log loss on held-out folds in ``fit`` (``calibration_cv``). Rows are
        finite and sum to 1 for any finite input: a clip that no class can
        generate (scores ``-inf`` or NaN, e.g. frames far beyond the data's
        range) gets equal probabilities. ``novelty_score`` says how unlike the
        training data a clip is, which these probabilities do not.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        proba : ndarray of shape (n_clips, n_classes)
        """
        return np.exp(self.predict_log_proba(X))

    def novelty_score(self, X):
        """Mean log density of each clip's frames under the tree's nodes: lower is more novel.

        The nodes of ``layer_`` as a Gaussian mixture, each weighted by its share
        of the training frames, in standardised units (``center_``,
        ``scale_``): ``mean_i log sum_k w_k N(x_i | k)``. Unlike the generation
        probabilities, whose ``Ps(k | x)`` is normalised per frame (so a frame far
        from every node still picks one with certainty), this density falls as
        a clip moves away from the training frames. Threshold it, e.g., at a low
        quantile of the training clips' scores to flag clips to reject.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        score : ndarray of shape (n_clips,)
            Higher for clips like the training data (sklearn's ``score_samples``
            convention for novelty); ``-inf`` when a frame is so far that its
            density underflows.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        frames, offsets = stack_clips(clips)
        frames = (frames - self.center_) / self.scale_
        density = np.empty(len(frames))
        for start in range(0, len(frames), _NOVELTY_CHUNK):  # bounded memory: chunk x nodes
            chunk = frames[start : start + _NOVELTY_CHUNK]
            with np.errstate(over="ignore", invalid="ignore"):
                log_pdf = self.tree_.log_likelihood(chunk, self.layer_)
            log_pdf[np.isnan(log_pdf)] = -np.inf
            density[start : start + _NOVELTY_CHUNK] = mixture_log_density(
                log_pdf, self.log_node_weights_
            )
        return np.add.reduceat(density, offsets[:-1]) / np.diff(offsets)

    def predict(self, X):
        """The class whose graph generates each clip with the highest probability.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        labels : ndarray of shape (n_clips,)
        """
        check_is_fitted(self)
        # Classes whose best sequence is too far below another's are left out of the
        # K-best pass: they cannot win (see beam_decode's prune), so labels are unchanged.
        log_prob = self._class_log_probs(check_clips(X, estimator=self), exact=False, prune=True)
        return self.classes_[np.argmax(log_prob, axis=1)]
