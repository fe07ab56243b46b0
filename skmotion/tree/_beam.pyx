# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled top-down beam Viterbi (see :mod:`skmotion.tree._decode`).

The recursions of a Viterbi pass run frame after frame, as they must; done in
numpy they cost one Python step per frame and layer. Here one call decodes a
group of *searches*, each one clip searched top-down under one graph (the
guide, or a problem's own graph), layer after layer, with no Python between:

1. a frame's candidates at layer ``l`` are the children of its kept nodes at
   ``l - 1`` (a leaf copied down has one child, itself);
2. their Gaussian log densities (a copied leaf's is carried down, not recomputed);
3. at a *scored* layer, every problem of the search (the clip under one graph)
   runs its max-product pass over the candidates: the best sequence's score, or
   the ``n_paths`` best sequences (list Viterbi), or first the best and then,
   for the problems that may still win their clip, the list (``"prune"``);
4. above the last layer, a max-product forward-backward pass under the search
   graph scores each candidate by the best sequence through it, and each frame
   keeps its ``n_paths`` best for the next layer.

The arithmetic is that of the numpy reference (:mod:`skmotion.tree._viterbi`):
a step's score is ``move + emission`` of the arriving node, added to the score
so far, and ties go to the lower candidate slot (or rank, then slot). Slot
``side * width + w`` of a frame is child ``side`` (0 left, 1 right) of its
``w``-th kept node; -1 is "no node". Emissions are ``log Po(x | k)``; the
normaliser of ``Ps`` is the same for every candidate of a frame, so the caller
subtracts its per-clip sum from the scores.

:func:`decode_searches` allocates once (:func:`_allocate`, the longest search's
scratch), then runs one search after another (:func:`_search`: steps 1, 2 and 4,
with :func:`_score_layer` for step 3) and, for ``"prune"``, the lists of the
problems still live (:func:`_prune`). The arrays it reads are laid out by
:mod:`skmotion.tree._layout`.
"""

import numpy as np

from libc.math cimport INFINITY, NAN, log
from libc.stdlib cimport free, malloc

from skmotion.tree._emission cimport skm_diag_run, skm_full_run, skm_lowrank_run, skm_step_all
from skmotion.tree._pairs cimport pair_moves

ctypedef Py_ssize_t intp

#: What a call computes per problem; see :func:`decode_searches`.
MODES = ("best", "kbest", "prune")

cdef enum:
    BEST = 0
    KBEST = 1
    PRUNE = 2


cdef struct Gaussians:
    const double* means     # (n_tree_nodes, d)
    const double* prec      # diag: (n_tree_nodes, d) precisions; full: (n_tree_nodes, d, d) upper factors
    const double* shifts    # full only: (n_tree_nodes, d), mean @ factor
    const double* const_    # (n_tree_nodes,)
    const intp* lr_start    # full only: first row of a node's low-rank vectors, -1 for the factor
    const intp* lr_rank
    const double* lr_vectors
    const double* lr_weights
    const double* lr_inv_floor
    intp d
    bint full


cdef struct Table:
    const double* dense         # (K + 1, K + 1, n_graphs) log probabilities (K: no node), or NULL
    const intp* pair_start      # (K + 1,): the transitions seen from node m are pairs pair_start[m]:pair_start[m + 1]
    const intp* pair_dst        # their destinations, sorted within m
    const double* pair_log      # (n_pairs, n_graphs) their log probabilities in every graph
    const double* unseen_log    # (K + 1, n_graphs) a never-seen transition from each node; row K: -inf
    intp k
    intp n_graphs


cdef struct Layer:
    const intp* children    # (K_{l-1}, 2): layer indices here of the children of the layer above's nodes
    const intp* ids         # (K_l,): layer index -> tree node id
    Table search            # the search graphs' transitions
    Table score             # the scored graphs' transitions
    const unsigned char* search_allowed    # (n_search_graphs, K_l) nodes a search may visit, or NULL for all
    const unsigned char* score_allowed     # (n_score_graphs, K_l) nodes a scored graph may visit, or NULL
    intp k


cdef inline void _emissions(const Gaussians* g, const double* x, intp n, intp node, double* out, intp stride,
                            double* y) noexcept nogil:
    """Log densities of ``n`` consecutive frames from ``x`` under tree node ``node``'s Gaussian.

    Written to ``out[i * stride]``; ``y`` is scratch of ``4 d`` doubles.
    """
    cdef intp row
    if g.full:
        row = g.lr_start[node]
        if row >= 0:
            skm_lowrank_run(x, n, g.d, g.means + node * g.d, g.lr_vectors + row * g.d, g.lr_weights + row,
                            g.lr_rank[node], g.lr_inv_floor[node], g.const_[node], out, stride, y)
        else:
            skm_full_run(x, n, g.d, g.prec + node * g.d * g.d, g.shifts + node * g.d, g.const_[node], out, stride,
                         y)
    else:
        skm_diag_run(x, n, g.d, g.means + node * g.d, g.prec + node * g.d, g.const_[node], out, stride)


cdef inline const double* _moves_of(const Table* t, intp src, intp dst) noexcept nogil:
    """``log p(src -> dst)`` in every graph, ``n_graphs`` contiguous values; -inf when either is "no node"."""
    if t.dense != NULL:  # no search and no branch: "no node" is row and column K
        return t.dense + ((t.k if src < 0 else src) * (t.k + 1) + (t.k if dst < 0 else dst)) * t.n_graphs
    if src < 0 or dst < 0:
        return t.unseen_log + t.k * t.n_graphs
    return pair_moves(t.pair_start, t.pair_dst, t.pair_log, t.unseen_log, t.n_graphs, src, dst)


cdef bint _same_row(const intp* a, const intp* b, intp n) noexcept nogil:
    cdef intp i
    for i in range(n):
        if a[i] != b[i]:
            return False
    return True


cdef void _steps(intp n_steps, intp n_cand, const Table* tab, intp graph, const intp* cand, const double* emit,
                 double* moves, double* steps) noexcept nogil:
    """``steps[t, i, j]``: move from slot ``i`` at ``t`` to slot ``j`` at ``t + 1``, plus ``j``'s emission.

    A node stays for many frames, so the candidates of consecutive frames often
    repeat; the moves ``(n_cand, n_cand)`` are looked up again only when they change.
    """
    cdef intp t, i, j, src
    cdef double* row
    cdef const double* move
    for t in range(n_steps - 1):
        if t == 0 or not (_same_row(cand + t * n_cand, cand + (t - 1) * n_cand, n_cand)
                          and _same_row(cand + (t + 1) * n_cand, cand + t * n_cand, n_cand)):
            for i in range(n_cand):
                src = cand[t * n_cand + i]
                for j in range(n_cand):
                    moves[i * n_cand + j] = _moves_of(tab, src, cand[(t + 1) * n_cand + j])[graph]
        for i in range(n_cand):
            row = steps + (t * n_cand + i) * n_cand
            move = moves + i * n_cand
            for j in range(n_cand):
                row[j] = move[j] + emit[(t + 1) * n_cand + j]


cdef void _max_marginals(intp n_steps, intp n_cand, const double* emit, const double* steps,
                         double* fwd, double* bwd) noexcept nogil:
    """Forward and backward max-product scores; their sum is each slot's max-marginal."""
    cdef intp t, i, j
    cdef double best, v
    for j in range(n_cand):
        fwd[j] = emit[j]
        bwd[(n_steps - 1) * n_cand + j] = 0.0
    for t in range(1, n_steps):
        for j in range(n_cand):
            best = -INFINITY
            for i in range(n_cand):
                v = fwd[(t - 1) * n_cand + i] + steps[((t - 1) * n_cand + i) * n_cand + j]
                if v > best:
                    best = v
            fwd[t * n_cand + j] = best
    for t in range(n_steps - 2, -1, -1):
        for i in range(n_cand):
            best = -INFINITY
            for j in range(n_cand):
                v = steps[(t * n_cand + i) * n_cand + j] + bwd[(t + 1) * n_cand + j]
                if v > best:
                    best = v
            bwd[t * n_cand + i] = best


cdef intp _pick(double* scores, intp n, double* value) noexcept nogil:
    """Index of the first maximum of ``scores[:n]``; its value goes to ``value`` and the entry to -inf."""
    cdef intp i, arg = 0
    cdef double best = scores[0]
    for i in range(1, n):
        if scores[i] > best:
            best = scores[i]
            arg = i
    scores[arg] = -INFINITY
    value[0] = best
    return arg


cdef double _best(intp n_steps, intp n_cand, const double* emit, const double* steps, double* fwd) noexcept nogil:
    """The score of the best sequence: the forward max-product pass alone."""
    cdef intp t, i, j
    cdef double best, v
    cdef double* prev = fwd
    cdef double* cur = fwd + n_cand
    cdef double* tmp
    for j in range(n_cand):
        prev[j] = emit[j]
    for t in range(1, n_steps):
        for j in range(n_cand):
            best = -INFINITY
            for i in range(n_cand):
                v = prev[i] + steps[((t - 1) * n_cand + i) * n_cand + j]
                if v > best:
                    best = v
            cur[j] = best
        tmp = prev
        prev = cur
        cur = tmp
    best = -INFINITY
    for j in range(n_cand):
        if prev[j] > best:
            best = prev[j]
    return best


cdef void _kbest(intp n_steps, intp n_cand, intp n_paths, const intp* cand, const double* emit,
                 const double* steps, double* delta, double* scratch, intp* head, intp* back, intp* paths,
                 intp path_stride, double* scores) noexcept nogil:
    """List Viterbi: the ``n_paths`` best slot sequences' scores and, unless ``paths`` is NULL, their node paths.

    ``head`` is scratch of ``n_cand``: the rank of each slot's next unpicked
    entry. Rows of ``paths`` stay as they are for missing sequences.
    """
    cdef intp t, r, r2, i, j, e, arg, rank, state, n_entries = n_paths * n_cand
    cdef double best
    cdef double* prev = delta
    cdef double* cur = delta + n_entries
    cdef double* tmp
    cdef bint track = paths != NULL
    # prev[r * n_cand + j]: the rank-r sequence ending in slot j (decreasing in r)
    for e in range(n_entries):
        prev[e] = emit[e] if e < n_cand else -INFINITY
    for t in range(1, n_steps):
        for j in range(n_cand):
            # Entry r * n_cand + i: the rank-r sequence ending in slot i, moved on to j. Each
            # slot's entries decrease with the rank, so the best remaining entry is always one
            # of the slots' first unpicked ones (their heads): the picks merge n_cand sorted
            # lists, ties to the lowest entry as an argmax over all entries would give.
            for i in range(n_cand):
                head[i] = 0
                scratch[i] = prev[i] + steps[((t - 1) * n_cand + i) * n_cand + j]
            for r in range(n_paths):
                arg = -1
                best = -INFINITY
                for i in range(n_cand):
                    if head[i] < n_paths and scratch[i] > best:
                        best = scratch[i]
                        arg = i
                if arg < 0:  # only -inf left: no sequence of this rank
                    for r2 in range(r, n_paths):
                        cur[r2 * n_cand + j] = -INFINITY
                        if track:
                            back[(t * n_paths + r2) * n_cand + j] = 0
                    break
                # among equal heads the lowest entry: the lowest rank, then the lowest slot
                for i in range(n_cand):
                    if head[i] < n_paths and scratch[i] == best and head[i] * n_cand + i < head[arg] * n_cand + arg:
                        arg = i
                cur[r * n_cand + j] = best
                if track:
                    back[(t * n_paths + r) * n_cand + j] = head[arg] * n_cand + arg
                head[arg] += 1
                if head[arg] < n_paths:
                    scratch[arg] = prev[head[arg] * n_cand + arg] + steps[((t - 1) * n_cand + arg) * n_cand + j]
        tmp = prev
        prev = cur
        cur = tmp
    for e in range(n_entries):
        scratch[e] = prev[e]
    for r in range(n_paths):
        e = _pick(scratch, n_entries, &scores[r])
        if scores[r] == -INFINITY or not track:
            continue
        rank = e // n_cand
        state = e % n_cand
        for t in range(n_steps - 1, -1, -1):
            paths[r * path_stride + t] = cand[t * n_cand + state]
            if t:
                e = back[(t * n_paths + rank) * n_cand + state]
                rank = e // n_cand
                state = e % n_cand


cdef Gaussians _gaussians(object gauss):
    cdef Gaussians g
    cdef const double[:, ::1] means = gauss["means"]
    cdef const double[::1] prec = gauss["prec"]
    cdef const double[:, ::1] shifts = gauss["shifts"]
    cdef const double[::1] const_ = gauss["const"]
    g.means = &means[0, 0]
    g.prec = &prec[0]
    g.shifts = &shifts[0, 0]
    g.const_ = &const_[0]
    cdef const intp[::1] lr_start = gauss["lr_start"]
    cdef const intp[::1] lr_rank = gauss["lr_rank"]
    cdef const double[:, ::1] lr_vectors = gauss["lr_vectors"]
    cdef const double[::1] lr_weights = gauss["lr_weights"]
    cdef const double[::1] lr_inv_floor = gauss["lr_inv_floor"]
    g.lr_start = &lr_start[0]
    g.lr_rank = &lr_rank[0]
    g.lr_vectors = &lr_vectors[0, 0] if lr_vectors.shape[0] else NULL
    g.lr_weights = &lr_weights[0] if lr_weights.shape[0] else NULL
    g.lr_inv_floor = &lr_inv_floor[0]
    g.d = means.shape[1]
    g.full = gauss["full"]
    return g


cdef Table _table(object table):
    cdef Table t
    cdef const intp[::1] pair_start = table["pair_start"]
    cdef const intp[::1] pair_dst = table["pair_dst"]
    cdef const double[:, ::1] pair_log = table["pair_log"]
    cdef const double[:, ::1] unseen_log = table["unseen_log"]
    cdef const double[::1] dense = table["dense"]
    t.pair_start = &pair_start[0]
    t.pair_dst = &pair_dst[0] if pair_dst.shape[0] else NULL
    t.pair_log = &pair_log[0, 0] if pair_log.shape[0] else NULL
    t.unseen_log = &unseen_log[0, 0]
    t.dense = &dense[0] if dense.shape[0] else NULL
    t.k = table["k"]
    t.n_graphs = table["n_graphs"]
    return t


cdef const unsigned char* _mask(const unsigned char[:, ::1] allowed):
    return &allowed[0, 0] if allowed.shape[0] else NULL


cdef Layer _layer(object spec):
    cdef Layer out
    cdef const intp[:, ::1] children = spec[0]
    cdef const intp[::1] ids = spec[1]
    out.children = &children[0, 0]
    out.ids = &ids[0]
    out.k = ids.shape[0]
    out.search = _table(spec[2])
    out.score = _table(spec[3])
    out.search_allowed = _mask(spec[4])
    out.score_allowed = _mask(spec[5])
    return out


cdef struct Work:
    # per frame of the longest clip, at most 2 n_paths candidates (the root has 1 kept node, then n_paths)
    intp* beam          # (T, n_paths) kept nodes of the layer above
    intp* next_beam
    double* beam_emit   # (T, n_paths) their emissions, when known
    double* next_emit
    intp* cand          # (slots, T, 2 n_paths) candidates of each stored layer
    double* emit        # (slots, T, 2 n_paths) their emissions
    double* masked      # (T, 2 n_paths) emissions with a scored graph's forbidden nodes at -inf
    double* steps       # (T, 2 n_paths, 2 n_paths)
    double* fwd
    double* bwd
    double* moves
    double* delta
    double* scratch
    intp* head
    intp* back          # (T, n_paths, 2 n_paths), or NULL when no paths are wanted
    double* moves_all   # (2 n_paths, 2 n_paths, P): the moves in each of a search's P graphs, gathered
    const double** move_rows  # (2 n_paths, 2 n_paths): where each pair's P moves are
    double* prev_all    # (2 n_paths, P)
    double* cur_all
    double* y           # (4 d,)


cdef void _free_work(Work* w) noexcept:
    free(w.beam); free(w.next_beam); free(w.beam_emit); free(w.next_emit); free(w.cand); free(w.emit)
    free(w.masked); free(w.steps); free(w.fwd); free(w.bwd); free(w.moves); free(w.delta); free(w.scratch)
    free(w.head); free(w.back); free(w.y); free(w.moves_all); free(w.move_rows); free(w.prev_all)
    free(w.cur_all)


cdef bint _alloc_work(Work* w, intp max_steps, intp n_paths, intp slots, intp d, bint paths,
                      intp max_graphs) noexcept:
    cdef intp t = max(max_steps, 1), nc = 2 * n_paths, g = max(max_graphs, 1)
    w.beam = <intp*> malloc(t * n_paths * sizeof(intp))
    w.next_beam = <intp*> malloc(t * n_paths * sizeof(intp))
    w.beam_emit = <double*> malloc(t * n_paths * sizeof(double))
    w.next_emit = <double*> malloc(t * n_paths * sizeof(double))
    w.cand = <intp*> malloc(slots * t * nc * sizeof(intp))
    w.emit = <double*> malloc(slots * t * nc * sizeof(double))
    w.masked = <double*> malloc(t * nc * sizeof(double))
    w.steps = <double*> malloc(t * nc * nc * sizeof(double))
    w.fwd = <double*> malloc(t * nc * sizeof(double))
    w.bwd = <double*> malloc(t * nc * sizeof(double))
    w.moves = <double*> malloc(nc * nc * sizeof(double))
    w.delta = <double*> malloc(2 * n_paths * nc * sizeof(double))
    w.scratch = <double*> malloc(n_paths * nc * sizeof(double))
    w.head = <intp*> malloc(nc * sizeof(intp))
    w.back = <intp*> malloc(t * n_paths * nc * sizeof(intp)) if paths else NULL
    w.y = <double*> malloc(4 * max(d, 1) * sizeof(double))
    w.moves_all = <double*> malloc(nc * nc * g * sizeof(double))
    w.move_rows = <const double**> malloc(nc * nc * sizeof(double*))
    w.prev_all = <double*> malloc(nc * g * sizeof(double))
    w.cur_all = <double*> malloc(nc * g * sizeof(double))
    return not (w.beam == NULL or w.next_beam == NULL or w.beam_emit == NULL or w.next_emit == NULL
                or w.cand == NULL or w.emit == NULL or w.masked == NULL or w.steps == NULL or w.fwd == NULL
                or w.bwd == NULL or w.moves == NULL or w.delta == NULL or w.scratch == NULL or w.head == NULL
                or (paths and w.back == NULL) or w.y == NULL or w.moves_all == NULL or w.move_rows == NULL or w.prev_all == NULL
                or w.cur_all == NULL)


cdef intp _candidates(const Layer* lay, intp n_steps, intp width, intp search_graph, bint carry,
                      const Gaussians* g, const double* frames, Work* w, intp* cand, double* emit,
                      bint emissions) noexcept nogil:
    """Each frame's candidates (children of its kept nodes) and, with ``emissions``, their log densities.

    A leaf copied down is its own only child: with ``carry`` (the kept nodes'
    emissions are known) its emission is carried, not recomputed. The others
    are computed per run of frames whose slot holds the same node. Returns the
    candidates per frame.
    """
    cdef intp t, side, j, c, node, child, end, n_cand = 2 * width
    cdef const unsigned char* allowed = (lay.search_allowed + search_graph * lay.k
                                         if lay.search_allowed != NULL else NULL)
    for t in range(n_steps):
        for side in range(2):
            for j in range(width):
                c = t * n_cand + side * width + j
                node = w.beam[t * width + j]
                child = -1 if node < 0 else lay.children[2 * node + side]
                if child >= 0 and allowed != NULL and not allowed[child]:
                    child = -1
                cand[c] = child
                if not emissions:
                    continue
                if child < 0:
                    emit[c] = -INFINITY
                elif carry and side == 0 and lay.children[2 * node + 1] < 0:
                    emit[c] = w.beam_emit[t * width + j]
                else:
                    emit[c] = NAN  # to compute, below
    if not emissions:
        return n_cand
    for c in range(n_cand):
        t = 0
        while t < n_steps:
            if emit[t * n_cand + c] == emit[t * n_cand + c]:  # known (not NaN)
                t += 1
                continue
            child = cand[t * n_cand + c]
            end = t + 1
            while end < n_steps and cand[end * n_cand + c] == child and emit[end * n_cand + c] != emit[end * n_cand + c]:
                end += 1
            _emissions(g, frames + t * g.d, end - t, lay.ids[child], emit + t * n_cand + c, n_cand, w.y)
            t = end
    return n_cand


cdef intp _keep(intp n_steps, intp n_cand, intp n_paths, const intp* cand, const double* emit, bint have_emit,
                const Table* tab, intp graph, Work* w) noexcept nogil:
    """The next layer's beam (``w.next_beam``, ``w.next_emit``): each frame's ``n_paths`` best candidates.

    The best max-marginals are kept (ties to the lower slot), -1 for candidates
    of no finite score; with ``n_cand <= n_paths`` all are kept, unscored (and
    their emissions carried when ``have_emit``). A frame's kept nodes are stored
    in node order, -1 last: consecutive frames often keep the same nodes, whose
    slots then match, so their moves are looked up once and a slot's emissions
    run over many frames. Returns the new width.
    """
    cdef intp t, c, r, i, keep, node
    cdef double v, e
    cdef intp* kept
    cdef double* kept_emit
    if n_cand <= n_paths:
        for t in range(n_steps * n_cand):
            w.next_beam[t] = cand[t]
            if have_emit:
                w.next_emit[t] = emit[t]
        return n_cand
    keep = n_paths
    _steps(n_steps, n_cand, tab, graph, cand, emit, w.moves, w.steps)
    _max_marginals(n_steps, n_cand, emit, w.steps, w.fwd, w.bwd)
    for t in range(n_steps):
        kept = w.next_beam + t * keep
        kept_emit = w.next_emit + t * keep
        for c in range(n_cand):
            w.fwd[t * n_cand + c] += w.bwd[t * n_cand + c]
        for r in range(keep):
            c = _pick(w.fwd + t * n_cand, n_cand, &v)
            node = cand[t * n_cand + c] if v > -INFINITY else -1
            e = emit[t * n_cand + c]
            i = r  # insertion into node order, -1 last
            while i > 0 and (kept[i - 1] < 0 or (0 <= node < kept[i - 1])):
                kept[i] = kept[i - 1]
                kept_emit[i] = kept_emit[i - 1]
                i -= 1
            kept[i] = node
            kept_emit[i] = e
    return keep


cdef void _best_all(intp n_steps, intp n_cand, const Table* tab, const intp* graphs, intp n_graphs,
                    const intp* cand, const double* emit, Work* w, double* out, intp out_stride) noexcept nogil:
    """The best sequence's score under each of a search's graphs at once.

    The graphs share the candidates and their emissions, and the table holds
    one transition of every graph contiguously: each step runs over the graphs
    in the innermost loop, which the compiler vectorises. When the graphs are
    the table's in order (as MotionTreeHMM asks), that loop reads the table in
    place; otherwise their values are gathered first. The sums are those of
    :func:`_best` for each graph alone, in the same order.
    """
    cdef intp t, i, j, q, src, P = n_graphs
    cdef double best
    cdef double* prev = w.prev_all
    cdef double* cur = w.cur_all
    cdef double* tmp
    cdef double* gathered
    cdef const double* base
    cdef bint in_order = True
    for q in range(1, P):
        in_order = in_order and graphs[q] == graphs[0] + q
    for j in range(n_cand):
        for q in range(P):
            prev[j * P + q] = emit[j]
    for t in range(1, n_steps):
        if t == 1 or not (_same_row(cand + (t - 1) * n_cand, cand + (t - 2) * n_cand, n_cand)
                          and _same_row(cand + t * n_cand, cand + (t - 1) * n_cand, n_cand)):
            for i in range(n_cand):
                src = cand[(t - 1) * n_cand + i]
                for j in range(n_cand):
                    base = _moves_of(tab, src, cand[t * n_cand + j])
                    if in_order:
                        w.move_rows[i * n_cand + j] = base + graphs[0]
                    else:
                        gathered = w.moves_all + (i * n_cand + j) * P
                        for q in range(P):
                            gathered[q] = base[graphs[q]]
                        w.move_rows[i * n_cand + j] = gathered
        skm_step_all(prev, w.move_rows, emit + t * n_cand, n_cand, P, cur)
        tmp = prev
        prev = cur
        cur = tmp
    for q in range(P):
        best = -INFINITY
        for j in range(n_cand):
            if prev[j * P + q] > best:
                best = prev[j * P + q]
        out[q * out_stride] = best


cdef void _score(intp mode, intp n_steps, intp n_cand, intp n_paths, const Layer* lay, intp graph,
                 const intp* cand, const double* emit, Work* w, double* scores, intp* paths,
                 intp path_stride) noexcept nogil:
    """One problem at one scored layer: its best score (``BEST``) or its ``n_paths`` best sequences."""
    cdef intp i
    cdef const unsigned char* allowed
    if lay.score_allowed != NULL:  # the graph's prior leaves its unvisited nodes out
        allowed = lay.score_allowed + graph * lay.k
        for i in range(n_steps * n_cand):
            w.masked[i] = emit[i] if cand[i] >= 0 and allowed[cand[i]] else -INFINITY
        emit = w.masked
    _steps(n_steps, n_cand, &lay.score, graph, cand, emit, w.moves, w.steps)
    if mode == BEST:
        scores[0] = _best(n_steps, n_cand, emit, w.steps, w.fwd)
    else:
        _kbest(n_steps, n_cand, n_paths, cand, emit, w.steps, w.delta, w.scratch, w.head, w.back, paths,
               path_stride, scores)


cdef struct Decode:
    # What one call decodes: the searches' inputs, the layers, the outputs and the scratch.
    const double* frames        # (n_frames, d)
    const intp* frame_start     # (n_searches,)
    const intp* n_steps         # (n_searches,)
    const intp* search_graph    # (n_searches,)
    const intp* problem_start   # (n_searches + 1,)
    const intp* score_graph     # (n_problems,)
    Layer* lays                 # entries 1 .. n_layers
    Gaussians g
    intp n_layers
    intp first_scored
    intp n_scored
    intp n_paths
    intp max_steps
    intp mode
    double* scores              # (n_problems, n_scored, n_paths)
    intp* paths                 # (n_problems, n_paths, max_steps), or NULL when no paths are wanted
    Work w
    intp* best_widths           # (n_scored,) candidates per frame at each scored layer ("prune")
    double* best_sum            # (n_problems,) summed best scores ("prune")
    bint* live                  # (n_problems,) problems that may still win their search ("prune")


cdef void _release(Decode* dec) noexcept:
    _free_work(&dec.w)
    free(dec.lays)
    free(dec.best_widths)
    free(dec.best_sum)
    free(dec.live)


cdef int _allocate(Decode* dec, list layers, intp n_searches, intp n_problems) except -1:
    """The layers' views and the scratch of the longest search; a MemoryError when they do not fit.

    Everything is allocated before anything may raise, so :func:`_release` always applies.
    """
    cdef intp s, l, max_graphs = 0
    cdef intp slots = 1 + (dec.n_scored if dec.mode == PRUNE else 0)
    for s in range(n_searches):
        max_graphs = max(max_graphs, dec.problem_start[s + 1] - dec.problem_start[s])
    dec.lays = <Layer*> malloc((dec.n_layers + 1) * sizeof(Layer))
    dec.best_widths = <intp*> malloc((dec.n_scored + 1) * sizeof(intp))
    dec.best_sum = <double*> malloc(max(n_problems, 1) * sizeof(double))
    dec.live = <bint*> malloc(max(n_problems, 1) * sizeof(bint))
    cdef bint ok = _alloc_work(&dec.w, dec.max_steps, dec.n_paths, slots, dec.g.d, dec.paths != NULL,
                               max_graphs)
    if not ok or dec.lays == NULL or dec.best_widths == NULL or dec.best_sum == NULL or dec.live == NULL:
        raise MemoryError(f"decoding {dec.max_steps} frames with {2 * dec.n_paths} candidates each")
    for l in range(1, dec.n_layers + 1):
        dec.lays[l] = _layer(layers[l])
    return 0


cdef void _score_layer(Decode* dec, intp s, intp l, intp n_cand, const intp* cand, const double* emit) noexcept nogil:
    """Every problem of search ``s`` at scored layer ``l``: the best score, or the ``n_paths`` best sequences.

    With ``"prune"`` the best scores alone (summed per problem into ``best_sum``);
    the lists come after the last layer, for the problems still live.
    """
    cdef intp p, li = l - dec.first_scored, p0 = dec.problem_start[s], p1 = dec.problem_start[s + 1]
    cdef intp row = dec.n_scored * dec.n_paths
    cdef const Layer* lay = &dec.lays[l]
    cdef bint paths_now = dec.paths != NULL and l == dec.n_layers and dec.mode == KBEST
    dec.best_widths[li] = n_cand
    if dec.mode != KBEST and lay.score_allowed == NULL and p1 > p0:
        _best_all(dec.n_steps[s], n_cand, &lay.score, dec.score_graph + p0, p1 - p0, cand, emit, &dec.w,
                  dec.scores + p0 * row + li * dec.n_paths, row)
    else:
        for p in range(p0, p1):
            _score(BEST if dec.mode == PRUNE else dec.mode, dec.n_steps[s], n_cand, dec.n_paths, lay,
                   dec.score_graph[p], cand, emit, &dec.w, dec.scores + p * row + li * dec.n_paths,
                   dec.paths + p * dec.n_paths * dec.max_steps if paths_now else NULL, dec.max_steps)
    if dec.mode == PRUNE:
        for p in range(p0, p1):
            dec.best_sum[p] += dec.scores[p * row + li * dec.n_paths]


cdef void _search(Decode* dec, intp s) noexcept nogil:
    """Search ``s`` top-down: each layer's candidates and emissions, its scores if scored, the next beam.

    With ``"prune"`` each scored layer keeps its candidates and emissions in its
    own slot of the scratch, for the lists :func:`_prune` may run afterwards.
    """
    cdef intp t, p, l, slot, n_cand, width = 1, n = dec.n_steps[s], n_paths = dec.n_paths
    cdef intp slot_size = dec.max_steps * 2 * n_paths
    cdef bint carry = False, scored, need
    cdef Work* w = &dec.w
    cdef intp* cand
    cdef double* emit
    cdef intp* tmp_i
    cdef double* tmp_d
    for t in range(n):
        w.beam[t] = 0  # layer 0: the root
    for p in range(dec.problem_start[s], dec.problem_start[s + 1]):
        dec.best_sum[p] = 0.0
    for l in range(1, dec.n_layers + 1):
        scored = l >= dec.first_scored
        slot = 1 + l - dec.first_scored if (scored and dec.mode == PRUNE) else 0
        cand = w.cand + slot * slot_size
        emit = w.emit + slot * slot_size
        # emissions are needed to score this layer or to choose among its candidates
        need = scored or (2 * width > n_paths and l < dec.n_layers)
        n_cand = _candidates(&dec.lays[l], n, width, dec.search_graph[s], carry, &dec.g,
                             dec.frames + dec.frame_start[s] * dec.g.d, w, cand, emit, need)
        if scored:
            _score_layer(dec, s, l, n_cand, cand, emit)
        if l < dec.n_layers:
            width = _keep(n, n_cand, n_paths, cand, emit, need, &dec.lays[l].search, dec.search_graph[s], w)
            carry = need
            tmp_i = w.beam
            w.beam = w.next_beam
            w.next_beam = tmp_i
            tmp_d = w.beam_emit
            w.beam_emit = w.next_emit
            w.next_emit = tmp_d


cdef void _prune(Decode* dec, intp s) noexcept nogil:
    """``"prune"``: the lists of the problems of search ``s`` that may still hold its highest summed score.

    The sum of ``n_paths`` sequences lies between the best one and ``n_paths``
    times it, at each layer: a problem whose summed best scores plus
    ``n_scored log(n_paths)`` stay below the best sum cannot win, and gets
    ``-inf``. A search left with one live problem has its winner, which keeps
    its best scores alone.
    """
    cdef intp p, li, l, n_live = 0, row = dec.n_scored * dec.n_paths
    cdef intp slot_size = dec.max_steps * 2 * dec.n_paths
    cdef double top = -INFINITY, margin = dec.n_scored * log(<double> dec.n_paths)
    for p in range(dec.problem_start[s], dec.problem_start[s + 1]):
        top = max(top, dec.best_sum[p])
    for p in range(dec.problem_start[s], dec.problem_start[s + 1]):
        # kept with a margin for rounding in the sums of n_paths terms
        dec.live[p] = dec.best_sum[p] + margin >= top - 1e-9 * abs(top)
        n_live += dec.live[p]
        if not dec.live[p]:
            for li in range(dec.n_scored):
                dec.scores[p * row + li * dec.n_paths] = -INFINITY
    if n_live == 1:
        return
    for p in range(dec.problem_start[s], dec.problem_start[s + 1]):
        if not dec.live[p]:
            continue
        for li in range(dec.n_scored):
            l = dec.first_scored + li
            _score(KBEST, dec.n_steps[s], dec.best_widths[li], dec.n_paths, &dec.lays[l], dec.score_graph[p],
                   dec.w.cand + (1 + li) * slot_size, dec.w.emit + (1 + li) * slot_size, &dec.w,
                   dec.scores + p * row + li * dec.n_paths,
                   dec.paths + p * dec.n_paths * dec.max_steps if dec.paths != NULL and l == dec.n_layers
                   else NULL, dec.max_steps)


def decode_searches(const double[:, ::1] frames, const intp[::1] frame_start, const intp[::1] n_steps,
                    const intp[::1] search_graph, const intp[::1] problem_start, const intp[::1] score_graph,
                    object gauss, list layers, intp first_scored, intp n_paths, str mode, bint want_paths):
    """Decode searches top-down through ``len(layers) - 1`` layers, scoring the last ones.

    Search ``s`` decodes frames ``frame_start[s] : frame_start[s] + n_steps[s]``
    under graph ``search_graph[s]`` of the search tables; its problems are
    ``problem_start[s] : problem_start[s + 1]``, problem ``p`` the same clip under
    graph ``score_graph[p]`` of the scored tables.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, d)
    frame_start, n_steps, search_graph : ndarray of shape (n_searches,)
    problem_start : ndarray of shape (n_searches + 1,)
    score_graph : ndarray of shape (n_problems,)
    gauss : dict
        The nodes' Gaussians as :func:`skmotion.tree._layout.gaussian_arrays` lays them out.
    layers : list
        Entry ``l`` (1 to ``L``; entry 0 is unused) is ``(children, ids,
        search_table, score_table, search_allowed, score_allowed)``, as
        ``skmotion.tree._decode._layer_specs`` makes it: the children in
        layer ``l`` of the nodes of ``l - 1``, the layer's tree node ids, the
        two graphs' transition tables, and the allowed-node masks
        ``(n_graphs, K_l)`` of uint8, or ``(0, 0)`` for all nodes.
    first_scored : int
        Layers ``first_scored .. L`` are scored (``1 <= first_scored <= L``).
    n_paths : int
        Nodes kept per frame, and sequences per problem.
    mode : {"best", "kbest", "prune"}
        ``"best"``: the best sequence's score at each scored layer. ``"kbest"``:
        the ``n_paths`` best sequences. ``"prune"``: the best first; then the
        list only for the problems whose summed best scores plus
        ``n_scored log(n_paths)`` reach the best sum of their search (the
        others cannot hold the highest summed probability and get ``-inf``); a
        search left with one such problem keeps its best scores alone.
    want_paths : bool
        Return the node paths at layer ``L`` (``"kbest"`` and ``"prune"``).

    Returns
    -------
    scores : ndarray of shape (n_problems, n_scored, n_paths)
        Log scores (``log Po`` emissions, no normaliser), best first; ``-inf``
        for missing sequences.
    paths : ndarray of shape (n_problems, n_paths, max(n_steps)) or None
        Node sequences at layer ``L``; -1 past a clip's length and for missing ones.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}; got {mode!r}.")
    cdef Decode dec
    cdef intp s, n_searches = frame_start.shape[0], n_problems = score_graph.shape[0]
    dec.n_layers = len(layers) - 1
    if dec.n_layers < 1 or not 1 <= first_scored <= dec.n_layers:
        raise ValueError(f"need 1 <= first_scored <= {dec.n_layers} layers; got {first_scored}.")
    dec.mode = MODES.index(mode)
    dec.first_scored = first_scored
    dec.n_scored = dec.n_layers - first_scored + 1
    dec.n_paths = n_paths
    dec.max_steps = 0
    for s in range(n_searches):
        dec.max_steps = max(dec.max_steps, n_steps[s])
    dec.frames = &frames[0, 0]
    dec.frame_start = &frame_start[0]
    dec.n_steps = &n_steps[0]
    dec.search_graph = &search_graph[0]
    dec.problem_start = &problem_start[0]
    dec.score_graph = &score_graph[0]
    dec.g = _gaussians(gauss)
    scores_array = np.full((n_problems, dec.n_scored, n_paths), -np.inf)
    cdef double[:, :, ::1] scores = scores_array
    dec.scores = &scores[0, 0, 0]
    paths_array = None
    cdef intp[:, :, ::1] paths
    dec.paths = NULL
    if want_paths and dec.mode != BEST:
        paths_array = np.full((n_problems, n_paths, dec.max_steps), -1, dtype=np.intp)
        paths = paths_array
        dec.paths = &paths[0, 0, 0]
    try:
        _allocate(&dec, layers, n_searches, n_problems)
        with nogil:
            for s in range(n_searches):
                if dec.n_steps[s]:
                    _search(&dec, s)
                    if dec.mode == PRUNE:
                        _prune(&dec, s)
    finally:
        _release(&dec)
    return scores_array, paths_array
