# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Weighted sums of rows per group, in row order: the per-clip (and per clip and node) sums
of the tree encoder's residuals and moments.

``out[g] = sum_{i: group[i] == g} weight[i] * values[i]``, each sum taken row after row
from 0, as ``scipy.sparse``'s CSR product takes it (``y += a * x``, in column order), so
the results are the same doubles as the product of the (group x row) averaging matrix,
without building it: on a batch of one clip, building the sparse matrix cost 15-20 times
the sums themselves. The module is compiled without floating-point contraction (no fused
multiply-add), so the rounding is that of the separate product and sum.
"""

import numpy as np

ctypedef Py_ssize_t intp


def group_sums(values, group, weight, n_groups):
    """Per group, the weighted sum of its rows, in row order.

    Parameters
    ----------
    values : ndarray of shape (n_rows, n_columns), C-contiguous float64
    group : ndarray of shape (n_rows,) of intp
        Each row's group, in ``0 .. n_groups - 1`` (checked).
    weight : ndarray of shape (n_rows,) of float64
    n_groups : int

    Returns
    -------
    sums : ndarray of shape (n_groups, n_columns)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils._group_sums import group_sums
    >>> values = np.arange(8.0).reshape(4, 2)
    >>> group_sums(values, np.array([1, 0, 1, 1]), np.array([1.0, 1.0, 0.5, 2.0]), 2).tolist()
    [[2.0, 3.0], [14.0, 17.5]]
    """
    values = np.ascontiguousarray(values, dtype=np.float64)
    group = np.ascontiguousarray(group, dtype=np.intp)
    weight = np.ascontiguousarray(weight, dtype=np.float64)
    if values.ndim != 2 or group.shape != (len(values),) or weight.shape != (len(values),):
        raise ValueError(
            f"values must be 2-D and group and weight give one entry per row; got shapes "
            f"{values.shape}, {group.shape} and {weight.shape}."
        )
    out = np.zeros((n_groups, values.shape[1]))
    _sums(values, group, weight, out)
    return out


cdef void _sums(const double[:, ::1] values, const intp[::1] group, const double[::1] weight,
                double[:, ::1] out) except *:
    cdef intp n = values.shape[0], d = values.shape[1], n_groups = out.shape[0], i, c, g
    cdef double w
    with nogil:
        for i in range(n):
            g = group[i]
            if g < 0 or g >= n_groups:
                with gil:
                    raise ValueError(f"group[{i}] is {g}, outside 0 .. {n_groups - 1}.")
            w = weight[i]
            for c in range(d):
                out[g, c] += w * values[i, c]
