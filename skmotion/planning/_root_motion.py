"""Root motion on the floor from body-frame marker velocities (Yamane et al. 2011, section V-C).

The database stores every marker's position ``p`` and velocity ``v`` in the
moving body frame (origin on the floor below the root, ``x`` forward, ``y``
left, ``z`` up): the horizontal travel and turning were removed. They come
back through the Jacobian of the markers with respect to the root's motion.
If the body frame moves at planar velocity ``(u_x, u_y)`` and turns at
``w`` about the vertical, a marker carried along moves at::

    v = (u_x - w p_y,  u_y + w p_x,  0)  +  (the body's own motion)

Solving ``v = J u`` over all markers for ``u = (u_x, u_y, w)`` with the
singularity-robust (damped least squares) inverse
``u = (J^T J + lambda^2 I)^-1 J^T v`` is the **rigid-body fit** (only markers
known): the limbs' own motion is left in the residual. With a **skeleton**,
``J`` gains one column per joint channel (from forward kinematics at the
node's pose), so the limbs' motion is explained by the joints and the root's
part is what remains.
"""

import numpy as np

from skmotion.planning._ik import damped_solve, marker_jacobian, plan_axes

__all__ = ["planar_step", "rigid_root_velocity", "skeleton_root_velocity"]


def rigid_root_velocity(positions, velocities, *, damping=1e-3):
    """Planar velocity and turning rate of the body frame by a rigid-body fit of all markers.

    Parameters
    ----------
    positions, velocities : ndarray of shape (n_states, n_markers, 3)
        Marker positions and velocities in the body frame (``x`` forward,
        ``y`` left, ``z`` up), in any consistent units.
    damping : float, default=1e-3
        Relative damping of the least-squares inverse (see the module notes).

    Returns
    -------
    velocity : ndarray of shape (n_states, 3)
        ``(u_x, u_y, w)``: forward and leftward speed of the body frame's
        origin and its turning rate (radians per time unit, counter-clockwise
        seen from above).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.planning import rigid_root_velocity
    >>> p = np.array([[[0.0, 0.1, 1.0], [0.0, -0.1, 1.0], [0.2, 0.0, 1.5]]])
    >>> u, w = np.array([1.0, 0.5]), 0.3              # a rigid body turning while it moves
    >>> v = np.stack([u[0] - w * p[..., 1], u[1] + w * p[..., 0], 0 * p[..., 2]], axis=-1)
    >>> rigid_root_velocity(p, v, damping=0.0).round(6)
    array([[1. , 0.5, 0.3]])
    """
    px, py = positions[..., 0], positions[..., 1]
    vx, vy = velocities[..., 0], velocities[..., 1]
    m = np.full(px.shape[0], float(px.shape[1]))
    sx, sy, r2 = px.sum(axis=1), py.sum(axis=1), (px**2 + py**2).sum(axis=1)
    zero = np.zeros_like(m)
    # J^T J and J^T v of the rows [1, 0, -p_y] and [0, 1, p_x], summed over the markers.
    jtj = np.stack(
        [np.stack([m, zero, -sy], -1), np.stack([zero, m, sx], -1), np.stack([-sy, sx, r2], -1)], -2
    )
    jtv = np.stack([vx.sum(axis=1), vy.sum(axis=1), (px * vy - py * vx).sum(axis=1)], axis=-1)
    return damped_solve(jtj, jtv, damping)


def skeleton_root_velocity(skeleton, markers, channels, velocities, *, damping=1e-3):
    """Planar velocity and turning rate of the root from the full marker Jacobian of a skeleton.

    The unknowns are the root's twist (three translations, three rotations
    about the root marker, the yaw one being the turning rate) and the rates of
    every non-root channel; ``J`` is the root's rigid-body columns beside the
    finite-difference Jacobian of the markers with respect to the joint
    channels, at the pose ``channels`` (from :func:`damped_ik`).

    Parameters
    ----------
    skeleton : Skeleton
    markers : MarkerSet
    channels : ndarray of shape (n_states, n_channels)
        Poses whose markers lie at the body-frame positions (in the skeleton's
        unit and world axes, see :func:`plan_axes`).
    velocities : ndarray of shape (n_states, n_markers, 3)
        Marker velocities in the body frame (``x`` forward, ``y`` left, ``z`` up).
    damping : float, default=1e-3
        Relative damping of the least-squares inverse.

    Returns
    -------
    velocity : ndarray of shape (n_states, 3)
        ``(u_x, u_y, w)`` as :func:`rigid_root_velocity`, in the units of
        ``velocities``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.preprocessing import marker_preset
    >>> from skmotion.planning import skeleton_root_velocity
    >>> sk = humanoid_skeleton(); ms = marker_preset(sk)
    >>> v = np.zeros((1, len(ms), 3)); v[..., 0] = 1.2       # every marker moves forward
    >>> skeleton_root_velocity(sk, ms, np.zeros((1, sk.n_channels)), v).round(4) + 0.0
    array([[1.2, 0. , 0. ]])
    """
    # The root's channels come first; its motion is the twist columns below.
    joint_cols = np.arange(len(skeleton.channels[0]), skeleton.n_channels)
    positions, jac = marker_jacobian(skeleton, markers, channels, joint_cols)
    axes = plan_axes(skeleton.up_axis)
    p = positions @ axes  # (n, M, 3) in the body frame
    jac = np.einsum("ji,nmjk->nmik", axes, jac)
    root = p[:, markers.names.index("pelvis") if "pelvis" in markers.names else 0]
    rel = p - root[:, None, :]
    n, m = p.shape[:2]
    twist = np.zeros((n, m, 3, 6))
    twist[..., 0, 0] = twist[..., 1, 1] = twist[..., 2, 2] = 1.0
    for axis in range(3):
        e = np.zeros(3)
        e[axis] = 1.0
        twist[..., 3 + axis] = np.cross(e, rel)
    full = np.concatenate([twist, jac], axis=-1).reshape(n, 3 * m, -1)
    jtj = np.einsum("nji,njk->nik", full, full)
    jtv = np.einsum("nji,nj->ni", full, velocities.reshape(n, -1))
    u = damped_solve(jtj, jtv, damping)
    # The yaw column turns about the root marker, the body frame about the point
    # below it on the floor: the same planar motion, as the two share x and y.
    return u[:, [0, 1, 5]]


def planar_step(velocity, dt):
    """The body-frame displacement of one frame at a constant planar twist (exact).

    Parameters
    ----------
    velocity : ndarray of shape (n, 3)
        ``(u_x, u_y, w)`` in the body frame.
    dt : float
        The frame time.

    Returns
    -------
    step : ndarray of shape (n, 3)
        ``(dx, dy, dtheta)``: where the body frame is after ``dt``, in the
        body frame at its start, and the heading change.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.planning import planar_step
    >>> # a quarter circle of radius 2/pi
    >>> planar_step(np.array([[1.0, 0.0, np.pi / 2]]), 1.0).round(6)
    array([[0.63662 , 0.63662 , 1.570796]])
    """
    ux, uy, w = velocity[:, 0], velocity[:, 1], velocity[:, 2]
    theta = w * dt
    small = np.abs(theta) < 1e-9
    safe = np.where(small, 1.0, theta)
    # sin(t)/t and (1 - cos t)/t, with their limits at t = 0.
    a = np.where(small, 1.0, np.sin(safe) / safe)
    b = np.where(small, 0.0, (1.0 - np.cos(safe)) / safe)
    return np.column_stack([(ux * a - uy * b) * dt, (ux * b + uy * a) * dt, theta])
