# The stream's answers object (skmotion/tree/_online/_state.pyx), cimported by _online, whose kernel
# fills its C buffers directly.


cdef class OnlineState:
    cdef readonly Py_ssize_t frame, node, lagged_node
    cdef Py_ssize_t label_index, n_classes, n_best
    cdef double* proba_buf        # (n_classes,) then (n_best,): proba, next_proba
    cdef Py_ssize_t* next_buf     # (n_best,) next nodes
    cdef object classes, ancestors
    cdef object _proba, _next_nodes, _next_proba, _label, _nodes

    cdef int allocate(self, Py_ssize_t n_classes, Py_ssize_t n_best) except -1
