"""Sliding windows over long takes: where a detector looks, and the windows it learns from.

Free functions on arrays. A window of ``window`` frames *ends* at a frame: the
window ending at ``t`` is frames ``t - window + 1 .. t``, the frames a causal
detector has seen when frame ``t`` arrives.
"""

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__ = ["evaluation_ends", "labels_per_take", "take_windows", "training_windows"]


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


def training_windows(takes, action_points, labels, *, window, none_label, n_negatives, gap, rng):
    """Windows ending at action points (their gesture) and ending elsewhere (``none_label``).

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
        Negative windows drawn per take (fewer when the take has fewer places).
    gap : int
        A negative window ends more than ``gap`` frames from every action point.
    rng : numpy.random.Generator

    Returns
    -------
    windows : list of ndarray of shape (window, n_channels)
    y : ndarray of object
    """
    windows, y = [], []
    for take, points, names in zip(takes, action_points, labels):
        keep = (points >= window - 1) & (points < len(take))
        windows += take_windows(take, points[keep], window)
        y += list(names[keep])
        ends = np.arange(window - 1, len(take))
        if len(points) and len(ends):
            distance = np.abs(ends[:, None] - points[None, :]).min(axis=1)
            ends = ends[distance > gap]
        chosen = np.sort(rng.choice(ends, size=min(n_negatives, len(ends)), replace=False))
        windows += take_windows(take, chosen, window)
        y += [none_label] * len(chosen)
    return windows, np.asarray(y, dtype=object)
