"""The one text rule of every reader (BVH, ASF, AMC, .ts), and vectorised helpers for
the numeric blocks of text motion files.

The rule (documented in docs/errors.md):

- A UTF-8 byte-order mark at the start of a file is skipped; a UTF-16/32 one is an error.
- Line breaks are LF, CRLF or a lone CR (old Mac files); all three count as one line.
- Tokens are separated by spaces, tabs and line breaks. Any other control byte
  (``\\x00``-``\\x1f`` but TAB, LF, CR; and ``\\x7f``) is an error naming its line.
- A number is ASCII: ``[+-]`` digits, an optional ``.`` and fraction, an optional
  ``e``/``E`` exponent (``12``, ``-0.5``, ``.5``, ``1.``, ``3e-4``). Python's ``float``
  also takes ``1_000``, ``infinity`` and non-ASCII digits; the readers do not.
  A number too large for a float (``1e400``) is a non-finite value, an error.

The readers locate every whitespace-separated token of a block with NumPy on the
raw bytes, so checking the layout (values per line, which line a token is on)
costs a few array operations rather than a Python loop over lines.
"""

import io
import re

import numpy as np

from skmotion.io._errors import MotionFileError

__all__ = [
    "Tokens",
    "decode_text",
    "is_special",
    "number_bytes_only",
    "parse_floats",
    "parse_number",
    "read_bytes",
    "read_text",
]

_BOM = b"\xef\xbb\xbf"
_WIDE_BOMS = (b"\xff\xfe", b"\xfe\xff", b"\x00\x00\xfe\xff")
_CONTROL_BYTES = bytes(range(0, 9)) + b"\x0b\x0c" + bytes(range(14, 32)) + b"\x7f"
_NOT_CONTROL = bytes(b for b in range(256) if b not in _CONTROL_BYTES)
_CONTROL = re.compile(b"[" + re.escape(_CONTROL_BYTES) + b"]")
_NUMERIC_BYTES = b"0123456789+-.eE \t\r\n"
NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_CHUNK_TOKENS = 1 << 16


def read_bytes(path):
    """The bytes of a file, with a MotionFileError naming it when it cannot be read."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except IsADirectoryError:
        raise MotionFileError(path, None, "is a folder, not a file") from None


def read_text(path):
    """The bytes of a text motion file under the one rule of every reader.

    A UTF-8 byte-order mark is dropped, CRLF and lone CR line breaks become LF, and a
    control byte other than TAB, LF and CR raises a MotionFileError naming its line.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    data : bytes
        The text with LF line breaks only.

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.io._text import read_text
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "a.txt")
    ...     _ = open(path, "wb").write(b"\\xef\\xbb\\xbfMOTION\\rFrames: 1\\r\\n")
    ...     read_text(path)
    b'MOTION\\nFrames: 1\\n'
    """
    data = read_bytes(path)
    if data.startswith(_BOM):
        data = data[len(_BOM) :]
    elif data.startswith(_WIDE_BOMS):
        raise MotionFileError(
            path,
            None,
            "not a text file skmotion reads (UTF-16/32 byte-order mark): save it as UTF-8",
        )
    if b"\r" in data:
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    if data.translate(None, _NOT_CONTROL):  # the control bytes only; empty for clean text
        found = _CONTROL.search(data)
        raise MotionFileError(
            path,
            data.count(b"\n", 0, found.start()) + 1,
            f"not a text file: control byte {found.group()!r} (only spaces, tabs and line "
            "breaks separate values)",
        )
    return data


def decode_text(data):
    """Text of a file's bytes: UTF-8 (as skmotion writes), else Latin-1 (older tools)."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def parse_number(word):
    """``word`` as a float under the readers' number rule; ValueError when it is not one.

    Examples
    --------
    >>> from skmotion.io._text import parse_number
    >>> parse_number("-1.5e2")
    -150.0
    >>> parse_number("1_000")
    Traceback (most recent call last):
    ...
    ValueError: not a number: '1_000'
    """
    if not NUMBER.fullmatch(word):
        raise ValueError(f"not a number: {word!r}")
    return float(word)


def is_special(word):
    """True for the spellings of NaN and infinity (a non-finite value, not a word)."""
    return word.lower().lstrip("+-") in ("nan", "inf", "infinity")


def number_bytes_only(data):
    """True when ``data`` holds only digits, signs, dots, ``e``/``E`` and separators."""
    return not data.translate(None, _NUMERIC_BYTES)


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


def _first_bad_token(tokens, path, index, data):
    """Raise the MotionFileError of the first token of ``index`` that is not a finite number.

    Chunks of tokens are converted at once and only a failing chunk is examined token
    by token, so locating an error in a large file costs about as much as reading it.
    """
    for lo in range(0, len(index), _CHUNK_TOKENS):
        chunk = index[lo : lo + _CHUNK_TOKENS]
        piece = data[tokens.starts[chunk[0]] : tokens.ends[chunk[-1]]]
        if number_bytes_only(piece):
            try:
                if np.isfinite(np.array(piece.split(), dtype=float)).all():
                    continue
            except ValueError:
                pass
        for k in chunk:
            word = tokens.text(k)
            try:
                problem = None if np.isfinite(parse_number(word)) else "non-finite"
            except ValueError:
                problem = "non-finite" if is_special(word) else "non-numeric"
            if problem:
                raise MotionFileError(path, int(tokens.lines[k]), f"{problem} value {word!r}")
    raise MotionFileError(path, tokens.first_line, "values that cannot be read as numbers")


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
    data = tokens.data if buffer is None else buffer.tobytes()
    values = None
    if number_bytes_only(data):
        if rows is not None and len(rows):
            per_row = np.diff(np.r_[rows, len(tokens)]) - (
                np.add.reduceat(drop.astype(np.intp), rows) if drop is not None else 0
            )
            if (per_row == per_row[0]).all():
                base = buffer if buffer is not None else np.frombuffer(data, dtype=np.uint8).copy()
                values = _as_table(base, tokens, rows)
        if values is None:
            try:
                values = np.array(data.split(), dtype=float)
            except ValueError:
                values = None
    if values is not None and np.isfinite(values).all():
        return values
    index = np.flatnonzero(which) if which is not None else np.arange(len(tokens))
    _first_bad_token(tokens, path, index, data)
