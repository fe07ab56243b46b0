"""Vectorised helpers for the numeric blocks of text motion files.

The readers locate every whitespace-separated token of a block with NumPy on the
raw bytes, so checking the layout (values per line, which line a token is on)
costs a few array operations rather than a Python loop over lines.
"""

import io

import numpy as np

from skmotion.io._errors import MotionFileError

__all__ = ["Tokens", "parse_floats", "read_bytes"]


def read_bytes(path):
    """The bytes of a file, with a MotionFileError naming it when it cannot be read."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except IsADirectoryError:
        raise MotionFileError(path, None, "is a folder, not a file") from None


class Tokens:
    """Whitespace-separated tokens of a byte string, located by NumPy.

    Parameters
    ----------
    data : bytes
        The text.
    first_line : int, default=1
        The file line number of the first line of ``data``.

    Attributes
    ----------
    starts, ends : ndarray of int
        Byte offsets of each token (``data[starts[k]:ends[k]]``).
    lines : ndarray of int
        File line number of each token.
    """

    def __init__(self, data, first_line=1):
        self.data = data
        buffer = np.frombuffer(data, dtype=np.uint8)
        # Every byte <= 32 (space, tab, CR, LF, ...) separates tokens.
        solid = buffer > 32
        edges = np.diff(solid.astype(np.int8), prepend=np.int8(0), append=np.int8(0))
        self.starts = np.flatnonzero(edges == 1)
        self.ends = np.flatnonzero(edges == -1)
        newlines = np.flatnonzero(buffer == 10)
        self.lines = np.searchsorted(newlines, self.starts) + first_line
        self.n_lines = len(newlines) + (0 if data.endswith(b"\n") else 1)
        self.first_line = first_line

    def __len__(self):
        return len(self.starts)

    def text(self, k):
        """Token ``k`` as a string."""
        return self.data[self.starts[k] : self.ends[k]].decode("latin-1")

    def per_line(self):
        """Number of tokens on each line, indexed from ``first_line``."""
        return np.bincount(self.lines - self.first_line, minlength=self.n_lines)


def _blanked(tokens, drop):
    """The text with the tokens selected by ``drop`` overwritten by spaces."""
    buffer = np.frombuffer(tokens.data, dtype=np.uint8).copy()
    starts, ends = tokens.starts[drop], tokens.ends[drop]
    lengths = ends - starts
    offsets = np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    buffer[np.repeat(starts, lengths) + offsets] = 32
    return buffer


def _as_table(buffer, tokens, rows):
    """Values via ``numpy.loadtxt``, one text line per row; None when rows differ in length."""
    buffer[(buffer == 10) | (buffer == 13)] = 32
    buffer[tokens.starts[rows[1:]] - 1] = 10  # a token start always follows a separator
    try:
        return np.loadtxt(io.BytesIO(buffer.tobytes()), dtype=float, ndmin=2, comments=None).ravel()
    except ValueError:
        return None


def parse_floats(tokens, path, which=None, rows=None):
    """The tokens (all, or those selected by ``which``) as floats, in file order.

    Non-numeric and non-finite values raise a MotionFileError naming the line.

    Parameters
    ----------
    tokens : Tokens
    path : str or path-like
        For error messages.
    which : ndarray of bool, default=None
        Tokens to parse; the others are blanked out first.
    rows : ndarray of int, default=None
        Indices of the tokens that start a record (an AMC frame number). When
        every record holds the same number of values the text is reshaped to
        one line per record and parsed by ``numpy.loadtxt``, which is faster.

    Returns
    -------
    values : ndarray of float
    """
    drop = None if which is None else ~which
    buffer = _blanked(tokens, drop) if drop is not None and drop.any() else None
    values = None
    if rows is not None and len(rows):
        per_row = np.diff(np.r_[rows, len(tokens)]) - (
            np.add.reduceat(drop.astype(np.intp), rows) if drop is not None else 0
        )
        if (per_row == per_row[0]).all():
            base = (
                buffer if buffer is not None else np.frombuffer(tokens.data, dtype=np.uint8).copy()
            )
            values = _as_table(base, tokens, rows)
    if values is None:
        data = tokens.data if buffer is None else buffer.tobytes()
        try:
            values = np.array(data.split(), dtype=float)
        except ValueError:
            values = None
    if values is not None and np.isfinite(values).all():
        return values
    index = np.flatnonzero(which) if which is not None else np.arange(len(tokens))
    for k in index:
        word = tokens.text(k)
        try:
            problem = None if np.isfinite(float(word)) else "non-finite"
        except ValueError:
            problem = "non-numeric"
        if problem:
            raise MotionFileError(path, int(tokens.lines[k]), f"{problem} value {word!r}")
    raise AssertionError("unreachable: a value failed to parse but every token is numeric")
