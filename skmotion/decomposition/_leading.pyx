# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled leading eigenpairs of each clip's smaller Gram matrix (see :mod:`._clip_svd`).

One call takes a list of clips of any lengths and, clip after clip with no
Python between (and without the GIL):

1. divides the clip by its largest absolute value (the Gram matrix of a clip
   near 1e300 would overflow): for a peak between 1e-100 and 1e100 by scaling
   the Gram matrix, otherwise by copying the scaled clip first;
2. forms the smaller Gram matrix, ``A^T A`` (channels x channels) or ``A A^T``
   (frames x frames) for a clip with fewer frames than channels, with one
   ``dsyrk``;
3. one leading pair: power steps (``dsymv``), the residual ``|G v - lambda v|``
   checked every ``check`` steps against ``tolerance * lambda``; several pairs:
   subspace iteration on a block of ``n_pairs + 4`` vectors (two ``dsymm``
   products per Householder QR, a Rayleigh-Ritz step by Jacobi rotations every
   ``check`` steps, every pair's residual within ``tolerance * lambda_1``);
   LAPACK's ``dsyevr`` for exactly the pairs asked (``range="I"``) when these
   have not converged after ``max_steps``, or when the matrix is smaller than
   twice the block;
4. for a short clip, the right singular vectors from the left ones,
   ``v = A^T w / |A^T w|`` (``dgemv``).

BLAS and LAPACK are SciPy's (``scipy.linalg.cython_blas`` and
``cython_lapack``), reached through the function pointers SciPy exports, so
building needs no SciPy headers. The per-clip problems are small, so the cost
that mattered was numpy's per-call overhead on stacked small matrices, which
this loop does not have.
"""

import numpy as np

from libc.math cimport INFINITY, fabs, sqrt
from libc.stdlib cimport free, malloc

from skmotion.utils._scipy_blas cimport dsyrk_t, scipy_function

ctypedef void (*dsymv_t)(char*, int*, double*, double*, int*, double*, int*, double*,
                         double*, int*) noexcept nogil
ctypedef void (*dgemv_t)(char*, int*, int*, double*, double*, int*, double*, int*, double*,
                         double*, int*) noexcept nogil
ctypedef void (*dsyevr_t)(char*, char*, char*, int*, double*, int*, double*, double*, int*,
                          int*, double*, int*, double*, double*, int*, int*, double*, int*,
                          int*, int*, int*) noexcept nogil

ctypedef void (*dsymm_t)(char*, char*, int*, int*, double*, double*, int*, double*, int*,
                         double*, double*, int*) noexcept nogil
ctypedef void (*dgeqrf_t)(int*, int*, double*, int*, double*, double*, int*, int*) noexcept nogil
ctypedef void (*dorgqr_t)(int*, int*, int*, double*, int*, double*, double*, int*,
                          int*) noexcept nogil
ctypedef void (*dgemm_t)(char*, char*, int*, int*, int*, double*, double*, int*, double*, int*,
                         double*, double*, int*) noexcept nogil

cdef dsyrk_t _dsyrk
cdef dgemm_t _dgemm
cdef dsymm_t _dsymm
cdef dgeqrf_t _dgeqrf
cdef dorgqr_t _dorgqr
cdef dsymv_t _dsymv
cdef dgemv_t _dgemv
cdef dsyevr_t _dsyevr


def _load():
    global _dsyrk, _dsymv, _dgemv, _dsyevr, _dgemm, _dsymm, _dgeqrf, _dorgqr
    _dsyrk = <dsyrk_t>scipy_function("blas", "dsyrk")
    _dsymv = <dsymv_t>scipy_function("blas", "dsymv")
    _dgemv = <dgemv_t>scipy_function("blas", "dgemv")
    _dsyevr = <dsyevr_t>scipy_function("lapack", "dsyevr")
    _dgemm = <dgemm_t>scipy_function("blas", "dgemm")
    _dsymm = <dsymm_t>scipy_function("blas", "dsymm")
    _dgeqrf = <dgeqrf_t>scipy_function("lapack", "dgeqrf")
    _dorgqr = <dorgqr_t>scipy_function("lapack", "dorgqr")


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


cdef inline double _norm(const double* v, int n) noexcept nogil:
    """The Euclidean norm of ``v[:n]``, summed in order (the same rounding at every call)."""
    cdef double total = 0.0
    cdef int i
    for i in range(n):
        total += v[i] * v[i]
    return sqrt(total)


cdef bint _power(int n, double* gram, double* x, double* y, double* value,
                 double tolerance, int check, int max_steps) noexcept nogil:
    """The leading eigenpair of ``gram`` (lower triangle) by power steps, into ``x``, ``value``.

    Starts from the row sums plus the first column (as the numpy route did).
    Returns whether the residual met the tolerance within ``max_steps``.
    """
    cdef char uplo = b"L"
    cdef int one = 1, step, i, j
    cdef double alpha = 1.0, beta = 0.0, norm, rayleigh, residual, entry
    for i in range(n):
        x[i] = 0.0
    for j in range(n):  # column j of the lower triangle: rows j..n-1
        for i in range(j, n):
            entry = gram[j * n + i]
            x[i] += entry
            if i != j:
                x[j] += entry
        x[j] += gram[j]  # first column: G[j, 0] = lower entry (j, 0)
    norm = _norm(x, n)
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
        norm = _norm(y, n)
        if norm == 0.0:
            return False
        for i in range(n):
            x[i] = y[i] / norm
    return False


ctypedef struct Space:
    # Scratch for one clip at a time: sizes for the largest clip of the call.
    double* scaled   # the unit-scaled clip
    double* gram     # the Gram matrix (lower triangle, column-major)
    double* pairs    # the pairs found, n x n_pairs column-major, then 2 work vectors
    double* x        # subspace iteration: basis, products (n x block each) ...
    double* y
    double* p
    double* h        # ... block x block Rayleigh quotient, rotation, Ritz values
    double* r
    double* ritz
    double* tau      # Householder scalars of the QR
    double* qwork
    int lqwork
    double* work     # dsyevr
    int lwork
    int* iwork
    int liwork
    int* support
    const double* start  # the fixed start block, n_max x block_max row-major
    int start_cols


cdef int _orthonormalise(int n, int b, double* x, Space* s) noexcept nogil:
    """Replace the ``n x b`` columns of ``x`` by an orthonormal basis of their span (QR).

    Householder (LAPACK): orthonormal to rounding however close the columns are
    (as after ``G^2`` products) and whatever the clip's rank. Returns its info.
    """
    cdef int info = 0
    _dgeqrf(&n, &b, x, &n, s.tau, s.qwork, &s.lqwork, &info)
    if info == 0:
        _dorgqr(&n, &b, &b, x, &n, s.tau, s.qwork, &s.lqwork, &info)
    return info


cdef void _symmetric_product(int n, int b, double* g, double* x, double* y) noexcept nogil:
    """``y = G x`` for ``n x n`` symmetric ``g`` (lower triangle) and ``n x b`` ``x``."""
    cdef char left = b"L", lower = b"L"
    cdef double one = 1.0, zero = 0.0
    _dsymm(&left, &lower, &n, &b, &one, g, &n, x, &n, &zero, y, &n)


cdef void _jacobi(int b, int n_pairs, double* a, double* v, double* values,
                  double* vectors) noexcept nogil:
    """The ``n_pairs`` largest eigenpairs of the small symmetric ``b x b`` matrix ``a``.

    Cyclic Jacobi rotations (Rutishauser's formulas) until the off-diagonal
    mass is below rounding: accurate to the last digits, and for the Ritz
    problems of a few vectors far cheaper than a LAPACK call (whose setup
    dominates at this size). ``a`` (full, column-major) is destroyed; ``v``
    is ``b x b`` scratch; ``vectors`` gets ``b x n_pairs`` column-major.
    """
    cdef int i, j, p, q, sweep, best
    cdef double off, scale, theta, t, c, sn, tau, app, aqq, apq, x, y
    for i in range(b * b):
        v[i] = 0.0
    for i in range(b):
        v[i * b + i] = 1.0
    for sweep in range(100):
        off = 0.0
        scale = 0.0
        for q in range(b):
            for p in range(b):
                if p < q:
                    off += a[q * b + p] * a[q * b + p]
                elif p == q:
                    scale += a[p * b + p] * a[p * b + p]
        if off <= 1e-34 * (scale + off) or off == 0.0:
            break
        for p in range(b - 1):
            for q in range(p + 1, b):
                apq = a[q * b + p]
                if apq == 0.0:
                    continue
                app, aqq = a[p * b + p], a[q * b + q]
                theta = (aqq - app) / (2.0 * apq)
                t = 1.0 / (fabs(theta) + sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                c = 1.0 / sqrt(t * t + 1.0)
                sn = t * c
                tau = sn / (1.0 + c)
                for i in range(b):  # columns p and q, then rows p and q (symmetric)
                    x, y = a[p * b + i], a[q * b + i]
                    a[p * b + i] = x - sn * (y + tau * x)
                    a[q * b + i] = y + sn * (x - tau * y)
                for i in range(b):
                    x, y = a[i * b + p], a[i * b + q]
                    a[i * b + p] = x - sn * (y + tau * x)
                    a[i * b + q] = y + sn * (x - tau * y)
                for i in range(b):
                    x, y = v[p * b + i], v[q * b + i]
                    v[p * b + i] = x - sn * (y + tau * x)
                    v[q * b + i] = y + sn * (x - tau * y)
    # The n_pairs largest, decreasing (selection: b is small); the diagonal
    # entries taken are marked by -inf.
    for j in range(n_pairs):
        best = -1
        for i in range(b):
            if a[i * b + i] != -INFINITY and (best < 0 or a[i * b + i] > a[best * b + best]):
                best = i
        values[j] = a[best * b + best]
        a[best * b + best] = -INFINITY
        for i in range(b):
            vectors[j * b + i] = v[best * b + i]


cdef bint _subspace(int n, int n_pairs, int b, Space* s, double* values, double tolerance,
                    int check, int max_steps) noexcept nogil:
    """Leading pairs by subspace iteration (as the numpy route did), into values, s.pairs.

    A block of ``b`` vectors: two products by ``G`` per QR, and every
    ``check`` steps a Rayleigh-Ritz step whose residuals ``|G v - lambda v|``
    must be within ``tolerance * lambda_1``. Returns whether they were.
    """
    cdef char no = b"N", yes = b"T"
    cdef double one = 1.0, zero = 0.0, residual, bound
    cdef int i, j, step
    cdef bint ok
    for j in range(b):
        for i in range(n):
            s.y[i + j * n] = s.start[i * s.start_cols + j]
    _symmetric_product(n, b, s.gram, s.y, s.x)
    if _orthonormalise(n, b, s.x, s) != 0:
        return False
    for step in range(2, max_steps + 1, 2):
        # Two products per orthonormalisation, which costs more than a product;
        # the Gram matrix of a unit-scaled clip keeps G^2 X well within range.
        _symmetric_product(n, b, s.gram, s.x, s.y)
        _symmetric_product(n, b, s.gram, s.y, s.x)
        if _orthonormalise(n, b, s.x, s) != 0:
            return False
        if step % check and step < max_steps:
            continue
        _symmetric_product(n, b, s.gram, s.x, s.p)
        _dgemm(&yes, &no, &b, &b, &n, &one, s.x, &n, s.p, &n, &zero, s.h, &b)
        _jacobi(b, n_pairs, s.h, s.work, s.ritz, s.r)
        # Candidates V = X R (into pairs) and G V = P R (into y).
        _dgemm(&no, &no, &n, &n_pairs, &b, &one, s.x, &n, s.r, &b, &zero, s.pairs, &n)
        _dgemm(&no, &no, &n, &n_pairs, &b, &one, s.p, &n, s.r, &b, &zero, s.y, &n)
        bound = tolerance * fabs(s.ritz[0])
        ok = True
        for j in range(n_pairs):
            residual = 0.0
            for i in range(n):
                residual += (s.y[i + j * n] - s.ritz[j] * s.pairs[i + j * n]) ** 2
            if sqrt(residual) > bound:
                ok = False
                break
        if ok:
            for j in range(n_pairs):
                values[j] = s.ritz[j]
            return True
    return False


cdef int _pairs_of_gram(int n, int n_pairs, Space* s, double* values, double tolerance,
                        int check, int max_steps) noexcept nogil:
    """The ``n_pairs`` leading pairs of ``s.gram`` into ``values`` and ``s.pairs``.

    One pair: power steps; several: subspace iteration with a block of
    ``n_pairs + 4`` when that is under half the size (else the full problem
    costs no more); LAPACK's dsyevr whenever these do not converge. Returns
    LAPACK's info.
    """
    cdef int b = min(n, n_pairs + 4)
    if n_pairs == 1:
        if _power(n, s.gram, s.pairs, s.pairs + n, values, tolerance, check, 4 * max_steps):
            return 0
    elif 2 * b < n:
        if _subspace(n, n_pairs, b, s, values, tolerance, check, max_steps):
            return 0
    return _top_pairs(n, n_pairs, s.gram, values, s.pairs, s.work, s.lwork, s.iwork, s.liwork,
                      s.support)


cdef int _one_clip(const double* clip, int n_frames, int n_channels, int n_vectors,
                   double* values, double* vectors, Space* s, double tolerance, int check,
                   int max_steps) noexcept nogil:
    """Leading eigenpairs of one clip into ``values`` (n_vectors) and ``vectors``.

    ``vectors`` is the clip's ``n_channels x n_vectors`` block, row-major (as
    numpy lays out ``vectors[c]``). Returns LAPACK's info (0 = success).
    """
    cdef int size = n_frames * n_channels, i, j, n, n_pairs, info = 0
    cdef bint tall = n_frames >= n_channels
    cdef double peak = 0.0, alpha = 1.0, beta = 0.0, norm, squared
    cdef const double* a = clip
    cdef char uplo = b"L", no = b"N", yes = b"T"
    cdef int one = 1
    for i in range(size):
        if fabs(clip[i]) > peak:
            peak = fabs(clip[i])
    if peak == 0.0:
        return 0  # an all-zero clip: zero values and vectors
    if 1e-100 < peak < 1e100:
        # The Gram matrix of the clip itself cannot overflow or underflow: scale
        # it (by 1 / peak^2) instead of copying the clip.
        squared = (1.0 / peak) * (1.0 / peak)
    else:
        squared = 1.0
        for i in range(size):
            s.scaled[i] = clip[i] / peak
        a = s.scaled
    # The row-major clip (frames x channels) is the column-major B = A^T
    # (channels x frames): A^T A = B B^T, A A^T = B^T B.
    n = n_channels if tall else n_frames
    if tall:
        _dsyrk(&uplo, &no, &n, &n_frames, &squared, <double*>a, &n_channels, &beta, s.gram, &n)
    else:
        _dsyrk(&uplo, &yes, &n, &n_channels, &squared, <double*>a, &n_channels, &beta, s.gram,
               &n)
    n_pairs = n_vectors if n_vectors < n else n
    info = _pairs_of_gram(n, n_pairs, s, values, tolerance, check, max_steps)
    for j in range(n_pairs):
        if tall:
            for i in range(n_channels):
                vectors[i * n_vectors + j] = s.pairs[j * n + i]
        else:  # v = A^T w = B w (into gram, no longer needed), then unit norm
            _dgemv(&no, &n_channels, &n_frames, &alpha, <double*>a, &n_channels,
                   s.pairs + j * n, &one, &beta, s.gram, &one)
            norm = _norm(s.gram, n_channels)
            for i in range(n_channels):
                vectors[i * n_vectors + j] = s.gram[i] / norm if norm > 0.0 else 0.0
    return info


# The normal draws the start blocks are cut from (grown on demand): drawing a
# block afresh cost about as much as the pairs of a 40 x 60 clip.
_DRAWS = np.zeros(0)


def _start_block(int n_max, int block):
    """The fixed start block of subspace iteration (reproducible answers).

    ``default_rng(0).standard_normal((n_max, block))``: the generator fills an
    array draw after draw, so that block is the first ``n_max * block`` draws
    of any longer call, reshaped (read-only, shared between calls).
    """
    global _DRAWS
    cdef Py_ssize_t size = n_max * block
    draws = _DRAWS  # one read: another thread may swap in a longer array meanwhile
    if len(draws) < size:
        draws = np.random.default_rng(0).standard_normal(max(size, 2 * len(draws)))
        draws.setflags(write=False)
        _DRAWS = draws
    return draws[:size].reshape(n_max, block)


def leading_spectra(list clips, int n_vectors, double tolerance, int check, int max_steps):
    """Leading eigenvalues and right singular vectors of each clip (unit-scaled).

    Parameters
    ----------
    clips : list of C-contiguous float64 ndarray of shape (n_frames_i, n_channels)
    n_vectors : int
        Pairs per clip (at most ``n_channels``); a clip with fewer frames gets
        ``n_frames`` of them and zeros after.
    tolerance, check, max_steps : float, int, int
        The residual bound relative to the largest eigenvalue, the steps
        between checks, and the steps of subspace iteration (four times as
        many power steps for one pair) before LAPACK takes over.

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
    cdef const double[:, ::1] view
    cdef int longest = 0, n_max, block
    frames_out = np.zeros(max(m, 1), dtype=np.intc)
    cdef int[::1] frames = frames_out
    for c in range(m):
        view = clips[c]
        if view.shape[1] != n_channels:
            raise ValueError(f"clip {c} has {view.shape[1]} channels, not {n_channels}.")
        frames[c] = view.shape[0]
        longest = max(longest, frames[c])
    n_max = max(1, min(longest, n_channels))
    block = min(n_max, n_vectors + 4)
    start = _start_block(n_max, block)
    failed = _run(clips, &frames[0], n_channels, n_vectors, &values[0, 0], &vectors[0, 0, 0],
                  longest, n_max, block, start, tolerance, check, max_steps)
    if failed >= 0:
        raise np.linalg.LinAlgError(f"clip {failed}: the eigen-decomposition did not converge.")
    return values_out, vectors_out


cdef Py_ssize_t _run(list clips, int* frames, int n_channels, int n_vectors, double* values,
                     double* vectors, int longest, int n_max, int block,
                     const double[:, ::1] start, double tolerance, int check,
                     int max_steps) except? -2:
    """The loop over clips, without the GIL; the first failed clip, or -1."""
    cdef Py_ssize_t m = len(clips), c, failed = -1
    cdef const double** pointers = <const double**>malloc(max(m, 1) * sizeof(double*))
    cdef const double[:, ::1] view
    cdef Space s
    cdef int n_work = max(n_max * n_max, n_channels) + 3 * n_max * block + 2 * block * block
    n_work += n_max * (max(n_vectors, block) + 2) + 3 * block + 2
    s.lqwork, s.lwork, s.liwork = 64 * n_max, max(26 * n_max, block * block), 10 * n_max
    s.scaled = <double*>malloc(max(1, longest * n_channels) * sizeof(double))
    s.gram = <double*>malloc((n_work + s.lqwork + s.lwork) * sizeof(double))
    s.iwork = <int*>malloc((s.liwork + 2 * n_max) * sizeof(int))
    if not (pointers and s.scaled and s.gram and s.iwork):
        free(pointers); free(s.scaled); free(s.gram); free(s.iwork)
        raise MemoryError()
    # One allocation carved into the double buffers, one into the int ones.
    s.pairs = s.gram + max(n_max * n_max, n_channels)
    s.x = s.pairs + n_max * (max(n_vectors, block) + 2)
    s.y = s.x + n_max * block
    s.p = s.y + n_max * block
    s.h = s.p + n_max * block
    s.r = s.h + block * block
    s.ritz = s.r + block * block
    s.tau = s.ritz + block
    s.qwork = s.tau + block
    s.work = s.qwork + s.lqwork
    s.support = s.iwork + s.liwork
    s.start, s.start_cols = &start[0, 0], block
    for c in range(m):
        view = clips[c]
        pointers[c] = &view[0, 0] if view.shape[0] else NULL
    with nogil:
        for c in range(m):
            if pointers[c] == NULL:
                continue
            if _one_clip(pointers[c], frames[c], n_channels, n_vectors, values + c * n_vectors,
                         vectors + c * n_channels * n_vectors, &s, tolerance, check,
                         max_steps) != 0:
                failed = c
                break
    free(pointers); free(s.scaled); free(s.gram); free(s.iwork)
    return failed
