"""Point trajectories in the body frame, in 2-D or 3-D: one pass over the frames, scale-safe.

The computation of :class:`VirtualMarkerTransform` on point positions. Per
frame the body frame is one matrix ``M`` (rotation about the vertical, the
up-axis flip and the division by the body size folded together) and a shift
``t``, so the features are ``p @ M.T - t``. Three things make it robust and
fast where a direct formula is not:

- **scale**: no square of a coordinate is ever formed: the body size is
  computed on the chain points multiplied by a power of two (exact) that brings
  them into ``[0.5, 1)``, the facing uses ``hypot``, and ``M`` holds unit
  vectors divided by the size, so clips of 1e-150 or 1e160 metres give the
  same features; a body lost in rounding (its size below ~1e-10 of its
  coordinates) is a clear error instead of a division by zero;
- **speed**: the per-frame work (facing vector, ``M``, ``t``, the products,
  the velocities) is one compiled loop (``_position_frame_loops.pyx``) that
  reads each frame once and writes its output once: over 2 * 10^6 frames per
  second on one core, where numpy's gathers, batched ``matmul`` and shift were
  memory passes of their own (3.5 to 5.5 times slower; docs/positions.md);
- **memory**: the output array is allocated once and written in place; the
  only temporary is the chain's step lengths (one value per frame and step).
"""

import numpy as np

from skmotion.preprocessing import _position_frame_loops as _loops

__all__ = ["position_frame_features"]

#: Frames per call of the compiled loops (and per forward-kinematics block of
#: VirtualMarkerTransform): large enough for the per-call overhead to vanish, small
#: enough that FK's temporaries stay in cache-sized blocks.
CHUNK = 4096
# A body smaller than this fraction of its largest coordinate is lost in rounding.
_TINY = 1e-10


def _power_of_two_scale(peak):
    """1, or a power of two that brings ``peak`` (the largest |coordinate|) into [0.5, 1)
    when squares of the coordinates could overflow or lose precision (beyond 1e100 or below
    1e-100)."""
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
        The body-size chain (:func:`skmotion.kinematics.body_size`); None keeps the input unit.
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
        pairs are vertically aligned in a frame; the message says which. When
        velocities are asked for without ``frame_rate``.
    IndexError
        When a point index is out of range.
    """
    n_frames, n_points, dim = points.shape
    if dim not in (2, 3):
        raise ValueError(f"points need 2 or 3 coordinates each; got {dim}")
    if dim == 2 and up not in ("y", "-y"):
        raise ValueError(f"2-D points need up='y' or up='-y' (image rows); got {up!r}")
    if velocities and frame_rate is None:
        raise ValueError("velocities need frame_rate= (frames per second)")
    if points.dtype not in (np.float32, np.float64):
        points = points.astype(np.float64)
    points = np.ascontiguousarray(points)
    axis = "xyz".index(up[-1])
    flip = _flip(dim, up)
    if size_chain is not None and len(size_chain) < 2:
        raise ValueError(f"the size chain needs two points or more, got {list(size_chain)}")
    # One pass for the size chain and the floor (the lowest point over the clip).
    size, low, high = _size_and_heights(points, () if size_chain is None else size_chain, axis)
    size = 1.0 if size_chain is None else size
    if isinstance(floor, str):
        level = low if flip[axis] > 0 else -high
    else:
        level = float(floor) * flip[axis]
    outputs = np.arange(n_points) if outputs is None else outputs
    root, lefts, rights, outputs = _point_indices(
        n_points, root=root, lefts=lefts, rights=rights, outputs=outputs
    )
    out = np.empty((n_frames, len(outputs), dim * (2 if velocities else 1)))
    rate = 0.0 if frame_rate is None else float(frame_rate)
    if dim == 2:
        # One mirror sign per clip: the subject's left positive (median over frames).
        sign = -1.0 if np.median(_lateral(points[..., 0], lefts, rights)) < 0 else 1.0
        for start in range(0, n_frames, chunk):
            stop = min(start + chunk, n_frames)
            args = (root, outputs, sign / size, flip[1] / size, level / size, velocities, rate)
            _loops.frames_2d(points, out, start, stop, *args)
        return out.reshape(n_frames, out.shape[1] * out.shape[2])
    for start in range(0, n_frames, chunk):
        stop = min(start + chunk, n_frames)
        args = (root, lefts, rights, outputs, axis, flip, level, size, _TINY, velocities, rate)
        flat = _loops.frames_3d(points, out, start, stop, *args)
        if flat >= 0:
            raise ValueError(
                f"the left and right facing markers are vertically aligned at frame {flat}: "
                "no facing direction on the floor"
            )
    return out.reshape(n_frames, out.shape[1] * out.shape[2])


def _point_indices(n_points, allow_empty=False, **groups):
    """Each group of point indices as an intp array, checked: the compiled loops do not."""
    arrays = {what: np.asarray(group, dtype=np.intp).reshape(-1) for what, group in groups.items()}
    for what, array in arrays.items():
        values = array.tolist()  # min/max of a short list: far cheaper than numpy's
        if not values and not allow_empty and what != "outputs":
            raise ValueError(f"{what} names no point")
        if values and not (0 <= min(values) and max(values) < n_points):
            raise IndexError(f"{what} {values} out of range for {n_points} points")
    if "lefts" in arrays and len(arrays["lefts"]) != len(arrays["rights"]):
        raise ValueError(f"lefts {groups['lefts']} and rights {groups['rights']} differ in length")
    return list(arrays.values())


def _flip(dim, up):
    """Signs that turn the input so that ``up`` points up (a half turn keeps handedness)."""
    flip = np.ones(dim)
    if up.startswith("-"):
        axis = "xyz".index(up[-1])
        flip[axis] = -1.0
        if dim == 3:
            flip[(axis + 2) % 3] = -1.0
    return flip


def _row_medians(values):
    """``np.median(values, axis=1)`` (the same values), reordering ``values`` in place:
    numpy's median costs more than the whole frame loop of a 100-frame clip."""
    half = values.shape[1] // 2
    if values.shape[1] % 2:
        values.partition(half, axis=1)
        return values[:, half]
    values.partition((half - 1, half), axis=1)
    return (values[:, half - 1] + values[:, half]) / 2.0


def _size_and_heights(points, chain, axis):
    """Body size along a chain (nan for an empty chain), computed on power-of-two scaled
    points (no overflow); and the lowest and highest coordinate ``axis`` over the clip."""
    (chain,) = _point_indices(points.shape[1], size_chain=chain, allow_empty=True)
    steps = np.empty((max(len(chain) - 1, 0), len(points)))
    peak, low, high = _loops.chain_steps(points, chain, 1.0, steps, axis)
    if not len(chain):
        return np.nan, low, high
    scale = _power_of_two_scale(peak)
    if scale != 1.0:
        _loops.chain_steps(points, chain, scale, steps, axis)
    size = float(_row_medians(steps).sum()) if len(points) else np.nan
    if not size > _TINY * peak * scale:
        what = "0" if size == 0 else f"{size / scale:.3g}"
        raise ValueError(
            f"the body size along the size chain is {what} while coordinates reach "
            f"{peak:.3g}: the body is lost in floating-point rounding "
            "(or the size joints coincide); centre the clip or check the size joints"
        )
    return size / scale, low, high
