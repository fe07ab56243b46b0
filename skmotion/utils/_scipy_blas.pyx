# cython: language_level=3
"""SciPy's BLAS and LAPACK for skmotion's compiled modules, through the pointers SciPy exports.

``scipy.linalg.cython_blas`` and ``cython_lapack`` export each function's C pointer in a
capsule; a compiled module looks its functions up once, at import, through
:func:`scipy_function` (cimported from ``_scipy_blas.pxd``). Building skmotion then needs
no SciPy headers, and every module calls the BLAS that SciPy itself calls.
"""

from cpython.pycapsule cimport PyCapsule_GetName, PyCapsule_GetPointer


cdef void* scipy_function(str library, str name) except NULL:
    """The C function ``name`` of ``scipy.linalg.cython_<library>`` (``"blas"`` or ``"lapack"``)."""
    if library == "blas":
        from scipy.linalg import cython_blas as functions
    elif library == "lapack":
        from scipy.linalg import cython_lapack as functions
    else:
        raise ValueError(f"library: 'blas' or 'lapack', got {library!r}.")
    capsule = functions.__pyx_capi__[name]
    return PyCapsule_GetPointer(capsule, PyCapsule_GetName(capsule))
