"""The subject's size from marker positions: summed median distances along a chain of markers."""

import numpy as np

__all__ = ["body_size"]


def body_size(positions, chain):
    """Subject size: the summed median distances between consecutive markers of a chain.

    With a chain from the ankle up to the head top this is the standing height
    measured along the body. Distances between markers on the same link never
    change, the others barely, so the median over the clip is robust to the
    pose, and it scales exactly with the subject.

    Parameters
    ----------
    positions : ndarray of shape (n_frames, n_markers, 3)
    chain : sequence of int
        Marker indices, in order along the body.

    Returns
    -------
    size : float

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import body_size
    >>> points = np.array([[[0, 0, 0], [0, 3, 0], [4, 3, 0]]], dtype=float)
    >>> body_size(points, [0, 1, 2])
    7.0
    """
    chain = np.asarray(chain, dtype=np.intp)
    steps = np.linalg.norm(positions[:, chain[1:]] - positions[:, chain[:-1]], axis=-1)
    return float(np.median(steps, axis=0).sum())
