# A layer's candidates and their emissions (skmotion/tree/_decoder/_beam_candidates.pyx), cimported by _beam.

from skmotion.tree._decoder._beam_structs cimport Gaussians, Layer, Work, intp

cdef intp _candidates(const Layer* lay, intp n_steps, intp width, intp search_graph, bint carry,
                      const Gaussians* g, const double* frames, Work* w, intp* cand, double* emit,
                      bint emissions) noexcept nogil
