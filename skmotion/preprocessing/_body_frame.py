"""Marker trajectories in the floor-level, facing-aligned body frame (Yamane et al. 2011, III-A)."""

import numpy as np

from skmotion.kinematics import body_size  # re-exported: preprocessing.body_size stays

__all__ = ["body_frame_features", "body_size"]


def body_frame_features(
    positions, *, frame_rate, root, left, right, up_axis="y", floor="lowest", size=1.0
):
    """Positions and velocities of markers in the body frame, ``(n_frames, 6 * n_markers)``.

    For each frame the reference frame has its origin on the floor below the
    root marker, its ``z`` axis up and its ``x`` axis the subject's facing
    direction on the floor: with ``l`` the unit horizontal part of
    ``left - right`` and ``u`` the up axis, forward is ``l x u``, and the frame
    ``(forward, left, up)`` is right-handed. This removes horizontal travel and
    turning from the positions. Velocities are the time derivatives of the
    world positions (central differences, one-sided at the ends) turned into
    the same frame. Positions and velocities are divided by ``size``.

    Parameters
    ----------
    positions : ndarray of shape (n_frames, n_markers, 3)
        World positions, ``n_frames >= 2``.
    frame_rate : float
        Frames per second; velocities are per second.
    root, left, right : int
        Marker indices of the root (the origin is below it) and of a left and
        a right marker that give the facing (the hips, say).
    up_axis : {"x", "y", "z"}, default="y"
        The world's vertical axis.
    floor : "lowest" or float, default="lowest"
        Height of the floor along the up axis: a number, or the lowest marker
        height over the clip.
    size : float, default=1.0
        Lengths are divided by it (see :func:`body_size`).

    Returns
    -------
    features : ndarray of shape (n_frames, 6 * n_markers)
        Per marker ``(px, py, pz, vx, vy, vz)`` with ``x`` forward, ``y`` to
        the subject's left and ``z`` up.

    Raises
    ------
    ValueError
        When the left and right markers are vertically aligned in a frame, so
        that no facing direction exists; the message names the frame.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import body_frame_features
    >>> # Three markers (root, left, right) walking along world +x, facing +x, y up.
    >>> t = np.arange(3)[:, None, None] / 10.0
    >>> start = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, -0.1], [0.0, 1.0, 0.1]])
    >>> moving = start + t * np.array([1.5, 0.0, 0.0])
    >>> out = body_frame_features(moving, frame_rate=10, root=0, left=1, right=2, floor=0.0)
    >>> out[1, :6].round(6) + 0.0  # the root: 1 m above the floor, moving forward at 1.5 m/s
    array([0. , 0. , 1. , 1.5, 0. , 0. ])
    """
    n_frames, n_markers, _ = positions.shape
    up = "xyz".index(up_axis)
    e_up = np.zeros(3)
    e_up[up] = 1.0
    lateral = positions[:, left] - positions[:, right]
    lateral[:, up] = 0.0
    norm = np.linalg.norm(lateral, axis=1)
    flat = np.flatnonzero(~(norm > 1e-12 * max(1.0, float(np.abs(positions).max()))))
    if flat.size:
        raise ValueError(
            f"the left and right facing markers are vertically aligned at frame {flat[0]}: "
            "no facing direction on the floor"
        )
    e_left = lateral / norm[:, None]
    e_forward = np.cross(e_left, e_up)
    # Rows are the body axes in world coordinates: body = R @ world.
    rotation = np.stack([e_forward, e_left, np.broadcast_to(e_up, e_left.shape)], axis=1)
    origin = positions[:, root].copy()
    origin[:, up] = positions[..., up].min() if isinstance(floor, str) else floor
    velocity = np.gradient(positions, axis=0) * frame_rate
    local_p = np.einsum("fij,fmj->fmi", rotation, positions - origin[:, None, :])
    local_v = np.einsum("fij,fmj->fmi", rotation, velocity)
    out = np.concatenate([local_p, local_v], axis=2) / size
    return out.reshape(n_frames, 6 * n_markers)
