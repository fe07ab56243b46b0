# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""A layer's candidates in the compiled beam decoder, and their Gaussian log densities.

Steps 1 and 2 of :mod:`skmotion.tree._decoder._beam`: each frame's candidates at a
layer are the children of its kept nodes at the layer above, and their
emissions ``log Po(x | k)`` are computed by the loops of ``_emission.h`` over
runs of frames whose slot holds the same node (a copied leaf's is carried).
"""

from libc.math cimport INFINITY, NAN

from skmotion.tree._decoder._emission cimport skm_diag_run, skm_full_run, skm_lowrank_run


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
