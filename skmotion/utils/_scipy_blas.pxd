# The C type of BLAS dsyrk as SciPy exports it, and the lookup of SciPy's exported functions
# (skmotion/utils/_scipy_blas.pyx), shared by the compiled modules that call BLAS or LAPACK.

ctypedef void (*dsyrk_t)(char*, char*, int*, int*, double*, double*, int*, double*,
                         double*, int*) noexcept nogil

cdef void* scipy_function(str library, str name) except NULL
