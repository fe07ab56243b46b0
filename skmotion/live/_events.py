"""Events from window scores: one decision rule, shared by the batch and the streaming detector.

A detector scores a window every ``step`` frames: one probability per class,
the "nothing known" class among them. The rule emits an event at an evaluated
frame when the best gesture's probability reaches ``threshold`` and at least
``refractory`` frames have passed since the last event. The threshold trades
misses for false alarms; the refractory period turns the run of high scores
around one repetition into one event. Both the batch ``detect`` and the stream
call :func:`next_events`, so they emit the same events from the same scores.
"""

from typing import NamedTuple

import numpy as np

__all__ = ["Event", "gesture_scores", "next_events"]


class Event(NamedTuple):
    """A recognised motion: the frame it was emitted at, its label and its score."""

    frame: int
    label: object
    score: float


def gesture_scores(proba, none_index):
    """Per evaluated window: the best gesture's column (``none_index`` never wins) and probability."""
    masked = np.array(proba, dtype=float, copy=True)
    if none_index is not None:
        masked[:, none_index] = -np.inf
    best = np.argmax(masked, axis=1)
    return best, masked[np.arange(len(masked)), best]


def next_events(ends, proba, classes, none_index, *, threshold, refractory, last):
    """Events among evaluated windows, in order, and the frame of the last event.

    Parameters
    ----------
    ends : ndarray of int
        The frame each window ends at (increasing).
    proba : ndarray of shape (len(ends), n_classes)
        Class probabilities of each window.
    classes : ndarray
        The class of each column.
    none_index : int or None
        The column of "nothing known" (never emitted).
    threshold : float
        The least gesture probability of an event.
    refractory : int
        The fewest frames between two events.
    last : int or None
        The frame of the last event before ``ends[0]`` (None: none yet).

    Returns
    -------
    events : list of Event
    last : int or None
    """
    best, score = gesture_scores(proba, none_index)
    events = []
    # only the windows at or above the threshold can emit: a short loop, not one per frame
    for i in np.flatnonzero(score >= threshold):
        frame = int(ends[i])
        if last is None or frame - last >= refractory:
            events.append(Event(frame, classes[best[i]], float(score[i])))
            last = frame
    return events, last
