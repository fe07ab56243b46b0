# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled frame loops of the body frame of point trajectories (see ``_position_frame``).

One pass over the frames, each frame read once and its output written once, with
no temporary arrays: numpy needed a dozen passes (gathers of the facing and root
points, the per-frame matrices, a batched ``matmul``, the shift) for the same
arithmetic. The operations and their order are those of the numpy formulation
(:func:`skmotion.preprocessing._position_frame.position_frame_features`
documents them), so the results agree with it to the last bit or to rounding.

Points are float32 or float64, C-contiguous ``(n_frames, n_points, dim)``; the
arithmetic is in float64; ``out`` is the float64 ``(n_frames, n_out, k)``
output. Every loop releases the GIL (clips run in parallel threads).
"""

import numpy as np

from libc.math cimport fabs, hypot, sqrt

ctypedef Py_ssize_t intp

ctypedef fused real:
    float
    double


def chain_steps(const real[:, :, ::1] points, const intp[::1] chain, double scale,
                double[:, ::1] steps, intp axis):
    """Fill ``steps[k, f]``, the length of step ``k`` of the chain at frame ``f``.

    The points are multiplied by ``scale`` (a power of two, exact) first. Returns
    the largest ``|coordinate|`` of the chain points (unscaled), and the lowest and
    highest coordinate ``axis`` of all points over the clip (the floor), read in
    the same pass.
    """
    cdef intp n = points.shape[0], n_points = points.shape[1], dim = points.shape[2]
    cdef intp n_steps = max(chain.shape[0] - 1, 0)
    cdef intp f, k, d, a, b
    cdef double diff, total, value, peak = 0.0, low = 0.0, high = 0.0
    # one running minimum and maximum per point: independent chains the CPU overlaps
    cdef double[::1] lows = np.zeros(n_points), highs = np.zeros(n_points)
    if n:
        lows = np.array(np.asarray(points)[0, :, axis], dtype=np.float64)
        highs = lows.copy()
    with nogil:
        for f in range(n):
            for k in range(n_points):
                value = points[f, k, axis]
                lows[k] = min(lows[k], value)
                highs[k] = max(highs[k], value)
            for k in range(chain.shape[0]):
                a = chain[k]
                for d in range(dim):
                    peak = max(peak, fabs(points[f, a, d]))
            for k in range(n_steps):
                a, b = chain[k], chain[k + 1]
                total = 0.0
                for d in range(dim):
                    diff = points[f, b, d] * scale - points[f, a, d] * scale
                    total = diff * diff if d == 0 else total + diff * diff
                steps[k, f] = sqrt(total)
        if n_points:
            low, high = lows[0], highs[0]
            for k in range(1, n_points):
                low = min(low, lows[k])
                high = max(high, highs[k])
    return peak, low, high


cdef inline void _mean(const real[:, :, ::1] points, intp f, const intp[::1] members,
                       double* mean, intp dim) noexcept nogil:
    """The mean of some points of frame ``f`` (summed in order, then divided)."""
    cdef intp k, d
    for d in range(dim):
        mean[d] = points[f, members[0], d]
        for k in range(1, members.shape[0]):
            mean[d] += points[f, members[k], d]
        mean[d] /= members.shape[0]


cdef inline void _velocity(const real[:, :, ::1] points, intp f, intp j, double rate,
                           double* v, intp dim) noexcept nogil:
    """``np.gradient`` over frames at frame ``f`` of point ``j``, times the frame rate."""
    cdef intp n = points.shape[0], d
    for d in range(dim):
        if n < 2:
            v[d] = 0.0
        elif f == 0:
            v[d] = (<double>points[1, j, d] - points[0, j, d]) * rate
        elif f == n - 1:
            v[d] = (<double>points[n - 1, j, d] - points[n - 2, j, d]) * rate
        else:
            v[d] = (<double>points[f + 1, j, d] - points[f - 1, j, d]) / 2.0 * rate


def frames_3d(const real[:, :, ::1] points, double[:, :, ::1] out, intp start, intp stop,
              const intp[::1] root, const intp[::1] lefts, const intp[::1] rights,
              const intp[::1] outputs, intp up, const double[::1] flip, double level,
              double size, double tiny, bint velocities, double rate):
    """Body-frame positions (and velocities) of frames ``start:stop``, 3-D.

    Per frame: the summed left-minus-right vector ``l`` (flipped so that ``up``
    points up), its horizontal unit vector, the matrix ``M.T`` whose columns are
    forward, left and up divided by the size, and the shift ``t`` (the root's
    image, its vertical part the floor); a point ``p`` goes to ``p @ M.T - t``.
    ``M.T`` has two non-zero entries in the forward and left columns and one in
    the up column, so only those products are formed. Returns the first frame
    whose facing vector is vertical (no direction on the floor), or -1.
    """
    cdef intp h1 = (up + 1) % 3, h2 = (up + 2) % 3
    cdef intp f, k, o, j, d
    cdef double lat[3]
    cdef double origin[3]
    cdef double v[3]
    cdef double norm, peak, c1, c2
    cdef double a0, b0, a1, b1, cz, s0, s1, s2, qh1, qh2
    cdef intp flat = -1
    with nogil:
        for f in range(start, stop):
            for d in range(3):
                lat[d] = <double>points[f, lefts[0], d] - points[f, rights[0], d]
                for k in range(1, lefts.shape[0]):
                    lat[d] += <double>points[f, lefts[k], d] - points[f, rights[k], d]
                lat[d] *= flip[d]
            norm = hypot(lat[h1], lat[h2])
            peak = max(max(fabs(lat[0]), fabs(lat[1])), fabs(lat[2]))
            if not norm > tiny * peak:
                flat = f
                break
            c1 = lat[h1] / norm / size
            c2 = lat[h2] / norm / size
            # the non-zero entries of M.T: forward = (c2, -c1), left = (c1, c2) on (h1, h2)
            a0, b0 = c2 * flip[h1], -c1 * flip[h2]
            a1, b1 = c1 * flip[h1], c2 * flip[h2]
            cz = 1.0 / size * flip[up]
            _mean(points, f, root, origin, 3)
            s0 = origin[h1] * a0 + origin[h2] * b0
            s1 = origin[h1] * a1 + origin[h2] * b1
            s2 = level / size
            for o in range(outputs.shape[0]):
                j = outputs[o]
                qh1, qh2 = points[f, j, h1], points[f, j, h2]
                out[f, o, 0] = (qh1 * a0 + qh2 * b0) - s0
                out[f, o, 1] = (qh1 * a1 + qh2 * b1) - s1
                out[f, o, 2] = points[f, j, up] * cz - s2
                if velocities:
                    _velocity(points, f, j, rate, v, 3)
                    out[f, o, 3] = v[h1] * a0 + v[h2] * b0
                    out[f, o, 4] = v[h1] * a1 + v[h2] * b1
                    out[f, o, 5] = v[up] * cz
    return flat


def frames_2d(const real[:, :, ::1] points, double[:, :, ::1] out, intp start, intp stop,
              const intp[::1] root, const intp[::1] outputs, double ax, double ay,
              double level, bint velocities, double rate):
    """Image-plane positions (and velocities) of frames ``start:stop``, 2-D.

    ``x`` is multiplied by ``ax`` (the mirror sign over the size) and shifted by
    the root's image; ``y`` by ``ay`` (the up sign over the size) and shifted by
    the floor ``level`` (already divided by the size).
    """
    cdef intp f, o, j
    cdef double origin[2]
    cdef double v[2]
    cdef double shift
    with nogil:
        for f in range(start, stop):
            _mean(points, f, root, origin, 1)
            shift = origin[0] * ax
            for o in range(outputs.shape[0]):
                j = outputs[o]
                out[f, o, 0] = points[f, j, 0] * ax - shift
                out[f, o, 1] = points[f, j, 1] * ay - level
                if velocities:
                    _velocity(points, f, j, rate, v, 2)
                    out[f, o, 2] = v[0] * ax
                    out[f, o, 3] = v[1] * ay
