"""Events from window scores: one decision rule, shared by the batch and the streaming detector.

A detector scores a window every ``step`` frames: one probability per class,
the "nothing known" class among them; a window's *score* is its best
motion's probability. Four triggers turn scores into events:

- ``"rise"``: an event at the first window whose score reaches
  ``threshold`` (the earliest answer; a recogniser that knows a motion before
  it completes fires early);
- ``"fall"``: an event when the score falls back below ``threshold`` after a
  run of windows at or above it, labelled with the run's best motion and
  score. A window that ends as a motion completes stops matching once the
  motion is over, so the fall marks the completion; a higher threshold
  fires sooner (the score drops below it earlier);
- ``"peak"``: in a run of windows at or above ``threshold``, an event at
  the first window whose score is below the run's best so far (the score
  has peaked one window before), labelled with the run's best motion and
  score; a run that never turns down fires as ``"fall"``, at its end. One
  event per run at most. For a recogniser whose score peaks as a motion
  completes: the event comes one window after the peak.
- ``"maximum"``: an event ``delay`` frames after a window whose score is at
  or above ``threshold`` and the highest of every window ending within
  ``delay`` frames before or after it (strictly above those before it, at
  least those after it: one event per plateau), labelled with that window's
  best motion and score; emitted at the first window ending ``delay`` frames
  or more after it. A look-ahead of a few frames, a part of the latency
  budget, picks the true peak of a score that peaks at the completion, where
  ``"peak"`` fires at its first downturn.

In all, an event needs ``refractory`` frames since the last one. The
threshold trades misses for false alarms and, with the trigger, latency.
Both the batch ``detect`` and the stream call :func:`next_events` with the
same state, so they emit the same events from the same scores.
"""

from typing import NamedTuple

import numpy as np

__all__ = ["Event", "TRIGGERS", "TriggerState", "gesture_scores", "next_events"]

TRIGGERS = ("fall", "maximum", "peak", "rise")


class Event(NamedTuple):
    """A recognised motion: the frame it was emitted at, its label and its score."""

    frame: int
    label: object
    score: float


class TriggerState(NamedTuple):
    """What the rule remembers between windows: a few numbers, whatever the stream's length.

    ``last``: the frame of the last event (None: none yet); ``run_best`` and
    ``run_score``: the best motion's column and score in the current run of
    windows at or above the threshold (``run_best`` None: no run; ``run_score``
    infinite: the ``"peak"`` trigger has fired in this run); ``recent``
    (``"maximum"`` only): the windows at or above the threshold that a later
    window may still decide, an array of rows ``(end, score, best, decided)``
    covering at most the last ``2 * delay`` frames (windows below the threshold
    can neither be a maximum nor hide one, so they are not kept).
    """

    last: object = None
    run_best: object = None
    run_score: float = -np.inf
    recent: object = None


def gesture_scores(proba, none_index):
    """Per window: the best gesture's column (never ``none_index``) and its probability."""
    masked = np.array(proba, dtype=float, copy=True)
    if none_index is not None:
        masked[:, none_index] = -np.inf
    best = np.argmax(masked, axis=1)
    return best, masked[np.arange(len(masked)), best]


def next_events(
    ends, proba, classes, none_index, *, threshold, refractory, trigger, state, delay=0
):
    """Events among scored windows, in order, and the rule's state after them.

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
        The score that starts (``"rise"``) or whose loss ends (``"fall"``) an event.
    refractory : int
        The fewest frames between two events.
    trigger : {"fall", "maximum", "peak", "rise"}
    state : TriggerState
        The state after the previous windows (``TriggerState()`` at the start).
    delay : int, default=0
        The look-ahead of ``"maximum"``, in frames (the other triggers ignore it).

    Returns
    -------
    events : list of Event
    state : TriggerState
    """
    best, score = gesture_scores(proba, none_index)
    above = score >= threshold
    last, run_best, run_score = state[:3]
    if trigger == "maximum":
        return _maximum_events(ends, best, score, above, classes, refractory, delay, state)
    events = []
    if trigger == "rise":
        # only the windows at or above the threshold can emit: a short loop, not one per frame
        for i in np.flatnonzero(above):
            frame = int(ends[i])
            if last is None or frame - last >= refractory:
                events.append(Event(frame, classes[best[i]], float(score[i])))
                last = frame
        return events, TriggerState(last, None, -np.inf)
    if trigger == "peak":
        return _peak_events(ends, best, score, above, classes, refractory, state)
    # "fall": walk the runs of windows above the threshold, one event at each run's end
    flips = np.flatnonzero(np.diff(np.r_[run_best is not None, above].astype(np.int8)))
    start = 0 if run_best is not None else None
    for i in flips:
        if start is None:  # a run starts at window i
            start, run_best, run_score = i, None, -np.inf
            continue
        top = start + int(np.argmax(score[start:i])) if i > start else None
        if top is not None and score[top] > run_score:
            run_best, run_score = best[top], float(score[top])
        frame = int(ends[i])  # the first window below the threshold: the run is over
        if last is None or frame - last >= refractory:
            events.append(Event(frame, classes[run_best], run_score))
            last = frame
        start, run_best, run_score = None, None, -np.inf
    if start is not None and start < len(score):  # a run still open: remember its best
        top = start + int(np.argmax(score[start:]))
        if score[top] > run_score or run_best is None:
            run_best, run_score = best[top], float(score[top])
    return events, TriggerState(last, run_best, run_score)


def _peak_events(ends, best, score, above, classes, refractory, state):
    """The ``"peak"`` trigger: :func:`next_events` on windows with their best motions and scores.

    Only the windows at or above the threshold and the first one below after
    each run can change anything: a loop over those, not over every window.
    """
    last, run_best, run_score = state[:3]
    was_above = np.r_[run_best is not None, above[:-1]]
    events = []

    def emit(i, column, value):
        nonlocal last
        frame = int(ends[i])
        if last is None or frame - last >= refractory:
            events.append(Event(frame, classes[column], float(value)))
            last = frame

    for i in np.flatnonzero(above | was_above):
        fired = run_score == np.inf
        if not above[i]:  # the run is over: it fires at its end unless it fired at a peak
            if run_best is not None and not fired:
                emit(i, run_best, run_score)
            run_best, run_score = None, -np.inf
        elif run_best is None or (not fired and score[i] > run_score):
            run_best, run_score = best[i], float(score[i])  # a run starts, or climbs
        elif not fired and score[i] < run_score:  # it turns down: the peak was before
            emit(i, run_best, run_score)
            run_score = np.inf
    return events, TriggerState(last, run_best, run_score)


def _maximum_events(ends, best, score, above, classes, refractory, delay, state):
    """The ``"maximum"`` trigger: :func:`next_events` on windows with their best motions and scores.

    Only the windows at or above the threshold can be a maximum or hide one:
    the state's undecided ones and the new ones are compared with each other
    (at most ``delay`` neighbours on either side), and each is decided at the
    first new window ending ``delay`` frames after it.
    """
    new = np.column_stack(
        [np.asarray(ends, dtype=float), score, best.astype(float), np.zeros(len(score))]
    )[above]
    rows = new if state.recent is None else np.vstack([state.recent, new])
    end, value = rows[:, 0], rows[:, 1]
    n = len(rows)
    peak = np.ones(n, dtype=bool)
    for k in range(1, delay + 1):  # ends are distinct frames: at most `delay` on each side
        near = end[k:] - end[:-k] <= delay if n > k else np.zeros(0, dtype=bool)
        peak[k:] &= ~(near & (value[:-k] >= value[k:]))  # an earlier window as high
        peak[:-k] &= ~(near & (value[k:] > value[:-k]))  # a later window higher
    # decided now: the first new window ending `delay` frames after it exists
    at = np.searchsorted(ends, end + delay, side="left")
    ready = (rows[:, 3] == 0) & (at < len(ends))
    last = state.last
    events = []
    for i in np.flatnonzero(ready & peak):
        frame = int(ends[at[i]])
        if last is None or frame - last >= refractory:
            events.append(Event(frame, classes[int(rows[i, 2])], float(value[i])))
            last = frame
    rows[ready, 3] = 1.0
    if len(ends):  # a later window can only be compared with the last 2 * delay frames
        rows = rows[end > ends[-1] - 2 * delay]
    return events, TriggerState(last, None, -np.inf, rows if len(rows) else None)


def maximum_step(state, end, score, best, classes, *, threshold, refractory, delay):
    """:func:`next_events` with ``trigger="maximum"`` on one window, in Python scalars.

    The same decisions as :func:`_maximum_events` on a single window ``end``
    with its best motion's column ``best`` and probability ``score`` (the
    stream's one-frame path: a few rows, no array operations but the state's).

    Returns
    -------
    events : list of Event
    state : TriggerState
    """
    rows = [] if state.recent is None else state.recent.tolist()
    if score >= threshold:
        rows.append([float(end), score, float(best), 0.0])
    last, events = state.last, []
    for row in rows:
        row_end, value = row[0], row[1]
        if row[3] or row_end + delay > end:  # decided before, or its look-ahead not over
            continue
        row[3] = 1.0
        peak = all(
            not (0 < row_end - e <= delay and v >= value)
            and not (0 < e - row_end <= delay and v > value)
            for e, v, _, _ in rows
        )
        if peak and (last is None or end - last >= refractory):
            events.append(Event(int(end), classes[int(row[2])], float(value)))
            last = int(end)
    rows = [row for row in rows if row[0] > end - 2 * delay]
    return events, TriggerState(last, None, -np.inf, np.array(rows) if rows else None)
