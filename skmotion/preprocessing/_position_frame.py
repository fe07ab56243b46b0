"""Point trajectories in the body frame, in 2-D or 3-D: chunked over frames and scale-safe.

The computation of :class:`VirtualMarkerTransform` on point positions. Two
things make it robust where a direct formula is not:

- **scale**: the points are first multiplied by a power of two that brings the
  largest coordinate into ``[0.5, 1)``. That is exact in floating point, so the
  result is bit-for-bit the unscaled one, but no square or product can
  overflow or underflow (clips of 1e-150 or 1e160 metres work); a body that is
  lost in rounding (its size below ~1e-10 of its largest coordinate) is a clear
  error instead of a division by zero;
- **memory**: the output array is allocated once and filled in chunks of
  frames, so the temporaries stay a few MB whatever the clip length.
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
    """A power of two that brings the largest finite |coordinate| into [0.5, 1)."""
    peak = float(np.max(np.abs(points))) if points.size else 0.0
    if not np.isfinite(peak) or peak == 0.0:
        return 1.0
    return float(np.ldexp(1.0, -np.frexp(peak)[1]))


def _up_frame(points, up):
    """The points turned so that axis ``up`` (``"-y"`` allowed) points up, handedness kept."""
    axis = "xyz".index(up[-1])
    if not up.startswith("-"):
        return points, axis
    flipped = points.copy()
    flipped[..., axis] *= -1
    if points.shape[-1] == 3:  # a half turn about another axis keeps a right-handed frame
        flipped[..., (axis + 2) % 3] *= -1
    return flipped, axis


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
    scale = _power_of_two_scale(points)
    size = 1.0
    if size_chain is not None:
        chain = list(size_chain)
        size = chain_size(points[:, chain] * scale, range(len(chain)))
        if not size > _TINY:
            what = "0" if size == 0 else f"{size / scale:.3g}"
            raise ValueError(
                f"the body size along the size chain is {what} while coordinates reach "
                f"{0.5 / scale:.3g}: the body is lost in floating-point rounding (or the size "
                "joints coincide); centre the clip or check the size joints"
            )
    per_point = dim * (2 if velocities else 1)
    n_out = n_points if outputs is None else len(outputs)
    outputs = None if outputs is None else np.asarray(outputs, dtype=np.intp)
    out = np.empty((n_frames, n_out, per_point))
    sign = 1.0
    if dim == 2:
        lateral = _lateral(points[..., 0], lefts, rights)
        sign = -1.0 if np.median(lateral) < 0 else 1.0
    flip = -1.0 if up.startswith("-") else 1.0
    if isinstance(floor, str):
        heights = points[..., axis]
        level = (np.min(heights) if flip > 0 else -np.max(heights)) * scale
    else:
        level = float(floor) * scale * flip
    for start in range(0, n_frames, chunk):
        stop = min(start + chunk, n_frames)
        lo, hi = max(start - 1, 0), min(stop + 1, n_frames)
        block = _up_frame(points[lo:hi] * scale, up)[0]
        args = (block, outputs, start - lo, stop - lo, root, lefts, rights, level, size, start)
        if dim == 3:
            _fill_3d(out[start:stop], *args, frame_rate, velocities, axis)
        else:
            _fill_2d(out[start:stop], *args, frame_rate, velocities, sign)
    if size_chain is None:
        out /= scale
    return out.reshape(n_frames, n_out * per_point)


def _velocity(block, a, b, frame_rate):
    # Central differences on the chunk plus one frame either side equal the
    # whole-clip np.gradient; one-sided only at the clip's own ends.
    if len(block) < 2:
        return np.zeros_like(block[a:b])
    return np.gradient(block, axis=0)[a:b] * frame_rate


def _fill_3d(
    out, block, outputs, a, b, root, lefts, rights, level, size, start, frame_rate, velocities, up
):
    p = block[a:b]
    h1, h2 = (up + 1) % 3, (up + 2) % 3
    lateral = _lateral(p, lefts, rights)
    l1, l2 = lateral[:, h1], lateral[:, h2]
    norm = np.hypot(l1, l2)
    flat = np.flatnonzero(~(norm > _TINY * max(size, _TINY)))
    if flat.size:
        raise ValueError(
            f"the left and right facing markers are vertically aligned at frame {start + flat[0]}: "
            "no facing direction on the floor"
        )
    # (h1, h2, up) is right-handed, so forward = left x up = (l2, -l1) in (h1, h2).
    c1 = (l1 / (norm * size))[:, None]
    c2 = (l2 / (norm * size))[:, None]
    origin = p[:, list(root)].mean(axis=1)
    q = p if outputs is None else p[:, outputs]
    d1 = q[..., h1] - origin[:, None, h1]
    d2 = q[..., h2] - origin[:, None, h2]
    out[..., 0] = c2 * d1 - c1 * d2
    out[..., 1] = c1 * d1 + c2 * d2
    out[..., 2] = (q[..., up] - level) / size
    if velocities:
        v = _velocity(block if outputs is None else block[:, outputs], a, b, frame_rate)
        out[..., 3] = c2 * v[..., h1] - c1 * v[..., h2]
        out[..., 4] = c1 * v[..., h1] + c2 * v[..., h2]
        out[..., 5] = v[..., up] / size


def _fill_2d(
    out, block, outputs, a, b, root, lefts, rights, level, size, start, frame_rate, velocities, sign
):
    p = block[a:b]
    origin = p[:, list(root), 0].mean(axis=1)
    q = p if outputs is None else p[:, outputs]
    out[..., 0] = (q[..., 0] - origin[:, None]) * (sign / size)
    out[..., 1] = (q[..., 1] - level) / size
    if velocities:
        v = _velocity(block if outputs is None else block[:, outputs], a, b, frame_rate)
        out[..., 2] = v[..., 0] * (sign / size)
        out[..., 3] = v[..., 1] / size
