# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled loops of the occurrence search (neighbors/_occurrences.py).

Two recurrences that numpy cannot vectorise, each one pass over a take:

- the z-normalised distance of every window of ``m`` frames from the FFT's
  dot products and the window's spread, which is updated in O(1) per frame and
  recomputed exactly (two passes over the window) every ``_EXACT_EVERY``
  windows so rounding cannot drift; a window is constant exactly when the run
  of equal values ending at its last frame is ``m`` long (no tolerance to
  choose). One pass per channel, adding into the total, where numpy needed
  five arrays and as many passes; per stretch of ``_EXACT_EVERY`` windows,
  the spreads first (the serial part), then the distances in a loop without
  branches, which the compiler vectorises (setup.py's flags);
- subsequence dynamic time warping (Mueller, "Information Retrieval for Music
  and Motion", 2007, section 4.4): the query must be matched whole, the take
  may start and end anywhere. One column of the cost matrix per take frame;
  the start frame of the best path travels with its cost.
"""

import numpy as np

from libc.math cimport INFINITY, sqrt

# Windows between two exact recomputations of a channel's mean and spread.
DEF _EXACT_EVERY = 256
# Stands in for a spread of 0 where the result is not used.
DEF _TINY = 1e-300


cdef inline void _exact(const double[::1] x, Py_ssize_t i, Py_ssize_t m,
                        double* mean, double* m2) noexcept nogil:
    cdef double s = 0.0, d
    cdef Py_ssize_t j
    for j in range(i, i + m):
        s += x[j]
    s /= m
    mean[0] = s
    s = 0.0
    for j in range(i, i + m):
        d = x[j] - mean[0]
        s += d * d
    m2[0] = s


def add_znorm_distance(
    const double[::1] x, const double[:, ::1] dots, Py_ssize_t hop, Py_ssize_t m,
    bint query_constant, double[::1] total,
):
    """Add one channel's z-normalised distance of every window to the query into ``total``.

    Parameters
    ----------
    x : ndarray of shape (n,)
        The channel of the take.
    dots : ndarray of shape (n_blocks, block)
        The FFT blocks' correlations: ``dots[i // hop, i % hop]`` is
        ``sum_j q_hat[j] x[i + j]`` with ``q_hat`` the z-normalised query
        channel (ignored when the query channel is constant); read as they
        come out of the inverse FFT, without gathering them first.
    hop : int
        Windows per block, ``n_blocks * hop >= n - m + 1``.
    m : int
        The query's length, ``2 <= m <= n``.
    query_constant : bool
        The query channel is constant: the distance is 0 to a constant window
        and ``sqrt(m)`` to any other (stumpy's convention).
    total : ndarray of shape (n - m + 1,)
        Accumulates the distances, in place.
    """
    cdef Py_ssize_t n = x.shape[0], w = n - m + 1
    cdef Py_ssize_t i, k, run = 1, stop
    cdef double mu = 0.0, m2 = 0.0, new_mu, x_in, x_out, squared, spread, varies, root_m = sqrt(m)
    # Multiplications, not divisions, on the chain that carries the mean from frame to frame.
    cdef double inv_m = 1.0 / m
    # The spreads (m2) of a stretch of windows; -inf marks a constant window.
    cdef double m2s[_EXACT_EVERY]
    cdef double* out
    cdef const double* dot
    if dots.shape[0] * hop < w or dots.shape[1] < hop or total.shape[0] != w:
        raise ValueError(f"dots and total need {w} values")
    with nogil:
        # The run of equal values ending at frame m - 2, before the first window's last frame.
        for i in range(1, m - 1):
            run = run + 1 if x[i] == x[i - 1] else 1
        i = 0
        while i < w:
            # A stretch never crosses a block of the dots.
            stop = min(i + _EXACT_EVERY, w, (i // hop + 1) * hop)
            _exact(x, i, m, &mu, &m2)
            # The serial part: each window's spread from the previous one's.
            for k in range(i, stop):
                if k > i:
                    x_in = x[k + m - 1]
                    x_out = x[k - 1]
                    new_mu = mu + (x_in - x_out) * inv_m
                    m2 = m2 + (x_in - x_out) * (x_in - new_mu + x_out - mu)
                    mu = new_mu
                run = run + 1 if x[k + m - 1] == x[k + m - 2] else 1
                # A constant window: its spread is exactly 0, whatever m2 rounded to.
                m2s[k - i] = -INFINITY if run >= m else m2
            out = &total[i]
            dot = &dots[i // hop, i % hop]
            if query_constant:
                for k in range(stop - i):
                    out[k] += 0.0 if m2s[k] == -INFINITY else root_m
            else:
                # Independent windows, no branch the compiler cannot turn into a
                # select: this loop is vectorised. 2 m (1 - rho), rho = dots / (m std)
                # and m std = sqrt(m m2); a spread that is 0 (or rounded below) is
                # sqrt(m) from the query.
                for k in range(stop - i):
                    varies = m2s[k] > 0.0
                    spread = m2s[k] if m2s[k] > _TINY else _TINY
                    # At most 4 m (rho >= -1): the clamps only undo rounding, and keep
                    # the product by 0 below finite.
                    squared = 2.0 * (m - dot[k] * root_m / sqrt(spread))
                    squared = squared if squared > 0.0 else 0.0
                    squared = squared if squared < 4.0 * m else 4.0 * m
                    out[k] += varies * sqrt(squared) + (1.0 - varies) * root_m
            i = stop
    return total


def subsequence_dtw(const double[:, ::1] query, const double[:, ::1] take):
    """Cost and start of the best warping path of the whole query ending at each take frame.

    The local cost is the squared Euclidean distance between a query frame and
    a take frame; steps are (1, 1), (1, 0) and (0, 1); ties prefer the
    diagonal, then the query step, then the take step.

    Parameters
    ----------
    query : ndarray of shape (m, d), C-contiguous float64
    take : ndarray of shape (n, d), C-contiguous float64

    Returns
    -------
    cost : ndarray of shape (n,)
        Accumulated squared cost of the best path ending at each frame.
    start : ndarray of shape (n,) of intp
        The take frame where that path starts.
    """
    cdef Py_ssize_t m = query.shape[0], d = query.shape[1], n = take.shape[0]
    cdef Py_ssize_t i, j, c
    cdef double local, diff, best
    cdef Py_ssize_t best_start
    if take.shape[1] != d:
        raise ValueError(f"the query has {d} channels and the take {take.shape[1]}")
    cost_arr = np.empty(n)
    start_arr = np.empty(n, dtype=np.intp)
    cdef double[::1] out_cost = cost_arr
    cdef Py_ssize_t[::1] out_start = start_arr
    prev_arr = np.empty(m)
    cur_arr = np.empty(m)
    prev_s_arr = np.empty(m, dtype=np.intp)
    cur_s_arr = np.empty(m, dtype=np.intp)
    cdef double[::1] prev = prev_arr, cur = cur_arr, swap
    cdef Py_ssize_t[::1] prev_s = prev_s_arr, cur_s = cur_s_arr, swap_s
    with nogil:
        for i in range(n):
            for j in range(m):
                local = 0.0
                for c in range(d):
                    diff = query[j, c] - take[i, c]
                    local += diff * diff
                if j == 0:
                    # The free start: the path may begin at any take frame, and starting
                    # here is never worse than arriving from frame i - 1 (costs are >= 0).
                    best = 0.0
                    best_start = i
                elif i == 0:
                    best = cur[j - 1]
                    best_start = cur_s[j - 1]
                else:
                    best = prev[j - 1]
                    best_start = prev_s[j - 1]
                    if cur[j - 1] < best:
                        best = cur[j - 1]
                        best_start = cur_s[j - 1]
                    if prev[j] < best:
                        best = prev[j]
                        best_start = prev_s[j]
                cur[j] = local + best
                cur_s[j] = best_start
            out_cost[i] = cur[m - 1]
            out_start[i] = cur_s[m - 1]
            swap = prev
            prev = cur
            cur = swap
            swap_s = prev_s
            prev_s = cur_s
            cur_s = swap_s
    return cost_arr, start_arr
