"""Sliding windows over long takes: where a detector looks, and the windows it learns from.

Free functions on arrays. A window of ``window`` frames *ends* at a frame: the
window ending at ``t`` is frames ``t - window + 1 .. t``, the frames a causal
detector has seen when frame ``t`` arrives.
"""

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__ = [
    "evaluation_ends",
    "labels_per_take",
    "take_windows",
    "training_ends",
    "training_windows",
]


def evaluation_ends(n_frames, window, step):
    """The frames at which a detector evaluates its window: ``window - 1``, then every ``step``.

    The first full window ends at frame ``window - 1``; a stream counts its
    frames from 0 and evaluates when ``(t - window + 1) % step == 0``, so batch
    and stream look at the same windows.
    """
    if n_frames < window:
        return np.zeros(0, dtype=np.intp)
    return np.arange(window - 1, n_frames, step, dtype=np.intp)


def labels_per_take(y, sizes, mismatch):
    """Per take, one label per item (frame or action point) from ``y``.

    ``y`` gives each take one label, or an array of one label per item; ``sizes``
    are the items of each take; ``mismatch`` is the error's text after ``"y: "``,
    formatted with the take ``i``, the labels it ``got`` and its ``n`` items.
    """
    labels = []
    for i, (label, n) in enumerate(zip(y, sizes)):
        if np.ndim(label) == 0:
            labels.append(np.full(n, label, dtype=object))
            continue
        label = np.asarray(label, dtype=object)
        if label.shape != (n,):
            raise ValueError("y: " + mismatch.format(i=i, got=len(label), n=n))
        labels.append(label)
    return labels


def take_windows(take, ends, window):
    """The windows of ``take`` ending at ``ends``, as read-only views (no copy)."""
    views = sliding_window_view(take, window, axis=0)  # (n_frames - window + 1, channels, window)
    return [views[t - window + 1].T for t in ends]


def training_ends(takes, action_points, labels, *, window, none_label, n_negatives, gap, rng):
    """Per take, the frames its training windows end at and their labels.

    Windows end at the action points (labelled with their gesture) and at
    ``n_negatives`` frames drawn from those more than ``gap`` frames from
    every action point (labelled ``none_label``; fewer when the take has fewer
    places). Only ends of full windows (from frame ``window - 1``) are kept.

    Parameters
    ----------
    takes : list of ndarray of shape (n_frames_i, n_channels)
    action_points : list of ndarray of int
        Per take, the frames at which a repetition is complete.
    labels : list of ndarray
        Per take, the gesture of each action point.
    window : int
    none_label : str
    n_negatives : int
    gap : int
    rng : numpy.random.Generator

    Returns
    -------
    ends : list of ndarray of int
    y : list of ndarray of object
    """
    all_ends, all_y = [], []
    for take, points, names in zip(takes, action_points, labels):
        keep = (points >= window - 1) & (points < len(take))
        ends = np.arange(window - 1, len(take))
        if len(points) and len(ends):
            distance = np.abs(ends[:, None] - points[None, :]).min(axis=1)
            ends = ends[distance > gap]
        chosen = np.sort(rng.choice(ends, size=min(n_negatives, len(ends)), replace=False))
        all_ends.append(np.r_[points[keep], chosen].astype(np.intp))
        all_y.append(np.r_[np.asarray(names, dtype=object)[keep], [none_label] * len(chosen)])
    return all_ends, [np.asarray(y, dtype=object) for y in all_y]


def training_windows(takes, action_points, labels, *, window, none_label, n_negatives, gap, rng):
    """Windows ending at action points (their gesture) and ending elsewhere (``none_label``).

    The windows of :func:`training_ends`, as arrays of shape (window, n_channels).

    Returns
    -------
    windows : list of ndarray of shape (window, n_channels)
    y : ndarray of object
    """
    ends, y = training_ends(
        takes,
        action_points,
        labels,
        window=window,
        none_label=none_label,
        n_negatives=n_negatives,
        gap=gap,
        rng=rng,
    )
    windows = [w for take, e in zip(takes, ends) for w in take_windows(take, e, window)]
    return windows, np.concatenate(y) if y else np.zeros(0, dtype=object)
