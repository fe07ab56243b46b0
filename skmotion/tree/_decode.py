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

from skmotion.tree._viterbi import best_scores, kbest_viterbi, max_marginals

__all__ = ["NODE_PRIORS", "beam_decode", "exhaustive_viterbi", "node_log_posterior"]

#: Where the uniform node prior of ``Ps(k | x)`` is spread.
NODE_PRIORS = ("graph", "layer")

# Below this, a sum of exp() may have lost its precision to underflow; such
# entries are recomputed exactly.
_UNDERFLOW = 1e-200


def _log_normaliser(log_po, allowed):
    """``log sum_{j allowed in g} Po(x | j)`` for every frame and graph, ``(n_frames, n_graphs)``."""
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


def _trim_candidates(cand, none):
    """Drop candidate slots that hold no node at any step of any problem.

    The children of distinct nodes are distinct, so the candidates of a frame
    never repeat; only "no node" entries (``none``) can, and slots of nothing
    but those are dropped.
    """
    used = (cand != none).any(axis=(0, 2))
    used[0] = True
    return cand if used.all() else np.ascontiguousarray(cand[:, used])


def _emissions(tree, layer, frames, pos, cand, graph_of_problem, allowed, normalise):
    """Log emission score of each candidate, ``(n_steps, n_candidates, n_problems)``.

    ``cand`` holds node indices, ``K`` for "no candidate" (-inf). With
    ``normalise`` the scores are ``log Ps(k | x)``; without, ``log Po(x | k)``:
    the normaliser is the same for every node of a frame (within a graph), so
    it changes no ranking of sequences.
    """
    k = len(tree.node_ids(layer))
    if normalise:
        log_po = np.empty((len(frames), k + 1))
        log_po[:, :k] = tree.log_likelihood(frames, layer)
        log_po[:, k] = -np.inf
        emit = log_po.ravel().take(pos[:, None, :] * (k + 1) + cand)
        norm = _log_normaliser(log_po[:, :k], allowed)
        graph_col = graph_of_problem if allowed.shape[0] > 1 else np.zeros_like(graph_of_problem)
        emit -= norm[pos, graph_col[None, :]][:, None, :]
        return emit
    # only the candidates' densities: far fewer than every node on every frame
    rows = np.broadcast_to(pos[:, None, :], cand.shape)
    real = cand < k
    emit = np.full(cand.shape, -np.inf)
    emit[real] = tree.log_likelihood_pairs(frames[rows[real]], layer, cand[real])
    return emit


def _trellis(graphs, layer, cand, emit, graph_of_problem, pad, moves=None):
    """The candidates' trellis ``(initial, steps)`` for :mod:`_viterbi`.

    ``moves``, when given, holds the transitions' log probabilities already.
    """
    if moves is None:
        moves = graphs.log_prob(layer, graph_of_problem, cand[:-1, :, None, :], cand[1:, None, :, :])
    steps = moves
    steps += emit[1:, None, :, :]
    # A padded step repeats the last frame: identity moves of score 0.
    t, b = np.nonzero(pad[1:])
    steps[t, :, :, b] = np.where(np.eye(cand.shape[1], dtype=bool), 0.0, -np.inf)
    return emit[0], steps


def _shared_moves(graphs, layer, cand, clip_of_problem, graph_of_problem):
    """Transition log probabilities of problems that share their clip's candidates.

    ``cand`` is ``(n_steps, n_candidates, n_clips)``; each candidate pair is read
    once for all graphs, and problem ``b`` takes clip ``clip_of_problem[b]`` under
    graph ``graph_of_problem[b]``. Returns ``(n_steps - 1, n_candidates, n_candidates, n_problems)``.
    """
    moves = graphs.log_prob_all(layer, cand[:-1, :, None, :], cand[1:, None, :, :])
    moves = moves.reshape(moves.shape[:3] + (cand.shape[2] * graphs.n_graphs,))
    column = clip_of_problem * graphs.n_graphs + graph_of_problem
    if len(column) == moves.shape[3] and (column == np.arange(len(column))).all():
        return moves  # every graph of every clip, clip after clip: already in order
    return np.take(moves, column, axis=3)


def _candidates(tree, graphs, depth, beam, graph_of_problem, node_prior):
    """Children (in layer ``depth``) of the kept nodes, ``(n_steps, n_candidates, n_problems)``.

    Node index ``K`` of a layer stands for "no node"; its children are none too.
    """
    k = graphs.n_nodes(depth)
    kids = tree.children(depth - 1)
    children = np.full((len(kids) + 1, 2), k, dtype=np.intp)
    children[:-1] = np.where(kids >= 0, kids, k)
    cand = np.concatenate([children[:, 0][beam], children[:, 1][beam]], axis=1)
    allowed = _allowed_nodes(graphs, depth, node_prior)
    if allowed.shape[0] > 1:
        ok = np.append(allowed, np.zeros((len(allowed), 1), dtype=bool), axis=1)
        cand = np.where(ok.ravel().take(graph_of_problem * (k + 1) + cand), cand, k)
    return _trim_candidates(cand, k), allowed


def _layout(offsets, clip_of_problem):
    """Frame bookkeeping of a batch, time first and problems last.

    Short clips are padded by repeating their last frame (``pad`` marks those
    steps). Returns the positions of each step's frame in ``used`` (the sorted
    frame indices the batch needs), ``used`` and ``pad``.
    """
    lengths = np.diff(offsets)[clip_of_problem]
    steps = np.arange(int(lengths.max()))[:, None]
    frame_idx = offsets[clip_of_problem][None, :] + np.minimum(steps, lengths[None, :] - 1)
    used, pos = np.unique(frame_idx, return_inverse=True)
    return pos.reshape(frame_idx.shape), used, steps >= lengths[None, :]


def _descend(tree, graphs, frames, pos, pad, graph_of_problem, *, layer, n_paths, node_prior):
    """The per-frame beam at ``layer``: each frame's ``n_paths`` best nodes, ``(n_steps, width, n_problems)``."""
    beam = np.zeros((pos.shape[0], 1, pos.shape[1]), dtype=np.intp)
    for depth in range(1, layer + 1):
        cand, allowed = _candidates(tree, graphs, depth, beam, graph_of_problem, node_prior)
        if cand.shape[1] <= n_paths:
            beam = cand  # the beam keeps every candidate: nothing to score
            continue
        emit = _emissions(tree, depth, frames, pos, cand, graph_of_problem, allowed, normalise=False)
        marginals = max_marginals(*_trellis(graphs, depth, cand, emit, graph_of_problem, pad))
        keep = np.argsort(-marginals, axis=1, kind="stable")[:, :n_paths]
        beam = np.take_along_axis(cand, keep, axis=1)
        beam[np.take_along_axis(marginals, keep, axis=1) == -np.inf] = graphs.n_nodes(depth)
    return beam


def beam_decode(tree, graphs, frames, offsets, clip_of_problem, graph_of_problem, *, layer, n_paths=5,
                node_prior="graph", guide=None, normalise=True, prune=False):
    """Top-down beam Viterbi: the best node sequences of clips under graphs, layer by layer.

    Every frame starts at the root. Going one layer down, a frame's candidates
    are the children of its kept nodes; a max-product forward-backward pass over
    these candidates scores each by the best sequence through it, and the
    ``n_paths`` best of every frame are kept: a per-frame beam, the best
    sequences through ``n_paths`` distinct nodes at each frame. At ``layer``, a
    K-best Viterbi pass over the candidates gives the ``n_paths`` best
    sequences. With ``n_paths`` at least the number of nodes of every layer
    nothing is pruned, and the result is that of :func:`exhaustive_viterbi`.

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
        The layer to stop at (the root is layer 0).
    n_paths : int, default=5
        Nodes kept per frame at each layer, and sequences returned.
    node_prior : {"graph", "layer"}, default="graph"
    guide : TransitionGraphs, default=None
        When given (one graph, e.g. the global graph), the layers above
        ``layer`` are searched once per clip under it, and every problem's
        graph only runs the last K-best pass on the candidates this shared
        beam leaves: much faster with many graphs, and the same with a wide
        beam. By default each problem searches under its own graph.
    normalise : bool, default=True
        Score with ``log Ps``; without, with ``log Po`` (rankings within a
        problem are the same; across the graphs of a clip too when the
        normaliser is shared, ``node_prior="layer"``).
    prune : bool, default=False
        Classification only: run the K-best pass only on the problems that may
        hold the highest summed score of their clip. The sum of ``n_paths``
        sequences lies between the best one and ``n_paths`` times it, so a
        problem whose best sequence scores more than ``log(n_paths)`` below
        the best sequence of another problem of the same clip can never win;
        it gets ``-inf`` scores and -1 paths. Which problem wins is unchanged.

    Returns
    -------
    paths : ndarray of shape (n_problems, n_paths, max_frames)
        Node sequences (layer indices) at ``layer``, best first; a problem's
        sequences are valid up to its clip's length; -1 rows for missing ones.
    scores : ndarray of shape (n_problems, n_paths)
        Their log probabilities ``log P(N | X)`` (``-inf`` for missing sequences).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree, TransitionGraphs, beam_decode
    >>> frames = np.r_[np.zeros((20, 2)), np.ones((20, 2))] + np.arange(40)[:, None] * 1e-3
    >>> tree = MotionTree.build(frames, min_samples_leaf=10, max_depth=1)
    >>> graphs = TransitionGraphs.count(tree.iter_apply(frames), tree.n_nodes, offsets=[0, 40],
    ...                                 graph_of_clip=[0])
    >>> paths, scores = beam_decode(tree, graphs, frames[18:22], [0, 4], [0], [0], layer=1, n_paths=1)
    >>> paths[0].tolist()
    [[0, 0, 1, 1]]
    """
    layer = tree.check_layer(layer)
    offsets = np.asarray(offsets, dtype=np.intp)
    clip_of_problem = np.asarray(clip_of_problem, dtype=np.intp)
    graph_of_problem = np.asarray(graph_of_problem, dtype=np.intp)
    frames = np.asarray(frames, dtype=np.float64)
    pos, used, pad = _layout(offsets, clip_of_problem)
    n_problems, n_steps = len(clip_of_problem), pos.shape[0]
    if layer == 0:
        paths = np.full((n_problems, n_paths, n_steps), -1, dtype=np.intp)
        paths[:, 0] = 0
        scores = np.full((n_problems, n_paths), -np.inf)
        scores[:, 0] = 0.0
        return paths, scores
    moves = None
    if guide is None:
        beam = _descend(tree, graphs, frames[used], pos, pad, graph_of_problem, layer=layer - 1,
                        n_paths=n_paths, node_prior=node_prior)
        cand, allowed = _candidates(tree, graphs, layer, beam, graph_of_problem, node_prior)
        emit = _emissions(tree, layer, frames[used], pos, cand, graph_of_problem, allowed, normalise)
    else:
        clips, inverse = np.unique(clip_of_problem, return_inverse=True)
        clip_pos, clip_used, clip_pad = _layout(offsets, clips)
        first = np.zeros(len(clips), dtype=np.intp)
        beam = _descend(tree, guide, frames[clip_used], clip_pos, clip_pad, first, layer=layer - 1,
                        n_paths=n_paths, node_prior=node_prior)
        if node_prior == "layer":  # the same candidates and emissions for every graph of a clip
            cand, allowed = _candidates(tree, graphs, layer, beam, first, node_prior)
            emit = _emissions(tree, layer, frames[clip_used], clip_pos, cand, first, allowed, normalise)
            moves = _shared_moves(graphs, layer, cand, inverse, graph_of_problem)
            cand, emit = cand[:, :, inverse], emit[:, :, inverse]
        else:
            cand, allowed = _candidates(tree, graphs, layer, beam[:, :, inverse], graph_of_problem, node_prior)
            emit = _emissions(tree, layer, frames[used], pos, cand, graph_of_problem, allowed, normalise)
    initial, steps = _trellis(graphs, layer, cand, emit, graph_of_problem, pad, moves)
    if prune and n_paths > 1:
        return _pruned_kbest(initial, steps, cand, clip_of_problem, n_paths)
    return _paths(cand, *kbest_viterbi(initial, steps, n_paths))


def _pruned_kbest(initial, steps, cand, clip_of_problem, n_paths):
    """:func:`kbest_viterbi` on the problems that may win their clip; -inf for the others."""
    best = best_scores(initial, steps)
    clips, inverse = np.unique(clip_of_problem, return_inverse=True)
    top = np.full(len(clips), -np.inf)
    np.maximum.at(top, inverse, best)
    # Kept with a margin for rounding in the sums of n_paths terms.
    live = np.flatnonzero(best + np.log(n_paths) >= top[inverse] - 1e-9 * np.abs(top[inverse]))
    paths = np.full((len(best), n_paths, len(cand)), -1, dtype=np.intp)
    scores = np.full((len(best), n_paths), -np.inf)
    slots, live_scores = kbest_viterbi(initial[:, live], steps[..., live], n_paths)
    paths[live], scores[live] = _paths(cand[..., live], slots, live_scores)
    return paths, scores


def _paths(cand, slots, scores):
    """Node sequences from the K-best pass's candidate slots."""
    nodes = cand.transpose(2, 0, 1)  # (problem, step, candidate)
    paths = np.take_along_axis(nodes[:, None], np.maximum(slots, 0)[..., None], axis=3)[..., 0]
    paths[slots < 0] = -1
    return paths, scores
