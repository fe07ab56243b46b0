"""The training frames' per-channel mean and standard deviation, and their standardisation in place.

``frames.std(axis=0)`` makes a centred copy of all frames, and ``(frames - mean) /
std`` another; on ten million frames each is the size of the frames themselves. Here
the squares are summed block by block and the standardisation is written over the
frames (a fit's own stacked copy): the same doubles, without the copies. NumPy sums
a C-ordered array over its first axis row after row, so carrying the running sums
into the next block as its first row gives the sums of the whole array exactly.
"""

import numpy as np

__all__ = ["StackedClips", "carried_sum", "column_mean_std", "standardise_in_place"]

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


class StackedClips:
    """The clips' frames as the stacked array they make, read a block of rows at a time.

    A fit over many frames need not stack them (a copy the size of the frames): every
    pass over the stacked frames reads consecutive blocks of a given number of rows
    from the stacked array's first row, each copied into one reused buffer (and there
    standardised, once :attr:`center` and :attr:`scale` are set). The blocks hold the
    doubles of the stacked array's rows and of :func:`standardise_in_place` on them.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        Validated float64 clips (``check_clips``); read, never written.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._standardise import StackedClips
    >>> clips = [np.arange(6.0).reshape(3, 2), np.ones((2, 2))]
    >>> stacked = StackedClips(clips)
    >>> [(start, block[:, 0].tolist()) for start, block in stacked.blocks(2)]
    [(0, [0.0, 2.0]), (2, [4.0, 1.0]), (4, [1.0])]
    >>> [m.tolist() for m in stacked.mean_std()]
    [[1.6, 2.2], [1.3564659966250536, 1.6]]
    >>> stacked.center, stacked.scale = stacked.mean_std()
    >>> z = standardise_in_place(np.concatenate(clips), stacked.center, stacked.scale)
    >>> all(np.array_equal(block, z[at : at + 2]) for at, block in stacked.blocks(2))
    True
    """

    def __init__(self, clips):
        self.clips = clips
        self.n_frames = sum(len(clip) for clip in clips)
        self.n_channels = clips[0].shape[1]
        self.center = None
        self.scale = None

    def blocks(self, rows, spare_row=False, raw=False):
        """Yield ``(start, block)``: rows ``start`` to ``start + rows`` of the stacked frames
        (standardised when :attr:`center` is set, unless ``raw``), the last block shorter.

        The block is a view of a buffer the next block overwrites. ``spare_row``: the
        view has one more row, first, that the caller may write (the block's rows are
        ``view[1:]``), for sums carried from block to block.
        """
        first = int(bool(spare_row))
        center = None if raw else self.center
        buffer = np.empty((min(rows, max(self.n_frames, 1)) + first, self.n_channels))
        filled, start = 0, 0
        for clip in self.clips:
            at = 0
            while at < len(clip):
                take = min(rows - filled, len(clip) - at)
                into = buffer[first + filled : first + filled + take]
                if center is None:
                    into[:] = clip[at : at + take]
                else:  # the copy and standardise_in_place's subtraction in one pass
                    np.subtract(clip[at : at + take], center, out=into)
                filled += take
                at += take
                if filled == rows:
                    yield start, self._ready(buffer, first, filled, center)
                    start, filled = start + rows, 0
        if filled:
            yield start, self._ready(buffer, first, filled, center)

    def _ready(self, buffer, first, filled, center):
        if center is not None:
            rows = buffer[first : first + filled]
            np.divide(rows, self.scale, out=rows)
        return buffer[: first + filled]

    def mean_std(self):
        """:func:`column_mean_std` of the stacked raw frames: the same doubles with two
        channels or more (NumPy sums a single column pairwise, not row after row)."""
        center, self.center = self.center, None
        try:
            mean = carried_sum(self.blocks(_BLOCK_ROWS, spare_row=True)) / self.n_frames
            squares = carried_sum(
                _centred(block, mean) for block in self.blocks(_BLOCK_ROWS, spare_row=True)
            )
        finally:
            self.center = center
        return mean, np.sqrt(squares / self.n_frames)


def _centred(pair, mean):
    start, view = pair
    np.subtract(view[1:], mean, out=view[1:])
    np.multiply(view[1:], view[1:], out=view[1:])
    return start, view


def carried_sum(pairs):
    """The column sums of consecutive blocks (each with a spare first row) as NumPy sums
    the rows of one array: row after row, the running sums carried into the next block."""
    total = None
    for _, view in pairs:
        if total is None:
            total = np.add.reduce(view[1:], axis=0)
        else:
            view[0] = total
            total = np.add.reduce(view, axis=0)
    return total
