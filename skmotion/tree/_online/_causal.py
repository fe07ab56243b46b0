"""The causal stream: a top-down beam kept between calls, at a bounded cost per frame.

:meth:`MotionTreeHMM.stream` with ``mode="online"`` returns an
:class:`OnlineMotionStream`. For each new frame ``x_t``, layer by layer from
the root down:

- the frame's *candidates* ``C_t^l`` at layer ``l`` are the children of its
  kept nodes ``B_t^{l-1}`` at the layer above (``B_t^0`` is the root);
- on the global graph ``G``, the forward max-product score of candidate ``j``
  is ``delta_t(j) = max_{i in C_{t-1}^l} [delta_{t-1}(i) + log p_G(i -> j)] +
  log Po(x_t | j)`` (``delta_0(j) = log Po(x_0 | j)``): the log probability of
  the best node sequence ending in ``j`` whose every node was a candidate of its
  frame. The ``beam`` best candidates are kept: ``B_t^l``;
- at the classifying layers (``score_layers_``), every class (or clip) graph
  ``g`` runs the same recursion over the same candidates as a list Viterbi:
  ``alpha_t^g(j, r)``, the ``r``-th best of ``alpha_{t-1}^g(i, s) + log p_g(i
  -> j) + log Ps_g(x_t | j)`` over ``i`` and ``s``, for ``r < n_paths``: the
  ``n_paths`` best sequences under ``g`` ending in ``j`` whose nodes were all
  candidates. The class's running log-likelihood is, summed over the scored
  layers, ``log`` of the summed probabilities of the ``n_paths`` best
  ``alpha_t^g`` entries over all candidates: the batch classifier's
  generation probability (``n_paths`` best sequences summed) on the causal
  beam (with ``graph="clip"``, a class's value is its best clip's). ``Ps_g``
  is ``Po`` divided by the graph's normaliser under ``node_prior="graph"``;
  under ``"layer"`` the normaliser is common to all classes and left out, as
  ``predict_proba`` leaves it out.

This is the batch decoder made causal: a frame's beam depends on the frames
before it only (forward scores instead of forward + backward max-marginals).
With a beam as wide as the widest layer every node is a candidate, and the
recursions are the exhaustive (list) Viterbi over all nodes: the current node
is the last node of :func:`~skmotion.tree.exhaustive_viterbi` of the frames so
far, and the class log-likelihood sums its ``n_paths`` best scores under the
class graph. The tests check both against numpy references.

The state kept between calls is, per layer, the last frame's candidates (at
most ``2 beam``), their scores under the global and the class graphs, plus, at
the stream's layer, ``lag + 1`` frames of candidates and back-pointers for the
fixed-lag answer: ``O(beam x layers x n_graphs x n_paths + beam x lag)`` numbers, and a
frame costs the same whatever came before. The per-frame loop is compiled
(:mod:`skmotion.tree._online._kernel`).
"""

import numpy as np

from skmotion.tree._calibration import sum_of_paths
from skmotion.tree._decoder._decode import _log_normaliser
from skmotion.tree._decoder._tables import _cached, gaussian_arrays
from skmotion.tree._online._exact import layer_ancestors, stream_args, update_frames
from skmotion.tree._online._kernel import OnlineKernel
from skmotion.utils._validation import check_int

__all__ = ["OnlineMotionStream"]


def _transition_table(graph_sets, layer):
    """Seen pairs of any graph, sorted by source then destination, and their log probabilities.

    Column ``c`` is the ``c``-th graph of ``graph_sets`` (each a
    :class:`TransitionGraphs`, its graphs in order); ``unseen_log[m, c]`` is a
    never-seen transition from ``m``. The values are ``log_prob``'s, looked up
    for all graphs of a set at once (one broadcast call, not one per graph).
    """
    k = graph_sets[0].n_nodes(layer)
    keys = []
    for graphs in graph_sets:
        stacked = graphs.stacked_counts(layer)  # graph g: rows g K .. (g + 1) K - 1
        rows = np.repeat(np.arange(stacked.shape[0], dtype=np.intp), np.diff(stacked.indptr))
        keys.append((rows % k) * k + stacked.indices)
    pairs = np.unique(np.concatenate(keys).astype(np.intp))
    src, dst = np.divmod(pairs, k)
    pair_log = np.concatenate(
        [
            graphs.log_prob(layer, np.arange(graphs.n_graphs)[None, :], src[:, None], dst[:, None])
            for graphs in graph_sets
        ],
        axis=1,
    )
    with np.errstate(divide="ignore"):
        unseen = np.concatenate(
            [np.log(graphs.unseen_probability(layer)).T for graphs in graph_sets], axis=1
        )
    return (
        np.searchsorted(src, np.arange(k + 1)).astype(np.intp),
        np.ascontiguousarray(dst, dtype=np.intp),
        np.ascontiguousarray(pair_log, dtype=np.float64).reshape(len(pairs), -1),
        np.ascontiguousarray(unseen, dtype=np.float64),
    )


def _layer_tables(model, depth, scored):
    """A layer's children, node ids and transition table as the kernel reads them.

    Made once per model state and kept while its global graph lives (the
    decoder's weak-keyed cache): ``fit`` and ``partial_fit`` make new graphs,
    so a refitted model gets new tables, and a stream costs no conversion.
    The kernel only reads them, so every stream of the model shares them.
    """
    tree = model.tree_
    key = ("online layer", depth, model.graphs_ if scored else None, tree)

    def make():
        sets = [model.global_graph_] + ([model.graphs_] if scored else [])
        children = np.ascontiguousarray(tree.children(depth - 1), dtype=np.intp)
        ids = np.ascontiguousarray(tree.node_ids(depth), dtype=np.intp)
        return (children, ids, *_transition_table(sets, depth))

    return _cached(model.global_graph_, key, make)


class OnlineMotionStream:
    """A causal online decoder over a fitted :class:`MotionTreeHMM`; see ``MotionTreeHMM.stream``.

    Parameters
    ----------
    model : MotionTreeHMM
        A fitted model, not copied: after ``fit`` or ``partial_fit`` the
        stream refuses to go on (start a new one).
    layer : int, default=None
        The layer to estimate the state at; the model's ``layer_`` by default.
    lag : int, default=0
        Also report the node ``lag`` frames back on the backtrace of the
        current best sequence (fixed-lag smoothing).
    beam : int, default=None
        Nodes kept per frame and layer; the model's ``n_paths`` by default.
    n_best : int, default=3
        Predicted next nodes to report (0: none, the cheapest update).

    Attributes
    ----------
    n_frames : int
        Frames seen so far.

    Notes
    -----
    Under ``node_prior="graph"`` each class graph's normaliser of ``Ps`` needs
    the density of every node of the scored layers; it is computed in numpy
    before each frame, a slower path than the compiled one of the default
    ``node_prior="layer"``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.tree import MotionTreeHMM
    >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
    >>> X = [clip[:, 6:] for clip in data.clips]
    >>> model = MotionTreeHMM(max_depth=4).fit(X, data.target)
    >>> stream = model.stream(mode="online", lag=3)
    >>> for frame in X[5]:
    ...     state = stream.update(frame)
    >>> bool(state.label == model.predict(X[5:6])[0]), state.proba.round(2).tolist()
    (True, [0.0, 1.0])
    >>> len(state.nodes) == model.layer_ + 1, stream.n_frames == len(X[5])
    (True, True)
    """

    def __init__(self, model, *, layer=None, lag=0, beam=None, n_best=3):
        self.model = model
        tree, self.layer, self.lag = stream_args(model, layer, lag)
        self._tree = tree
        self.beam = check_int("beam", model.n_paths if beam is None else beam, 1)
        self.n_best = min(check_int("n_best", n_best, 0), int(tree.n_nodes[self.layer]))
        # row k: node k's ancestors at layers 0 .. layer
        self._ancestors = _cached(
            tree,
            ("online ancestors", self.layer),
            lambda: np.stack(layer_ancestors(tree, self.layer), axis=1),
        )
        n_channels = model.n_features_in_
        self._center = np.ascontiguousarray(model.center_, dtype=np.float64)
        self._scale = np.ascontiguousarray(model.scale_, dtype=np.float64)
        self._zeros, self._ones = np.zeros(n_channels), np.ones(n_channels)
        if model.graph == "class":
            self._class_of_graph = np.arange(model.graphs_.n_graphs, dtype=np.intp)
        else:
            self._class_of_graph = np.asarray(model.graph_classes_, dtype=np.intp)
        self._depth = max(self.layer, model.layer_)
        self._scored = [int(s) for s in model.score_layers_ if s > 0]
        self._n_graphs = model.graphs_.n_graphs
        self._n_paths = int(model.n_paths)
        self._build()
        self.reset()

    def _build(self):
        """The model's tables as the kernel reads them (made once per fitted model, shared)."""
        model, tree = self.model, self._tree
        self._gauss = gaussian_arrays(tree)  # the batch decoder's layout: one for both kernels
        self._layers, self._norms = [], {}
        for depth in range(1, self._depth + 1):
            scored = depth in self._scored
            allowed = np.zeros((0, 0), dtype=np.uint8)
            norm = np.zeros(0)
            if scored and model.node_prior == "graph":
                allowed = np.ascontiguousarray(model.graphs_.visits(depth) > 0, dtype=np.uint8)
                norm = self._norms[depth] = np.zeros(self._n_graphs)
            tables = _layer_tables(model, depth, scored)
            self._layers.append((*tables, allowed, norm, scored))
        self._global = self._layers[self.layer - 1][2:5] if self.layer else None

    def _new_state(self):
        n, s = self._depth + 1, 2 * self.beam
        state = {
            "cand": np.full((n, s), -1, dtype=np.intp),
            "n_cand": np.zeros(n, dtype=np.intp),
            "kept": np.zeros((n, self.beam), dtype=np.intp),
            "n_kept": np.zeros(n, dtype=np.intp),
            "emit": np.zeros((n, s)),
            "delta": np.zeros((n, s)),
            "alpha": np.zeros((n, s, max(self._n_graphs, 1), self._n_paths)),
            "delta_off": np.zeros(n),
            "alpha_off": np.zeros(n),
            "ring_cand": np.full((self.lag + 1, s), -1, dtype=np.intp),
            "ring_back": np.full((self.lag + 1, s), -1, dtype=np.intp),
            "n_frames": np.zeros(1, dtype=np.intp),
        }
        state["cand"][0, 0] = 0  # the root, every frame's one node at layer 0
        state["n_cand"][0] = state["n_kept"][0] = 1
        return state

    def _make_kernel(self):
        kernel = OnlineKernel(
            self._gauss,
            self._layers,
            self._state,
            self.beam,
            self._n_graphs,
            self._n_paths,
            self.layer,
            self.lag + 1,
        )
        kernel.answers(
            self.model,
            self._tree,
            self.model.classes_,
            self._class_of_graph,
            self._ancestors,
            self.n_best,
            self.lag,
            self._center,
            self._scale,
            not self._norms,
        )
        self._kernel = kernel
        # the common case, one checked frame with no Python between (None: not that case)
        self._step = kernel.step

    def reset(self):
        """Forget the frames: the next update starts a new clip."""
        self._state = self._new_state()
        self._make_kernel()
        return self

    @property
    def n_frames(self):
        return int(self._state["n_frames"][0])

    def __getstate__(self):
        state = self.__dict__.copy()
        del state["_kernel"], state["_step"]  # pointers into the arrays: made again on loading
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._make_kernel()

    def _frames(self, frames):
        """The frames as a C-contiguous float64 ``(n, n_channels)`` array; shape checked."""
        model = self.model
        if model.tree_ is not self._tree:
            raise ValueError(
                "the model was fit again (fit or partial_fit) since this stream was made; "
                "start a new stream."
            )
        X = update_frames(model, frames)
        return X if X.flags.c_contiguous else np.ascontiguousarray(X)

    def _not_finite(self, X, flat):
        row, col = divmod(int(flat), X.shape[1])
        return ValueError(
            f"frames must be finite; frame {self.n_frames + row} (row {row} of this "
            f"update), channel {col} is {X[row, col]}."
        )

    def update(self, frames):
        """Take one frame ``(n_channels,)`` or a chunk ``(n_frames, n_channels)``; the state now.

        A single float64 frame goes through the compiled kernel with no Python
        in between (its shape, values and the model are still checked there);
        anything else is converted and checked first, with the same answers.

        Returns
        -------
        state : OnlineState
            The keys of :meth:`MotionStream.update` (a mapping, like its
            ``Bunch``, and attributes): ``frame``, ``node``, ``nodes``,
            ``lagged_node``, ``proba``, ``label``, ``next_nodes``,
            ``next_proba``, here from the causal recursions (see the module).
            The arrays are made on first access.
        """
        state = self._step(frames)
        if state is not None:
            return state
        X = self._frames(frames)
        model = self.model
        if not self._norms:
            bad = self._kernel.advance(X, self._center, self._scale)
            if bad >= 0:
                raise self._not_finite(X, bad)
            return self.state()
        # node_prior="graph": each class graph's normaliser, frame by frame
        if not np.isfinite(X).all():
            raise self._not_finite(X, np.flatnonzero(~np.isfinite(X))[0])
        for frame in (X - model.center_) / model.scale_:
            for depth, norm in self._norms.items():
                log_po = self._tree.log_likelihood(frame[None], depth)
                norm[:] = _log_normaliser(log_po, model.graphs_.visits(depth) > 0)[0]
            self._kernel.advance(frame[None], self._zeros, self._ones)
        return self.state()

    def class_log_likelihood(self):
        """Each graph's running log-likelihood, summed over the scored layers.

        At a scored layer: ``log`` of the summed probabilities of the graph's
        ``n_paths`` best sequences through the candidates (the batch
        classifier's generation probability, on the causal beam).

        Returns
        -------
        log_likelihood : ndarray of shape (n_graphs,)
            Under ``node_prior="layer"``, without the normaliser common to all graphs.
        """
        st = self._state
        out = np.zeros(self._n_graphs)
        for depth in self._scored:
            entries = st["alpha"][depth, : st["n_cand"][depth]]  # (n_cand, n_graphs, n_paths)
            entries = np.moveaxis(entries, 1, 0).reshape(self._n_graphs, -1)
            best = -np.sort(-entries, axis=1)[:, : self._n_paths]
            out += sum_of_paths(best) + st["alpha_off"][depth]
        return out

    def state(self):
        """The answers for the frames seen so far (see :meth:`update`)."""
        if not self._state["n_frames"][0]:
            raise ValueError("the stream has seen no frame yet; call update first.")
        return self._kernel.result()
