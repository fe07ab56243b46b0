# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled top-down beam Viterbi (see :mod:`skmotion.tree._decoder._decode`).

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

The arithmetic is that of the numpy reference (:mod:`skmotion.tree._decoder._viterbi`):
a step's score is ``move + emission`` of the arriving node, added to the score
so far, and ties go to the lower candidate slot (or rank, then slot). Slot
``side * width + w`` of a frame is child ``side`` (0 left, 1 right) of its
``w``-th kept node; -1 is "no node". Emissions are ``log Po(x | k)``; the
normaliser of ``Ps`` is the same for every candidate of a frame, so the caller
subtracts its per-clip sum from the scores.

:func:`decode_searches` allocates once (:func:`_allocate`, the longest search's
scratch, in :mod:`skmotion.tree._decoder._beam_memory`), then runs one search after
another (:func:`_search`: steps 1 and 2 in :mod:`skmotion.tree._decoder._beam_candidates`,
step 4, and :func:`_score_layer` for step 3)
and, for ``"prune"``, the lists of the problems still live (:func:`_prune`). The
passes that score a problem (:func:`_best`, :func:`_best_all`, :func:`_kbest`)
are in :mod:`skmotion.tree._decoder._beam_passes`; the structs the three modules share
are declared in ``_beam_structs.pxd``. The arrays it reads
are laid out by :mod:`skmotion.tree._decoder._tables`.
"""

import numpy as np

from libc.math cimport INFINITY, log

from skmotion.tree._decoder._beam_candidates cimport _candidates
from skmotion.tree._decoder._beam_memory cimport _allocate, _gaussians, _release
from skmotion.tree._decoder._beam_passes cimport _best, _best_all, _kbest
from skmotion.tree._decoder._beam_structs cimport (
    BEST, KBEST, PRUNE, Decode, Layer, Table, Work, _moves_of, _pick, _same_row, intp,
)

#: What a call computes per problem; see :func:`decode_searches`.
MODES = ("best", "kbest", "prune")


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
        The nodes' Gaussians as :func:`skmotion.tree._decoder._tables.gaussian_arrays` lays them out.
    layers : list
        Entry ``l`` (1 to ``L``; entry 0 is unused) is ``(children, ids,
        search_table, score_table, search_allowed, score_allowed)``, as
        ``skmotion.tree._decoder._decode._layer_specs`` makes it: the children in
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
