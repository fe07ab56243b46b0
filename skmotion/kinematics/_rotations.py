"""The one rotation helper: Euler angles to matrices and back.

Conventions: angles in radians; an Euler order such as ``"ZXY"`` is *intrinsic*
(BVH semantics): the local rotation is ``Rz(z) @ Rx(x) @ Ry(y)``, applied to
column vectors. This equals the extrinsic order read backwards (``"yxz"``).
"""

import numpy as np

__all__ = ["check_rotation_order", "euler_to_matrix", "matrix_to_euler", "yaw_matrix"]

AXES = "XYZ"


def check_rotation_order(order, *, where="rotation order"):
    """Return ``order`` upper-cased if it is a permutation of ``"XYZ"``.

    Parameters
    ----------
    order : str
        Three distinct axes, e.g. ``"ZXY"``.
    where : str, default="rotation order"
        What is being checked, for the error message.

    Returns
    -------
    order : str
        The upper-case order.

    Examples
    --------
    >>> from skmotion.kinematics import check_rotation_order
    >>> check_rotation_order("zxy")
    'ZXY'
    """
    if not isinstance(order, str) or sorted(order.upper()) != list(AXES):
        raise ValueError(f"{where} must be a permutation of 'XYZ' (e.g. 'ZXY'), got {order!r}.")
    return order.upper()


def _elementary(axis, angles):
    """Rotations by ``angles`` about one coordinate axis, shape (..., 3, 3)."""
    c, s = np.cos(angles), np.sin(angles)
    out = np.zeros(angles.shape + (3, 3))
    i = AXES.index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    out[..., i, i] = 1.0
    out[..., j, j] = c
    out[..., k, k] = c
    out[..., j, k] = -s
    out[..., k, j] = s
    return out


def euler_to_matrix(angles, order):
    """Rotation matrices from intrinsic Euler angles.

    The result equals ``scipy.spatial.transform.Rotation.from_euler(order,
    angles).as_matrix()`` (upper-case order: intrinsic), which the tests check
    for every order; it is built from elementary rotations with NumPy because
    ``from_euler`` costs about 3 microseconds per rotation in SciPy 1.17, which
    would dominate forward kinematics.

    Parameters
    ----------
    angles : array-like of shape (..., 3)
        Angles in radians, in the sequence of ``order`` (``angles[..., 0]`` is
        the rotation about ``order[0]``).
    order : str
        Intrinsic order, a permutation of ``"XYZ"``.

    Returns
    -------
    matrices : ndarray of shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import euler_to_matrix
    >>> euler_to_matrix([np.pi / 2, 0, 0], "ZXY").round(6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    order = check_rotation_order(order)
    angles = np.asarray(angles, dtype=float)
    if angles.shape[-1:] != (3,):
        raise ValueError(f"angles must have shape (..., 3); got {angles.shape}.")
    first, second, third = (_elementary(axis, angles[..., k]) for k, axis in enumerate(order))
    return first @ second @ third


def matrix_to_euler(matrices, order):
    """Intrinsic Euler angles (radians) of rotation matrices.

    Parameters
    ----------
    matrices : array-like of shape (..., 3, 3)
        Rotation matrices.
    order : str
        Intrinsic order, a permutation of ``"XYZ"``.

    Returns
    -------
    angles : ndarray of shape (..., 3)
        In the sequence of ``order``; the middle angle lies in [-pi/2, pi/2].

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import euler_to_matrix, matrix_to_euler
    >>> R = euler_to_matrix([0.1, -0.2, 0.3], "ZXY")
    >>> matrix_to_euler(R, "ZXY").round(6)
    array([ 0.1, -0.2,  0.3])
    """
    order = check_rotation_order(order)
    matrices = np.asarray(matrices, dtype=float)
    flat = matrices.reshape(-1, 3, 3)
    from scipy.spatial.transform import Rotation  # on use: scipy.spatial takes ~0.5 s to import

    angles = Rotation.from_matrix(flat).as_euler(order)
    return angles.reshape(matrices.shape[:-2] + (3,))


def yaw_matrix(yaw, up_axis="y"):
    """Rotations by ``yaw`` radians about the vertical axis.

    Parameters
    ----------
    yaw : array-like of shape (...)
        Angles in radians, counter-clockwise seen from above.
    up_axis : {"x", "y", "z"}, default="y"
        The vertical axis.

    Returns
    -------
    matrices : ndarray of shape (..., 3, 3)

    Examples
    --------
    >>> from skmotion.kinematics import yaw_matrix
    >>> yaw_matrix(0.0).round(6) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    axis = "xyz".index(up_axis.lower())
    yaw = np.asarray(yaw, dtype=float)
    rotvec = np.zeros(yaw.shape + (3,))
    rotvec[..., axis] = yaw
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(yaw.shape + (3, 3))
