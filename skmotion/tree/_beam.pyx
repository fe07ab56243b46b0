# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled inner loops of the top-down beam Viterbi (see :mod:`skmotion.tree._decode`).

The recursions of a Viterbi pass run frame after frame, as they must; done in
numpy they cost one Python step per frame and layer. Here one call handles one
layer of every problem (a clip decoded under one graph): it forms each frame's
candidates (the children of its kept nodes), their Gaussian log densities and
the transition log probabilities between consecutive candidates, then runs the
max-product pass that layer needs. The arithmetic is that of the numpy
reference (:mod:`skmotion.tree._viterbi`): a step's score is ``move + emission``
of the arriving node, added to the score so far, and ties go to the lower
candidate slot (or rank, then slot).

Candidate slots of a frame: ``side * width + w`` is child ``side`` (0 left, 1
right) of the frame's ``w``-th kept node; -1 is "no node".
"""

import numpy as np

from libc.math cimport INFINITY
from libc.stdlib cimport free, malloc

ctypedef Py_ssize_t intp


cdef struct Gaussians:
    const double* means     # (n_tree_nodes, d)
    const double* prec      # diag: (n_tree_nodes, d) precisions; full: (n_tree_nodes, d, d) upper factors
    const double* shifts    # full only: (n_tree_nodes, d), mean @ factor
    const double* const_    # (n_tree_nodes,)
    const intp* ids         # layer index -> tree node id
    intp d
    bint full


cdef struct Table:
    const intp* indptr      # (n_graphs * K + 1,)
    const intp* indices     # destination nodes of the stored transitions, sorted within a row
    const double* seen      # their log probabilities
    const double* unseen    # (n_graphs * K,) log probability of a transition never seen
    const double* dense     # (K + 1, K + 1, n_graphs) log probabilities (K: no node), or NULL
    intp k
    intp n_graphs


cdef struct Problem:
    const double* frames    # the clip's first frame
    intp n_steps
    const intp* beam        # the clip's rows of the previous layer's beam, (n_steps, width)
    intp width
    intp graph
    const unsigned char* allowed   # the graph's allowed nodes, or NULL for all
    const double* norm      # per-frame normaliser to subtract, or NULL
    intp norm_stride


cdef inline double _emission(const Gaussians* g, const double* x, intp node, double* y) noexcept nogil:
    """Log density of frame ``x`` under the node's Gaussian; ``y`` is scratch of ``d`` doubles.

    Sums run in four independent parts: one running sum is a chain of
    dependent additions that the compiler may not reorder, four keep the
    processor's pipelines full.
    """
    cdef intp n = g.ids[node], d = g.d, a, b
    cdef const double* p
    cdef const double* mu
    cdef double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0, xa
    if g.full:
        # y = x @ U - mean @ U, U upper triangular, row by row (contiguous and independent per column)
        p = g.prec + n * d * d
        mu = g.shifts + n * d
        for b in range(d):
            y[b] = -mu[b]
        for a in range(d):
            xa = x[a]
            for b in range(a, d):
                y[b] += xa * p[a * d + b]
        for b in range(d):
            y[b] = y[b] * y[b]
    else:
        p = g.prec + n * d
        mu = g.means + n * d
        for a in range(d):
            y[a] = (x[a] - mu[a]) * (x[a] - mu[a]) * p[a]
    a = 0
    while a + 4 <= d:
        s0 += y[a]
        s1 += y[a + 1]
        s2 += y[a + 2]
        s3 += y[a + 3]
        a += 4
    while a < d:
        s0 += y[a]
        a += 1
    return g.const_[n] - 0.5 * ((s0 + s1) + (s2 + s3))


cdef inline double _transition(const Table* t, intp graph, intp src, intp dst) noexcept nogil:
    """``log p(src -> dst)`` in a graph; -inf when either is "no node"."""
    if src < 0 or dst < 0:
        return -INFINITY
    if t.dense != NULL:
        return t.dense[(src * (t.k + 1) + dst) * t.n_graphs + graph]
    cdef intp row = graph * t.k + src
    cdef intp lo = t.indptr[row], hi = t.indptr[row + 1], end = t.indptr[row + 1], mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if t.indices[mid] < dst:
            lo = mid + 1
        else:
            hi = mid
    if lo < end and t.indices[lo] == dst:
        return t.seen[lo]
    return t.unseen[row]


cdef void _candidates(const Problem* pb, const intp* children, intp* cand) noexcept nogil:
    """Children of each frame's kept nodes, ``(n_steps, 2 * width)``; -1 for none or not allowed."""
    cdef intp t, side, w, node, child, width = pb.width, n_cand = 2 * pb.width
    for t in range(pb.n_steps):
        for side in range(2):
            for w in range(width):
                node = pb.beam[t * width + w]
                child = -1 if node < 0 else children[2 * node + side]
                if child >= 0 and pb.allowed != NULL and not pb.allowed[child]:
                    child = -1
                cand[t * n_cand + side * width + w] = child


cdef void _emissions(const Problem* pb, const Gaussians* g, const intp* cand, intp n_cand, double* emit,
                     double* y) noexcept nogil:
    cdef intp t, c, node
    cdef const double* x
    for t in range(pb.n_steps):
        x = pb.frames + t * g.d
        for c in range(n_cand):
            node = cand[t * n_cand + c]
            if node < 0:
                emit[t * n_cand + c] = -INFINITY
            else:
                emit[t * n_cand + c] = _emission(g, x, node, y)
                if pb.norm != NULL:
                    emit[t * n_cand + c] -= pb.norm[t * pb.norm_stride]


cdef bint _same_row(const intp* a, const intp* b, intp n) noexcept nogil:
    cdef intp i
    for i in range(n):
        if a[i] != b[i]:
            return False
    return True


cdef void _steps(const Problem* pb, const Table* tab, const intp* cand, const double* emit, intp n_cand,
                 double* moves, double* steps) noexcept nogil:
    """``steps[t, i, j]``: move from slot ``i`` at ``t`` to slot ``j`` at ``t + 1``, plus ``j``'s emission.

    A node stays for many frames, so the candidates of consecutive frames often
    repeat; the moves ``(n_cand, n_cand)`` are looked up again only when they change.
    """
    cdef intp t, i, j, src, dst
    cdef double* row
    cdef const double* move
    cdef const double* base
    for t in range(pb.n_steps - 1):
        if t == 0 or not (_same_row(cand + t * n_cand, cand + (t - 1) * n_cand, n_cand)
                          and _same_row(cand + (t + 1) * n_cand, cand + t * n_cand, n_cand)):
            if tab.dense != NULL:  # no search and no branch: "no node" is row and column K, -inf
                for i in range(n_cand):
                    src = cand[t * n_cand + i]
                    base = tab.dense + (tab.k if src < 0 else src) * (tab.k + 1) * tab.n_graphs + pb.graph
                    for j in range(n_cand):
                        dst = cand[(t + 1) * n_cand + j]
                        moves[i * n_cand + j] = base[(tab.k if dst < 0 else dst) * tab.n_graphs]
            else:
                for i in range(n_cand):
                    src = cand[t * n_cand + i]
                    for j in range(n_cand):
                        moves[i * n_cand + j] = _transition(tab, pb.graph, src, cand[(t + 1) * n_cand + j])
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
    """List Viterbi: the ``n_paths`` best slot sequences, as node paths (rows of -1 stay for missing ones).

    ``head`` is scratch of ``n_cand``: the rank of each slot's next unpicked entry.
    """
    cdef intp t, r, r2, i, j, e, arg, rank, state, n_entries = n_paths * n_cand
    cdef double best
    cdef double* prev = delta
    cdef double* cur = delta + n_entries
    cdef double* tmp
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
                        back[(t * n_paths + r2) * n_cand + j] = 0
                    break
                # among equal heads the lowest entry: the lowest rank, then the lowest slot
                for i in range(n_cand):
                    if head[i] < n_paths and scratch[i] == best and head[i] * n_cand + i < head[arg] * n_cand + arg:
                        arg = i
                cur[r * n_cand + j] = best
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
        if scores[r] == -INFINITY:
            continue
        rank = e // n_cand
        state = e % n_cand
        for t in range(n_steps - 1, -1, -1):
            paths[r * path_stride + t] = cand[t * n_cand + state]
            if t:
                e = back[(t * n_paths + rank) * n_cand + state]
                rank = e // n_cand
                state = e % n_cand


cdef Gaussians _gaussians(object gauss, const intp[::1] ids):
    cdef Gaussians g
    cdef const double[:, ::1] means = gauss["means"]
    cdef const double[::1] prec = gauss["prec"]
    cdef const double[:, ::1] shifts = gauss["shifts"]
    cdef const double[::1] const_ = gauss["const"]
    g.means = &means[0, 0]
    g.prec = &prec[0]
    g.shifts = &shifts[0, 0]
    g.const_ = &const_[0]
    g.ids = &ids[0]
    g.d = means.shape[1]
    g.full = gauss["full"]
    return g


cdef Table _table(object table):
    cdef Table t
    cdef const intp[::1] indptr = table[0]
    cdef const intp[::1] indices = table[1]
    cdef const double[::1] seen = table[2]
    cdef const double[::1] unseen = table[3]
    cdef const double[::1] dense = table[5]
    t.indptr = &indptr[0]
    t.indices = &indices[0] if indices.shape[0] else NULL
    t.seen = &seen[0] if seen.shape[0] else NULL
    t.unseen = &unseen[0]
    t.dense = &dense[0] if dense.shape[0] else NULL
    t.k = table[4]
    t.n_graphs = table[6]
    return t


def descend_layer(const double[:, ::1] frames, const intp[::1] frame_start, const intp[::1] n_steps,
                  const intp[:, ::1] beam, const intp[::1] beam_start, const intp[::1] graph,
                  const intp[:, ::1] children, const unsigned char[:, ::1] allowed, object gauss,
                  const intp[::1] ids, object table, intp n_paths):
    """One layer down: the new per-frame beam of every problem.

    Problem ``p`` decodes frames ``frame_start[p] : frame_start[p] + n_steps[p]``
    under graph ``graph[p]``; its rows of ``beam`` (the kept nodes of the layer
    above, ``(n_rows, width)``, -1 for none) start at ``beam_start[p]``, and so
    do its rows of the result. A frame keeps the ``n_paths`` candidates with the
    best max-marginal (best first, ties to the lower slot; -1 for candidates of
    no finite score); with ``2 * width <= n_paths`` it keeps them all unscored.

    ``allowed`` is ``(n_graphs, K)``, or ``(0, 0)`` for every node. ``gauss`` and
    ``table`` come from :meth:`MotionTree.kernel_gaussians` and
    :meth:`TransitionGraphs.kernel_table`.
    """
    cdef intp width = beam.shape[1], n_cand = 2 * width, n_problems = frame_start.shape[0]
    cdef intp keep = min(n_paths, n_cand), max_steps = 0, p, t, c, r
    cdef double v
    cdef Gaussians g = _gaussians(gauss, ids)
    cdef Table tab = _table(table)
    out_array = np.full((beam.shape[0], keep), -1, dtype=np.intp)
    cdef intp[:, ::1] out = out_array
    cdef Problem pb
    for p in range(n_problems):
        max_steps = max(max_steps, n_steps[p])
    cdef intp* cand = <intp*> malloc(max(max_steps * n_cand, 1) * sizeof(intp))
    cdef double* emit = <double*> malloc(max(max_steps * n_cand, 1) * sizeof(double))
    cdef double* steps = <double*> malloc(max(max_steps * n_cand * n_cand, 1) * sizeof(double))
    cdef double* fwd = <double*> malloc(max(max_steps * n_cand, 1) * sizeof(double))
    cdef double* bwd = <double*> malloc(max(max_steps * n_cand, 1) * sizeof(double))
    cdef double* moves = <double*> malloc(n_cand * n_cand * sizeof(double))
    cdef double* y = <double*> malloc(g.d * sizeof(double))
    if cand == NULL or emit == NULL or steps == NULL or fwd == NULL or bwd == NULL or moves == NULL or y == NULL:
        free(cand); free(emit); free(steps); free(fwd); free(bwd); free(moves); free(y)
        raise MemoryError(f"decoding {max_steps} frames with {n_cand} candidates each")
    try:
        with nogil:
            for p in range(n_problems):
                if n_steps[p] == 0:
                    continue
                pb.frames = &frames[frame_start[p], 0]
                pb.n_steps = n_steps[p]
                pb.beam = &beam[beam_start[p], 0]
                pb.width = width
                pb.graph = graph[p]
                pb.allowed = &allowed[graph[p], 0] if allowed.shape[0] else NULL
                pb.norm = NULL
                _candidates(&pb, &children[0, 0], cand)
                if n_cand <= n_paths:
                    for t in range(pb.n_steps):
                        for c in range(n_cand):
                            out[beam_start[p] + t, c] = cand[t * n_cand + c]
                    continue
                _emissions(&pb, &g, cand, n_cand, emit, y)
                _steps(&pb, &tab, cand, emit, n_cand, moves, steps)
                _max_marginals(pb.n_steps, n_cand, emit, steps, fwd, bwd)
                for t in range(pb.n_steps):
                    for c in range(n_cand):
                        fwd[t * n_cand + c] += bwd[t * n_cand + c]
                    for r in range(keep):
                        c = _pick(fwd + t * n_cand, n_cand, &v)
                        out[beam_start[p] + t, r] = cand[t * n_cand + c] if v > -INFINITY else -1
    finally:
        free(cand); free(emit); free(steps); free(fwd); free(bwd); free(moves); free(y)
    return out_array


def kbest_layer(const double[:, ::1] frames, const intp[::1] frame_start, const intp[::1] n_steps,
                const intp[:, ::1] beam, const intp[::1] beam_start, const intp[::1] graph,
                const intp[:, ::1] children, const unsigned char[:, ::1] allowed, object gauss,
                const intp[::1] ids, object table, const double[:, ::1] norm, const intp[::1] norm_col,
                intp n_paths, bint best_only):
    """The last layer: the ``n_paths`` best node sequences of every problem, or only the best score.

    Problems as for :func:`descend_layer`. ``norm`` is ``(n_frames, n_columns)``,
    the log normaliser of ``Ps`` subtracted from the emissions (column
    ``norm_col[p]`` for problem ``p``), or ``(0, 0)`` for none.

    Returns
    -------
    paths : ndarray of shape (n_problems, n_paths, max(n_steps))
        Node sequences, best first; -1 past a problem's length and for missing
        sequences. Not computed (all -1) with ``best_only``.
    scores : ndarray of shape (n_problems, n_paths)
        Their log scores (``-inf`` for missing ones); with ``best_only`` the
        first column holds the best sequence's score and the others ``-inf``.
    """
    cdef intp width = beam.shape[1], n_cand = 2 * width, n_problems = frame_start.shape[0]
    cdef intp max_steps = 0, p
    cdef Gaussians g = _gaussians(gauss, ids)
    cdef Table tab = _table(table)
    for p in range(n_problems):
        max_steps = max(max_steps, n_steps[p])
    paths_array = np.full((n_problems, n_paths, max_steps), -1, dtype=np.intp)
    scores_array = np.full((n_problems, n_paths), -np.inf)
    cdef intp[:, :, ::1] paths = paths_array
    cdef double[:, ::1] scores = scores_array
    cdef Problem pb
    cdef bint same
    cdef intp size = max(max_steps * n_cand, 1)
    cdef intp* cand = <intp*> malloc(size * sizeof(intp))
    cdef double* emit = <double*> malloc(size * sizeof(double))
    cdef double* steps = <double*> malloc(size * n_cand * sizeof(double))
    cdef double* delta = <double*> malloc(2 * max(n_paths * n_cand, 1) * sizeof(double))
    cdef double* scratch = <double*> malloc(max(n_paths * n_cand, 1) * sizeof(double))
    cdef intp* back = <intp*> malloc(size * n_paths * sizeof(intp))
    cdef intp* head = <intp*> malloc(max(n_cand, 1) * sizeof(intp))
    cdef double* moves = <double*> malloc(n_cand * n_cand * sizeof(double))
    cdef double* y = <double*> malloc(g.d * sizeof(double))
    if (cand == NULL or emit == NULL or steps == NULL or delta == NULL or scratch == NULL or back == NULL
            or head == NULL or moves == NULL or y == NULL):
        free(cand); free(emit); free(steps); free(delta); free(scratch); free(back); free(head); free(moves); free(y)
        raise MemoryError(f"decoding {max_steps} frames with {n_cand} candidates each")
    try:
        with nogil:
            for p in range(n_problems):
                if n_steps[p] == 0:
                    continue
                pb.frames = &frames[frame_start[p], 0]
                pb.n_steps = n_steps[p]
                pb.beam = &beam[beam_start[p], 0]
                pb.width = width
                pb.graph = graph[p]
                pb.allowed = &allowed[graph[p], 0] if allowed.shape[0] else NULL
                pb.norm = &norm[frame_start[p], norm_col[p]] if norm.shape[0] else NULL
                pb.norm_stride = norm.shape[1]
                # Problems of one clip in a row share its candidates and emissions.
                same = (p > 0 and pb.allowed == NULL and frame_start[p] == frame_start[p - 1]
                        and n_steps[p] == n_steps[p - 1] and beam_start[p] == beam_start[p - 1]
                        and (pb.norm == NULL or norm_col[p] == norm_col[p - 1]))
                if not same:
                    _candidates(&pb, &children[0, 0], cand)
                    _emissions(&pb, &g, cand, n_cand, emit, y)
                _steps(&pb, &tab, cand, emit, n_cand, moves, steps)
                if best_only:
                    scores[p, 0] = _best(pb.n_steps, n_cand, emit, steps, delta)
                else:
                    _kbest(pb.n_steps, n_cand, n_paths, cand, emit, steps, delta, scratch, head, back,
                           &paths[p, 0, 0], max_steps, &scores[p, 0])
    finally:
        free(cand); free(emit); free(steps); free(delta); free(scratch); free(back); free(head); free(moves); free(y)
    return paths_array, scores_array
