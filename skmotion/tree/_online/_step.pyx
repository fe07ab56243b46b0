# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The online stream's per-frame work: one frame through every layer.

Steps 1 to 5 of :mod:`skmotion.tree._online._kernel`, as functions of the kernel's C
state (a ``Kernel`` of ``_structs.pxd``, held by
:class:`~skmotion.tree._online.OnlineKernel`): a layer's candidates and their
densities (:func:`_candidates`), the global graph's forward step
(:func:`_forward`, over the moves :func:`_move_table` keeps), the kept nodes
(:func:`_keep_best`), every class graph's list step (:func:`_classes`), and
:func:`_frame`, which runs them layer after layer.
"""

from libc.math cimport INFINITY

from skmotion.tree._decoder._emission cimport skm_diag_run, skm_full_run, skm_lowrank_run
from skmotion.tree._online._structs cimport Layer, _moves, _push


cdef double _density(Kernel* k, const double* x, intp node) noexcept nogil:
    """``log Po(x | node)`` of tree node ``node``."""
    cdef double out
    cdef intp row
    if k.full:
        row = k.lr_start[node]
        if row >= 0:
            skm_lowrank_run(x, 1, k.d, k.means + node * k.d, k.lr_vectors + row * k.d, k.lr_weights + row,
                            k.lr_rank[node], k.lr_inv_floor[node], k.const_[node], &out, 1, k.y)
        else:
            skm_full_run(x, 1, k.d, k.prec + node * k.d * k.d, k.shifts + node * k.d, k.const_[node], &out, 1,
                         k.y)
    else:
        skm_diag_run(x, 1, k.d, k.means + node * k.d, k.prec + node * k.d, k.const_[node], &out, 1)
    return out


cdef intp _candidates(Kernel* k, intp l, const double* x) noexcept nogil:
    """Layer ``l``'s candidates of this frame (children of the kept nodes above) and their densities."""
    cdef const Layer* lay = &k._layers[l - 1]
    cdef intp w, side, slot, child, n = 0, parent_id
    cdef intp above = l - 1
    for w in range(k.n_kept[above]):
        slot = k.kept[above * k.beam + w]
        parent_id = -1 if above == 0 else k._layers[above - 1].ids[k.cand[above * k.slots + slot]]
        for side in range(2):
            child = lay.children[k.cand[above * k.slots + slot] * 2 + side]
            if child < 0:
                continue
            k.new_cand[n] = child
            if lay.ids[child] == parent_id:  # a leaf copied down: the same Gaussian
                k.new_emit[n] = k.emit[above * k.slots + slot]
            else:
                k.new_emit[n] = _density(k, x, lay.ids[child])
            n += 1
    return n


cdef const double* _move_table(Kernel* k, intp l, intp n) noexcept nogil:
    """``log p(i -> j)`` in every column, ``(n_prev, n, n_cols)``, from the previous frame's candidates."""
    cdef Layer* lay = &k._layers[l - 1]
    cdef intp i, j, c, n_prev = k.n_cand[l], cols = lay.table.n_cols
    cdef const intp* prev = k.cand + l * k.slots
    cdef const double* move
    if lay.n_src == n_prev and lay.n_dst == n:
        for i in range(n_prev):
            if lay.move_src[i] != prev[i]:
                break
        else:
            for j in range(n):
                if lay.move_dst[j] != k.new_cand[j]:
                    break
            else:
                return lay.moves
    for i in range(n_prev):
        lay.move_src[i] = prev[i]
        for j in range(n):
            move = _moves(&lay.table, prev[i], k.new_cand[j])
            for c in range(cols):
                lay.moves[(i * n + j) * cols + c] = move[c]
    for j in range(n):
        lay.move_dst[j] = k.new_cand[j]
    lay.n_src = n_prev
    lay.n_dst = n
    return lay.moves


cdef void _forward(Kernel* k, intp l, intp n, bint first) noexcept nogil:
    """The global graph's max-product step at layer ``l`` over its ``n`` new candidates."""
    cdef const Layer* lay = &k._layers[l - 1]
    cdef intp i, j, arg, n_prev = k.n_cand[l]
    cdef double best, v
    cdef const double* prev_delta = k.delta + l * k.slots
    cdef const double* moves = NULL
    cdef intp cols = lay.table.n_cols
    if not first:
        moves = _move_table(k, l, n)
    for j in range(n):
        if first:
            k.new_delta[j] = k.new_emit[j]
            k.back[j] = -1
            continue
        best = -INFINITY
        arg = -1
        for i in range(n_prev):
            v = prev_delta[i] + (moves[(i * n + j) * cols] + k.new_emit[j])
            if v > best:
                best = v
                arg = i
        k.new_delta[j] = best
        k.back[j] = arg


cdef void _keep_best(Kernel* k, intp l, intp n) noexcept nogil:
    """The ``beam`` best new candidates by forward score, best first (ties to the lower slot)."""
    cdef intp r, j, arg, m = 0
    cdef double best
    cdef double* scratch = k.delta + l * k.slots  # overwritten next, by the new scores
    for j in range(n):
        scratch[j] = k.new_delta[j]
    for r in range(min(k.beam, n)):
        arg = -1
        best = -INFINITY
        for j in range(n):
            if scratch[j] > best:
                best = scratch[j]
                arg = j
        if arg < 0:
            break
        scratch[arg] = -INFINITY
        k.kept[l * k.beam + m] = arg
        m += 1
    k.n_kept[l] = m


cdef void _classes(Kernel* k, intp l, intp n, bint first) noexcept nogil:
    """Every graph's list step at a scored layer: the ``n_paths`` best sequences into each new candidate.

    Entry ``(j, g, r)``: the rank-``r`` sequence under graph ``g`` ending in
    candidate ``j`` (decreasing in ``r``; -inf when there are fewer).
    """
    cdef const Layer* lay = &k._layers[l - 1]
    cdef intp i, j, g, r, G = k.n_graphs, P = k.n_paths, n_prev = k.n_cand[l]
    cdef intp size = n * G * P
    cdef double e, move, v, top = -INFINITY
    cdef const double* prev_alpha = k.alpha + l * k.slots * G * P
    cdef const double* prev
    cdef const double* moves = NULL
    cdef intp cols = lay.table.n_cols
    cdef double* out
    if not first:
        moves = _move_table(k, l, n)  # made by the global step just before: a cache hit
    for j in range(n):
        for g in range(G):
            out = k.new_alpha + (j * G + g) * P
            for r in range(P):
                out[r] = -INFINITY
            if lay.allowed != NULL and not lay.allowed[g * lay.k + k.new_cand[j]]:
                continue
            e = k.new_emit[j]
            if lay.log_norm != NULL:
                e = e - lay.log_norm[g]
            if first:
                out[0] = e
            else:
                # each previous candidate's list is in decreasing order: once an entry
                # misses the best P so far, the rest of its list does too
                for i in range(n_prev):
                    move = moves[(i * n + j) * cols + 1 + g] + e
                    prev = prev_alpha + (i * G + g) * P
                    for r in range(P):
                        v = prev[r] + move
                        if not (v > out[P - 1]):
                            break
                        _push(v, out, P)
            if out[0] > top:
                top = out[0]
    if top == -INFINITY:
        top = 0.0
    for j in range(size):
        k.alpha[l * k.slots * G * P + j] = k.new_alpha[j] - top
    k.alpha_off[l] += top


cdef void _frame(Kernel* k, const double* x, intp t) noexcept nogil:
    """One frame through every layer."""
    cdef intp l, n, j, r, s = k.slots
    cdef bint first = t == 0
    cdef double top
    cdef intp* row
    for l in range(1, k.n_layers + 1):
        n = _candidates(k, l, x)
        _forward(k, l, n, first)
        if k._layers[l - 1].scored and k.n_graphs:
            _classes(k, l, n, first)
        _keep_best(k, l, n)
        top = k.new_delta[k.kept[l * k.beam]] if k.n_kept[l] else 0.0
        for j in range(n):
            k.delta[l * s + j] = k.new_delta[j] - top
            k.emit[l * s + j] = k.new_emit[j]
            k.cand[l * s + j] = k.new_cand[j]
        k.delta_off[l] += top
        k.n_cand[l] = n
        if l == k.stream_layer:
            row = k.ring_cand + (t % k.ring) * s
            for j in range(s):
                row[j] = k.new_cand[j] if j < n else -1
                k.ring_back[(t % k.ring) * s + j] = k.back[j] if j < n else -1
