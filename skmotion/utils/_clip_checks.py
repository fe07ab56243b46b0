"""One clip at a time: its conversion to a float array and the per-clip checks.

:func:`~skmotion.utils.check_clips` decides what kind of collection it was given;
the functions here take its clips one by one, convert each to a C-contiguous float
array and reject, naming the clip (and the frame and channel), what a clip may not be.
"""

import numpy as np
import pandas as pd
import scipy.sparse as sp


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
