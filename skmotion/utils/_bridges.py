"""Clip collections to and from the forms of aeon, sktime and tslearn.

skmotion's clips are frames by channels, ``(n_frames_i, n_channels)``, and may differ
in length. aeon (and sktime's ``numpy3D``) put channels first: a 3-D array
``(n_cases, n_channels, n_timepoints)`` when every series has one length, else aeon's
"np-list", a list of 2-D arrays ``(n_channels, n_timepoints_i)``. tslearn pads a
collection into ``(n_ts, max_sz, d)`` with NaN after each series' end
(``tslearn.utils.to_time_series_dataset``). These functions are plain array reshapes;
no other library is imported.
"""

import numpy as np

from skmotion.utils._clips import check_clips

__all__ = ["from_aeon", "from_tslearn", "to_aeon", "to_tslearn"]


def to_aeon(X, *, equal_length="auto"):
    """A clip collection in aeon's channels-first form.

    Parameters
    ----------
    X : clip collection
        A list of ``(n_frames_i, n_channels)`` arrays, a 3-D array or a
        ``(clip, frame)`` DataFrame.
    equal_length : {"auto", True, False}, default="auto"
        ``"auto"`` gives a 3-D array when every clip has one length, else a
        list; ``False`` always a list; ``True`` a 3-D array, or an error
        naming the first clip of another length.

    Returns
    -------
    X_aeon : ndarray of shape (n_clips, n_channels, n_frames) or list of ndarray
        aeon's ``numpy3D``, or its ``np-list`` of ``(n_channels, n_frames_i)``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import from_aeon, to_aeon
    >>> clips = [np.arange(6.0).reshape(3, 2), np.arange(8.0).reshape(4, 2)]
    >>> [x.shape for x in to_aeon(clips)]
    [(2, 3), (2, 4)]
    >>> to_aeon([clips[0], clips[0]]).shape
    (2, 2, 3)
    >>> all(np.array_equal(a, b) for a, b in zip(from_aeon(to_aeon(clips)), clips))
    True
    """
    if equal_length not in ("auto", True, False):
        raise ValueError(f"equal_length must be 'auto', True or False; got {equal_length!r}.")
    clips = check_clips(X, allow_nan=True)
    lengths = clips.lengths
    same = bool(np.all(lengths == lengths[0]))
    if equal_length is True and not same:
        k = int(np.flatnonzero(lengths != lengths[0])[0])
        raise ValueError(
            f"to_aeon(equal_length=True): clip {k} has {lengths[k]} frames, clip 0 has "
            f"{lengths[0]}; resample first (ResampleClips(n_frames=...)) or pass "
            "equal_length='auto' for aeon's list of unequal-length series."
        )
    if same and equal_length is not False:
        return np.ascontiguousarray(np.stack(list(clips)).transpose(0, 2, 1))
    return [np.ascontiguousarray(clip.T) for clip in clips]


def from_aeon(X):
    """Clips (frames by channels) from aeon's or sktime's channels-first collections.

    Parameters
    ----------
    X : ndarray of shape (n_cases, n_channels, n_timepoints) or list of ndarray
        aeon's ``numpy3D`` (sktime's ``numpy3D``) or ``np-list`` of
        ``(n_channels, n_timepoints_i)`` arrays; a 2-D array
        ``(n_cases, n_timepoints)`` is read as univariate series.

    Returns
    -------
    clips : list of ndarray of shape (n_timepoints_i, n_channels)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import from_aeon
    >>> [c.shape for c in from_aeon(np.zeros((5, 3, 40)))][:2]
    [(40, 3), (40, 3)]
    """
    if isinstance(X, np.ndarray):
        if X.ndim == 2:
            X = X[:, None, :]
        if X.ndim != 3:
            raise ValueError(
                f"from_aeon: a {X.ndim}-D array; expected aeon's numpy3D (n_cases, n_channels, "
                "n_timepoints) or a list of (n_channels, n_timepoints) arrays."
            )
        return [np.ascontiguousarray(case.T, dtype=float) for case in X]
    out = []
    for k, case in enumerate(X):
        case = np.asarray(case, dtype=float)
        if case.ndim != 2:
            raise ValueError(
                f"from_aeon: case {k} has shape {case.shape}; each case of aeon's np-list is "
                "(n_channels, n_timepoints)."
            )
        out.append(np.ascontiguousarray(case.T))
    return out


def to_tslearn(X):
    """A clip collection as tslearn's padded dataset ``(n_clips, max_frames, n_channels)``.

    Shorter clips are padded with NaN after their end, as
    ``tslearn.utils.to_time_series_dataset`` does.

    Parameters
    ----------
    X : clip collection

    Returns
    -------
    X_tslearn : ndarray of shape (n_clips, max_n_frames, n_channels)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.utils import from_tslearn, to_tslearn
    >>> padded = to_tslearn([np.ones((2, 1)), np.ones((3, 1))])
    >>> padded[:, :, 0]
    array([[ 1.,  1., nan],
           [ 1.,  1.,  1.]])
    >>> [c.shape for c in from_tslearn(padded)]
    [(2, 1), (3, 1)]
    """
    clips = check_clips(X, allow_nan=True)
    out = np.full((len(clips), int(clips.lengths.max()), clips.n_channels), np.nan)
    for k, clip in enumerate(clips):
        out[k, : len(clip)] = clip
    return out


def from_tslearn(X):
    """Clips from tslearn's padded dataset: each series ends before its trailing NaN frames.

    Parameters
    ----------
    X : array-like of shape (n_ts, max_sz, d)

    Returns
    -------
    clips : list of ndarray of shape (n_frames_i, d)
    """
    X = np.asarray(X, dtype=float)
    if X.ndim != 3:
        raise ValueError(f"from_tslearn: a {X.ndim}-D array; expected (n_ts, max_sz, d).")
    # a frame belongs to the series when any of its channels is a number (tslearn's ts_size)
    seen = ~np.isnan(X).all(axis=2)
    ends = np.where(seen.any(axis=1), X.shape[1] - np.argmax(seen[:, ::-1], axis=1), 0)
    return [np.ascontiguousarray(x[:end]) for x, end in zip(X, ends)]
