# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Rows of an array put in a new order in place: the tree build's reordering of a node's block.

``block[:] = block[order]`` makes a copy of the whole block first; at the root that is a
second copy of all frames. Following the permutation's cycles moves each row once through
one row of scratch space (and a byte per row to mark the rows placed). The values are
copied, never computed, so the result is the same as the gather's.
"""

import numpy as np

from libc.string cimport memcpy

ctypedef Py_ssize_t intp


def permute_rows(double[:, ::1] block, const intp[::1] order):
    """Reorder the rows of ``block`` in place: row ``i`` becomes the old row ``order[i]``.

    Parameters
    ----------
    block : ndarray of shape (n, d), C-contiguous float64, writable
    order : ndarray of shape (n,) of intp
        A permutation of ``0 .. n - 1`` (checked as the rows are moved).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._permute import permute_rows
    >>> block = np.arange(8.0).reshape(4, 2)
    >>> permute_rows(block, np.array([2, 0, 3, 1]))
    >>> block.tolist()
    [[4.0, 5.0], [0.0, 1.0], [6.0, 7.0], [2.0, 3.0]]
    """
    cdef intp n = block.shape[0], d = block.shape[1], i, j, k, moved = 0
    if order.shape[0] != n:
        raise ValueError(f"order has {order.shape[0]} entries for {n} rows.")
    if n == 0 or d == 0:
        return
    placed_array = np.zeros(n, dtype=np.uint8)
    scratch_array = np.empty(d)
    cdef unsigned char[::1] placed = placed_array
    cdef double[::1] scratch = scratch_array
    cdef size_t row_bytes = d * sizeof(double)
    cdef bint bad = False
    with nogil:
        for i in range(n):
            if placed[i]:
                continue
            placed[i] = 1
            k = order[i]
            if k == i:
                continue
            memcpy(&scratch[0], &block[i, 0], row_bytes)
            j = i
            while True:  # along the cycle through i: row j takes row order[j]
                k = order[j]
                if k < 0 or k >= n or moved > n:
                    bad = True
                    break
                moved += 1
                if k == i:
                    memcpy(&block[j, 0], &scratch[0], row_bytes)
                    break
                if placed[k]:
                    bad = True
                    break
                memcpy(&block[j, 0], &block[k, 0], row_bytes)
                placed[k] = 1
                j = k
            if bad:
                break
    if bad:
        raise ValueError("order is not a permutation of the rows; the block is left partly moved.")


def scatter_rows(const double[:, ::1] block, const intp[::1] place, intp low, intp high,
                 double[:, ::1] out):
    """Copy each row of ``block`` whose place is in ``[low, high)`` to ``out[place - low]``.

    The lean fit's gather of one child's frames from consecutive blocks of the clips
    (``_clip_build``): one compiled pass, no mask or index arrays the size of a block.

    Parameters
    ----------
    block : ndarray of shape (n, d), C-contiguous float64
    place : ndarray of shape (n,) of intp
        Each row's place among all rows of the node being split.
    low, high : int
        The child's places.
    out : ndarray of shape (high - low, d), C-contiguous float64, writable

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._permute import scatter_rows
    >>> out = np.zeros((2, 2))
    >>> scatter_rows(np.arange(6.0).reshape(3, 2), np.array([3, 0, 2]), 2, 4, out)
    >>> out.tolist()
    [[4.0, 5.0], [0.0, 1.0]]
    """
    cdef intp n = block.shape[0], d = block.shape[1], r, p
    if place.shape[0] != n or out.shape[1] != d or out.shape[0] != high - low:
        raise ValueError("scatter_rows: block, place and out do not match.")
    if d == 0:
        return
    cdef size_t row_bytes = d * sizeof(double)
    with nogil:
        for r in range(n):
            p = place[r]
            if low <= p < high:
                memcpy(&out[p - low, 0], &block[r, 0], row_bytes)
