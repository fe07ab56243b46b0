# The scoring passes over a scored layer's candidates (skmotion/tree/_decoder/_beam_passes.pyx), cimported
# by _beam.

from skmotion.tree._decoder._beam_structs cimport Table, Work, intp

cdef void _best_all(intp n_steps, intp n_cand, const Table* tab, const intp* graphs, intp n_graphs,
                    const intp* cand, const double* emit, Work* w, double* out, intp out_stride) noexcept nogil
cdef double _best(intp n_steps, intp n_cand, const double* emit, const double* steps, double* fwd) noexcept nogil
cdef void _kbest(intp n_steps, intp n_cand, intp n_paths, const intp* cand, const double* emit,
                 const double* steps, double* delta, double* scratch, intp* head, intp* back, intp* paths,
                 intp path_stride, double* scores) noexcept nogil
