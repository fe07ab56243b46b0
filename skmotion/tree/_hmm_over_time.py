"""MotionTreeHMM's answers over time: node sequences, the next nodes, class profiles, plans.

``decode`` (state estimation) and ``predict_next`` (prediction) on the global
graph, ``predict_proba_windows`` (class probabilities of sliding windows) and
``plan`` (a delegate to :func:`skmotion.planning.plan_from_database`).
"""

import numpy as np
from sklearn.utils import Bunch
from sklearn.utils.validation import check_is_fitted

from skmotion.tree._calibration import log_softmax_rows, per_frame
from skmotion.utils._clips import check_clips
from skmotion.utils._validation import check_int

__all__ = ["OverTimeMixin"]


_check_count = check_int  # the one integer check, skmotion.utils._validation


class OverTimeMixin:
    """The answers over time of :class:`MotionTreeHMM`, which mixes this class in.

    ``decode``, ``predict_next``, ``predict_proba_windows`` and ``plan``.
    Decodes with the model's ``_decode`` and ``_class_log_probs`` (its
    recognition methods) on the fitted ``tree_`` and ``global_graph_``.
    """

    def predict_proba_windows(self, X, width, step=1):
        """Class probabilities of sliding windows: the time profiles of the paper's Figures 10-12.

        Each window's row is ``predict_proba`` of the window as a clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        width : int
            Frames per window. A clip shorter than ``width`` gives one window,
            the whole clip.
        step : int, default=1
            Frames between the starts of consecutive windows.

        Returns
        -------
        profiles : list of ndarray of shape (n_windows_i, n_classes)
            For clip ``i``, the windows start at frames
            ``0, step, 2 step, ...`` up to ``max(n_frames_i - width, 0)``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        width, step = _check_count("width", width), _check_count("step", step)
        starts = [np.arange(0, max(len(c) - width, 0) + 1, step) for c in clips]
        windows = [c[s : s + width] for c, st in zip(clips, starts) for s in st]
        log_prob = self._class_log_probs(windows, exact=False)
        scores = per_frame(log_prob, [len(w) for w in windows]) / self.temperature_
        proba = np.exp(log_softmax_rows(scores))
        return np.split(proba, np.cumsum([len(s) for s in starts])[:-1])

    def _resolve_layer(self, layer):
        return self.layer_ if layer is None else self.tree_.check_layer(layer)

    def decode(self, X, layer=None):
        """The most likely node sequence of each clip on the global graph (state estimation).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        layer : int, default=None
            The layer to decode at; ``layer_`` by default.

        Returns
        -------
        nodes : list of ndarray of shape (n_frames_i,)
            Layer indices of the nodes (see ``tree_.node_ids(layer)``).
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        paths, _ = self._decode(
            clips, self.global_graph_, self._resolve_layer(layer), 1, exact=False
        )
        return [p[0, 0] for p in paths]

    def predict_next(self, X, n_steps=1, *, n_best=3, layer=None):
        """The most likely nodes ``n_steps`` frames after each clip ends (prediction).

        The current node's probability comes from the ``n_paths`` best sequences
        on the global graph (their normalised probabilities, by last node); it is
        carried ``n_steps`` transitions forward on the global graph.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        n_steps : int, default=1
            How many frames ahead.
        n_best : int, default=3
            How many nodes to return per clip (at most the layer's node count).
        layer : int, default=None
            The layer to predict at; ``layer_`` by default.

        Returns
        -------
        prediction : Bunch
            nodes : ndarray of shape (n_clips, n_best)
                Layer indices of the most likely nodes, most likely first.
            probabilities : ndarray of shape (n_clips, n_best)
                Their probabilities (the confidence of the prediction).
            means : ndarray of shape (n_clips, n_best, n_channels)
                Their mean frames: the predicted states.
            layer : int
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        n_steps, n_best = _check_count("n_steps", n_steps), _check_count("n_best", n_best)
        layer = self._resolve_layer(layer)
        k = self.tree_.n_nodes[layer]
        paths, scores = self._decode(clips, self.global_graph_, layer, 1, exact=False)
        scores = scores[:, 0, -1]  # the one graph, at the one layer
        weights = np.exp(log_softmax_rows(scores))
        current = np.zeros((len(clips), k))
        for i, p in enumerate(paths):
            valid = p[0, :, -1] >= 0
            np.add.at(current[i], p[0, valid, -1], weights[i, valid])
        future = self.global_graph_.propagate(layer, 0, current, n_steps)
        n_best = min(n_best, k)
        nodes = np.argsort(-future, axis=1, kind="stable")[:, :n_best]
        return Bunch(
            nodes=nodes,
            probabilities=np.take_along_axis(future, nodes, axis=1),
            means=self.tree_.means(layer)[nodes] * self.scale_ + self.center_,
            layer=layer,
        )

    def plan(self, start, goal, *, frame_rate, **options):
        """Plan a motion on the global graph that takes the root from ``start`` to ``goal``.

        A* over (node, root pose on the floor) finds the most probable node
        path whose root ends near the goal, using only transitions seen in the
        data (Yamane, Yamaguchi and Nakamura, section V-C). The model must have been fit on
        virtual-marker clips (:class:`~skmotion.preprocessing.VirtualMarkerTransform`).
        The planner is :func:`skmotion.planning.plan_from_database`, which
        checks the parameters; see the user guide (``docs/planning.md``).

        Parameters
        ----------
        start : tuple of (float, float, float)
            The root's ``(x, y, heading)`` on the floor at the first frame.
        goal : tuple of (float, float)
            The goal position on the floor, metres.
        frame_rate : float
            Frames per second of the training clips.
        **options
            ``body_size``, ``transformer``, ``layer``, ``max_frames``,
            ``tolerance``, ``start_node``, ``heuristic_weight``, ``cell``,
            ``heading_bins``, ``max_expansions``: see
            :func:`~skmotion.planning.plan_from_database`.

        Returns
        -------
        plan : MotionPlan

        Raises
        ------
        UnreachableGoalError
            (a ``ValueError``) when no motion of the database reaches the goal.

        Examples
        --------
        >>> from skmotion.datasets import make_walks
        >>> from skmotion.io import as_motions
        >>> from skmotion.preprocessing import VirtualMarkerTransform
        >>> from skmotion.tree import MotionTreeHMM
        >>> walks = make_walks(2, directions=["forward", "left"], random_state=0)
        >>> motions = as_motions(walks.clips, walks.skeletons, walks.frame_rate)
        >>> X = VirtualMarkerTransform().fit_transform(motions)
        >>> model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
        >>> plan = model.plan((0, 0, 0), (2.0, 1.0), frame_rate=30, body_size=1.6, tolerance=0.15)
        >>> plan.reached < 0.15, bool((plan.seen_counts > 0).all())
        (True, True)
        """
        from skmotion.planning import plan_from_database

        return plan_from_database(self, start, goal, frame_rate=frame_rate, **options)
