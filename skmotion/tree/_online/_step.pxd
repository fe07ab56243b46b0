# One frame through every layer of the online stream (skmotion/tree/_online/_step.pyx), cimported
# by _online.

from skmotion.tree._online._structs cimport Kernel, intp

cdef void _frame(Kernel* k, const double* x, intp t) noexcept nogil
