# The beam decoder's views of the caller's arrays and its scratch (skmotion/tree/_decoder/_beam_memory.pyx),
# cimported by _beam.

from skmotion.tree._decoder._beam_structs cimport Decode, Gaussians, intp

cdef Gaussians _gaussians(object gauss)
cdef void _release(Decode* dec) noexcept
cdef int _allocate(Decode* dec, list layers, intp n_searches, intp n_problems) except -1
