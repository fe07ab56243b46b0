"""Class labels of one type: numbers, or strings, never both."""

from numbers import Number

import numpy as np
import pandas as pd
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import column_or_1d

__all__ = ["check_clip_labels", "check_label_types"]


def _kind(value):
    if isinstance(value, (str, bytes, np.str_, np.bytes_)):
        return "str"
    if isinstance(value, (bool, np.bool_)):
        return "bool"
    if isinstance(value, Number):
        return "number"
    return type(value).__name__


def check_label_types(y, input_name="y"):
    """Refuse labels that mix strings with numbers (or other objects).

    NumPy turns ``[1, "walk"]`` into the strings ``["1", "walk"]`` (so ``predict``
    would return ``"1"`` where the caller gave ``1``), and an object array of
    both cannot be sorted into ``classes_``. Neither is guessed: mixed labels
    raise a TypeError naming the two types and where each first occurs.

    Parameters
    ----------
    y : array-like
        The labels, one per clip (a list, tuple, array, Series or Index).
    input_name : str, default="y"
        The name used in the message.

    Returns
    -------
    y : array-like
        ``y`` itself, unchanged.

    Raises
    ------
    TypeError
        When strings and non-strings are mixed.

    Examples
    --------
    >>> from skmotion.utils._labels import check_label_types
    >>> check_label_types(["walk", "run"])
    ['walk', 'run']
    >>> check_label_types([1, "walk", 2])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    TypeError: y mixes label types: number (1 at clip 0) and str ('walk' at clip 1). ...
    """
    if isinstance(y, (pd.Series, pd.Index)):
        values = y.to_numpy()
    elif isinstance(y, (list, tuple)):
        values = y
    elif isinstance(y, np.ndarray) and y.dtype == object:
        values = y.ravel()
    else:
        return y  # a typed array holds one type
    if isinstance(values, np.ndarray) and values.dtype != object:
        return y
    first = {}
    for i, value in enumerate(values):
        if isinstance(value, (list, tuple, np.ndarray)) and np.ndim(value) == 1 and len(value) == 1:
            value = value[0]  # a column vector, [[1], [2], ...]
        first.setdefault(_kind(value), (i, value))
    if "str" in first and len(first) > 1:
        other = min((k for k in first if k != "str"), key=lambda k: first[k][0])
        (a, (i, u)), (b, (j, v)) = sorted(
            [("str", first["str"]), (other, first[other])], key=lambda item: item[1][0]
        )
        raise TypeError(
            f"{input_name} mixes label types: {a} ({u!r} at clip {i}) and {b} ({v!r} at clip "
            f"{j}). Use labels of one type, e.g. [str(v) for v in {input_name}]."
        )
    return y


def check_clip_labels(y, n_clips):
    """``y`` as a 1-D array of classification labels, one per clip.

    Raises a ValueError when the counts differ or the labels are not classes
    (sklearn's ``check_classification_targets``).

    Examples
    --------
    >>> from skmotion.utils._labels import check_clip_labels
    >>> check_clip_labels(["walk", "run"], 2).tolist()
    ['walk', 'run']
    >>> check_clip_labels(["walk"], 2)
    Traceback (most recent call last):
    ...
    ValueError: y has 1 labels but X holds 2 clips; give one label per clip.
    """
    y = column_or_1d(np.asarray(y), warn=True)
    if len(y) != n_clips:
        raise ValueError(
            f"y has {len(y)} labels but X holds {n_clips} clips; give one label per clip."
        )
    check_classification_targets(y)
    return y
