"""Point trajectories in the body frame, in 2-D or 3-D: chunked over frames and scale-safe.

The computation of :class:`VirtualMarkerTransform` on point positions. Per
frame the body frame is one matrix ``M`` (rotation about the vertical, the
up-axis flip and the division by the body size folded together) and a shift
``t``, so the features are ``p @ M.T - t``: one batched ``matmul`` per chunk.
Three things make it robust and fast where a direct formula is not:

- **scale**: no square of a coordinate is ever formed: the body size is
  computed on the chain points multiplied by a power of two (exact) that brings
  them into ``[0.5, 1)``, the facing uses ``hypot``, and ``M`` holds unit
  vectors divided by the size, so clips of 1e-150 or 1e160 metres give the
  same features; a body lost in rounding (its size below ~1e-10 of its
  coordinates) is a clear error instead of a division by zero;
- **memory**: the output array is allocated once and filled in chunks of
  frames, so the temporaries stay a few MB whatever the clip length;
- **speed**: without velocities ``matmul`` writes straight into the output.
"""

import numpy as np

__all__ = ["chain_size", "position_frame_features"]

#: Frames per chunk: large enough for numpy's per-call overhead to vanish, small
#: enough that the temporaries stay in cache-sized blocks.
CHUNK = 4096
# A body smaller than this fraction of its largest coordinate is lost in rounding.
_TINY = 1e-10


def chain_size(points, chain):
    """Summed median distance between consecutive points of a chain (any dimension).

    Parameters
    ----------
    points : ndarray of shape (n_frames, n_points, dim)
    chain : sequence of int

    Returns
    -------
    size : float

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing._position_frame import chain_size
    >>> chain_size(np.array([[[0.0, 0.0], [3.0, 4.0], [3.0, 5.0]]]), [0, 1, 2])
    6.0
    """
    chain = np.asarray(chain, dtype=np.intp)
    steps = np.sqrt(((points[:, chain[1:]] - points[:, chain[:-1]]) ** 2).sum(axis=-1))
    return float(np.median(steps, axis=0).sum())


def _power_of_two_scale(points):
    """1, or a power of two that brings the largest |coordinate| into [0.5, 1) when squares
    of the coordinates could overflow or lose precision (beyond 1e100 or below 1e-100)."""
    peak = max(float(np.max(points)), -float(np.min(points))) if points.size else 0.0
    if not np.isfinite(peak) or peak == 0.0 or 1e-100 < peak < 1e100:
        return 1.0
    return float(np.ldexp(1.0, -np.frexp(peak)[1]))


def _lateral(p, lefts, rights):
    """Sum of the left-minus-right vectors of the facing pairs, per frame."""
    return sum(p[:, left] - p[:, right] for left, right in zip(lefts, rights))


def position_frame_features(
    points,
    *,
    root,
    lefts,
    rights,
    size_chain=None,
    up="y",
    floor="lowest",
    frame_rate=None,
    velocities=True,
    outputs=None,
    chunk=CHUNK,
):
    """Body-frame positions (and velocities) of points, divided by the body size.

    3-D: the frame has its origin on the floor below the root, ``z`` up and
    ``x`` the facing direction on the floor (``l x up``, with ``l`` the
    horizontal part of the summed left-minus-right vectors), ``y`` to the
    subject's left. 2-D (image plane): ``z`` is up (the image's up when
    ``up="-y"``) and ``y`` is the horizontal axis signed so that the
    subject's left is positive over the clip (the sign of the median left-
    minus-right offset; a subject turned by 180 degrees about the vertical
    mirrors the image, and this sign undoes it); the origin is on the clip's
    floor below the root. Depth (``x``) does not exist in 2-D.

    Parameters
    ----------
    points : ndarray of shape (n_frames, n_points, dim)
        Positions, ``dim`` 2 or 3, finite.
    root : sequence of int
        Points whose mean is the root.
    lefts, rights : sequence of int
        Facing pairs: point ``lefts[k]`` is on the subject's left, ``rights[k]``
        on the right.
    size_chain : sequence of int, default=None
        The body-size chain (:func:`chain_size`); None keeps the input unit.
    up : {"x", "y", "z", "-x", "-y", "-z"}, default="y"
        The vertical axis of the input (in 2-D, ``"y"`` or ``"-y"``).
    floor : "lowest" or float, default="lowest"
        Floor height along ``up``: the lowest point over the clip, or a number.
    frame_rate : float, default=None
        Frames per second; needed for velocities.
    velocities : bool, default=True
        Append velocities (central differences, per second).
    outputs : sequence of int, default=None
        The points to output (all by default); the roles may use any point.
    chunk : int, default=4096
        Frames processed at a time.

    Returns
    -------
    features : ndarray of shape (n_frames, k * n_outputs)
        Per point ``(px, py, pz[, vx, vy, vz])`` in 3-D, ``(py, pz[, vy, vz])``
        in 2-D.

    Raises
    ------
    ValueError
        When the body size is 0 or lost in rounding, or (3-D) when the facing
        pairs are vertically aligned in a frame; the message says which.
    """
    n_frames, n_points, dim = points.shape
    if dim == 2 and up not in ("y", "-y"):
        raise ValueError(f"2-D points need up='y' or up='-y' (image rows); got {up!r}")
    axis = "xyz".index(up[-1])
    flip = _flip(dim, up)
    size = 1.0 if size_chain is None else _safe_size(points[:, list(size_chain)])
    if isinstance(floor, str):
        heights = points[..., axis]
        level = float(np.min(heights) if flip[axis] > 0 else -np.max(heights))
    else:
        level = float(floor) * flip[axis]
    per_point = dim * (2 if velocities else 1)
    n_out = n_points if outputs is None else len(outputs)
    outputs = None if outputs is None else np.asarray(outputs, dtype=np.intp)
    out = np.empty((n_frames, n_out, per_point))
    if dim == 2:
        # One mirror sign per clip: the subject's left positive (median over frames).
        sign = -1.0 if np.median(_lateral(points[..., 0], lefts, rights)) < 0 else 1.0
    for start in range(0, n_frames, chunk):
        stop = min(start + chunk, n_frames)
        p = points[start:stop]
        if dim == 3:
            matrix_t, shift = _frames_3d(p, root, lefts, rights, level, size, flip, axis, start)
        else:
            matrix_t = np.diag([sign, flip[1]]) / size
            origin = p[:, list(root), 0].mean(axis=1)
            shift = np.stack([origin * (sign / size), np.full(len(p), level / size)], axis=1)
        q = p if outputs is None else p[:, outputs]
        positions = out[start:stop, :, :dim]
        if velocities:  # matmul writes fast only into contiguous arrays
            positions = np.empty((stop - start, n_out, dim))
        np.matmul(q, matrix_t, out=positions)
        positions -= shift[:, None, :]
        if velocities:
            out[start:stop, :, :dim] = positions
            lo, hi = max(start - 1, 0), min(stop + 1, n_frames)
            block = points[lo:hi] if outputs is None else points[lo:hi, outputs]
            v = _velocity(block, start - lo, stop - lo, frame_rate)
            out[start:stop, :, dim:] = np.matmul(v, matrix_t)
    return out.reshape(n_frames, n_out * per_point)


def _flip(dim, up):
    """Signs that turn the input so that ``up`` points up (a half turn keeps handedness)."""
    flip = np.ones(dim)
    if up.startswith("-"):
        axis = "xyz".index(up[-1])
        flip[axis] = -1.0
        if dim == 3:
            flip[(axis + 2) % 3] = -1.0
    return flip


def _safe_size(chain_points):
    """Body size along a chain, computed on power-of-two scaled points (no overflow)."""
    scale = _power_of_two_scale(chain_points)
    scaled = chain_points if scale == 1.0 else chain_points * scale
    size = chain_size(scaled, range(chain_points.shape[1]))
    if not size > _TINY * np.abs(scaled).max(initial=0.0):
        what = "0" if size == 0 else f"{size / scale:.3g}"
        raise ValueError(
            f"the body size along the size chain is {what} while coordinates reach "
            f"{np.abs(chain_points).max():.3g}: the body is lost in floating-point rounding "
            "(or the size joints coincide); centre the clip or check the size joints"
        )
    return size / scale


def _velocity(block, a, b, frame_rate):
    # Central differences on the chunk plus one frame either side equal the
    # whole-clip np.gradient; one-sided only at the clip's own ends.
    if len(block) < 2:
        return np.zeros_like(block[a:b])
    return np.gradient(block, axis=0)[a:b] * frame_rate


def _frames_3d(p, root, lefts, rights, level, size, flip, up, start):
    """Per frame, ``M.T`` and the shift ``t`` with body-frame points ``p @ M.T - t``."""
    h1, h2 = (up + 1) % 3, (up + 2) % 3
    lateral = _lateral(p, lefts, rights) * flip
    l1, l2 = lateral[:, h1], lateral[:, h2]
    norm = np.hypot(l1, l2)
    flat = np.flatnonzero(~(norm > _TINY * np.abs(lateral).max(axis=1, initial=0.0)))
    if flat.size:
        raise ValueError(
            f"the left and right facing markers are vertically aligned at frame {start + flat[0]}: "
            "no facing direction on the floor"
        )
    c1, c2 = l1 / norm / size, l2 / norm / size
    # Columns of M.T (rows of M): forward, left, up in the flipped input axes; (h1, h2, up)
    # is right-handed, so forward = left x up = (l2, -l1) in (h1, h2). Built transposed and
    # contiguous because matmul is several times faster so.
    matrix_t = np.zeros((len(p), 3, 3))
    matrix_t[:, h1, 0], matrix_t[:, h2, 0] = c2, -c1
    matrix_t[:, h1, 1], matrix_t[:, h2, 1] = c1, c2
    matrix_t[:, up, 2] = 1.0 / size
    matrix_t *= flip[:, None]  # undo the up-axis flip on the input side
    origin = p[:, list(root)].mean(axis=1)
    shift = np.einsum("fj,fji->fi", origin, matrix_t)
    shift[:, 2] = level / size
    return matrix_t, shift
