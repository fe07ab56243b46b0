# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The tree build's passes over a node's frames, compiled and without the GIL.

Two passes do most of the build's work, and each reads the node's rows once:

- :func:`shifted_moments`: the sums and the scatter (or only its diagonal) of the rows
  about a shift (the parent's mean). The rows are centred chunk by chunk into a small
  buffer that stays in the cache, and each chunk's scatter is added by one BLAS
  ``dsyrk`` (SciPy's, through the function pointers it exports, so building needs no
  SciPy headers); NumPy's ``block - mean`` followed by ``centred.T @ centred`` wrote and
  read a centred copy of every chunk through memory.
- :func:`partition_rows`: the rows whose projection is below the cut moved before the
  others, in place, by swapping pairs from both ends (Hoare's partition): each row that
  is on the wrong side is moved once, and rows are read in sequence. The children need
  their frames as one block each, not sorted: sorting the rows by projection (an
  ``argsort`` and a permutation along its cycles, random reads of whole rows) cost the
  build more than the arithmetic.

Without the GIL, the nodes of a layer can be processed in threads.
"""

import numpy as np

from libc.string cimport memcpy

from skmotion.utils._scipy_blas cimport dsyrk_t, scipy_function

ctypedef Py_ssize_t intp

cdef dsyrk_t _dsyrk = <dsyrk_t>scipy_function("blas", "dsyrk")

# Rows per chunk: a buffer of about 256 KB, which stays in the cache between the
# centring and the product.
cdef intp _CHUNK_VALUES = 32768


def moment_chunk_rows(intp d):
    """Rows per chunk of :func:`shifted_moments` over ``d`` channels (its blocks' unit)."""
    return max(1, _CHUNK_VALUES // max(d, 1))


def shifted_moments(const double[:, ::1] block, const double[::1] shift, bint scatter=True,
                    out=None):
    """Sums and scatter of rows about a shift: ``sum(x - s)`` and ``sum (x - s)(x - s)^T``.

    The node's mean is ``s + sums / n`` and its scatter about the mean is
    ``products - outer(sums, sums) / n``. With a shift near the mean (the parent's
    mean) the correction is small, so little is lost to cancellation.

    Parameters
    ----------
    block : ndarray of shape (n, d), C-contiguous float64
    shift : ndarray of shape (d,)
    scatter : bool, default=True
        False: only the diagonal of the products (the per-channel sums of squares),
        without the ``d x d`` product: what a node that is not split needs for a
        diagonal or spherical covariance.
    out : tuple of (sums, products), default=None
        Running sums and products (as returned) to add this block's to, in place: the
        rows of one array given in consecutive blocks of a multiple of the chunk's rows
        (``32768 // d``) add up to the doubles of the whole array in one call (the
        chunks, and the order their sums are added in, are the same).

    Returns
    -------
    sums : ndarray of shape (d,)
    products : ndarray of shape (d, d), or (d,) when ``scatter`` is False

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._node_passes import shifted_moments
    >>> rows = np.array([[1.0, 2.0], [3.0, 6.0]])
    >>> sums, products = shifted_moments(rows, np.array([1.0, 1.0]))
    >>> sums.tolist(), products.tolist()
    ([2.0, 6.0], [[4.0, 10.0], [10.0, 26.0]])
    >>> shifted_moments(rows, np.array([1.0, 1.0]), scatter=False)[1].tolist()
    [4.0, 26.0]
    """
    cdef intp n = block.shape[0], d = block.shape[1], start, stop, r, c, rows
    if shift.shape[0] != d:
        raise ValueError(f"shift has {shift.shape[0]} values for {d} channels.")
    cdef intp chunk = max(1, _CHUNK_VALUES // max(d, 1))
    if out is None:
        sums_array = np.zeros(d)
        products_array = np.zeros((d, d)) if scatter else np.zeros(d)
    else:
        sums_array, products_array = out
        wanted = (int(d), int(d)) if scatter else (int(d),)
        if tuple(sums_array.shape) != (d,) or tuple(products_array.shape) != wanted:
            raise ValueError("out's sums and products do not match the block's channels.")
    chunk_sums_array = np.empty(d)
    cdef double[::1] sums = sums_array, chunk_sums = chunk_sums_array
    cdef double[::1] squares
    cdef double[:, ::1] products, buffer
    cdef double value
    cdef int n_int = d, k_int, ld = d
    cdef double one = 1.0
    cdef char upper = b"U", no_trans = b"N"
    if scatter:
        products = products_array
        buffer = np.empty((chunk, d))
    else:
        squares = products_array
    if n == 0 or d == 0:
        return sums_array, products_array
    start = 0
    with nogil:
        while start < n:
            stop = min(start + chunk, n)
            rows = stop - start
            for c in range(d):  # per chunk, then added: sums of sums round less
                chunk_sums[c] = 0.0
            if scatter:
                for r in range(rows):
                    for c in range(d):
                        value = block[start + r, c] - shift[c]
                        buffer[r, c] = value
                        chunk_sums[c] += value
                # row-major rows x d is column-major d x rows: products += buffer^T buffer
                k_int = <int>rows
                _dsyrk(&upper, &no_trans, &n_int, &k_int, &one, &buffer[0, 0], &ld, &one,
                       &products[0, 0], &ld)
            else:
                for r in range(rows):
                    for c in range(d):
                        value = block[start + r, c] - shift[c]
                        chunk_sums[c] += value
                        squares[c] += value * value
            for c in range(d):
                sums[c] += chunk_sums[c]
            start = stop
        if scatter:  # dsyrk filled the upper triangle of the column-major matrix: the lower here
            for r in range(d):
                for c in range(r + 1, d):
                    products[r, c] = products[c, r]
    return sums_array, products_array


def partition_rows(double[:, ::1] block, const double[::1] projection, double cut,
                   index=None):
    """Move the rows whose projection is below ``cut`` before the others, in place.

    Parameters
    ----------
    block : ndarray of shape (n, d), C-contiguous float64, writable
    projection : ndarray of shape (n,)
        One number per row (read, not moved).
    cut : float
    index : ndarray of shape (n,) of intp, default=None
        Moved as the rows are (where each row came from).

    Returns
    -------
    n_below : int
        How many rows are below the cut: they are now ``block[:n_below]``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._node_passes import partition_rows
    >>> block = np.arange(10.0).reshape(5, 2)
    >>> partition_rows(block, np.array([3.0, 0.0, 4.0, 1.0, 2.0]), 2.5)
    3
    >>> block[:, 0].tolist()
    [8.0, 2.0, 6.0, 4.0, 0.0]
    """
    cdef intp n = block.shape[0], d = block.shape[1], i = 0, j, below = 0, t
    if projection.shape[0] != n:
        raise ValueError(f"projection has {projection.shape[0]} values for {n} rows.")
    cdef intp[::1] where
    cdef bint moved_index = index is not None
    if moved_index:
        where = index
        if where.shape[0] != n:
            raise ValueError(f"index has {where.shape[0]} values for {n} rows.")
    scratch_array = np.empty(max(d, 1))
    cdef double[::1] scratch = scratch_array
    cdef size_t row_bytes = d * sizeof(double)
    j = n - 1
    with nogil:
        for t in range(n):
            if projection[t] < cut:
                below += 1
        while True:
            while i < j and projection[i] < cut:
                i += 1
            while i < j and not projection[j] < cut:
                j -= 1
            if i >= j:
                break
            # row i belongs after the cut, row j before it
            if d > 0:
                memcpy(&scratch[0], &block[i, 0], row_bytes)
                memcpy(&block[i, 0], &block[j, 0], row_bytes)
                memcpy(&block[j, 0], &scratch[0], row_bytes)
            if moved_index:
                t = where[i]
                where[i] = where[j]
                where[j] = t
            i += 1
            j -= 1
    return below
