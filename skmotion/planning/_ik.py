"""Damped least-squares inverse kinematics of marker sets, batched over poses.

The Jacobian of the markers with respect to the channels comes from finite
differences of the batched forward kinematics (one call for every pose and
every perturbed channel at once), so any skeleton, rotation order or bone
axis works. Gauss-Newton steps are damped (Levenberg-Marquardt, the
singularity-robust inverse of the paper's reference [15]), so poses near a
singularity or with redundant channels stay stable.
"""

import numpy as np

from skmotion.kinematics import matrix_to_euler, yaw_matrix

__all__ = ["damped_ik", "facing_pose", "marker_jacobian", "plan_axes"]


def plan_axes(up_axis):
    """The matrix ``T`` with ``plan = world @ T``: world axes to the planner's.

    The planner's axes are x forward, y left, z up.

    The planner's frame is right-handed with ``z`` up. Its ``x`` and ``y``
    are the world axes following the up axis cyclically, so a Y-up skeleton
    facing ``+Z`` with its left at ``+X`` (BVH, the built-in humanoid) faces
    the planner's ``+x``. ``T`` is a permutation: ``world = plan @ T.T``.

    Parameters
    ----------
    up_axis : {"x", "y", "z"}

    Returns
    -------
    T : ndarray of shape (3, 3)

    Examples
    --------
    >>> from skmotion.planning import plan_axes
    >>> # world z -> plan x, world x -> plan y, world y -> plan z
    >>> plan_axes("y").astype(int).tolist()
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]]
    """
    u = "xyz".index(up_axis.lower())
    t = np.zeros((3, 3))
    t[(u + 1) % 3, 0] = t[(u + 2) % 3, 1] = t[u, 2] = 1.0
    return t


def damped_solve(jtj, jtv, damping):
    """``(J^T J + lambda^2 I)^-1 J^T v``, batched, with ``lambda^2 = damping^2 * mean diag(J^T J)``.

    Scaling the damping by the mean of the diagonal makes it unit-free: 1e-3
    changes a well-conditioned solution by about one part in a million.
    """
    k = jtj.shape[-1]
    scale = np.trace(jtj, axis1=-2, axis2=-1)[..., None, None] / k
    return np.linalg.solve(jtj + damping**2 * scale * np.eye(k), jtv[..., None])[..., 0]


def marker_jacobian(skeleton, markers, channels, columns, *, eps=1e-6):
    """Marker positions and their derivatives with respect to some channels, for many poses.

    Parameters
    ----------
    skeleton : Skeleton
    markers : MarkerSet
    channels : ndarray of shape (n_poses, n_channels)
    columns : array-like of int of shape (n_columns,)
        The channels to differentiate by.
    eps : float, default=1e-6
        The forward-difference step (radians, or length units).

    Returns
    -------
    positions : ndarray of shape (n_poses, n_markers, 3)
    jacobian : ndarray of shape (n_poses, n_markers, 3, n_columns)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import Skeleton
    >>> from skmotion.preprocessing import MarkerSet
    >>> from skmotion.planning import marker_jacobian
    >>> arm = Skeleton(["a", "b"], [-1, 0], [[0, 0, 0], [1, 0, 0]], [["Zrotation"], []])
    >>> _, jac = marker_jacobian(arm, MarkerSet([("tip", "b", (0, 0, 0))]), np.zeros((1, 1)), [0])
    >>> jac[0, 0, :, 0].round(5) + 0.0      # turning about z moves the tip along +y
    array([0., 1., 0.])
    """
    channels = np.asarray(channels, dtype=float)
    columns = np.asarray(columns, dtype=np.intp)
    n, k = len(channels), len(columns)
    batch = np.repeat(channels[:, None, :], k + 1, axis=1)
    batch[:, 1 + np.arange(k), columns] += eps
    pos = markers.positions(skeleton, batch.reshape(-1, channels.shape[1])).reshape(
        n, k + 1, len(markers), 3
    )
    jac = (pos[:, 1:] - pos[:, :1]) / eps
    return pos[:, 0], np.moveaxis(jac, 1, -1)


def damped_ik(skeleton, markers, targets, initial, *, damping=1e-2, n_iter=30, tol=1e-7):
    """Channels whose markers best fit target positions: damped Gauss-Newton, batched over poses.

    Each step solves ``(J^T J + lambda^2 I) dq = J^T e`` for all poses at
    once, with ``e`` the marker errors and ``lambda^2 = damping^2`` times the
    mean diagonal of ``J^T J`` (a unit-free damping).

    Parameters
    ----------
    skeleton : Skeleton
    markers : MarkerSet
    targets : ndarray of shape (n_poses, n_markers, 3)
        World positions, in the skeleton's length unit.
    initial : ndarray of shape (n_poses, n_channels)
        Starting channels (see :func:`facing_pose`).
    damping : float, default=1e-2
    n_iter : int, default=30
        Gauss-Newton steps (each one forward-kinematics call for all poses).
    tol : float, default=1e-7
        Stop when no channel moves more than this.

    Returns
    -------
    channels : ndarray of shape (n_poses, n_channels)
    rms : ndarray of shape (n_poses,)
        Root-mean-square marker distance left, in the skeleton's unit.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import Skeleton
    >>> from skmotion.preprocessing import MarkerSet
    >>> from skmotion.planning import damped_ik
    >>> arm = Skeleton(["a", "b", "c"], [-1, 0, 1], [[0, 0, 0], [1, 0, 0], [1, 0, 0]],
    ...                [["Zrotation"], ["Zrotation"], []])
    >>> tip = MarkerSet([("tip", "c", (0, 0, 0))])
    >>> q, rms = damped_ik(arm, tip, np.array([[[1.0, 1.0, 0.0]]]), np.array([[1.2, -1.2]]))
    >>> # up 90, then back 90
    >>> np.degrees(np.angle(np.exp(1j * q))).round(3) + 0.0, float(rms[0]) < 1e-6
    (array([[ 90., -90.]]), True)
    """
    q = np.array(initial, dtype=float)
    columns = np.arange(skeleton.n_channels)
    for _ in range(n_iter):
        pos, jac = marker_jacobian(skeleton, markers, q, columns)
        jac = jac.reshape(len(q), -1, len(columns))
        err = (targets - pos).reshape(len(q), -1)
        step = damped_solve(
            np.einsum("nji,njk->nik", jac, jac), np.einsum("nji,nj->ni", jac, err), damping
        )
        q += step
        if np.abs(step).max() < tol:
            break
    pos = markers.positions(skeleton, q)
    return q, np.sqrt(((targets - pos) ** 2).sum(axis=-1).mean(axis=-1))


def facing_pose(skeleton, markers, targets, *, root, left, right):
    """Starting channels for IK: the rest pose turned to the targets' facing, root marker on theirs.

    Parameters
    ----------
    skeleton : Skeleton
        Its root has three position channels.
    markers : MarkerSet
    targets : ndarray of shape (n_poses, n_markers, 3)
        World positions, in the skeleton's unit.
    root, left, right : int
        Marker indices of the root marker and of a left and a right marker.

    Returns
    -------
    channels : ndarray of shape (n_poses, n_channels)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.preprocessing import marker_preset
    >>> from skmotion.planning import facing_pose
    >>> sk = humanoid_skeleton(); ms = marker_preset(sk)
    >>> rest = ms.positions(sk, np.zeros((1, sk.n_channels)))
    >>> q = facing_pose(sk, ms, rest + 1.0, root=ms.names.index("pelvis"),
    ...                 left=ms.names.index("left_hip"), right=ms.names.index("right_hip"))
    >>> bool(np.allclose(ms.positions(sk, q), rest + 1.0))
    True
    """
    up = "xyz".index(skeleton.up_axis)
    n = len(targets)
    q = np.zeros((n, skeleton.n_channels))
    root_channels = list(skeleton.channels[0])
    positions = [c for c in ("Xposition", "Yposition", "Zposition") if c in root_channels]
    if len(positions) != 3:
        raise ValueError(
            f"IK needs a root joint with three position channels; {skeleton.joints[0]!r} has "
            f"{root_channels}."
        )
    rest = markers.positions(skeleton, q[:1])[0]

    def heading(points):
        lateral = points[..., left, :] - points[..., right, :]
        a, b = (up + 1) % 3, (up + 2) % 3
        # The angle of the left direction about the up axis, counter-clockwise from above.
        return np.arctan2(lateral[..., b], lateral[..., a])

    turn = yaw_matrix(heading(targets) - heading(rest), skeleton.up_axis)
    order = skeleton.rotation_orders[0]
    axes = np.eye(3) if skeleton.axes is None else np.asarray(skeleton.axes)[0]
    # The root's local rotation is C M C^T with M from its channels: solve for M.
    angles = matrix_to_euler(axes.T @ turn @ axes, order)
    for c, name in enumerate(root_channels):
        if name.endswith("rotation") and name[0] in order:
            q[:, c] = angles[:, order.index(name[0])]
    placed = markers.positions(skeleton, q)
    for axis, name in enumerate(("Xposition", "Yposition", "Zposition")):
        q[:, root_channels.index(name)] = targets[:, root, axis] - placed[:, root, axis]
    return q
