# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled frame features and window scores of :class:`LinearGestureDetector` (see ``_linear``).

A window of ``n_segments * segment`` frames is described by the mean frame
feature of each of its segments, and a linear readout scores it. The readout
being linear, a window's decision is a sum over its frames of one row per
frame and segment: ``decision = bias + sum_k sum_{frame in segment k}
feature(frame) @ weights[k]`` (``weights`` already divided by the segment's
length and by the training standardisation). Each new frame is featurised
once, its rows for every segment (``n_segments x n_classes`` numbers) go into
a ring of the last window's frames, and the window's decision is summed from
that ring: ``window x n_classes`` additions, a few hundred, so cheaper than
keeping running sums and free of their rounding drift. The batch scores of a
take are this same loop from an empty state, so the stream and the batch give
the same numbers to the last bit.

Frame features: the frame's joints relative to a root joint and divided by the
distance between two joints (the body's size), and the difference of that from
the previous frame (a velocity; zero at a stream's first frame).
"""

import numpy as np

from libc.math cimport INFINITY, exp, isfinite, sqrt


cdef inline void _soft_poses(const double *pose, Py_ssize_t n_channels, const double *poses,
                             Py_ssize_t n_poses, double width, double *out) noexcept nogil:
    """``out[j]``: the soft assignment of ``pose`` to reference pose ``j`` (they sum to 1);
    ``poses`` holds ``n_poses`` rows of ``n_channels``."""
    cdef Py_ssize_t j, c
    cdef double d, e, nearest = INFINITY, total = 0.0
    for j in range(n_poses):
        d = 0.0
        for c in range(n_channels):
            e = pose[c] - poses[j * n_channels + c]
            d += e * e
        out[j] = d
        if d < nearest:
            nearest = d
    for j in range(n_poses):
        # a term below exp(-36) (2e-16) of the nearest pose's is under the rounding of the
        # sum: zero, rather than a subnormal number that slows every product it enters
        # (and a zero feature is skipped by the window update)
        e = (out[j] - nearest) / width
        out[j] = exp(-e) if e < 36.0 else 0.0
        total += out[j]
    for j in range(n_poses):
        out[j] /= total


cdef inline const double *_rows(const double[:, ::1] poses) noexcept nogil:
    """The first row of ``poses``, or NULL when it has none (never read then)."""
    return &poses[0, 0] if poses.shape[0] > 0 else NULL


cdef inline void _features(const double *x, Py_ssize_t n_channels, Py_ssize_t root,
                           Py_ssize_t size_a, Py_ssize_t size_b, double *previous,
                           bint first, const double *poses, Py_ssize_t n_poses,
                           double width, double *out) noexcept nogil:
    """``out[:n_channels]`` the normalised pose, ``out[n_channels:2 n_channels]`` its change,
    ``out[2 n_channels:]`` its soft assignment to the ``n_poses`` rows of ``poses``;
    updates ``previous``."""
    cdef Py_ssize_t c
    cdef double size = 1.0, d, q
    cdef double r[3]
    r[0] = r[1] = r[2] = 0.0
    if size_a >= 0:
        size = 0.0
        for c in range(3):
            d = x[3 * size_a + c] - x[3 * size_b + c]
            size += d * d
        size = sqrt(size)
        if size < 1e-9:
            size = 1.0
    if root >= 0:
        for c in range(3):
            r[c] = x[3 * root + c]
    for c in range(n_channels):
        q = x[c]
        if root >= 0:
            q = q - r[c % 3]
        q = q / size
        out[c] = q
        out[n_channels + c] = 0.0 if first else q - previous[c]
        previous[c] = q
    if n_poses > 0:
        _soft_poses(out, n_channels, poses, n_poses, width, out + 2 * n_channels)


def frame_features(const double[:, ::1] frames, Py_ssize_t root, Py_ssize_t size_a,
                   Py_ssize_t size_b, const double[:, ::1] poses, double width):
    """The features of every frame of a take (its first frame's velocity is zero).

    ``poses`` (n_poses, n_channels): the reference poses (zero rows: none), ``width``
    the squared distance that scales the soft assignment.
    """
    cdef Py_ssize_t n = frames.shape[0], m = frames.shape[1], t
    if poses.shape[0] and poses.shape[1] != m:
        raise ValueError(f"poses have {poses.shape[1]} channels, the frames {m}.")
    out = np.empty((n, 2 * m + poses.shape[0]))
    cdef double[:, ::1] o = out
    cdef double[::1] previous = np.zeros(m)
    cdef const double *reference = _rows(poses)
    with nogil:
        for t in range(n):
            _features(&frames[t, 0], m, root, size_a, size_b, &previous[0], t == 0, reference,
                      poses.shape[0], width, &o[t, 0])
    return out


cdef Py_ssize_t _window_scores(const double[:, ::1] frames, double[::1] previous,
                               double[::1] feature, double[:, :, ::1] ring, Py_ssize_t seen,
                               const double[:, ::1] weights, const double[::1] bias,
                               Py_ssize_t root, Py_ssize_t size_a, Py_ssize_t size_b,
                               const double[:, ::1] poses, double width,
                               Py_ssize_t segment, Py_ssize_t none_index, double[:, ::1] proba,
                               double[::1] score, Py_ssize_t[::1] best) noexcept nogil:
    cdef Py_ssize_t n = frames.shape[0], m = frames.shape[1], n_seg = ring.shape[1]
    cdef Py_ssize_t n_feat = weights.shape[0], n_cls = ring.shape[2], n_rows = n_seg * n_cls
    cdef Py_ssize_t window = ring.shape[0], t, i, k, j, f, c, slot, s
    cdef double v, top, total, w
    cdef double *row
    cdef const double *weight
    cdef const double *reference = _rows(poses)
    for t in range(n):
        for c in range(m):
            if not isfinite(frames[t, c]):
                return t
        s = seen + t
        _features(&frames[t, 0], m, root, size_a, size_b, &previous[0], s == 0, reference,
                  poses.shape[0], width, &feature[0])
        slot = s % window
        # the frame's rows for every segment, side by side: one contiguous loop per feature
        row = &ring[slot, 0, 0]
        for j in range(n_rows):
            row[j] = 0.0
        for f in range(n_feat):
            v = feature[f]
            if v != 0.0:
                weight = &weights[f, 0]
                for j in range(n_rows):
                    row[j] += v * weight[j]
        if s < window - 1:
            score[t] = -1.0
            best[t] = -1
            continue
        for c in range(n_cls):
            proba[t, c] = bias[c]
        # segment k holds frames s - window + 1 + k * segment ... (+ segment - 1)
        for k in range(n_seg):
            for j in range(segment):
                i = (s - window + 1 + k * segment + j) % window
                for c in range(n_cls):
                    proba[t, c] += ring[i, k, c]
        top = proba[t, 0]
        for c in range(1, n_cls):
            if proba[t, c] > top:
                top = proba[t, c]
        total = 0.0
        for c in range(n_cls):
            w = exp(proba[t, c] - top)
            proba[t, c] = w
            total += w
        score[t] = -1.0
        best[t] = -1
        for c in range(n_cls):
            proba[t, c] /= total
            if c != none_index and proba[t, c] > score[t]:
                score[t] = proba[t, c]
                best[t] = c
    return -1


def window_scores(const double[:, ::1] frames, double[::1] previous, double[::1] feature,
                  double[:, :, ::1] ring, Py_ssize_t seen, const double[:, ::1] weights,
                  const double[::1] bias, Py_ssize_t root, Py_ssize_t size_a, Py_ssize_t size_b,
                  const double[:, ::1] poses, double width, Py_ssize_t segment,
                  Py_ssize_t none_index, double[:, ::1] proba, double[::1] score,
                  Py_ssize_t[::1] best):
    """Feed ``frames`` to a stream that has seen ``seen`` frames; one score row per frame.

    ``ring`` (window, n_segments, n_classes) holds each of the last window's
    frames' rows, ``previous`` the last normalised pose, ``feature`` is
    scratch. ``weights`` (n_frame_features, n_segments * n_classes): row ``f``
    holds feature ``f``'s weights for segment 0's classes, then segment 1's, ... Row ``t`` of ``proba`` gets the softmax of the window ending at
    that frame, ``score[t]`` the best probability apart from ``none_index``
    and ``best[t]`` its class; a frame before the first full window gets
    ``score = -1`` (``proba`` untouched). ``poses`` and ``width``: as for
    :func:`frame_features`. Returns the index of the first frame holding NaN or
    infinity (the frames before it are taken), or -1.
    """
    # the GIL is kept: a call is a frame or a take of a few microseconds of work per frame
    return _window_scores(frames, previous, feature, ring, seen, weights, bias, root, size_a,
                          size_b, poses, width, segment, none_index, proba, score, best)
