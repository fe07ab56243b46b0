# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled psi distances between some queries and some stored clips (the ranking step).

:func:`~skmotion.neighbors._psi.psi_from_signatures` is a few matrix products,
which is right for whole collections; ranking a leaf's candidates first had to
gather their signatures (``vectors[columns]``: a copy of ``k x n_channels``
values per candidate) and then multiply strided slices, and the copies cost
more than the products. Here each candidate's signature is read where it is
stored, once per leaf, for all the leaf's queries.
"""

import numpy as np

from libc.math cimport fabs

from skmotion.utils._dot cimport dot4


def psi_distances(
    const double[:, ::1] query_weights,
    const double[:, :, ::1] query_vectors,
    const double[:, ::1] stored_weights,
    const double[:, :, ::1] stored_vectors,
    const Py_ssize_t[::1] rows,
    const Py_ssize_t[::1] columns,
):
    """``1 - psi`` between queries ``rows`` and stored clips ``columns``.

    Parameters
    ----------
    query_weights, query_vectors : ndarray of shape (n_queries, k) and (n_queries, k, n_channels)
    stored_weights, stored_vectors : ndarray of shape (n_stored, k) and (n_stored, k, n_channels)
        Signatures (:func:`~skmotion.neighbors._psi.signatures_from_spectra`).
    rows, columns : ndarray of intp
        Which queries and which stored clips; not checked (callers pass ids in range).

    Returns
    -------
    distances : ndarray of shape (len(rows), len(columns))
        ``1 - psi`` with psi clipped to ``[0, 1]``, as ``psi_from_signatures`` gives it.
    """
    cdef Py_ssize_t k = query_weights.shape[1], n = query_vectors.shape[2]
    cdef Py_ssize_t r, c, i, q, s
    cdef double total
    if stored_weights.shape[1] != k or stored_vectors.shape[2] != n:
        raise ValueError("the query and stored signatures differ in k or in channels.")
    out_array = np.empty((rows.shape[0], columns.shape[0]))
    cdef double[:, ::1] out = out_array
    with nogil:
        for c in range(columns.shape[0]):
            s = columns[c]
            for r in range(rows.shape[0]):
                q = rows[r]
                total = 0.0
                for i in range(k):
                    total += (query_weights[q, i] + stored_weights[s, i]) * fabs(
                        dot4(&query_vectors[q, i, 0], &stored_vectors[s, i, 0], n)
                    )
                total *= 0.5
                # Rounding can push a perfect match a hair above 1.
                out[r, c] = 1.0 - (0.0 if total < 0.0 else (1.0 if total > 1.0 else total))
    return out_array
