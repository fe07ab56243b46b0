"""Decoding clips on a motion tree: the top-down beam Viterbi and its exhaustive reference.

The probability of a node sequence ``n_1..n_M`` for frames ``x_1..x_M`` at one
layer of the tree, under one transition graph (paper section IV-A), is::

    P(N | X) = prod_i Pt(n_{i-1}, n_i) Ps(n_i | x_i),    Pt(n_0, n_1) = 1
    Ps(k | x) = Po(x | k) P(k) / sum_j Po(x | j) P(j)

with ``Po`` the node's Gaussian and ``P`` uniform over the *allowed* nodes: those
the graph's clips visit (``node_prior="graph"``, the paper's choice) or every
node of the layer (``node_prior="layer"``). Everything is computed in log space.

:func:`beam_decode` searches top-down (paper section IV-A): every frame starts
at the root, and going one layer down it may only move to a child of one of
its kept nodes. :func:`exhaustive_viterbi` searches all nodes of a layer, for
reference and small problems.
"""

import numpy as np
from scipy.special import logsumexp

from skmotion.tree._decoder._beam import decode_searches
from skmotion.tree._decoder._tables import children_table, gaussian_arrays, transition_table
from skmotion.tree._decoder._viterbi import kbest_viterbi
from skmotion.utils._validation import check_int

__all__ = ["NODE_PRIORS", "beam_decode", "exhaustive_viterbi", "node_log_posterior"]

#: Where the uniform node prior of ``Ps(k | x)`` is spread.
NODE_PRIORS = ("graph", "layer")

# Below this, a sum of exp() may have lost its precision to underflow; such
# entries are recomputed exactly.
_UNDERFLOW = 1e-200


def _log_normaliser(log_po, allowed):
    """``log sum_{j allowed in g} Po(x | j)`` of every frame and graph, ``(n_frames, n_graphs)``."""
    top = log_po.max(axis=1, keepdims=True)
    weights = np.exp(log_po - top) @ allowed.T.astype(np.float64)
    with np.errstate(divide="ignore"):
        out = np.log(weights) + top
    rows, cols = np.nonzero(weights < _UNDERFLOW)
    if len(rows):  # the graph's nodes are all far below the best node: sum exactly
        out[rows, cols] = logsumexp(np.where(allowed[cols], log_po[rows], -np.inf), axis=1)
    return out


def _allowed_nodes(graphs, layer, node_prior):
    """Which nodes each graph's prior covers, ``(n_graphs, K)``, or ``(1, K)`` for all."""
    if node_prior == "graph":
        return graphs.visits(layer) > 0
    if node_prior == "layer":
        return np.ones((1, graphs.n_nodes(layer)), dtype=bool)
    raise ValueError(f"node_prior must be one of {NODE_PRIORS}; got {node_prior!r}.")


def node_log_posterior(tree, graphs, layer, frames, node_prior="graph"):
    """``log Ps(k | x)`` of every frame, node and graph of one layer.

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs
    layer : int
    frames : ndarray of shape (n_frames, n_channels)
    node_prior : {"graph", "layer"}, default="graph"

    Returns
    -------
    log_ps : ndarray of shape (n_graphs, n_frames, K)
        ``-inf`` for nodes outside a graph's prior; ``logsumexp`` over the
        nodes is 0 for every graph and frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree, TransitionGraphs, node_log_posterior
    >>> frames = np.r_[np.zeros((20, 2)), np.ones((20, 2))] + np.arange(40)[:, None] * 1e-3
    >>> tree = MotionTree.build(frames, min_samples_leaf=10, max_depth=1)
    >>> graphs = TransitionGraphs.count(tree.iter_apply(frames), tree.n_nodes, offsets=[0, 40],
    ...                                 graph_of_clip=[0])
    >>> np.exp(node_log_posterior(tree, graphs, 1, frames[:1])).round(3).tolist()
    [[[1.0, 0.0]]]
    """
    layer = tree.check_layer(layer)
    log_po = tree.log_likelihood(frames, layer)
    allowed = _allowed_nodes(graphs, layer, node_prior)
    norm = _log_normaliser(log_po, allowed)
    allowed = np.broadcast_to(allowed, (graphs.n_graphs, allowed.shape[1]))
    norm = np.broadcast_to(norm, (len(frames), graphs.n_graphs))
    return np.where(allowed[:, None, :], log_po[None] - norm.T[:, :, None], -np.inf)


def exhaustive_viterbi(tree, graphs, layer, frames, graph=0, *, n_paths=1, node_prior="graph"):
    """The ``n_paths`` best node sequences of one clip over *all* nodes of a layer.

    The reference for :func:`beam_decode`: a K-best Viterbi whose states are
    every node of the layer, costing ``O(n_frames K^2 n_paths)``.

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs
    layer : int
    frames : ndarray of shape (n_frames, n_channels)
        One clip.
    graph : int, default=0
        Which graph of ``graphs``.
    n_paths : int, default=1
    node_prior : {"graph", "layer"}, default="graph"

    Returns
    -------
    paths : ndarray of shape (n_paths, n_frames)
        Node sequences (layer indices), best first; -1 rows when fewer exist.
    scores : ndarray of shape (n_paths,)
        Their log probabilities ``log P(N | X)``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree, TransitionGraphs, exhaustive_viterbi
    >>> frames = np.r_[np.zeros((20, 2)), np.ones((20, 2))] + np.arange(40)[:, None] * 1e-3
    >>> tree = MotionTree.build(frames, min_samples_leaf=10, max_depth=1)
    >>> graphs = TransitionGraphs.count(tree.iter_apply(frames), tree.n_nodes, offsets=[0, 40],
    ...                                 graph_of_clip=[0])
    >>> paths, scores = exhaustive_viterbi(tree, graphs, 1, frames[18:22])
    >>> paths.tolist()
    [[0, 0, 1, 1]]
    """
    layer = tree.check_layer(layer)
    emit = node_log_posterior(tree, graphs, layer, frames, node_prior)[graph]
    nodes = np.arange(emit.shape[1])
    trans = graphs.log_prob(layer, graph, nodes[:, None], nodes[None, :])
    steps = (trans[None] + emit[1:, None, :])[..., None]
    paths, scores = kbest_viterbi(emit[0][:, None], steps, n_paths)
    return paths[0], scores[0]


# The compiled decoder's mask for "every node allowed".
_ALL_NODES = np.zeros((0, 0), dtype=np.uint8)


def _kernel_allowed(graphs, layer, node_prior):
    """The allowed-node mask the compiled decoder reads: ``(n_graphs, K)``; ``(0, 0)``: all."""
    if node_prior == "layer":
        return _ALL_NODES
    return np.ascontiguousarray(_allowed_nodes(graphs, layer, node_prior), dtype=np.uint8)


def _layer_specs(tree, search, scored, layer, node_prior, mask_scored):
    """What the compiled decoder reads of layers ``1 .. layer`` (entry 0 unused).

    See ``decode_searches``; the per-object arrays come from :mod:`skmotion.tree._decoder._tables`.
    """
    specs = [None]
    for depth in range(1, layer + 1):
        specs.append(
            (
                children_table(tree, depth - 1),
                tree.node_ids(depth),
                transition_table(search, depth),
                transition_table(scored, depth),
                _kernel_allowed(search, depth, node_prior),
                _kernel_allowed(scored, depth, node_prior) if mask_scored else _ALL_NODES,
            )
        )
    return specs


def _clip_normalisers(tree, graphs, frames, offsets, clips, layers, node_prior):
    """``sum_t log sum_j Po(x_t | j) P(j)`` of each clip, per layer and graph column.

    Shape ``(n_layers, n_clips, n_cols)``.

    Only the frames of ``clips`` are evaluated.
    """
    starts, lengths = offsets[clips], offsets[clips + 1] - offsets[clips]
    rows = np.repeat(starts - np.concatenate([[0], np.cumsum(lengths)[:-1]]), lengths) + np.arange(
        lengths.sum()
    )
    sub = frames[rows]
    bounds = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    out = []
    for depth in layers:
        norm = _log_normaliser(
            tree.log_likelihood(sub, depth), _allowed_nodes(graphs, depth, node_prior)
        )
        sums = np.zeros((len(clips), norm.shape[1]))
        has = lengths > 0
        sums[has] = np.add.reduceat(norm, bounds[has], axis=0)
        out.append(sums)
    return np.array(out)


def beam_decode(
    tree,
    graphs,
    frames,
    offsets,
    clip_of_problem,
    graph_of_problem,
    *,
    layer,
    n_paths=5,
    score_layers=1,
    node_prior="graph",
    guide=None,
    normalise=True,
    prune=False,
    return_paths=True,
):
    """Top-down beam Viterbi: the best node sequences of clips under graphs, layer by layer.

    Every frame starts at the root. Going one layer down, a frame's candidates
    are the children of its kept nodes; a max-product forward-backward pass over
    these candidates scores each by the best sequence through it, and the
    ``n_paths`` best of every frame are kept: a per-frame beam, the best
    sequences through ``n_paths`` distinct nodes at each frame. At the scored
    layers (``layer`` and the ``score_layers - 1`` above it), a K-best Viterbi
    pass over the candidates gives the ``n_paths`` best sequences. With
    ``n_paths`` at least the number of nodes of every layer nothing is pruned,
    and the result is that of :func:`exhaustive_viterbi` at each scored layer.

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs
    frames : ndarray of shape (n_frames, n_channels)
        The frames of all clips, stacked.
    offsets : ndarray of shape (n_clips + 1,)
        Clip ``i`` is ``frames[offsets[i]:offsets[i + 1]]``.
    clip_of_problem, graph_of_problem : ndarray of shape (n_problems,)
        Each problem decodes one clip under one graph.
    layer : int
        The layer to stop at (the root is layer 0); the deepest scored layer.
    n_paths : int, default=5
        Nodes kept per frame at each layer, and sequences returned per scored layer.
    score_layers : int, default=1
        How many layers, ending at ``layer``, are scored (at most ``layer``:
        layers ``max(1, layer - score_layers + 1) .. layer``).
    node_prior : {"graph", "layer"}, default="graph"
    guide : TransitionGraphs, default=None
        When given (one graph, e.g. the global graph), the beams are searched
        once per clip under it, and every problem's graph only runs the K-best
        passes on the candidates this shared beam leaves: much faster with many
        graphs, and the same with a wide beam. By default each problem searches
        under its own graph.
    normalise : bool, default=True
        Score with ``log Ps``; without, with ``log Po`` (rankings within a
        problem are the same; across the graphs of a clip too when the
        normaliser is shared, ``node_prior="layer"``).
    prune : bool, default=False
        Classification only, with a ``guide``: run the K-best passes only on the
        problems that may hold the highest summed score of their clip (the
        clip's problems share its search, so this is decided per search, with
        nothing recomputed). At each scored layer the sum of ``n_paths``
        sequences lies between the best one and ``n_paths`` times it, so a
        problem whose best sequences (summed over the scored layers) score
        more than ``n_scored log(n_paths)`` below those of another problem of
        the same clip can never win; it gets ``-inf`` scores and -1 paths. A
        clip left with one problem has its winner: that problem gets
        only its best sequences' scores (the others ``-inf``) and -1 paths.
        Which problem wins is unchanged.
    return_paths : bool, default=True
        Whether to return the node sequences (scores only are cheaper).

    Returns
    -------
    paths : ndarray of shape (n_problems, n_paths, max_frames) or None
        Node sequences (layer indices) at ``layer``, best first; a problem's
        sequences end at its clip's length (-1 after it); -1 rows for missing
        ones. None without ``return_paths``.
    scores : ndarray of shape (n_problems, n_scored, n_paths)
        Log probabilities ``log P(N | X)`` of the ``n_paths`` best sequences
        at each scored layer, shallowest first (``-inf`` for missing ones).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree, TransitionGraphs, beam_decode
    >>> frames = np.r_[np.zeros((20, 2)), np.ones((20, 2))] + np.arange(40)[:, None] * 1e-3
    >>> tree = MotionTree.build(frames, min_samples_leaf=10, max_depth=1)
    >>> graphs = TransitionGraphs.count(tree.iter_apply(frames), tree.n_nodes, offsets=[0, 40],
    ...                                 graph_of_clip=[0])
    >>> paths, scores = beam_decode(tree, graphs, frames[18:22], [0, 4], [0], [0], layer=1,
    ...                             n_paths=1)
    >>> paths[0].tolist(), scores.shape
    ([[0, 0, 1, 1]], (1, 1, 1))
    """
    layer = tree.check_layer(layer)
    score_layers = check_int("score_layers", score_layers)
    if prune and guide is None:
        raise ValueError(
            "prune needs a guide: the problems of a clip are compared within the clip's "
            "shared search."
        )
    offsets = np.asarray(offsets, dtype=np.intp)
    clip_of_problem = np.asarray(clip_of_problem, dtype=np.intp)
    graph_of_problem = np.asarray(graph_of_problem, dtype=np.intp)
    frames = np.ascontiguousarray(frames, dtype=np.float64)
    n_problems = len(clip_of_problem)
    lengths = np.diff(offsets)
    n_steps = int(lengths[clip_of_problem].max()) if n_problems else 0
    if layer == 0:  # every frame at the root, with probability 1
        paths = np.full((n_problems, n_paths, n_steps), -1, dtype=np.intp)
        paths[:, 0] = np.where(np.arange(n_steps) < lengths[clip_of_problem][:, None], 0, -1)
        scores = np.full((n_problems, 1, n_paths), -np.inf)
        scores[:, :, 0] = 0.0
        return (paths if return_paths else None), scores
    first = max(1, layer - int(score_layers) + 1)
    if guide is None:  # every problem searches under its own graph
        order = None
        search_clip, search_graph, search = clip_of_problem, graph_of_problem, graphs
        problem_start = np.arange(n_problems + 1, dtype=np.intp)
        score_graph = graph_of_problem
    else:  # one search per clip under the guide, shared by the clip's problems
        # (problems in clip order, as MotionTreeHMM gives them, need no reordering)
        order = (
            None
            if (np.diff(clip_of_problem) >= 0).all()
            else np.argsort(clip_of_problem, kind="stable")
        )
        search_clip, per_clip = np.unique(clip_of_problem, return_counts=True)
        search_graph, search = np.zeros(len(search_clip), dtype=np.intp), guide
        problem_start = np.concatenate([[0], np.cumsum(per_clip)]).astype(np.intp)
        score_graph = (
            graph_of_problem if order is None else np.ascontiguousarray(graph_of_problem[order])
        )
    specs = _layer_specs(tree, search, graphs, layer, node_prior, mask_scored=guide is not None)
    # One sequence and no paths: the forward pass alone gives its score.
    mode = (
        "best"
        if n_paths == 1 and not return_paths
        else "prune"
        if prune and n_paths > 1
        else "kbest"
    )
    scores, paths = decode_searches(
        frames,
        offsets[search_clip],
        lengths[search_clip],
        search_graph,
        problem_start,
        score_graph,
        gaussian_arrays(tree),
        specs,
        first,
        n_paths,
        mode,
        return_paths,
    )
    if order is not None:
        back = np.empty_like(order)
        back[order] = np.arange(n_problems)
        scores = scores[back]
        paths = paths[back] if return_paths else None
    if normalise and n_problems:
        clips, inverse = np.unique(clip_of_problem, return_inverse=True)
        sums = _clip_normalisers(
            tree, graphs, frames, offsets, clips, range(first, layer + 1), node_prior
        )
        column = graph_of_problem if sums.shape[2] > 1 else np.zeros(n_problems, dtype=np.intp)
        scores -= sums[:, inverse, column].T[:, :, None]
    return paths, scores
