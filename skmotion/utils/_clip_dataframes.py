"""(clip, frame) MultiIndex DataFrames: split into clips, built from clips, channel names.

A DataFrame collection holds one row per frame, indexed by ``(clip, frame)``, one
column per channel. :func:`split_dataframe` is the DataFrame step of
:func:`~skmotion.utils.check_clips`, :func:`clips_to_dataframe` the DataFrame case
of :func:`~skmotion.utils.to_container`.
"""

import numpy as np
import pandas as pd

from skmotion.utils._clip_checks import _estimator_name


def _label(value):
    """repr of an index label, without numpy's scalar wrapper."""
    return repr(value.item() if isinstance(value, np.generic) else value)


def split_dataframe(X, input_name):
    """Split a (clip, frame) MultiIndex DataFrame into per-clip arrays.

    Returns the clips (views into ``X.to_numpy()``), the clip labels in order of
    appearance, the names of the two index levels and the columns.
    """
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
        _check_no_gap(input_name, frame_values, starts, labels, codes)
    values = X.to_numpy()
    clips = np.split(values, starts[1:])
    return clips, pd.Index(labels), tuple(index.names), X.columns


def _check_no_gap(input_name, frames, starts, labels, codes):
    """Integer frame labels must run without a hole within each clip.

    A missing frame is not closed silently (velocities, filters and gap filling
    would run across the hole as if no time had passed): it is an error that
    says how to mark the frames missing, as NaN rows that FillGaps can fill.
    Other frame labels (timestamps, floats) are only required to increase.
    """
    if frames.dtype.kind not in "iu":
        return
    step = np.diff(frames)
    step[starts[1:] - 1] = 1
    if (step == 1).all():
        return
    row = int(np.flatnonzero(step != 1)[0])
    clip_label = labels[codes[row]]
    before, after = frames[row].item(), frames[row + 1].item()
    raise ValueError(
        f"{input_name}: clip {_label(clip_label)} jumps from frame {before} to frame {after} "
        f"({after - before - 1} frames missing); frames are not closed up silently. To mark "
        "them missing, skmotion.utils.insert_missing_frames(df) adds a NaN row per missing "
        "frame, which FillGaps can fill."
    )


def insert_missing_frames(X):
    """A NaN row for every frame missing from a clip's integer frame labels.

    skmotion refuses a (clip, frame) DataFrame whose frame labels skip
    (``0, 1, 4``): closing the hole silently would let velocities, filters and
    gap filling run across it as if no time had passed. This makes the hole
    explicit instead: missing values that
    :class:`~skmotion.preprocessing.FillGaps` fills, or that an estimator
    which cannot take NaN refuses with a clear error.

    Parameters
    ----------
    X : DataFrame
        A collection with a two-level (clip, frame) MultiIndex and integer
        frame labels, increasing within each clip.

    Returns
    -------
    filled : DataFrame
        Each clip's rows for every frame from its first label to its last,
        NaN where the frame was missing; clips in their original order.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from skmotion.utils import insert_missing_frames
    >>> index = pd.MultiIndex.from_tuples([("a", 0), ("a", 1), ("a", 3), ("b", 5)],
    ...                                   names=["clip", "frame"])
    >>> df = pd.DataFrame({"x": [0.0, 1.0, 3.0, 5.0]}, index=index)
    >>> insert_missing_frames(df)["x"].tolist()
    [0.0, 1.0, nan, 3.0, 5.0]
    """
    clips, frames = X.index.get_level_values(0), X.index.get_level_values(1)
    if frames.dtype.kind not in "iu":
        raise ValueError(
            f"frame labels must be integers to find missing frames; got {frames.dtype}."
        )
    labels = pd.unique(clips)
    frame = pd.Series(np.asarray(frames), index=clips)
    first, last = frame.groupby(level=0, sort=False).min(), frame.groupby(level=0, sort=False).max()
    full = pd.MultiIndex.from_tuples(
        [(c, f) for c in labels for f in range(int(first[c]), int(last[c]) + 1)],
        names=X.index.names,
    )
    return X.reindex(full)


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


def _check_index_name(value, default):
    return value if value is not None else default


def clips_to_dataframe(clips, container, columns):
    """The clips as a (clip, frame) DataFrame, with the labels of ``container`` where they fit."""
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
