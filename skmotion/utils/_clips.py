"""The clip collection: validation, conversion and frame stacking.

One sample is one motion clip, a 2-D float array ``(n_frames, n_channels)``. A
collection is given as a list (or tuple) of such arrays, a 3-D array of
equal-length clips, or a pandas DataFrame with a two-level ``(clip, frame)``
MultiIndex. :func:`check_clips` is the only place where collections are checked
and converted; :func:`to_container` returns results in the caller's kind.
"""

from dataclasses import dataclass
from numbers import Integral

import numpy as np
import pandas as pd
import scipy.sparse as sp

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


def _label(value):
    """repr of an index label, without numpy's scalar wrapper."""
    return repr(value.item() if isinstance(value, np.generic) else value)


def _estimator_name(estimator):
    return type(estimator).__name__ if estimator is not None else "this function"


def _describe_bad_value(clip, clip_index, input_name):
    """Name the first NaN/inf in a clip: clip, frame and channel."""
    bad = ~np.isfinite(clip)
    frame, channel = np.argwhere(bad)[0]
    value = clip[frame, channel]
    what = "NaN" if np.isnan(value) else ("inf" if value > 0 else "-inf")
    n_bad = int(bad.sum())
    more = f" ({n_bad} non-finite values in this clip)" if n_bad > 1 else ""
    return (
        f"{input_name}: clip {clip_index} contains {what} at frame {frame}, channel {channel}{more}"
    )


def _as_float_clip(clip, clip_index, dtype, input_name):
    """Convert one clip to a numeric array, naming the clip when it cannot be."""
    if type(clip) is np.ndarray and clip.dtype in dtype:
        # already an accepted float array: none of the checks below applies (a query
        # batch is many small clips, where they would cost more than the clip's own work)
        return clip, clip.dtype
    if sp.issparse(clip):
        raise TypeError(
            f"{input_name}: clip {clip_index} is a sparse matrix; clips must be "
            "dense 2-D arrays of shape (n_frames, n_channels)."
        )
    if isinstance(clip, pd.DataFrame):
        clip = clip.to_numpy()
    arr = np.asarray(clip)
    if arr.dtype.kind == "c":
        raise ValueError(f"{input_name}: clip {clip_index} has complex values; clips must be real.")
    if arr.dtype.kind not in "biuf":
        try:
            arr = arr.astype(np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"{input_name}: clip {clip_index} has non-numeric data (dtype {arr.dtype}): {exc}"
            ) from None
    target = arr.dtype if arr.dtype in dtype else dtype[0]
    return arr, target


def _normalise_dtypes(dtype):
    if isinstance(dtype, (list, tuple)):
        return tuple(np.dtype(d) for d in dtype)
    return (np.dtype(dtype),)


def _collection_from_dataframe(X, input_name):
    """Split a (clip, frame) MultiIndex DataFrame into per-clip arrays."""
    index = X.index
    if not isinstance(index, pd.MultiIndex) or index.nlevels != 2:
        raise ValueError(
            f"{input_name} is a DataFrame without a two-level (clip, frame) "
            "MultiIndex; got index "
            f"{type(index).__name__} with {index.nlevels} level(s). Build one with "
            "pd.concat({clip_id: frame_table, ...}) or df.set_index(['clip', 'frame'])."
        )
    if len(X) == 0:
        raise ValueError(f"{input_name} is an empty collection: it holds no clips.")
    codes, labels = pd.factorize(index.get_level_values(0), sort=False)
    for level, what in ((codes, "clip"), (index.codes[1], "frame")):
        if (level < 0).any():  # pandas codes a missing label (NaN, None) as -1
            row = int(np.flatnonzero(level < 0)[0])
            raise ValueError(
                f"{input_name}: row {row} of the DataFrame has a missing {what} label (NaN) in "
                "its (clip, frame) index; every row needs a clip and a frame label."
            )
    starts = np.flatnonzero(np.r_[True, codes[1:] != codes[:-1]])
    if len(starts) != len(labels):
        repeated = labels[np.bincount(codes[starts]).argmax()]
        raise ValueError(
            f"{input_name}: the rows of clip {_label(repeated)} are not contiguous in the "
            "DataFrame; sort it by clip first (df.sort_index(level=0, sort_remaining=False))."
        )
    frames = index.get_level_values(1)
    if len(frames) > 1:
        frame_values = np.asarray(frames)
        try:
            step_ok = frame_values[1:] > frame_values[:-1]
        except TypeError:
            raise ValueError(
                f"{input_name}: the frame level of the index is not orderable "
                f"(dtype {frames.dtype})."
            ) from None
        step_ok[starts[1:] - 1] = True
        if not step_ok.all():
            row = int(np.flatnonzero(~step_ok)[0]) + 1
            clip_label = labels[codes[row]]
            raise ValueError(
                f"{input_name}: frames of clip {_label(clip_label)} are not strictly "
                f"increasing (at frame label {_label(frame_values[row])}); sort the index."
            )
    values = X.to_numpy()
    clips = np.split(values, starts[1:])
    container = Container(
        kind="dataframe",
        clip_labels=pd.Index(labels),
        index_names=tuple(index.names),
        columns=X.columns,
    )
    return clips, container


def _feature_names(X):
    """Channel names of a DataFrame whose columns are all strings, else None."""
    if isinstance(X, pd.DataFrame):
        columns = np.asarray(X.columns, dtype=object)
        if len(columns) and all(isinstance(c, str) for c in columns):
            return columns
    return None


def _check_feature_names(X, estimator, reset, input_name):
    names = _feature_names(X)
    if reset:
        if names is not None:
            estimator.feature_names_in_ = names
        elif hasattr(estimator, "feature_names_in_"):
            del estimator.feature_names_in_
        return
    fitted = getattr(estimator, "feature_names_in_", None)
    if fitted is None or names is None:
        return
    if len(fitted) == len(names) and np.array_equal(fitted, names):
        return
    raise ValueError(
        f"{input_name}: channel names differ from those seen in fit by "
        f"{_estimator_name(estimator)}: expected {list(fitted)}, got {list(names)}."
    )


def _check_each_clip(raw, dtypes, min_frames, allow_nan, copy, name, input_name):
    """The clips as C-contiguous float arrays, checked one by one; and their channel count."""
    clips = []
    n_channels = None
    for i, clip in enumerate(raw):
        arr, target = _as_float_clip(clip, i, dtypes, input_name)
        if arr.ndim != 2:
            raise ValueError(
                f"{input_name}: clip {i} is {arr.ndim}-D with shape {arr.shape}; "
                "expected a 2-D array of shape (n_frames, n_channels)"
                + (" (use clip.reshape(-1, 1) for one channel)." if arr.ndim == 1 else ".")
            )
        if arr.shape[0] == 0 and min_frames > 0:
            raise ValueError(f"{input_name}: clip {i} has no frames.")
        if arr.shape[1] == 0:
            raise ValueError(f"{input_name}: clip {i} has no channels.")
        if arr.shape[0] < min_frames:
            raise ValueError(
                f"{input_name}: clip {i} has {arr.shape[0]} frame(s); {name} needs "
                f"at least {min_frames}."
            )
        if n_channels is None:
            n_channels = arr.shape[1]
        elif arr.shape[1] != n_channels:
            raise ValueError(
                f"{input_name}: clip {i} has {arr.shape[1]} channels, but clip 0 has "
                f"{n_channels}; all clips of a collection share their channels."
            )
        arr = np.array(arr, dtype=target, order="C", copy=copy or None)
        # A finite sum means every value is finite (one pass, no temporary array);
        # a non-finite one may be an overflow of finite values, so look closer.
        if not np.isfinite(np.add.reduce(arr, axis=None)):
            if allow_nan:
                if np.isinf(arr).any():
                    raise ValueError(
                        _describe_bad_value(np.where(np.isnan(arr), 0, arr), i, input_name)
                    )
            elif not np.isfinite(arr).all():
                raise ValueError(
                    _describe_bad_value(arr, i, input_name)
                    + f"; {name} does not accept missing values (fill gaps first)."
                )
        clips.append(arr)
    return clips, n_channels


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
        raw, container = _collection_from_dataframe(X, input_name)
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


def _check_index_name(value, default):
    return value if value is not None else default


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
    n_channels = clips[0].shape[1] if len(clips) else 0
    if columns is None:
        if container.columns is not None and len(container.columns) == n_channels:
            columns = container.columns
        else:
            columns = [f"channel_{j}" for j in range(n_channels)]
    labels = container.clip_labels
    if labels is None or len(labels) != len(clips):
        labels = pd.RangeIndex(len(clips))
    names = container.index_names or ("clip", "frame")
    lengths = [len(c) for c in clips]
    index = pd.MultiIndex.from_arrays(
        [
            np.repeat(np.asarray(labels, dtype=object), lengths),
            np.concatenate([np.arange(n) for n in lengths]),
        ],
        names=[_check_index_name(names[0], "clip"), _check_index_name(names[1], "frame")],
    )
    values = np.concatenate(clips) if clips else np.empty((0, n_channels))
    return pd.DataFrame(values, index=index, columns=pd.Index(columns))


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
