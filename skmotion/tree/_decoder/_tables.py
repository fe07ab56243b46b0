"""The compiled decoder's view of a motion tree and its graphs: arrays made once per object.

:mod:`skmotion.tree._decoder._beam` reads plain C arrays. This module lays a
:class:`MotionTree`'s Gaussians and children and a :class:`TransitionGraphs`'
log probabilities out that way, the first time a decoder asks, and keeps
them while the object lives (a weak-keyed cache: the data structures carry
nothing of the decoder, and their pickles hold none of it).
"""

import weakref

import numpy as np

__all__ = ["children_table", "gaussian_arrays", "transition_table"]

# The compiled decoder reads a dense table up to 8 MB, and beyond it searches the
# short row of transitions seen from a node. On JapaneseVowels' trees a 256 KB
# limit was slower (more searches); limits from 2 MB to 64 MB timed alike.
_DECODER_DENSE_LIMIT = 1 << 20

_CACHE = weakref.WeakKeyDictionary()


def _cached(owner, key, make):
    """``make()`` once per owner and key (two threads may both make it: the results are equal)."""
    made = _CACHE.setdefault(owner, {})
    if key not in made:
        made[key] = make()
    return made[key]


def gaussian_arrays(tree):
    """The tree's node Gaussians as the compiled decoder reads them, by tree node id.

    Returns
    -------
    arrays : dict
        ``means`` ``(n, d)``; ``prec``: flat per-channel precisions (``"diag"``
        and ``"spherical"``, the latter repeated over channels) or flat upper
        triangular factors ``U`` with ``U U^T`` the precision (``"full"``);
        ``shifts`` ``(n, d)``, ``mean @ U`` (for the other kinds an unused ``(1, 1)`` array);
        ``const`` ``(n,)``; ``full``. For the Gaussians of ``"full"`` taken
        in low-rank form (``floor I + V^T diag(values) V``), ``lr_start[k]``
        is the first row of ``lr_vectors`` ``(R, d)`` of Gaussian ``k`` and
        ``lr_rank[k]`` their count, ``lr_weights`` ``(R,)`` holds
        ``values / (floor (floor + values))`` and ``lr_inv_floor[k]`` is
        ``1 / floor``; ``lr_start[k]`` is -1 for the others, which use ``U``.
    """
    return _cached(tree, "gaussians", lambda: _gaussian_arrays(tree.gaussians))


def _gaussian_arrays(gaussians):
    n, d = gaussians.means.shape
    prec, shifts, const = gaussians.precision_factors()
    if shifts is None:
        prec = np.broadcast_to(prec.reshape(n, -1), (n, d))
        shifts = np.zeros((1, 1))
    return {
        "means": np.ascontiguousarray(gaussians.means),
        "prec": np.ascontiguousarray(prec, dtype=np.float64).ravel(),
        "shifts": np.ascontiguousarray(shifts, dtype=np.float64),
        "const": np.ascontiguousarray(const, dtype=np.float64),
        "full": gaussians.kind == "full",
        **_low_rank_arrays(gaussians),
    }


def _low_rank_arrays(gaussians):
    """The low-rank form of the Gaussians where it is cheaper: ``O(r d)`` against ``O(d^2 / 2)``."""
    n, d = gaussians.means.shape
    start, rank = np.full(n, -1, dtype=np.intp), np.zeros(n, dtype=np.intp)
    inv_floor = np.zeros(n)
    vectors, weights, row = [np.zeros((0, d))], [np.zeros(0)], 0
    full = gaussians.kind == "full" and gaussians.low_rank is not None
    for k, parts in enumerate(gaussians.low_rank if full else ()):
        if parts is None or 4 * (len(parts[1]) + 2) > d:  # the triangular factor is as cheap
            continue
        floor, vecs, values = parts
        start[k], rank[k], inv_floor[k] = row, len(vecs), 1.0 / floor
        vectors.append(vecs)
        weights.append(values / (floor * (floor + values)))
        row += len(vecs)
    return {
        "lr_start": start,
        "lr_rank": rank,
        "lr_vectors": np.ascontiguousarray(np.vstack(vectors), dtype=np.float64),
        "lr_weights": np.concatenate(weights),
        "lr_inv_floor": inv_floor,
    }


def children_table(tree, layer):
    """``tree.children(layer)`` as the compiled decoder reads it: C-contiguous, made once."""
    layer = tree.check_layer(layer)
    return _cached(tree, ("children", layer), lambda: np.ascontiguousarray(tree.children(layer)))


def transition_table(graphs, layer):
    """A layer's log probabilities as the compiled decoder reads them, made once.

    The decoder asks for one transition in every graph at once, so the values
    of all graphs are contiguous.

    Returns
    -------
    table : dict
        ``k`` (nodes) and ``n_graphs``; ``pair_start`` ``(K + 1,)``: the
        transitions seen from node ``m`` in any graph are entries
        ``pair_start[m]:pair_start[m + 1]``, with destinations ``pair_dst``
        (sorted) and log probabilities ``pair_log`` ``(n_pairs, n_graphs)``
        (a graph that never made one has its unseen value there);
        ``unseen_log`` ``(K + 1, n_graphs)``: a never-seen transition from
        each node, and ``-inf`` in row ``K`` ("no node"); ``dense``: the
        flat ``(K + 1, K + 1, n_graphs)`` table of them all where it is at most
        8 MB (a lookup without a search), else empty.
    """
    return _cached(graphs, ("transitions", layer), lambda: _transition_table(graphs, layer))


def _transition_table(graphs, layer):
    csr = graphs.stacked_counts(layer)
    k, n_graphs = graphs.n_nodes(layer), graphs.n_graphs
    rows = np.repeat(np.arange(csr.shape[0]), np.diff(csr.indptr))
    graph, src = np.divmod(rows, k)
    denominator = graphs.row_totals(layer) + graphs.smoothing  # (n_graphs, K)
    # The same expressions as log_prob's, so both give the same doubles.
    unseen = np.log((0 + graphs.pseudo_count(layer)) / denominator)
    pairs, pair_of_entry = np.unique(src * k + csr.indices, return_inverse=True)
    pair_src, pair_dst = np.divmod(pairs, k)
    pair_log = np.ascontiguousarray(unseen[:, pair_src].T)
    pair_log[pair_of_entry, graph] = np.log(
        (csr.data + graphs.pseudo_count(layer)) / denominator[graph, src]
    )
    dense = graphs.log_table(layer)
    small = n_graphs * (k + 1) ** 2 <= _DECODER_DENSE_LIMIT and dense is not None
    return {
        "k": k,
        "n_graphs": n_graphs,
        "pair_start": np.searchsorted(pair_src, np.arange(k + 1)).astype(np.intp),
        "pair_dst": pair_dst.astype(np.intp),
        "pair_log": pair_log,
        "unseen_log": np.ascontiguousarray(np.vstack([unseen.T, np.full((1, n_graphs), -np.inf)])),
        "dense": dense if small else np.zeros(0),
    }
