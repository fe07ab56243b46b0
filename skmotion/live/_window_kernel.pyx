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
    cdef Py_ssize_t j, c, last = n_poses - n_poses % 4
    cdef double d, e, nearest = INFINITY, total = 0.0
    cdef double d0, d1, d2, d3
    cdef const double *p
    # four poses at a time: four independent sums hide the latency of an addition that
    # one running sum waits for (each pose's sum still runs over the channels in order,
    # so every distance is the same double as one pose at a time)
    for j in range(0, last, 4):
        p = poses + j * n_channels
        d0 = d1 = d2 = d3 = 0.0
        for c in range(n_channels):
            e = pose[c] - p[c]
            d0 += e * e
            e = pose[c] - p[n_channels + c]
            d1 += e * e
            e = pose[c] - p[2 * n_channels + c]
            d2 += e * e
            e = pose[c] - p[3 * n_channels + c]
            d3 += e * e
        out[j], out[j + 1], out[j + 2], out[j + 3] = d0, d1, d2, d3
    for j in range(last, n_poses):
        d = 0.0
        for c in range(n_channels):
            e = pose[c] - poses[j * n_channels + c]
            d += e * e
        out[j] = d
    for j in range(n_poses):
        if out[j] < nearest:
            nearest = out[j]
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


cdef Py_ssize_t _window_scores(const double *frames, Py_ssize_t n, Py_ssize_t m,
                               double[::1] previous, double[::1] feature,
                               double[:, :, ::1] ring, Py_ssize_t seen,
                               const double[:, ::1] weights, const double[::1] bias,
                               Py_ssize_t root, Py_ssize_t size_a, Py_ssize_t size_b,
                               const double[:, ::1] poses, double width,
                               Py_ssize_t segment, Py_ssize_t none_index, double[:, ::1] proba,
                               double[::1] score, Py_ssize_t[::1] best) noexcept nogil:
    """The loop of :func:`window_scores` over ``n`` frames of ``m`` channels, row after row."""
    cdef Py_ssize_t n_seg = ring.shape[1]
    cdef Py_ssize_t n_feat = weights.shape[0], n_cls = ring.shape[2], n_rows = n_seg * n_cls
    cdef Py_ssize_t window = ring.shape[0], t, i, k, j, f, c, slot, s
    cdef double v, top, total, w
    cdef double *row
    cdef const double *weight
    cdef const double *reference = _rows(poses)
    for t in range(n):
        for c in range(m):
            if not isfinite(frames[t * m + c]):
                return t
        s = seen + t
        _features(frames + t * m, m, root, size_a, size_b, &previous[0], s == 0, reference,
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
    if frames.shape[0] == 0:
        return -1
    return _window_scores(&frames[0, 0], frames.shape[0], frames.shape[1], previous, feature,
                          ring, seen, weights, bias, root, size_a, size_b, poses, width, segment,
                          none_index, proba, score, best)


cdef class FrameStep:
    """The one-frame call of a stream: the kernel's arrays bound once, one frame per call.

    A Python call that passes the seventeen arrays and numbers of
    :func:`window_scores` spends about as long unpacking them as the kernel
    spends on a frame; this holds them (the same arrays as the stream's, so
    the two calls share one state) and takes the frame alone.
    """

    cdef double[::1] previous, feature, score
    cdef double[:, :, ::1] ring
    cdef const double[:, ::1] weights, poses
    cdef const double[::1] bias
    cdef double[:, ::1] proba
    cdef Py_ssize_t[::1] best
    cdef Py_ssize_t root, size_a, size_b, segment, none_index
    cdef double width

    def __init__(self, double[::1] previous, double[::1] feature, double[:, :, ::1] ring,
                 const double[:, ::1] weights, const double[::1] bias, Py_ssize_t root,
                 Py_ssize_t size_a, Py_ssize_t size_b, const double[:, ::1] poses, double width,
                 Py_ssize_t segment, Py_ssize_t none_index, double[:, ::1] proba,
                 double[::1] score, Py_ssize_t[::1] best):
        if proba.shape[0] != 1 or score.shape[0] != 1 or best.shape[0] != 1:
            raise ValueError("FrameStep writes one row: proba, score and best hold one.")
        self.previous, self.feature, self.ring = previous, feature, ring
        self.weights, self.bias, self.poses, self.width = weights, bias, poses, width
        self.root, self.size_a, self.size_b = root, size_a, size_b
        self.segment, self.none_index = segment, none_index
        self.proba, self.score, self.best = proba, score, best

    def __call__(self, const double[::1] frame, Py_ssize_t seen):
        """Feed one frame to a stream that has seen ``seen``; ``(score, best)`` of its window
        (``(-1.0, -1)`` before the first full window), the probabilities in ``proba``.
        ``score`` is NaN when the frame holds NaN or infinity (nothing is taken then)."""
        if frame.shape[0] != self.previous.shape[0]:
            raise ValueError(f"a frame of {self.previous.shape[0]} channels is needed, "
                             f"got {frame.shape[0]}.")
        if _window_scores(&frame[0], 1, frame.shape[0], self.previous, self.feature, self.ring,
                          seen, self.weights, self.bias, self.root, self.size_a, self.size_b,
                          self.poses, self.width, self.segment, self.none_index, self.proba,
                          self.score, self.best) == 0:
            return float("nan"), -1
        return self.score[0], self.best[0]
