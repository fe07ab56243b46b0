# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Forward kinematics, one compiled pass over frames and joints.

NumPy's stacked 3 x 3 products cost far more per matrix than their nine sums of three
products (each level of the tree and each Euler factor is a separate pass over whole
arrays), so a clip of a hundred frames took milliseconds. Here each frame walks the
joints in index order (a parent's index is below its children's), building each local
rotation from its Euler angles and composing it with the parent's world pose.
"""

from libc.math cimport cos, sin


cdef inline void _times_elementary(double[3][3] m, int axis, double angle) noexcept nogil:
    """m := m @ (the rotation by ``angle`` about coordinate ``axis``)."""
    cdef int j = (axis + 1) % 3, k = (axis + 2) % 3, r
    cdef double c = cos(angle), s = sin(angle), mj, mk
    for r in range(3):
        mj = m[r][j]
        mk = m[r][k]
        m[r][j] = mj * c + mk * s
        m[r][k] = mk * c - mj * s


def forward_pass(
    const double[:, ::1] channels,
    const Py_ssize_t[:, ::1] rotation_column,
    const Py_ssize_t[:, ::1] axis_of_slot,
    const Py_ssize_t[:, ::1] position_column,
    const double[:, ::1] offsets,
    const double[:, :, ::1] axes,
    bint use_axes,
    const Py_ssize_t[::1] parents,
    double[:, :, :, ::1] rotations,
    double[:, :, ::1] positions,
):
    """World rotations and positions of every joint in every frame, written in place.

    Parameters
    ----------
    channels : ndarray of shape (n_frames, n_channels)
        The clip (angles in radians).
    rotation_column : ndarray of shape (n_joints, 3)
        The channel of each slot of the joint's rotation order, -1 where the joint
        has no channel for that axis (no rotation about it).
    axis_of_slot : ndarray of shape (n_joints, 3)
        The coordinate axis (0, 1, 2 for X, Y, Z) of each slot of the order.
    position_column : ndarray of shape (n_joints, 3)
        The channel of each coordinate of the joint's offset, -1 where the offset
        is fixed.
    offsets : ndarray of shape (n_joints, 3)
        The fixed offsets from the parents.
    axes : ndarray of shape (n_joints, 3, 3)
        Bone axes ``A`` (local = A @ euler @ A.T) when ``use_axes``.
    parents : ndarray of shape (n_joints,)
        Parent indices, below their children's; -1 for the root (joint 0).
    rotations : ndarray of shape (n_frames, n_joints, 3, 3)
        Output: world rotations.
    positions : ndarray of shape (n_frames, n_joints, 3)
        Output: world positions.
    """
    cdef Py_ssize_t n_frames = channels.shape[0], n_joints = offsets.shape[0]
    cdef Py_ssize_t f, j, p, s, column
    cdef int r, c
    cdef double[3][3] local
    cdef double[3][3] tmp
    cdef double[3] offset
    with nogil:
        for f in range(n_frames):
            for j in range(n_joints):
                for r in range(3):
                    column = position_column[j, r]
                    offset[r] = channels[f, column] if column >= 0 else offsets[j, r]
                    for c in range(3):
                        local[r][c] = 1.0 if r == c else 0.0
                for s in range(3):
                    column = rotation_column[j, s]
                    if column >= 0:
                        _times_elementary(local, <int>axis_of_slot[j, s], channels[f, column])
                if use_axes:
                    # local := A @ local @ A.T
                    for r in range(3):
                        for c in range(3):
                            tmp[r][c] = (
                                axes[j, r, 0] * local[0][c]
                                + axes[j, r, 1] * local[1][c]
                                + axes[j, r, 2] * local[2][c]
                            )
                    for r in range(3):
                        for c in range(3):
                            local[r][c] = (
                                tmp[r][0] * axes[j, c, 0]
                                + tmp[r][1] * axes[j, c, 1]
                                + tmp[r][2] * axes[j, c, 2]
                            )
                p = parents[j]
                if p < 0:
                    for r in range(3):
                        positions[f, j, r] = offset[r]
                        for c in range(3):
                            rotations[f, j, r, c] = local[r][c]
                    continue
                for r in range(3):
                    positions[f, j, r] = positions[f, p, r] + (
                        rotations[f, p, r, 0] * offset[0]
                        + rotations[f, p, r, 1] * offset[1]
                        + rotations[f, p, r, 2] * offset[2]
                    )
                    for c in range(3):
                        rotations[f, j, r, c] = (
                            rotations[f, p, r, 0] * local[0][c]
                            + rotations[f, p, r, 1] * local[1][c]
                            + rotations[f, p, r, 2] * local[2][c]
                        )


def marker_pass(
    const double[:, :, ::1] positions,
    const double[:, :, :, ::1] rotations,
    const Py_ssize_t[::1] joints,
    const double[:, ::1] offsets,
    double[:, :, ::1] out,
):
    """Points fixed on joints, ``p_joint + R_joint @ offset`` in every frame, written in place.

    The sum of the three products in the order of the pass above, then added to the
    joint's position: ``positions[:, joints] + einsum("fmij,mj->fmi", rotations[:, joints],
    offsets)`` (to rounding: NumPy's einsum may fuse a product into an FMA) without the two
    gathered copies and the einsum's per-call cost, most of a marker set's time per clip.

    Parameters
    ----------
    positions : ndarray of shape (n_frames, n_joints, 3)
    rotations : ndarray of shape (n_frames, n_joints, 3, 3)
    joints : ndarray of shape (n_points,)
        The joint of each point, in ``0 .. n_joints - 1`` (checked).
    offsets : ndarray of shape (n_points, 3)
        Each point in its joint's frame.
    out : ndarray of shape (n_frames, n_points, 3)
    """
    cdef Py_ssize_t n_frames = positions.shape[0], n_joints = positions.shape[1]
    cdef Py_ssize_t n_points = joints.shape[0], f, m, j
    cdef int r
    if (rotations.shape[0] != n_frames or rotations.shape[1] != n_joints
            or offsets.shape[0] != n_points or out.shape[0] != n_frames
            or out.shape[1] != n_points):
        raise ValueError("positions, rotations, joints, offsets and out do not agree.")
    for m in range(n_points):
        if not 0 <= joints[m] < n_joints:
            raise ValueError(f"point {m}'s joint {joints[m]} is not among the {n_joints}.")
    with nogil:
        for f in range(n_frames):
            for m in range(n_points):
                j = joints[m]
                for r in range(3):
                    out[f, m, r] = positions[f, j, r] + (
                        rotations[f, j, r, 0] * offsets[m, 0]
                        + rotations[f, j, r, 1] * offsets[m, 1]
                        + rotations[f, j, r, 2] * offsets[m, 2]
                    )
