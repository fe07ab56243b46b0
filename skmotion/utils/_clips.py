"""The clip collection: validation, conversion and frame stacking.

One sample is one motion clip, a 2-D float array ``(n_frames, n_channels)``. A
collection is given as a list (or tuple) of such arrays, a 3-D array of
equal-length clips, or a pandas DataFrame with a two-level ``(clip, frame)``
MultiIndex. :func:`check_clips` is the only place where collections are checked
and converted; :func:`to_container` returns results in the caller's kind.

The per-clip conversion and checks are in ``_clip_checks``, the DataFrame
splitting and building in ``_clip_dataframes``.
"""

from dataclasses import dataclass
from numbers import Integral

import numpy as np
import pandas as pd
import scipy.sparse as sp

from skmotion.utils._clip_checks import _check_each_clip, _estimator_name, _normalise_dtypes
from skmotion.utils._clip_dataframes import (
    _check_feature_names,
    clips_to_dataframe,
    split_dataframe,
)

__all__ = [
    "Clips",
    "Container",
    "check_clips",
    "split_frames",
    "stack_clips",
    "to_container",
]

CONTAINER_KINDS = frozenset({"list", "tuple", "ndarray", "dataframe"})


@dataclass(frozen=True)
class Container:
    """What kind of collection the caller gave, so results can go back in kind.

    Parameters
    ----------
    kind : {"list", "tuple", "ndarray", "dataframe"}
        The container of the input collection.
    clip_labels : pandas.Index or None
        For a DataFrame, the clip labels (first index level) in order of appearance.
    index_names : tuple of str or None
        For a DataFrame, the names of the two index levels.
    columns : pandas.Index or None
        For a DataFrame, its columns (the channel names).
    """

    kind: str
    clip_labels: object = None
    index_names: tuple = None
    columns: object = None


class Clips(list):
    """A validated clip collection: a list of C-contiguous float arrays.

    It behaves exactly like a list; its ``container`` attribute records the
    kind of collection the caller passed (see :func:`to_container`).
    """

    def __init__(self, clips, container):
        super().__init__(clips)
        self.container = container

    @property
    def n_channels(self):
        """Number of channels shared by all clips."""
        return self[0].shape[1]

    @property
    def lengths(self):
        """Number of frames of each clip, as an int array."""
        return np.fromiter((len(c) for c in self), dtype=np.intp, count=len(self))


def check_clips(
    X,
    *,
    estimator=None,
    reset=False,
    allow_nan=False,
    min_frames=None,
    min_clips=1,
    dtype=(np.float64, np.float32),
    copy=False,
    input_name="X",
):
    """Validate a clip collection and convert it to a list of float arrays.

    Parameters
    ----------
    X : list of array-like of shape (n_frames_i, n_channels), ndarray of shape \
            (n_clips, n_frames, n_channels) or DataFrame
        The collection. A DataFrame must have a two-level ``(clip, frame)``
        MultiIndex whose clip rows are contiguous and whose frames increase.
    estimator : estimator instance, default=None
        With ``reset=True`` its ``n_features_in_`` (the channel count) and,
        for DataFrames with string columns, ``feature_names_in_`` are set;
        with ``reset=False`` they are checked.
    reset : bool, default=False
        Whether this is the call of ``fit``.
    allow_nan : bool, default=False
        Whether NaN (a missing value) is allowed. Infinity never is.
    min_frames : int, default=None
        The fewest frames a clip may have. ``0`` accepts empty clips of shape
        ``(0, n_channels)`` (sequences of segment codes of clips without segments).
        None takes the ``min_frames`` of the estimator's :class:`~skmotion.base.MotionTags`
        (so an estimator states its minimum once), and 1 without an estimator.
    min_clips : int, default=1
        The fewest clips the collection may have.
    dtype : dtype or tuple of dtypes, default=(np.float64, np.float32)
        Accepted float dtypes; others are converted to the first.
    copy : bool, default=False
        Whether to always copy the clips (otherwise views are returned when the
        input already has the right dtype and layout).
    input_name : str, default="X"
        Name of the argument, used in error messages.

    Returns
    -------
    clips : Clips
        A list of C-contiguous 2-D arrays with a ``container`` attribute.

    Raises
    ------
    ValueError
        For an empty collection, a clip that is not 2-D, too few frames or clips,
        channel counts that differ between clips or from fit, non-numeric data,
        or NaN/inf where not allowed. The message names the clip.
    TypeError
        For a collection of an unsupported type (a dict, a sparse matrix, ...).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import check_clips
    >>> clips = check_clips([np.zeros((5, 3)), np.ones((8, 3))])
    >>> len(clips), clips.n_channels, clips.container.kind
    (2, 3, 'list')
    >>> check_clips([np.zeros((5, 3)), np.ones((8, 2))])
    Traceback (most recent call last):
    ...
    ValueError: X: clip 1 has 2 channels, but clip 0 has 3; all clips of a collection ...
    """
    dtypes = _normalise_dtypes(dtype)
    name = _estimator_name(estimator)
    if min_frames is None:
        tags = getattr(estimator, "__skmotion_tags__", None)
        min_frames = tags().min_frames if tags is not None else 1
    feature_source = X
    if isinstance(X, pd.DataFrame):
        raw, labels, index_names, columns = split_dataframe(X, input_name)
        container = Container(
            kind="dataframe", clip_labels=labels, index_names=index_names, columns=columns
        )
    elif isinstance(X, np.ndarray) or sp.issparse(X):
        if sp.issparse(X):
            raise TypeError(
                f"{input_name} is a sparse matrix; a clip collection is a list of "
                "2-D arrays, a 3-D array or a (clip, frame) DataFrame."
            )
        if X.ndim != 3:
            hint = " For a single clip pass [clip]." if X.ndim == 2 else ""
            raise ValueError(
                f"{input_name} is a {X.ndim}-D array of shape {X.shape}; a clip "
                "collection is a list of 2-D arrays (n_frames, n_channels), a 3-D "
                "array (n_clips, n_frames, n_channels) or a (clip, frame) "
                f"DataFrame.{hint}"
            )
        raw, container = list(X), Container(kind="ndarray")
    elif isinstance(X, (list, tuple)):
        raw = X
        container = Container(kind="tuple" if isinstance(X, tuple) else "list")
    else:
        raise TypeError(
            f"{input_name} must be a list of 2-D arrays, a 3-D array or a (clip, "
            f"frame) MultiIndex DataFrame; got {type(X).__name__}."
        )

    if len(raw) == 0:
        raise ValueError(f"{input_name} is an empty collection: it holds no clips.")
    if len(raw) < min_clips:
        raise ValueError(
            f"{input_name} holds {len(raw)} clip(s); {name} needs at least {min_clips}."
        )

    with np.errstate(
        over="ignore", invalid="ignore"
    ):  # the finite check sums the values, see below
        clips, n_channels = _check_each_clip(
            raw, dtypes, min_frames, allow_nan, copy, name, input_name
        )

    if estimator is not None:
        if reset:
            estimator.n_features_in_ = n_channels
        elif hasattr(estimator, "n_features_in_") and estimator.n_features_in_ != n_channels:
            raise ValueError(
                f"{input_name} has {n_channels} channels, but {name} was fitted with "
                f"{estimator.n_features_in_} channels."
            )
        _check_feature_names(feature_source, estimator, reset, input_name)
    return Clips(clips, container)


def to_container(clips, container, *, columns=None):
    """Return clips in the kind of collection the caller gave.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        The results, one per input clip, in input order.
    container : Container or "pandas"
        The ``container`` of the validated input (``Clips.container``), or the
        string ``"pandas"`` to force a ``(clip, frame)`` DataFrame.
    columns : array-like of str, default=None
        Channel names for a DataFrame result. By default the input's columns
        are kept when the channel count is unchanged, else ``channel_0, ...``.

    Returns
    -------
    collection : list, tuple, ndarray or DataFrame
        A list for list input, a tuple for tuple input, a 3-D array for 3-D
        input when all results have the same length (otherwise a list), and a
        DataFrame with the input's clip labels for DataFrame input.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import check_clips, to_container
    >>> clips = check_clips(np.zeros((2, 4, 3)))
    >>> to_container([c[:, :1] for c in clips], clips.container).shape
    (2, 4, 1)
    """
    if isinstance(container, str):
        if container != "pandas":
            raise ValueError(f"container must be a Container or 'pandas', got {container!r}.")
        container = Container(kind="dataframe")
    kind = container.kind
    if kind == "list":
        return list(clips)
    if kind == "tuple":
        return tuple(clips)
    if kind == "ndarray":
        lengths = {c.shape for c in clips}
        return np.stack(clips) if len(lengths) == 1 else list(clips)
    if kind != "dataframe":
        raise ValueError(
            f"Unknown container kind {kind!r}; expected one of {sorted(CONTAINER_KINDS)}."
        )
    return clips_to_dataframe(clips, container, columns)


def stack_clips(clips):
    """Stack all frames of all clips into one array, with the clip offsets.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        Validated clips (see :func:`check_clips`).

    Returns
    -------
    frames : ndarray of shape (sum(n_frames_i), n_channels)
        All frames, clip after clip.
    offsets : ndarray of shape (n_clips + 1,)
        Clip ``i`` is ``frames[offsets[i]:offsets[i + 1]]``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import stack_clips
    >>> frames, offsets = stack_clips([np.zeros((2, 3)), np.ones((4, 3))])
    >>> frames.shape, offsets.tolist()
    ((6, 3), [0, 2, 6])
    """
    lengths = np.fromiter((len(c) for c in clips), dtype=np.intp, count=len(clips))
    offsets = np.zeros(len(clips) + 1, dtype=np.intp)
    np.cumsum(lengths, out=offsets[1:])
    return np.concatenate(clips, axis=0), offsets


def split_frames(frames, offsets):
    """Split stacked per-frame results back into one array per clip.

    Parameters
    ----------
    frames : ndarray of shape (n_total_frames, ...)
        Per-frame values, clip after clip (as from :func:`stack_clips`).
    offsets : array-like of int of shape (n_clips + 1,)
        Clip boundaries; ``offsets[0] == 0`` and ``offsets[-1] == len(frames)``.

    Returns
    -------
    clips : list of ndarray
        Views into ``frames``, one per clip.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import split_frames
    >>> [part.tolist() for part in split_frames(np.arange(5), [0, 2, 5])]
    [[0, 1], [2, 3, 4]]
    """
    offsets = np.asarray(offsets)
    if (
        offsets.ndim != 1
        or len(offsets) < 2
        or not isinstance(offsets[0].item(), Integral)
        or offsets[0] != 0
        or offsets[-1] != len(frames)
        or np.any(np.diff(offsets) < 0)
    ):
        raise ValueError(
            f"offsets must increase from 0 to len(frames)={len(frames)}; got "
            f"{offsets.tolist() if offsets.size < 10 else offsets}."
        )
    return np.split(frames, offsets[1:-1])
