# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The online stream's answers, computed in C from the kernel's state after a frame.

The class posterior (:func:`_posterior`, from each graph's ``n_paths`` best
sequences summed at every scored layer, :func:`_sum_of_paths`) and the most
likely next nodes (:func:`_next`); :class:`~skmotion.tree._online.OnlineKernel`
writes them into an :class:`~skmotion.tree._online._state.OnlineState`.
"""

from libc.math cimport INFINITY, exp, log1p
from libc.stdlib cimport free, malloc

from skmotion.tree._online._structs cimport Table, _push


cdef double _sum_of_paths(Kernel* k, intp l, intp g) noexcept nogil:
    """``log sum exp`` of graph ``g``'s ``n_paths`` best sequences at layer ``l`` (as the batch sums them)."""
    cdef intp j, r, G = k.n_graphs, P = k.n_paths
    cdef double* best = k.new_alpha  # scratch: the step's buffer, free between frames
    cdef double rest = 0.0, v
    for r in range(P):
        best[r] = -INFINITY
    for j in range(k.n_cand[l]):
        for r in range(P):  # each candidate's list is in decreasing order
            v = k.alpha[((l * k.slots + j) * G + g) * P + r]
            if not (v > best[P - 1]):
                break
            _push(v, best, P)
    if best[0] == -INFINITY:
        return best[0]
    for r in range(1, P):
        rest += exp(best[r] - best[0])
    return best[0] + log1p(rest)


cdef intp _posterior(Kernel* k, const intp* class_of_graph, double* proba, intp n_classes) noexcept nogil:
    cdef intp l, j, g, c, G = k.n_graphs, arg = 0
    cdef double* ll = <double*> malloc(max(G, 1) * sizeof(double))
    cdef double top = -INFINITY, total = 0.0
    for g in range(G):
        ll[g] = 0.0
    for l in range(1, k.n_layers + 1):
        if k._layers[l - 1].scored:
            for g in range(G):
                ll[g] += _sum_of_paths(k, l, g) + k.alpha_off[l]
    for c in range(n_classes):
        proba[c] = -INFINITY
    for g in range(G):
        c = class_of_graph[g]
        if ll[g] > proba[c]:
            proba[c] = ll[g]
    free(ll)
    for c in range(n_classes):
        if proba[c] > top:
            top = proba[c]
            arg = c
    if top == -INFINITY:  # nothing scored (a one-layer tree): uniform
        for c in range(n_classes):
            proba[c] = 1.0 / n_classes
        return 0
    for c in range(n_classes):
        proba[c] = exp(proba[c] - top)
        total += proba[c]
    for c in range(n_classes):
        proba[c] /= total
    return arg


cdef void _next(Kernel* k, intp* next_nodes, double* next_proba, intp n_best) noexcept nogil:
    cdef intp L = k.stream_layer, r, w, m, p, u, n_union = 0, size = 0, arg, node, n_nodes
    cdef const Table* t = &k._layers[L - 1].table
    cdef intp n_kept = k.n_kept[L]
    cdef double total = 0.0, base = 0.0, best, unseen
    n_nodes = k._layers[L - 1].k
    for w in range(n_kept):
        m = k.cand[L * k.slots + k.kept[L * k.beam + w]]
        size += t.pair_start[m + 1] - t.pair_start[m]
    cdef double* weight = <double*> malloc(max(n_kept, 1) * sizeof(double))
    cdef intp* dests = <intp*> malloc(max(size, 1) * sizeof(intp))
    cdef double* value = <double*> malloc(max(size, 1) * sizeof(double))
    for w in range(n_kept):
        weight[w] = exp(k.delta[L * k.slots + k.kept[L * k.beam + w]])
        total += weight[w]
    for w in range(n_kept):
        weight[w] /= total
        m = k.cand[L * k.slots + k.kept[L * k.beam + w]]
        base += weight[w] * exp(t.unseen_log[m * t.n_cols])
    for w in range(n_kept):
        m = k.cand[L * k.slots + k.kept[L * k.beam + w]]
        unseen = exp(t.unseen_log[m * t.n_cols])
        for p in range(t.pair_start[m], t.pair_start[m + 1]):
            u = k.union_slot[t.pair_dst[p]]
            if u < 0:
                u = k.union_slot[t.pair_dst[p]] = n_union
                dests[u] = t.pair_dst[p]
                value[u] = base
                n_union += 1
            value[u] += weight[w] * (exp(t.pair_log[p * t.n_cols]) - unseen)
    for u in range(n_union):
        k.union_slot[dests[u]] = -1
    for r in range(n_best):
        arg = -1
        best = -INFINITY
        for u in range(n_union):
            if value[u] > best or (value[u] == best and arg >= 0 and dests[u] < dests[arg]):
                best = value[u]
                arg = u
        if arg >= 0 and best > base:
            next_nodes[r] = dests[arg]
            next_proba[r] = best
            value[arg] = -INFINITY
            continue
        # the rest share the base probability: the lowest nodes not listed yet
        node = 0
        while node < n_nodes:
            for u in range(r):
                if next_nodes[u] == node:
                    break
            else:
                break
            node += 1
        next_nodes[r] = node
        next_proba[r] = base
    free(weight)
    free(dests)
    free(value)
