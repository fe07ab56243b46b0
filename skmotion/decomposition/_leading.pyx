# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled leading eigenpairs of each clip's smaller Gram matrix (see :mod:`._clip_svd`).

One call takes a list of clips of any lengths and, clip after clip with no
Python between (and without the GIL):

1. divides the clip by its largest absolute value (into a scratch buffer: the
   Gram matrix of a clip near 1e300 would overflow);
2. forms the smaller Gram matrix, ``A^T A`` (channels x channels) or ``A A^T``
   (frames x frames) for a clip with fewer frames than channels, with one
   ``dsyrk``;
3. one leading pair: power steps (``dsymv``), the residual ``|G v - lambda v|``
   checked every ``check`` steps against ``tolerance * lambda``, and LAPACK's
   ``dsyevr`` for the top pair when not converged after ``max_steps``; several
   pairs: ``dsyevr`` for exactly those (``range="I"``, LAPACK's accuracy);
4. for a short clip, the right singular vectors from the left ones,
   ``v = A^T w / |A^T w|`` (``dgemv``).

BLAS and LAPACK are SciPy's (``scipy.linalg.cython_blas`` and
``cython_lapack``), reached through the function pointers SciPy exports, so
building needs no SciPy headers. The per-clip problems are small, so the cost
that mattered was numpy's per-call overhead on stacked small matrices, which
this loop does not have.
"""

import numpy as np

from cpython.pycapsule cimport PyCapsule_GetName, PyCapsule_GetPointer
from libc.math cimport fabs, sqrt
from libc.stdlib cimport free, malloc

ctypedef void (*dsyrk_t)(char*, char*, int*, int*, double*, double*, int*, double*,
                         double*, int*) noexcept nogil
ctypedef void (*dsymv_t)(char*, int*, double*, double*, int*, double*, int*, double*,
                         double*, int*) noexcept nogil
ctypedef void (*dgemv_t)(char*, int*, int*, double*, double*, int*, double*, int*, double*,
                         double*, int*) noexcept nogil
ctypedef void (*dsyevr_t)(char*, char*, char*, int*, double*, int*, double*, double*, int*,
                          int*, double*, int*, double*, double*, int*, int*, double*, int*,
                          int*, int*, int*) noexcept nogil

cdef dsyrk_t _dsyrk
cdef dsymv_t _dsymv
cdef dgemv_t _dgemv
cdef dsyevr_t _dsyevr


cdef void* _pointer(module, str name) except NULL:
    capsule = module.__pyx_capi__[name]
    return PyCapsule_GetPointer(capsule, PyCapsule_GetName(capsule))


def _load():
    global _dsyrk, _dsymv, _dgemv, _dsyevr
    from scipy.linalg import cython_blas, cython_lapack

    _dsyrk = <dsyrk_t>_pointer(cython_blas, "dsyrk")
    _dsymv = <dsymv_t>_pointer(cython_blas, "dsymv")
    _dgemv = <dgemv_t>_pointer(cython_blas, "dgemv")
    _dsyevr = <dsyevr_t>_pointer(cython_lapack, "dsyevr")


_load()


cdef int _top_pairs(int n, int n_pairs, double* gram, double* values, double* vectors,
                    double* work, int lwork, int* iwork, int liwork, int* support) noexcept nogil:
    """The ``n_pairs`` largest eigenpairs of ``gram`` (lower triangle), decreasing, by dsyevr.

    ``vectors`` is ``n x n_pairs`` column-major; ``gram`` is destroyed. Returns
    LAPACK's ``info``.
    """
    cdef char jobz = b"V", which = b"I", uplo = b"L"
    cdef int low = n - n_pairs + 1, high = n, found = 0, info = 0, i, j, k
    cdef double unused = 0.0, abstol = 0.0
    cdef double tmp
    _dsyevr(&jobz, &which, &uplo, &n, gram, &n, &unused, &unused, &low, &high, &abstol,
            &found, values, vectors, &n, support, work, &lwork, iwork, &liwork, &info)
    # LAPACK returns them increasing: reverse the order.
    for i in range(n_pairs // 2):
        j = n_pairs - 1 - i
        tmp = values[i]
        values[i] = values[j]
        values[j] = tmp
        for k in range(n):
            tmp = vectors[i * n + k]
            vectors[i * n + k] = vectors[j * n + k]
            vectors[j * n + k] = tmp
    return info


cdef bint _power(int n, double* gram, double* x, double* y, double* value,
                 double tolerance, int check, int max_steps) noexcept nogil:
    """The leading eigenpair of ``gram`` (lower triangle) by power steps, into ``x``, ``value``.

    Starts from the row sums plus the first column (as the numpy route did).
    Returns whether the residual met the tolerance within ``max_steps``.
    """
    cdef char uplo = b"L"
    cdef int one = 1, step, i, j
    cdef double alpha = 1.0, beta = 0.0, norm = 0.0, rayleigh, residual, entry
    for i in range(n):
        x[i] = 0.0
    for j in range(n):  # column j of the lower triangle: rows j..n-1
        for i in range(j, n):
            entry = gram[j * n + i]
            x[i] += entry
            if i != j:
                x[j] += entry
        x[j] += gram[j]  # first column: G[j, 0] = lower entry (j, 0)
    for i in range(n):
        norm += x[i] * x[i]
    norm = sqrt(norm)
    if norm == 0.0:
        return False
    for i in range(n):
        x[i] /= norm
    for step in range(1, max_steps + 1):
        _dsymv(&uplo, &n, &alpha, gram, &n, x, &one, &beta, y, &one)
        if step % check == 0:
            rayleigh = 0.0
            for i in range(n):
                rayleigh += x[i] * y[i]
            residual = 0.0
            for i in range(n):
                residual += (y[i] - rayleigh * x[i]) ** 2
            if sqrt(residual) <= tolerance * fabs(rayleigh):
                value[0] = rayleigh
                return True
        norm = 0.0
        for i in range(n):
            norm += y[i] * y[i]
        norm = sqrt(norm)
        if norm == 0.0:
            return False
        for i in range(n):
            x[i] = y[i] / norm
    return False


cdef int _one_clip(const double* clip, int n_frames, int n_channels, int n_vectors,
                   double* values, double* vectors, double* scaled, double* gram,
                   double* scratch, double* work, int lwork, int* iwork, int liwork,
                   int* support, double tolerance, int check, int max_steps) noexcept nogil:
    """Leading eigenpairs of one clip into ``values`` (n_vectors) and ``vectors``.

    ``vectors`` is the clip's ``n_channels x n_vectors`` block, row-major (as
    numpy lays out ``vectors[c]``). Returns LAPACK's info (0 = success).
    """
    cdef int size = n_frames * n_channels, i, j, n, n_pairs, info = 0
    cdef bint tall = n_frames >= n_channels
    cdef double peak = 0.0, alpha = 1.0, beta = 0.0, norm
    cdef char uplo = b"L", no = b"N", yes = b"T"
    cdef int one = 1
    for i in range(size):
        if fabs(clip[i]) > peak:
            peak = fabs(clip[i])
    if peak == 0.0:
        return 0  # an all-zero clip: zero values and vectors
    for i in range(size):
        scaled[i] = clip[i] / peak
    # The row-major clip (frames x channels) is the column-major B = A^T
    # (channels x frames): A^T A = B B^T, A A^T = B^T B.
    n = n_channels if tall else n_frames
    if tall:
        _dsyrk(&uplo, &no, &n, &n_frames, &alpha, scaled, &n_channels, &beta, gram, &n)
    else:
        _dsyrk(&uplo, &yes, &n, &n_channels, &alpha, scaled, &n_channels, &beta, gram, &n)
    n_pairs = n_vectors if n_vectors < n else n
    # scratch: n_pairs column-major vectors of length n, then two work vectors.
    if n_pairs == 1 and _power(n, gram, scratch, scratch + n, values, tolerance, check,
                               max_steps):
        pass
    else:
        info = _top_pairs(n, n_pairs, gram, values, scratch, work, lwork, iwork, liwork,
                          support)
    for j in range(n_pairs):
        if tall:
            for i in range(n_channels):
                vectors[i * n_vectors + j] = scratch[j * n + i]
        else:  # v = A^T w = B w, then unit norm
            _dgemv(&no, &n_channels, &n_frames, &alpha, scaled, &n_channels,
                   scratch + j * n, &one, &beta, gram, &one)
            norm = 0.0
            for i in range(n_channels):
                norm += gram[i] * gram[i]
            norm = sqrt(norm)
            for i in range(n_channels):
                vectors[i * n_vectors + j] = gram[i] / norm if norm > 0.0 else 0.0
    return info


def leading_spectra(list clips, int n_vectors, double tolerance, int check, int max_steps):
    """Leading eigenvalues and right singular vectors of each clip (unit-scaled).

    Parameters
    ----------
    clips : list of C-contiguous float64 ndarray of shape (n_frames_i, n_channels)
    n_vectors : int
        Pairs per clip (at most ``n_channels``); a clip with fewer frames gets
        ``n_frames`` of them and zeros after.
    tolerance, check, max_steps : float, int, int
        Power steps (one pair): the residual bound relative to the eigenvalue,
        the steps between checks, and the steps before LAPACK takes over.

    Returns
    -------
    values : ndarray of shape (n_clips, n_vectors)
        Decreasing.
    vectors : ndarray of shape (n_clips, n_channels, n_vectors)
    """
    cdef Py_ssize_t m = len(clips), c
    cdef int n_channels = clips[0].shape[1] if m else 0
    values_out = np.zeros((m, n_vectors))
    vectors_out = np.zeros((m, n_channels, n_vectors))
    cdef double[:, ::1] values = values_out
    cdef double[:, :, ::1] vectors = vectors_out
    cdef const double** pointers = <const double**>malloc(max(m, 1) * sizeof(double*))
    cdef int* frames = <int*>malloc(max(m, 1) * sizeof(int))
    cdef const double[:, ::1] view
    cdef int longest = 0, n_max, lwork, liwork, failed = -1
    try:
        for c in range(m):
            view = clips[c]
            if view.shape[1] != n_channels:
                raise ValueError(f"clip {c} has {view.shape[1]} channels, not {n_channels}.")
            pointers[c] = &view[0, 0] if view.shape[0] else NULL
            frames[c] = view.shape[0]
            longest = max(longest, frames[c])
        n_max = max(1, min(longest, n_channels))
        lwork, liwork = 26 * n_max, 10 * n_max
        failed = _run(m, pointers, frames, n_channels, n_vectors, &values[0, 0],
                      &vectors[0, 0, 0], longest, n_max, lwork, liwork, tolerance, check,
                      max_steps)
    finally:
        free(pointers)
        free(frames)
    if failed >= 0:
        raise np.linalg.LinAlgError(f"clip {failed}: the eigen-decomposition did not converge.")
    return values_out, vectors_out


cdef Py_ssize_t _run(Py_ssize_t m, const double** pointers, int* frames, int n_channels,
                     int n_vectors, double* values, double* vectors, int longest, int n_max,
                     int lwork, int liwork, double tolerance, int check, int max_steps):
    """The loop over clips, without the GIL; the first failed clip, or -1."""
    cdef double* scaled = <double*>malloc(max(1, longest * n_channels) * sizeof(double))
    cdef double* gram = <double*>malloc(max(n_max * n_max, n_channels) * sizeof(double))
    cdef double* scratch = <double*>malloc((n_max * (n_vectors + 2) + 2) * sizeof(double))
    cdef double* work = <double*>malloc(lwork * sizeof(double))
    cdef int* iwork = <int*>malloc(liwork * sizeof(int))
    cdef int* support = <int*>malloc(2 * n_max * sizeof(int))
    cdef Py_ssize_t c, failed = -1
    if not (scaled and gram and scratch and work and iwork and support):
        free(scaled); free(gram); free(scratch); free(work); free(iwork); free(support)
        raise MemoryError()
    with nogil:
        for c in range(m):
            if pointers[c] == NULL:
                continue
            if _one_clip(pointers[c], frames[c], n_channels, n_vectors,
                         values + c * n_vectors, vectors + c * n_channels * n_vectors,
                         scaled, gram, scratch, work, lwork, iwork, liwork, support,
                         tolerance, check, max_steps) != 0:
                failed = c
                break
    free(scaled); free(gram); free(scratch); free(work); free(iwork); free(support)
    return failed
