"""The training frames' per-channel mean and standard deviation, and their standardisation in place.

``frames.std(axis=0)`` makes a centred copy of all frames, and ``(frames - mean) /
std`` another; on ten million frames each is the size of the frames themselves. Here
the squares are summed block by block and the standardisation is written over the
frames (a fit's own stacked copy): the same doubles, without the copies. NumPy sums
a C-ordered array over its first axis row after row, so carrying the running sums
into the next block as its first row gives the sums of the whole array exactly.
"""

import numpy as np

__all__ = ["column_mean_std", "standardise_in_place"]

_BLOCK_ROWS = 1 << 15


def column_mean_std(frames):
    """``frames.mean(axis=0)`` and ``frames.std(axis=0)``, to the bit, without a full copy.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels), C-contiguous float64

    Returns
    -------
    mean, std : ndarray of shape (n_channels,)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._standardise import column_mean_std
    >>> frames = np.random.default_rng(0).normal(size=(100_000, 3))
    >>> mean, std = column_mean_std(frames)
    >>> bool(np.array_equal(mean, frames.mean(axis=0)) and np.array_equal(std, frames.std(axis=0)))
    True
    """
    n, d = frames.shape
    mean = frames.mean(axis=0)  # a running sum over rows: no copy
    buffer = np.empty((min(n, _BLOCK_ROWS) + 1, d))
    total = None
    for start in range(0, n, _BLOCK_ROWS):
        rows = frames[start : start + _BLOCK_ROWS]
        block = buffer[: len(rows) + 1]
        np.subtract(rows, mean, out=block[1:])
        np.multiply(block[1:], block[1:], out=block[1:])
        if total is None:
            total = np.add.reduce(block[1:], axis=0)
        else:
            block[0] = total
            total = np.add.reduce(block, axis=0)
    return mean, np.sqrt(total / n)


def standardise_in_place(frames, center, scale):
    """``frames[:] = (frames - center) / scale``, block by block (the same doubles)."""
    for start in range(0, len(frames), _BLOCK_ROWS):
        rows = frames[start : start + _BLOCK_ROWS]
        np.subtract(rows, center, out=rows)
        np.divide(rows, scale, out=rows)
    return frames
