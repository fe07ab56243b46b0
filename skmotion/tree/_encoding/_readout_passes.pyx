# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The encoder's per-clip readouts in one compiled pass over each clip's frames.

A clip's residuals (per node, the mean offset of its frames from the node's mean) and
moments (per channel, the mean and root mean square in training units) were about forty
small NumPy operations per call; on one clip of a few dozen frames their fixed costs were
most of the encoder's ``transform``. Here each clip is read once per block, its sums
taken in frame order into the output row, and the row finished in place. The dense
occupancy (and transitions) of ``histogram_rows`` are the entries of the sparse matrix
that ``histogram_features`` builds, without building it (a third of a dense transform).

The arithmetic is that of the NumPy expressions it replaces, operation for operation, so
the results are the same doubles (``tests/tree/test_encoder_readouts.py``):

- the sums are taken frame after frame from 0.0, each product rounded before it is
  added (the module is compiled without floating-point contraction), as
  ``utils/_group_sums`` and ``np.bincount`` take them;
- a row's squared norm is NumPy's pairwise summation (``np.add.reduce`` over a
  contiguous row: blocks of up to 128 values summed in eight interleaved partial sums,
  longer rows halved at a multiple of 8);
- the power 0.5 is a square root, as NumPy's ``x ** 0.5`` is (other powers are left
  to NumPy by the caller, whose ``pow`` may be vectorised differently).
"""

import numpy as np

from libc.math cimport sqrt

ctypedef Py_ssize_t intp


cdef double _pairwise_sum_of_squares(const double* a, intp n) noexcept nogil:
    """``np.add.reduce(a * a)`` for contiguous ``a``: NumPy's pairwise summation."""
    cdef intp i, half
    cdef double res, r0, r1, r2, r3, r4, r5, r6, r7
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i] * a[i]
        return res
    if n <= 128:
        r0 = a[0] * a[0]
        r1 = a[1] * a[1]
        r2 = a[2] * a[2]
        r3 = a[3] * a[3]
        r4 = a[4] * a[4]
        r5 = a[5] * a[5]
        r6 = a[6] * a[6]
        r7 = a[7] * a[7]
        i = 8
        while i < n - (n % 8):
            r0 += a[i] * a[i]
            r1 += a[i + 1] * a[i + 1]
            r2 += a[i + 2] * a[i + 2]
            r3 += a[i + 3] * a[i + 3]
            r4 += a[i + 4] * a[i + 4]
            r5 += a[i + 5] * a[i + 5]
            r6 += a[i + 6] * a[i + 6]
            r7 += a[i + 7] * a[i + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += a[i] * a[i]
            i += 1
        return res
    half = n // 2
    half -= half % 8
    return _pairwise_sum_of_squares(a, half) + _pairwise_sum_of_squares(a + half, n - half)


cdef void _signed_root_unit_norm(double* row, intp n, bint root) noexcept nogil:
    """``sign(b) * sqrt(|b|)`` per entry (when ``root``), then the row scaled to unit norm."""
    cdef intp i
    cdef double v, norm
    if root:
        for i in range(n):
            v = row[i]
            if v > 0:
                row[i] = sqrt(v)
            elif v < 0:
                row[i] = -sqrt(-v)
            elif v == 0:
                row[i] = 0.0  # np.sign(-0.0) is 0.0
            # NaN stays NaN, as sign(NaN) * sqrt(NaN) is
    norm = sqrt(_pairwise_sum_of_squares(row, n))
    if norm > 0:
        for i in range(n):
            row[i] = row[i] / norm


cdef inline void _cell_sizes(intp* size, intp parts, intp length) noexcept nogil:
    """``size[cell]``: the frames of a clip of ``length`` in each of its ``parts`` pyramid
    cells, frame ``t`` being in cell ``t * parts // length`` (the occupancy's and the
    moments' pyramids alike)."""
    cdef intp cell, t
    for cell in range(parts):
        size[cell] = 0
    for t in range(length):
        size[t * parts // length] += 1


cdef int _check_offsets(const intp[::1] offsets, intp n_frames) except -1:
    cdef intp i
    if offsets.shape[0] < 1 or offsets[0] != 0 or offsets[offsets.shape[0] - 1] != n_frames:
        raise ValueError(f"offsets must run from 0 to the {n_frames} frames.")
    for i in range(offsets.shape[0] - 1):
        if offsets[i + 1] < offsets[i]:
            raise ValueError(f"offsets must not decrease; offsets[{i + 1}] < offsets[{i}].")
    return 0


def residual_rows(const double[:, ::1] frames, const intp[:] node, const intp[::1] offsets,
                  const double[:, ::1] mean, const double[::1] center, const double[::1] scale,
                  bint finish, bint root):
    """Per clip and node, the mean offset of the clip's standardised frames from the node's mean.

    Row ``i``, columns ``g * d .. (g + 1) * d``: ``(S - s * center) / scale - s * mean[g]``
    with ``S = sum_t w x_t`` over the clip's frames in node ``g`` and ``s = sum_t w``,
    ``w = 1 / n_frames`` of the clip, each sum in frame order (the expression of
    ``residual_features``). With ``finish``, each row is then raised to the power 0.5 with
    its sign (when ``root``) and scaled to unit Euclidean norm.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, d), C-contiguous float64
        Raw frames, clip after clip.
    node : ndarray of shape (n_frames,) of intp
        Each frame's node in the layer, in ``0 .. k - 1`` (checked).
    offsets : ndarray of shape (n_clips + 1,) of intp
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]`` (checked).
    mean : ndarray of shape (k, d)
        The nodes' mean frames (standardised).
    center, scale : ndarray of shape (d,)
    finish, root : bool

    Returns
    -------
    rows : ndarray of shape (n_clips, k * d)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._readout_passes import residual_rows
    >>> frames = np.array([[1.0], [3.0], [10.0]])  # one channel, one clip of three frames
    >>> rows = residual_rows(frames, np.array([0, 0, 1]), np.array([0, 3]), np.zeros((2, 1)),
    ...                      np.zeros(1), np.ones(1), False, False)
    >>> (rows * 3).round(12).tolist()  # node 0: (1 + 3) / 3, node 1: 10 / 3
    [[4.0, 10.0]]
    """
    cdef intp n = frames.shape[0], d = frames.shape[1], k = mean.shape[0]
    cdef intp n_clips = offsets.shape[0] - 1, i, t, c, g
    cdef double w
    if node.shape[0] != n or mean.shape[1] != d or center.shape[0] != d or scale.shape[0] != d:
        raise ValueError(
            f"shapes do not agree: frames {(n, d)}, node {node.shape[0]}, mean "
            f"{(k, mean.shape[1])}, center {center.shape[0]}, scale {scale.shape[0]}."
        )
    _check_offsets(offsets, n)
    for t in range(n):
        if node[t] < 0 or node[t] >= k:
            raise ValueError(f"node[{t}] is {node[t]}, outside 0 .. {k - 1}.")
    rows_array = np.zeros((max(n_clips, 0), k * d))
    share_array = np.empty(k)
    cdef double[:, ::1] rows = rows_array
    cdef double[::1] share = share_array
    cdef double* row
    with nogil:
        for i in range(n_clips):
            row = &rows[i, 0] if k * d else NULL
            for g in range(k):
                share[g] = 0.0
            w = 1.0 / (offsets[i + 1] - offsets[i])
            for t in range(offsets[i], offsets[i + 1]):
                g = node[t]
                share[g] += w
                for c in range(d):
                    row[g * d + c] += w * frames[t, c]
            for g in range(k):
                for c in range(d):
                    row[g * d + c] = (
                        (row[g * d + c] - share[g] * center[c]) / scale[c] - share[g] * mean[g, c]
                    )
            if finish and k * d:
                _signed_root_unit_norm(row, k * d, root)
    return rows_array


def moment_rows(const double[:, ::1] frames, const intp[::1] offsets, const double[::1] center,
                const double[::1] scale, int order, const intp[::1] pyramid):
    """Per clip, each channel's mean over each pyramid cell, then (``order`` 2) its root mean
    square, in units of the training frames (``z = (x - center) / scale``).

    The expressions of ``moment_features``: a cell's mean is ``sum_t w (x_t - center) /
    scale`` with ``w = 1 / (frames in the cell)``, summed in frame order; a cell without a
    frame (a clip shorter than the level) takes the frame that spans it; the root mean
    square is ``sqrt(sum_t w (x_t - center) ** 2) / scale - 1`` over the whole clip.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, d), C-contiguous float64
    offsets : ndarray of shape (n_clips + 1,) of intp
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]``, none empty (checked).
    center, scale : ndarray of shape (d,)
    order : int
        1 (means) or 2 (means, then root mean squares).
    pyramid : ndarray of intp
        The levels (1: the whole clip), each at least 1.

    Returns
    -------
    rows : ndarray of shape (n_clips, (sum(pyramid) + order - 1) * d)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._readout_passes import moment_rows
    >>> frames = np.array([[1.0], [3.0], [2.0], [6.0]])  # one clip of four frames
    >>> rows = moment_rows(frames, np.array([0, 4]), np.zeros(1), np.ones(1), 2, np.array([1, 2]))
    >>> rows.round(6).tolist()  # mean; means of the halves; sqrt((1 + 9 + 4 + 36) / 4) - 1
    [[3.0, 2.0, 4.0, 2.535534]]
    """
    cdef intp n = frames.shape[0], d = frames.shape[1], n_clips = offsets.shape[0] - 1
    cdef intp n_levels = pyramid.shape[0], i, t, c, j, p, cell, length, start, column, total = 0
    cdef double w, x
    if center.shape[0] != d or scale.shape[0] != d:
        raise ValueError(f"center and scale must have {d} entries.")
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2; got {order}.")
    _check_offsets(offsets, n)
    for i in range(n_clips):
        if offsets[i + 1] == offsets[i]:
            raise ValueError(f"clip {i} has no frames.")
    for j in range(n_levels):
        if pyramid[j] < 1:
            raise ValueError(f"pyramid levels must be at least 1; got {pyramid[j]}.")
        total += pyramid[j]
    width = (total + order - 1) * d
    rows_array = np.zeros((max(n_clips, 0), width))
    size_array = np.empty(max(total, 1), dtype=np.intp)
    cdef double[:, ::1] rows = rows_array
    cdef intp[::1] size = size_array
    cdef double* row
    with nogil:
        for i in range(n_clips):
            row = &rows[i, 0] if width else NULL
            start, length = offsets[i], offsets[i + 1] - offsets[i]
            column = 0
            for j in range(n_levels):
                p = pyramid[j]
                _cell_sizes(&size[0], p, length)
                for t in range(length):
                    cell = t * p // length
                    w = 1.0 / size[cell]
                    for c in range(d):
                        row[column + cell * d + c] += w * (frames[start + t, c] - center[c])
                for cell in range(p):
                    if size[cell] == 0:  # the frame that spans the empty cell
                        t = start + cell * length // p
                        for c in range(d):
                            row[column + cell * d + c] = frames[t, c] - center[c]
                    for c in range(d):
                        row[column + cell * d + c] = row[column + cell * d + c] / scale[c]
                column += p * d
            if order == 2:
                w = 1.0 / length
                for t in range(start, start + length):
                    for c in range(d):
                        x = frames[t, c] - center[c]
                        row[column + c] += w * (x * x)
                for c in range(d):
                    row[column + c] = sqrt(row[column + c]) / scale[c] - 1.0
    return rows_array


def histogram_rows(const intp[:, ::1] nodes, const intp[::1] offsets,
                   const intp[:, ::1] blocks, intp width, bint root):
    """Per clip, the shares of its frames in each node and pyramid cell (and of its steps
    between nodes), dense: the entries of ``histogram_features``' sparse matrix.

    Each frame adds ``1 / (frames in its cell)`` (a step ``1 / (steps of its clip)``) to
    its entry, in frame order from 0.0; the sparse matrix sums the same equal addends, so
    the sums are the same doubles whatever order it adds them in. With ``root``, every
    entry is then replaced by its square root (NumPy's ``power(x, 0.5)``).

    Parameters
    ----------
    nodes : ndarray of shape (n_frames, n_routed) of intp
        Each frame's node in each routed layer.
    offsets : ndarray of shape (n_clips + 1,) of intp
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]`` (checked).
    blocks : ndarray of shape (n_blocks, 5) of intp
        Per block: kind (0 occupancy, 1 transitions), its column of ``nodes``, its
        pyramid parts (1 for transitions), the layer's nodes ``k`` and its first column.
    width : int
        Columns of the answer.
    root : bool

    Returns
    -------
    rows : ndarray of shape (n_clips, width)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._readout_passes import histogram_rows
    >>> nodes = np.array([[0], [1], [1]])  # one clip of three frames, a layer of two nodes
    >>> blocks = np.array([[0, 0, 1, 2, 0], [1, 0, 1, 2, 2]])  # occupancy, then transitions
    >>> (histogram_rows(nodes, np.array([0, 3]), blocks, 6, False) * 6).round(12).tolist()
    [[2.0, 4.0, 0.0, 3.0, 0.0, 0.0]]
    """
    cdef intp n = nodes.shape[0], n_clips = offsets.shape[0] - 1, n_blocks = blocks.shape[0]
    cdef intp b, i, t, cell, kind, column, parts, k, first, start, length, most = 1, a, z
    cdef double v
    _check_offsets(offsets, n)
    if blocks.shape[1] != 5:
        raise ValueError("blocks must have five columns: kind, column, parts, nodes, start.")
    for b in range(n_blocks):
        kind, column, parts, k, first = (blocks[b, 0], blocks[b, 1], blocks[b, 2], blocks[b, 3],
                                         blocks[b, 4])
        if kind not in (0, 1) or not 0 <= column < nodes.shape[1] or parts < 1 or k < 1 or (
                first < 0 or first + (parts * k if kind == 0 else k * k) > width):
            raise ValueError(f"block {b} does not fit {nodes.shape[1]} routed layers and "
                             f"{width} columns: {list(blocks[b])}.")
        for t in range(n):
            if not 0 <= nodes[t, column] < k:
                raise ValueError(f"frame {t}'s node {nodes[t, column]} is outside 0 .. {k - 1}.")
        most = max(most, parts)
    rows_array = np.zeros((max(n_clips, 0), width))
    size_array = np.empty(most, dtype=np.intp)
    cdef double[:, ::1] rows = rows_array
    cdef intp[::1] size = size_array
    with nogil:
        for b in range(n_blocks):
            kind, column, parts, k, first = (blocks[b, 0], blocks[b, 1], blocks[b, 2],
                                             blocks[b, 3], blocks[b, 4])
            for i in range(n_clips):
                start, length = offsets[i], offsets[i + 1] - offsets[i]
                if kind == 0:
                    _cell_sizes(&size[0], parts, length)
                    for t in range(length):
                        cell = t * parts // length
                        rows[i, first + cell * k + nodes[start + t, column]] += 1.0 / size[cell]
                elif length > 1:
                    v = 1.0 / (length - 1)
                    for t in range(start, start + length - 1):
                        a, z = nodes[t, column], nodes[t + 1, column]
                        if a != z:
                            rows[i, first + a * k + z] += v
        if root:
            for i in range(n_clips):
                for t in range(width):
                    rows[i, t] = sqrt(rows[i, t])
    return rows_array


def extremes_within(const double[:, ::1] frames, const double[:, ::1] centers,
                    const double[:, ::1] scales, double limit):
    """Whether every channel's ``max(|high - center|, |low - center|) / scale <= limit`` for
    every row of ``centers`` and ``scales``, ``high`` and ``low`` the channel's extremes over
    all frames: the magnitude checks' first test, from one pass over the frames.

    False also when a value is NaN or infinite (the caller then looks at each clip).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._readout_passes import extremes_within
    >>> frames = np.array([[0.0, 1.0], [2.0, -3.0]])
    >>> extremes_within(frames, np.zeros((1, 2)), np.ones((1, 2)), 3.0)
    True
    >>> extremes_within(frames, np.array([[0.0, 1.0]]), np.ones((1, 2)), 3.0)  # |-3 - 1| = 4
    False
    """
    cdef intp n = frames.shape[0], d = frames.shape[1], m = centers.shape[0], t, c, j
    cdef double x, r
    if centers.shape[1] != d or scales.shape[0] != m or scales.shape[1] != d:
        raise ValueError(f"centers and scales must have shape ({m}, {d}).")
    if n == 0:
        return True
    high_array, low_array, probe_array = np.empty(d), np.empty(d), np.zeros(d)
    cdef double[::1] high = high_array, low = low_array, probe = probe_array
    with nogil:
        for c in range(d):
            high[c] = frames[0, c]
            low[c] = frames[0, c]
        # branch-free (the loop over channels vectorises); x - x is NaN for NaN and infinity
        for t in range(n):
            for c in range(d):
                x = frames[t, c]
                high[c] = x if x > high[c] else high[c]
                low[c] = x if x < low[c] else low[c]
                probe[c] += x - x
    for c in range(d):
        if probe[c] != 0.0:
            return False
    for j in range(m):
        for c in range(d):
            # as _reach computes it: max(|high - c|, |low - c|) / s
            r = max(abs(high[c] - centers[j, c]), abs(low[c] - centers[j, c])) / scales[j, c]
            if not (r <= limit):
                return False
    return True
