"""GestureDetector: recognise motions as they happen in a long take, frame by frame or in batch."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, clone
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipEstimatorMixin, MotionTags
from skmotion.live._events import TRIGGERS, TriggerState, next_events
from skmotion.live._recognizers import class_proba, default_recognizer, recognizer_classes
from skmotion.live._stream import DetectorStream
from skmotion.live._windows import (
    evaluation_ends,
    labels_per_take,
    take_windows,
    training_windows,
)
from skmotion.utils._clips import check_clips
from skmotion.utils._sklearn_compat import HasMethods, Interval, StrOptions, _fit_context

__all__ = ["GestureDetector"]


def training_takes(estimator, X, y, action_points):
    """The checked takes of a detector's ``fit``, their action points and each point's label.

    Both detectors train on the same input; the rejection class may label no action point.
    """
    clips = check_clips(X, estimator=estimator, reset=True)
    if len(y) != len(clips):
        raise ValueError(f"y: {len(y)} labels for {len(clips)} takes.")
    points = _check_points(action_points, clips)
    sizes = [len(take_points) for take_points in points]
    labels = labels_per_take(y, sizes, "take {i} has {got} labels for its {n} action points.")
    none = estimator.none_label
    if any(none in set(names) for names in labels):
        raise ValueError(f"y: the rejection class {none!r} labels an action point.")
    return clips, points, labels


def _check_points(action_points, clips):
    if action_points is None:  # clips that each end as their motion completes
        return [np.array([len(take) - 1], dtype=np.intp) for take in clips]
    if len(action_points) != len(clips):
        raise ValueError(
            f"action_points: one array per take is needed ({len(clips)}), got {len(action_points)}."
        )
    checked = []
    for i, (points, take) in enumerate(zip(action_points, clips)):
        points = np.asarray(points)
        if points.size and (points.ndim != 1 or not np.issubdtype(points.dtype, np.integer)):
            raise ValueError(f"action_points: take {i} must be a 1-D array of frame indices.")
        points = points.astype(np.intp).ravel()
        bad = (points < 0) | (points >= len(take))
        if bad.any():
            raise ValueError(
                f"action_points: take {i} has frame {points[bad][0]} outside its "
                f"{len(take)} frames."
            )
        checked.append(np.sort(points))
    return checked


class GestureDetector(ClipEstimatorMixin, BaseEstimator):
    """Detect motions in a stream: an event ``(frame, label, score)`` when one is recognised.

    A clip recogniser scores the last ``window`` frames every ``step`` frames.
    It is trained on windows that end where a repetition of a motion is
    complete (its *action point*, labelled with the motion) against windows
    that end elsewhere (labelled ``none_label``, the rejection class: "nothing
    known is completing now"), the setting of Fothergill et al. (2012) for
    MSRC-12. An event is emitted at an evaluated frame when the best motion's
    probability falls back below ``threshold`` after a run above it (or, with
    ``trigger="rise"``, when it first reaches it) and ``refractory`` frames
    have passed since the last event: the threshold trades misses for false
    alarms, and ``step`` and ``refractory`` trade latency for cost and for
    repeated events.

    :meth:`detect` scores all windows of whole takes at once;
    :meth:`stream` returns a :class:`DetectorStream` fed one frame (or a
    chunk) at a time, which emits the same events from the same windows, with
    a ring buffer of ``window`` frames: its memory does not grow with the
    stream.

    Parameters
    ----------
    recognizer : classifier, default=None
        A clip classifier (``fit(X, y)`` on a list of clips, then
        ``predict_proba`` or ``decision_function``), cloned and trained by
        :meth:`fit`. None: ``make_pipeline(MotionTreeEncoder(),
        LogisticRegression())``; joint positions of a tracker want a
        ``VirtualMarkerTransform(layout=...)`` first. A recogniser fitted
        elsewhere (on windows, with ``none_label`` among its classes) plugs in
        wrapped in ``sklearn.frozen.FrozenEstimator``.
    window : int, default=30
        Frames per scored window (2 s at 15 frames/s).
    step : int, default=2
        Frames between two scored windows (the first ends at frame ``window - 1``).
    threshold : float, default=0.5
        The probability of the best motion that starts (``"rise"``) or whose
        loss ends (``"fall"``) an event.
    refractory : int, default=15
        The fewest frames between two events.
    trigger : {"fall", "maximum", "peak", "rise"}, default="fall"
        ``"rise"``: an event at the first window whose score reaches
        ``threshold``; ``"fall"``: when the score falls back below it after
        a run at or above it, with the run's best motion and score (a window
        stops matching once its motion is over: the fall marks the
        completion, where a recogniser that knows a motion early rises long
        before it); ``"peak"``: in such a run, at the first window whose
        score is below the run's best so far (one window after the peak; at
        the run's end if it never turns down), once per run; ``"maximum"``:
        ``delay`` frames after a window at or above ``threshold`` whose score
        is the highest of the windows ending within ``delay`` frames of it.
    delay : int, default=2
        The look-ahead of ``trigger="maximum"``, in frames.
    n_negatives : int, default=20
        Windows ending away from action points drawn per training take.
    negative_gap : int, default=3
        A negative window ends more than this many frames from every action point.
    none_label : str, default="none"
        The rejection class.
    random_state : int, RandomState instance or None, default=None
        Draws the negative windows.

    Attributes
    ----------
    recognizer_ : classifier
        The fitted recogniser.
    classes_ : ndarray
        Its classes, ``none_label`` among them.
    none_index_ : int
        The column of ``none_label`` in ``classes_``.
    n_features_in_ : int
        Channels per frame.

    See Also
    --------
    ActivitySegmenter : a label for every frame of a long take.

    References
    ----------
    S. Fothergill, H. Mentis, P. Kohli and S. Nowozin, "Instructing people for
    training gestural interactive systems", CHI 2012.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.live import GestureDetector
    >>> rng = np.random.default_rng(0)
    >>> take = rng.normal(0, 0.05, (400, 2))
    >>> points = np.arange(49, 400, 70)                  # a repetition completes at 49, 119, ...
    >>> for end in points:                               # a rise over 20 frames, then a drop
    ...     take[end - 19 : end + 1] += np.linspace(0, 1, 20)[:, None]
    >>> detector = GestureDetector(window=10, random_state=0)
    >>> detector = detector.fit([take], ["rise"], action_points=[points])
    >>> # trigger="fall": an event when the score drops after its run above the threshold,
    >>> # a few frames after each completion (the last one, at the take's end, never drops)
    >>> [(event.frame, event.label) for event in detector.detect([take])[0]]
    [(53, 'rise'), (123, 'rise'), (193, 'rise'), (263, 'rise'), (333, 'rise')]
    >>> stream = detector.stream()                       # the same, one frame at a time
    >>> [event.frame for frame in take for event in stream.update(frame)]
    [53, 123, 193, 263, 333]
    """

    _parameter_constraints = {
        "recognizer": [HasMethods(["fit"]), None],
        "window": [Interval(Integral, 1, None, closed="left")],
        "step": [Interval(Integral, 1, None, closed="left")],
        "threshold": [Interval(Real, 0, 1, closed="both")],
        "refractory": [Interval(Integral, 0, None, closed="left")],
        "trigger": [StrOptions(set(TRIGGERS))],
        "delay": [Interval(Integral, 0, None, closed="left")],
        "n_negatives": [Interval(Integral, 0, None, closed="left")],
        "negative_gap": [Interval(Integral, 0, None, closed="left")],
        "none_label": [str],
        "random_state": ["random_state"],
    }
    _motion_tags = MotionTags(output_kind="segments")

    def __init__(
        self,
        recognizer=None,
        *,
        window=30,
        step=2,
        threshold=0.5,
        refractory=15,
        trigger="fall",
        delay=2,
        n_negatives=20,
        negative_gap=3,
        none_label="none",
        random_state=None,
    ):
        self.recognizer = recognizer
        self.window = window
        self.step = step
        self.threshold = threshold
        self.refractory = refractory
        self.trigger = trigger
        self.delay = delay
        self.n_negatives = n_negatives
        self.negative_gap = negative_gap
        self.none_label = none_label
        self.random_state = random_state

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y, *, action_points=None):
        """Train the recogniser on windows ending at action points and elsewhere.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Long takes, each holding repetitions of motions.
        y : array-like of shape (n_takes,)
            The motion of each take, or per take an array with the motion of
            each of its action points.
        action_points : list of array-like of int, default=None
            Per take, the frames at which a repetition is complete. None: each
            take is one repetition, complete at its last frame (a collection
            of clips).

        Returns
        -------
        self : GestureDetector
            The fitted detector.
        """
        clips, points, labels = training_takes(self, X, y, action_points)
        rng = np.random.default_rng(check_random_state(self.random_state).randint(2**31))
        windows, targets = training_windows(
            clips,
            points,
            labels,
            window=self.window,
            none_label=self.none_label,
            n_negatives=self.n_negatives,
            gap=self.negative_gap,
            rng=rng,
        )
        if len(set(targets) - {self.none_label}) == 0:
            raise ValueError(
                f"no action point ends a full window of {self.window} frames: shorten window."
            )
        recognizer = default_recognizer() if self.recognizer is None else clone(self.recognizer)
        self.recognizer_ = recognizer.fit(windows, targets)
        self.classes_ = recognizer_classes(self.recognizer_)
        found = np.flatnonzero(self.classes_ == self.none_label)
        if not len(found):
            raise ValueError(
                f"the recogniser's classes lack the rejection class {self.none_label!r}."
            )
        self.none_index_ = int(found[0])
        return self

    def scores(self, X):
        """The evaluated frames of each take and the class probabilities of their windows.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        scores : list of (ndarray of int, ndarray of shape (n_windows_i, n_classes))
            Per take, the frame each window ends at and its probabilities
            (columns in the order of ``classes_``); empty for takes shorter than ``window``.
        """
        check_is_fitted(self)
        return self._scores(check_clips(X, estimator=self))

    def _scores(self, clips):
        ends = [evaluation_ends(len(take), self.window, self.step) for take in clips]
        windows = [w for take, e in zip(clips, ends) for w in take_windows(take, e, self.window)]
        proba = (
            class_proba(self.recognizer_, windows) if windows else np.zeros((0, len(self.classes_)))
        )
        splits = np.cumsum([len(e) for e in ends])[:-1]
        return list(zip(ends, np.split(proba, splits)))

    def detect(self, X):
        """The events of each take, as the stream would emit them.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        events : list of list of Event
            Per take, its events ``(frame, label, score)`` in time order.
        """
        check_is_fitted(self)
        out = []
        for ends, proba in self._scores(check_clips(X, estimator=self)):
            events, _ = next_events(
                ends,
                proba,
                self.classes_,
                self.none_index_,
                threshold=self.threshold,
                refractory=self.refractory,
                trigger=self.trigger,
                delay=self.delay,
                state=TriggerState(),
            )
            out.append(events)
        return out

    def stream(self):
        """A stream fed frame by frame, emitting the events of :meth:`detect`.

        Returns
        -------
        stream : DetectorStream
            ``update(frame)`` (one frame of ``n_features_in_`` channels, or a
            chunk of frames) returns the events of those frames.
        """
        check_is_fitted(self)
        return DetectorStream(
            lambda window: class_proba(self.recognizer_, [window]),
            n_channels=self.n_features_in_,
            window=self.window,
            step=self.step,
            classes=self.classes_,
            none_index=self.none_index_,
            threshold=self.threshold,
            refractory=self.refractory,
            trigger=self.trigger,
            delay=self.delay,
        )
