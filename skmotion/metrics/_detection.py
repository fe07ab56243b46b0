"""Scores of motion detection in a stream: events matched to annotated action points."""

import numpy as np

__all__ = ["detection_counts", "detection_f1"]


def _match(points, point_labels, frames, labels, latency, early):
    """Greedy in time: each action point takes the earliest free event of its label in reach."""
    used = np.zeros(len(frames), dtype=bool)
    hits = np.zeros(len(points), dtype=bool)
    for k, (a, label) in enumerate(zip(points, point_labels)):
        reach = (~used) & (frames >= a - early) & (frames <= a + latency) & (labels == label)
        found = np.flatnonzero(reach)
        if len(found):
            used[found[0]] = hits[k] = True
    return hits, used


def detection_counts(action_points, point_labels, events, *, latency, early=None):
    """True positives, false positives and misses per label, over takes.

    An action point is found by an event of its label emitted at most
    ``early`` frames before it and at most ``latency`` frames after it; each
    event finds at most one action point and each action point is found at
    most once (one event per repetition), greedily in time order. Events that
    find none are false positives (counted under their own label); action
    points that are not found are misses.

    Parameters
    ----------
    action_points : list of array-like of int
        Per take, the frames at which a repetition is complete.
    point_labels : list of array-like
        Per take, the label of each action point.
    events : list of list of (frame, label, score)
        Per take, the detector's events.
    latency : int
        Frames an event may come after its action point.
    early : int, default=None
        Frames an event may come before it (None: ``latency``).

    Returns
    -------
    counts : dict
        ``{label: (true_positives, false_positives, misses)}``.
    """
    early = latency if early is None else early
    counts = {}
    for points, names, found in zip(action_points, point_labels, events):
        points = np.asarray(points)
        names = np.asarray(names, dtype=object)
        frames = np.array([e[0] for e in found], dtype=np.intp)
        labels = np.array([e[1] for e in found], dtype=object)
        hits, used = _match(points, names, frames, labels, latency, early)
        for label in set(names) | set(labels):
            tp, fp, fn = counts.get(label, (0, 0, 0))
            counts[label] = (
                tp + int(np.sum(hits & (names == label))),
                fp + int(np.sum(~used & (labels == label))),
                fn + int(np.sum(~hits & (names == label))),
            )
    return counts


def detection_f1(action_points, point_labels, events, *, latency, early=None):
    """F1 of detection over all labels (micro): ``2 TP / (2 TP + FP + misses)``.

    See :func:`detection_counts` for the matching of events to action points.

    Parameters
    ----------
    action_points, point_labels, events, latency, early
        As for :func:`detection_counts`.

    Returns
    -------
    f1 : float
        1 when every action point is found and no event is false; 0 when none
        is found (or nothing was there to find and events were emitted).

    Examples
    --------
    >>> from skmotion.metrics import detection_f1
    >>> events = [[(12, "kick", 0.9), (30, "kick", 0.8), (52, "duck", 0.7)]]
    >>> detection_f1([[10, 50]], [["kick", "kick"]], events, latency=5)  # 1 found, 2 false, 1 miss
    0.4
    """
    counts = detection_counts(action_points, point_labels, events, latency=latency, early=early)
    tp, fp, fn = (sum(c[i] for c in counts.values()) for i in range(3))
    return 2 * tp / (2 * tp + fp + fn) if tp else 0.0
