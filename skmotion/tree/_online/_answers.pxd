# The online stream's answers from the kernel's state (skmotion/tree/_online/_answers.pyx), cimported
# by _online.

from skmotion.tree._online._structs cimport Kernel, intp

cdef intp _posterior(Kernel* k, const intp* class_of_graph, double* proba, intp n_classes) noexcept nogil
cdef void _next(Kernel* k, intp* next_nodes, double* next_proba, intp n_best) noexcept nogil
