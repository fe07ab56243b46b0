# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled steps of a query's leaf: the filter by the deeper levels, and Euclidean ranking.

:class:`~skmotion.neighbors._interval_index.IntervalIndex` materialises its first
levels only; a query's leaf of the paper's tree is the materialised leaf's items
whose first and last entries hold the query's entry at every deeper level
(:func:`filter_items`: one pass, no gathered copy of the entries). Feature
vectors are ranked by :func:`euclidean_block`, which reads each candidate's
vector where it is stored: sklearn's ``euclidean_distances`` validates its
inputs on every call, which cost more than the distances of a small leaf.
"""

import numpy as np

from libc.math cimport sqrt


ctypedef fused entry_t:
    signed char
    short
    int


def filter_items(const int[::1] items, const entry_t[:, :, ::1] deep, const entry_t[::1] entries):
    """The items whose ``deep[item, 0, l] <= entries[l] <= deep[item, 1, l]`` at every level ``l``.

    Parameters
    ----------
    items : ndarray of int32
        Item ids (in range; not checked), in the order they are returned.
    deep : ndarray of int8, int16 or int32 of shape (n_items, 2, n_levels)
        Each item's first and last entry per level (int8 for up to 127 entries:
        6 bytes per item at 3 levels, so the array of 10^6 items stays in cache).
    entries : ndarray of the same type, of shape (n_levels,)
        The query's entry per level.

    Returns
    -------
    kept : ndarray of int32
    """
    cdef Py_ssize_t n = items.shape[0], n_levels = entries.shape[0], i, level, count = 0
    cdef int item
    if deep.shape[2] != n_levels:
        raise ValueError("deep and entries differ in their number of levels.")
    out_array = np.empty(n, dtype=np.int32)
    cdef int[::1] out = out_array
    with nogil:
        for i in range(n):
            item = items[i]
            for level in range(n_levels):
                if deep[item, 0, level] > entries[level] or entries[level] > deep[item, 1, level]:
                    break
            else:
                out[count] = item
                count += 1
    return out_array[:count]


def euclidean_block(
    const double[:, ::1] query,
    const double[:, ::1] stored,
    const Py_ssize_t[::1] rows,
    const Py_ssize_t[::1] columns,
):
    """Euclidean distances between queries ``rows`` and stored vectors ``columns``.

    Sums of squared differences (not the expansion ``|x|^2 - 2 x.y + |y|^2``, which
    loses the small distances to cancellation).

    Parameters
    ----------
    query, stored : ndarray of shape (n_queries, n_features) and (n_stored, n_features)
    rows, columns : ndarray of intp
        Which queries and which stored vectors; not checked (callers pass ids in range).

    Returns
    -------
    distances : ndarray of shape (len(rows), len(columns))
    """
    cdef Py_ssize_t n_features = query.shape[1], r, c, j, q, s
    cdef double total, d
    if stored.shape[1] != n_features:
        raise ValueError("the query and stored vectors differ in their number of features.")
    out_array = np.empty((rows.shape[0], columns.shape[0]))
    cdef double[:, ::1] out = out_array
    with nogil:
        for r in range(rows.shape[0]):
            q = rows[r]
            for c in range(columns.shape[0]):
                s = columns[c]
                total = 0.0
                for j in range(n_features):
                    d = query[q, j] - stored[s, j]
                    total += d * d
                out[r, c] = sqrt(total)
    return out_array


def smallest_columns(const double[:, ::1] distances, Py_ssize_t n):
    """Per row, the columns of the ``n`` smallest distances, increasing, ties by column.

    What a stable argsort of each row gives in its first ``n`` places, by insertion
    into a sorted buffer of ``n`` (one pass over the row: ``n`` is small).

    Parameters
    ----------
    distances : ndarray of shape (n_rows, n_columns)
        No NaN (not checked).
    n : int
        From 1 to ``n_columns``.

    Returns
    -------
    columns : ndarray of intp of shape (n_rows, n)
    nearest : ndarray of shape (n_rows, n)
    """
    cdef Py_ssize_t n_rows = distances.shape[0], n_columns = distances.shape[1]
    cdef Py_ssize_t r, c, count, at
    cdef double d
    if not 1 <= n <= n_columns:
        raise ValueError(f"n must be from 1 to {n_columns}; got {n}.")
    columns_array = np.empty((n_rows, n), dtype=np.intp)
    nearest_array = np.empty((n_rows, n))
    cdef Py_ssize_t[:, ::1] columns = columns_array
    cdef double[:, ::1] nearest = nearest_array
    with nogil:
        for r in range(n_rows):
            count = 0
            for c in range(n_columns):
                d = distances[r, c]
                if count == n and not d < nearest[r, n - 1]:
                    continue
                at = count if count < n else n - 1
                # Shift the larger ones up; an equal one stays before (the lower column).
                while at > 0 and nearest[r, at - 1] > d:
                    nearest[r, at] = nearest[r, at - 1]
                    columns[r, at] = columns[r, at - 1]
                    at -= 1
                nearest[r, at] = d
                columns[r, at] = c
                if count < n:
                    count += 1
    return columns_array, nearest_array
