"""Reading the UEA/sktime ``.ts`` time-series classification format."""

import re
from pathlib import Path

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._text import NUMBER, is_special, number_bytes_only, read_text

__all__ = ["read_ts"]

_DIGITS = re.compile(r"[0-9]+")
_BOOLEAN_TAGS = ("timestamps", "missing", "univariate", "equallength")


def _parse_header(path, lines):
    """Header tags up to ``@data``; returns (tags, index of the first data line)."""
    tags = {}
    for number, raw in enumerate(lines, start=1):
        line = raw.strip(" \t")  # the text rule: blanks are spaces and tabs only
        if not line or line.startswith("#"):
            continue
        if not line.startswith("@"):
            raise MotionFileError(path, number, "data before the @data tag")
        key, _, value = line[1:].replace("\t", " ").partition(" ")  # tabs separate too
        key = key.lower()
        if key == "data":
            return tags, number
        value = value.strip(" \t")
        if key in _BOOLEAN_TAGS:
            if value.lower() not in ("true", "false"):
                raise MotionFileError(path, number, f"@{key} must be true or false, got {value!r}")
            tags[key] = value.lower() == "true"
        elif key == "classlabel":
            flag, _, labels = value.replace("\t", " ").partition(" ")
            if flag.lower() not in ("true", "false"):
                raise MotionFileError(
                    path, number, f"@classLabel must start with true or false, got {flag!r}"
                )
            tags["classlabel"] = (
                [w for w in labels.split(" ") if w] if flag.lower() == "true" else None
            )
        elif key in ("dimensions", "serieslength"):
            if not _DIGITS.fullmatch(value):
                raise MotionFileError(path, number, f"@{key} must be an integer, got {value!r}")
            tags[key] = int(value)
        else:
            tags[key] = value
    raise MotionFileError(path, None, "no @data tag: not a .ts file")


def _parse_dimension(path, number, index, text):
    values = [v.strip(" \t") for v in text.split(",")]
    column = None
    # Only digits, signs, dots, exponents and '?': float() alone would take '1_0' or 'inf'.
    if number_bytes_only(text.replace(",", " ").replace("?", " ").encode("utf-8")):
        try:
            column = np.array(["nan" if v == "?" else v for v in values], dtype=float)
        except ValueError:
            column = None
    if column is not None and not np.isinf(column).any():
        return column
    for position, value in enumerate(values, start=1):
        if value == "?":
            continue
        number_like = NUMBER.fullmatch(value) is not None
        if is_special(value) or (number_like and not np.isfinite(float(value))):
            # NaN is a missing value (written '?'); an infinity is a broken value.
            raise MotionFileError(
                path,
                number,
                f"dimension {index + 1}: non-finite value {value!r} at position {position} "
                "(write missing values as '?')",
            )
        if not number_like:
            raise MotionFileError(
                path, number, f"dimension {index + 1}: non-numeric value {value!r}"
            )
    raise MotionFileError(path, number, f"dimension {index + 1}: values that cannot be read")


def read_ts(path):
    """Read a UEA/sktime ``.ts`` file of (multivariate) series and class labels.

    Equal and unequal lengths are both read; each series becomes one clip with
    time first, ``(n_frames, n_dimensions)``. Missing values (``?``) become NaN.

    Parameters
    ----------
    path : str or path-like
        The ``.ts`` file.

    Returns
    -------
    clips : list of ndarray of shape (n_frames_i, n_dimensions)
        One clip per series.
    labels : ndarray of str of shape (n_clips,) or None
        The class label of each series, or None when the file has none.

    Raises
    ------
    MotionFileError
        For a malformed file (missing ``@data``, a wrong number of dimensions,
        dimensions of different lengths, a non-numeric value, an undeclared
        label, timestamps); the message names the file and line.

    Examples
    --------
    >>> import tempfile, os
    >>> from skmotion.io import read_ts
    >>> text = "@problemName toy\\n@univariate false\\n@dimensions 2\\n"
    >>> text += "@classLabel true a b\\n@data\\n1,2,3:4,5,6:a\\n7,8:9,10:b\\n"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "toy.ts")
    ...     _ = open(path, "w").write(text)
    ...     clips, labels = read_ts(path)
    >>> clips[0]
    array([[1., 4.],
           [2., 5.],
           [3., 6.]])
    >>> labels.tolist()
    ['a', 'b']
    """
    path = Path(path)
    try:
        lines = read_text(path).decode("utf-8").split("\n")
    except UnicodeDecodeError as exc:
        raise MotionFileError(path, None, f"not a text file ({exc.reason})") from None
    tags, data_line = _parse_header(path, lines)
    if tags.get("timestamps"):
        raise MotionFileError(path, None, "timestamped .ts files are not supported")
    class_labels = tags.get("classlabel")
    n_dims = tags.get("dimensions", 1 if tags.get("univariate") else None)
    clips, labels = [], []
    for number in range(data_line + 1, len(lines) + 1):
        line = lines[number - 1].strip(" \t")
        if not line or line.startswith("#"):
            continue
        fields = line.split(":")
        if class_labels is not None:
            label = fields.pop().strip(" \t")
            if label not in class_labels:
                raise MotionFileError(
                    path,
                    number,
                    f"class label {label!r} is not declared in @classLabel {class_labels}",
                )
            labels.append(label)
        if n_dims is None:
            n_dims = len(fields)
        if len(fields) != n_dims:
            raise MotionFileError(
                path, number, f"{len(fields)} dimensions, but the file declares {n_dims}"
            )
        columns = [_parse_dimension(path, number, k, text) for k, text in enumerate(fields)]
        lengths = {len(c) for c in columns}
        if len(lengths) != 1:
            raise MotionFileError(
                path,
                number,
                f"dimensions of one series differ in length: {[len(c) for c in columns]}",
            )
        if tags.get("equallength") and tags.get("serieslength") not in (None, len(columns[0])):
            raise MotionFileError(
                path,
                number,
                f"series of length {len(columns[0])}, but @seriesLength is {tags['serieslength']}",
            )
        clips.append(np.stack(columns, axis=1))
    if not clips:
        raise MotionFileError(path, None, "no series after @data")
    return clips, (np.asarray(labels) if class_labels is not None else None)
