# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The scoring passes of the compiled beam decoder: max-product over a scored layer's candidates.

A layer's candidates form a lattice of ``n_steps`` frames by ``n_cand`` slots,
with the step scores ``move + emission`` between consecutive frames (see
:mod:`skmotion.tree._decoder._beam`). At a scored layer a problem gets its best
sequence's score (:func:`_best`, or :func:`_best_all` for every graph of a
search at once) or its ``n_paths`` best sequences (:func:`_kbest`, a list
Viterbi).
"""

from libc.math cimport INFINITY

from skmotion.tree._decoder._beam_structs cimport _moves_of, _pick, _same_row
from skmotion.tree._decoder._emission cimport skm_step_all


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
