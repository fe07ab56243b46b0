"""Streaming recognition and state estimation: a clip decoded as its frames arrive.

:meth:`MotionTreeHMM.stream` returns a :class:`MotionStream`. Its answers after
each update are the batch answers for the frames seen so far (or for the last
``window`` of them): the same calls of :func:`~skmotion.tree.beam_decode`, so
they are equal to ``decode``, ``predict_proba``, ``predict`` and
``predict_next`` of that prefix, to the last bit.

Why re-decode rather than extend a beam: the top-down beam keeps, at every
layer, each frame's nodes with the best *max-marginals*, forward plus backward
scores over the whole clip. A new frame changes the backward scores of every
earlier frame, hence possibly earlier beams, candidates and paths: the batch
decoder is not causal, and an online decoder that never looks back gives other
answers. What the stream keeps between calls is the standardised frames; each
update decodes the prefix (cost growing with it) or, with ``window``, the last
``window`` frames (bounded cost; then the class posterior is exactly the
profile of ``predict_proba_windows``).
"""

import numpy as np
from sklearn.utils import Bunch

from skmotion.tree._calibration import log_softmax_rows, per_frame, sum_of_paths
from skmotion.tree._decoder._decode import beam_decode
from skmotion.tree._decoder._tables import _cached
from skmotion.tree._transitions import TransitionGraphs
from skmotion.utils._validation import check_int

__all__ = ["MotionStream"]


def stream_args(model, layer, lag):
    """The model's tree and a stream's checked layer (the model's ``layer_`` by default) and lag."""
    tree = model.tree_
    layer = model.layer_ if layer is None else tree.check_layer(layer)
    return tree, layer, check_int("lag", lag, 0)


def update_frames(model, frames):
    """An update's frame or chunk as a float64 ``(n, n_channels)`` array, its shape checked."""
    X = np.asarray(frames, dtype=np.float64)
    X = X[None] if X.ndim == 1 else X
    if X.ndim != 2 or X.shape[1] != model.n_features_in_ or not len(X):
        raise ValueError(
            f"update takes one frame of {model.n_features_in_} channels or a chunk "
            f"(n_frames, {model.n_features_in_}); got shape {np.shape(frames)}."
        )
    return X


def layer_ancestors(tree, layer):
    """Per layer 0 .. ``layer``, the index there of the ancestor of every node of ``layer``."""
    ancestors = [np.arange(tree.n_nodes[layer])]
    for depth in range(layer, 0, -1):
        ancestors.insert(0, tree.parents(depth)[ancestors[0]])
    return ancestors


def _side_by_side(graphs, other):
    """One TransitionGraphs holding ``graphs``' graphs, then ``other``'s."""
    import scipy.sparse as sp

    counts = [
        sp.vstack([graphs.count_matrix(layer), other.count_matrix(layer)], format="csr")
        for layer in range(graphs.n_layers)
    ]
    visits = [
        np.vstack([graphs.visits(layer), other.visits(layer)]) for layer in range(graphs.n_layers)
    ]
    return TransitionGraphs(counts, visits, graphs.smoothing)


class MotionStream:
    """An online decoder over one fitted :class:`MotionTreeHMM`; see :meth:`MotionTreeHMM.stream`.

    Parameters
    ----------
    model : MotionTreeHMM
        A fitted model, not copied: after ``fit`` or ``partial_fit`` the
        stream refuses to go on (start a new one).
    layer : int, default=None
        The layer to estimate the state at; the model's ``layer_`` by default.
    lag : int, default=0
        Also report the node ``lag`` frames back (fixed-lag smoothing: the
        best sequence's node there, knowing ``lag`` frames after it).
    window : int, default=None
        Decode the last ``window`` frames at each update (bounded cost), or
        every frame so far (None).
    n_best : int, default=3
        Predicted next nodes to report.

    Attributes
    ----------
    n_frames : int
        Frames seen so far.
    """

    def __init__(self, model, *, layer=None, lag=0, window=None, n_best=3):
        self.model = model
        tree, self.layer, self.lag = stream_args(model, layer, lag)
        self._tree = tree
        self.window = check_int("window", window, 1, allow_none=True)
        self.n_best = min(check_int("n_best", n_best, 1), int(tree.n_nodes[self.layer]))
        self._ancestors = layer_ancestors(tree, self.layer)
        self._guide = model.global_graph_ if model.node_prior == "layer" else None
        # At the classifying layer one decode serves both: the class graphs and, last, the
        # global graph, side by side (each graph's probabilities are computed alone, so
        # they are the same doubles; a layer's scores do not depend on the layers scored).
        self._combined = None
        if self.layer == model.layer_:
            # made once per fitted graphs (the decoder's weak-keyed cache), not per stream
            self._combined = _cached(
                model.global_graph_,
                ("exact combined", model.graphs_),
                lambda: _side_by_side(model.graphs_, model.global_graph_),
            )
        self._buffer = np.empty((64, tree.n_channels))
        self.n_frames = 0

    def reset(self):
        """Forget the frames: the next update starts a new clip."""
        self.n_frames = 0
        return self

    def _append(self, frames):
        model = self.model
        X = update_frames(model, frames)
        if not np.isfinite(X).all():
            row, col = np.argwhere(~np.isfinite(X))[0]
            raise ValueError(
                f"frames must be finite; frame {self.n_frames + row} (row {row} of this "
                f"update), channel {col} is {X[row, col]}."
            )
        need = self.n_frames + len(X)
        if need > len(self._buffer):
            grown = np.empty((max(need, 2 * len(self._buffer)), self._buffer.shape[1]))
            grown[: self.n_frames] = self._buffer[: self.n_frames]
            self._buffer = grown
        self._buffer[self.n_frames : need] = (X - model.center_) / model.scale_
        self.n_frames = need

    def _frames(self, last=None):
        start = 0 if last is None else max(0, self.n_frames - last)
        return self._buffer[start : self.n_frames]

    def _decode(self, frames, graphs, n_graphs, layer, score_layers, return_paths):
        """One clip under graphs ``0 .. n_graphs - 1``, as ``MotionTreeHMM`` decodes it."""
        model = self.model
        return beam_decode(
            model.tree_,
            graphs,
            frames,
            np.array([0, len(frames)]),
            np.zeros(n_graphs, dtype=np.intp),
            np.arange(n_graphs, dtype=np.intp),
            layer=layer,
            n_paths=model.n_paths,
            score_layers=score_layers,
            node_prior=model.node_prior,
            guide=self._guide,
            normalise=model.node_prior != "layer",
            return_paths=return_paths,
        )

    def class_log_proba(self, frames):
        """Log class posterior of standardised frames, as ``predict_proba`` computes it."""
        model = self.model
        _, scores = self._decode(
            frames,
            model.graphs_,
            len(model.graph_classes_),
            model.layer_,
            len(model.score_layers_),
            False,
        )
        return self._class_posterior(scores, len(frames))

    def _scores_and_path(self, frames):
        """Class log posterior, global paths and their scores at the stream's layer."""
        model = self.model
        if self._combined is None:
            paths, scores = self._decode(frames, model.global_graph_, 1, self.layer, 1, True)
            return self.class_log_proba(frames), paths[0], scores[0, -1]
        n_graphs = self._combined.n_graphs
        paths, scores = self._decode(
            frames, self._combined, n_graphs, model.layer_, len(model.score_layers_), True
        )
        return self._class_posterior(scores[:-1], len(frames)), paths[-1], scores[-1, -1]

    def _class_posterior(self, scores, n_frames):
        """Class log probabilities from each class (clip) graph's path scores, as ``predict_proba``.

        The model's calibration: per-frame scores over its ``temperature_``, then a softmax.
        """
        model = self.model
        per_graph = sum_of_paths(scores).sum(axis=1)
        if model.graph == "class":
            log_prob = per_graph
        else:
            log_prob = np.full(len(model.classes_), -np.inf)
            np.maximum.at(log_prob, model.graph_classes_, per_graph)
        scores = per_frame(log_prob[None], [n_frames]) / model.temperature_
        return log_softmax_rows(scores)[0]

    def update(self, frames):
        """Take one frame ``(n_channels,)`` or a chunk ``(n_frames, n_channels)``; the state now.

        Returns
        -------
        state : Bunch
            frame : int
                Index of the last frame taken (from 0).
            node : int
                The current node (layer index at ``layer``): the last node of
                the best sequence of the decoded frames on the global graph.
            nodes : ndarray of shape (layer + 1,)
                The current node's ancestors at layers ``0 .. layer``.
            lagged_node : int
                The best sequence's node ``lag`` frames back (-1 before).
            proba : ndarray of shape (n_classes,)
                The class posterior (``predict_proba`` of the decoded frames).
            label
                The class decision, ``classes_[argmax(proba)]``.
            next_nodes, next_proba : ndarray of shape (n_best,)
                The most likely nodes at the next frame and their probabilities
                (``predict_next`` with ``n_steps=1``).
        """
        self._append(frames)
        return self.state()

    def state(self):
        """The answers for the frames seen so far (see :meth:`update`)."""
        if self.n_frames == 0:
            raise ValueError("the stream has seen no frame yet; call update first.")
        model = self.model
        if model.tree_ is not self._tree:
            raise ValueError(
                "the model was fit again (fit or partial_fit) since this stream was made; "
                "start a new stream."
            )
        frames = self._frames(self.window)
        class_log_proba, paths, scores = self._scores_and_path(frames)
        best = paths[0]
        node = int(best[-1])
        log_w = log_softmax_rows(scores[None])[0]  # as predict_next weighs the paths
        current = np.zeros(int(model.tree_.n_nodes[self.layer]))
        valid = paths[:, -1] >= 0
        np.add.at(current, paths[valid, -1], np.exp(log_w[valid]))
        future = model.global_graph_.propagate(self.layer, 0, current[None], 1)[0]
        order = np.argsort(-future, kind="stable")[: self.n_best]
        proba = np.exp(class_log_proba)
        return Bunch(
            frame=self.n_frames - 1,
            node=node,
            nodes=np.array([a[node] for a in self._ancestors]),
            lagged_node=int(best[-1 - self.lag]) if self.lag < len(best) else -1,
            proba=proba,
            label=model.classes_[int(np.argmax(proba))],
            next_nodes=order,
            next_proba=future[order],
        )

    def path(self):
        """The best node sequence of every frame seen (the batch ``decode`` of the whole stream)."""
        paths, _ = self._decode(self._frames(), self.model.global_graph_, 1, self.layer, 1, True)
        return paths[0, 0].copy()
