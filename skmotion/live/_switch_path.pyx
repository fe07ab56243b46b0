# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""The best label path of a long take under a switch penalty (Viterbi), compiled.

Given a score per frame and label (log probabilities), the path ``l_0 ... l_{T-1}``
maximising ``sum_t score[t, l_t] - penalty * (number of t with l_t != l_{t-1})``.
Every label may follow every other at the same cost, so the best predecessor of
label ``k`` is either ``k`` itself or the previous frame's best label: the forward
pass costs ``T x K`` (not ``T x K x K``) and remembers one bit per frame and label
(stayed or switched) and the previous best label per frame. A loop over frames, so
compiled.
"""

import numpy as np


def switch_path(const double[:, ::1] score, double penalty):
    """The labels (column indices) of the best path; ties keep the label, then the lowest column.

    Parameters
    ----------
    score : ndarray of shape (n_frames, n_labels)
        Per frame, each label's score (a log probability); finite.
    penalty : float
        The cost of one change of label (>= 0).

    Returns
    -------
    path : ndarray of shape (n_frames,) of intp
    """
    cdef Py_ssize_t n = score.shape[0], k = score.shape[1], t, j, top, prev_top
    path = np.zeros(n, dtype=np.intp)
    if n == 0:
        return path
    switched_arr = np.zeros((n, k), dtype=np.uint8)
    leader_arr = np.zeros(n, dtype=np.intp)
    best_arr = np.empty(k)
    cdef unsigned char[:, ::1] switched = switched_arr
    cdef Py_ssize_t[::1] leader = leader_arr
    cdef Py_ssize_t[::1] p = path
    cdef double[::1] best = best_arr
    cdef double come
    with nogil:
        for j in range(k):
            best[j] = score[0, j]
        for t in range(1, n):
            prev_top = 0  # the previous frame's best label
            for j in range(1, k):
                if best[j] > best[prev_top]:
                    prev_top = j
            leader[t] = prev_top
            come = best[prev_top] - penalty
            for j in range(k):
                if come > best[j]:  # switching from the leader beats staying
                    best[j] = come
                    switched[t, j] = 1
                best[j] += score[t, j]
        top = 0
        for j in range(1, k):
            if best[j] > best[top]:
                top = j
        p[n - 1] = top
        for t in range(n - 1, 0, -1):
            if switched[t, top]:
                top = leader[t]
            p[t - 1] = top
    return path
