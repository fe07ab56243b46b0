# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Each clip's channel covariance, its upper triangle written row by row: one compiled pass.

Per clip, without Python between clips (and without the GIL): the channels' means (summed
frame after frame, then divided, as NumPy's ``mean(axis=0)``), the centred frames in a
buffer, their scatter by one BLAS ``dsyrk`` (SciPy's, through the function pointers it
exports, so building needs no SciPy headers), and each row of the triangle copied out
divided by the clip's frames. NumPy took a product of the full matrix and a fancy index of
its triangle per clip; the fancy index alone cost a third of the time on 192 channels.
"""

import numpy as np

from skmotion.utils._scipy_blas cimport dsyrk_t, scipy_function

ctypedef Py_ssize_t intp

cdef dsyrk_t _dsyrk = <dsyrk_t>scipy_function("blas", "dsyrk")


def covariance_rows(const double[:, ::1] frames, const intp[::1] offsets, out=None):
    """Per clip, entries ``(j, k)``, ``j <= k``, of its channels' covariance, row by row.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, d), C-contiguous float64
        The clips' frames, clip after clip.
    offsets : ndarray of shape (n_clips + 1,) of intp
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]``, none empty (checked).
    out : ndarray of shape (n_clips, d * (d + 1) // 2), default=None
        Written in place and returned (e.g. the columns of a larger table whose rows are
        strided): no copy of the rows into it afterwards.

    Returns
    -------
    rows : ndarray of shape (n_clips, d * (d + 1) // 2)
        ``sum_t (x_tj - m_j)(x_tk - m_k) / n`` over each clip's ``n`` frames, ``m`` its mean.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.recognition._covariance_rows import covariance_rows
    >>> frames = np.array([[0.0, 0.0], [2.0, 1.0], [4.0, 2.0], [1.0, 5.0]])
    >>> covariance_rows(frames, np.array([0, 3, 4])).round(3).tolist()  # two clips
    [[2.667, 1.333, 0.667], [0.0, 0.0, 0.0]]
    """
    cdef intp n = frames.shape[0], d = frames.shape[1], n_clips = offsets.shape[0] - 1
    cdef intp i, t, c, j, start, length, longest = 0, column
    if n_clips < 0 or offsets[0] != 0 or offsets[n_clips] != n:
        raise ValueError(f"offsets must run from 0 to the {n} frames.")
    for i in range(n_clips):
        if offsets[i + 1] <= offsets[i]:
            raise ValueError(f"clip {i} has no frames (offsets must increase).")
        longest = max(longest, offsets[i + 1] - offsets[i])
    if longest * d >= 2**31 or d >= 2**31:
        raise ValueError(f"a clip of {longest} frames x {d} channels is too large for BLAS.")
    rows_array = np.empty((n_clips, d * (d + 1) // 2)) if out is None else out
    if rows_array.shape != (n_clips, d * (d + 1) // 2):
        raise ValueError(f"out must have shape {(n_clips, d * (d + 1) // 2)}.")
    buffer_array = np.empty((max(longest, 1), max(d, 1)))
    product_array = np.empty((max(d, 1), max(d, 1)))
    mean_array = np.empty(max(d, 1))
    cdef double[:, :] rows = rows_array
    cdef double[:, ::1] buffer = buffer_array, product = product_array
    cdef double[::1] mean = mean_array
    cdef int d_int = <int>d, k_int
    cdef double one = 1.0, zero = 0.0
    cdef char lower = b"L", no_trans = b"N"
    if d == 0:
        return rows_array
    with nogil:
        for i in range(n_clips):
            start, length = offsets[i], offsets[i + 1] - offsets[i]
            for c in range(d):
                mean[c] = 0.0
            for t in range(start, start + length):
                for c in range(d):
                    mean[c] += frames[t, c]
            for c in range(d):
                mean[c] = mean[c] / length
            for t in range(length):
                for c in range(d):
                    buffer[t, c] = frames[start + t, c] - mean[c]
            # row-major length x d is column-major d x length: product = buffer^T buffer, the
            # column-major lower triangle, which is the upper triangle of the row-major rows
            k_int = <int>length
            _dsyrk(&lower, &no_trans, &d_int, &k_int, &one, &buffer[0, 0], &d_int, &zero,
                   &product[0, 0], &d_int)
            column = 0
            for j in range(d):
                for c in range(j, d):
                    rows[i, column] = product[j, c] / length
                    column += 1
    return rows_array
