"""LinearGestureDetector: segment means of frame features and a linear readout, frame by frame."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.cluster import KMeans
from sklearn.linear_model import LogisticRegression
from sklearn.preprocessing import StandardScaler
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipEstimatorMixin, MotionTags
from skmotion.live._detector import training_takes
from skmotion.live._events import TRIGGERS, TriggerState, maximum_step, next_events
from skmotion.live._window_kernel import context_scores, frame_features, window_scores
from skmotion.live._windows import training_ends
from skmotion.utils._clips import check_clips
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["LinearGestureDetector", "LinearDetectorStream", "segment_means"]


def segment_means(features, ends, n_segments, segment):
    """Per window ending at ``ends``: the mean feature of each of its segments, side by side.

    Segment ``k`` of the window ending at ``t`` holds frames
    ``t - window + 1 + k * segment`` to ``t - window + (k + 1) * segment``,
    ``window = n_segments * segment`` (one cumulative sum, no loop over frames).

    Returns
    -------
    means : ndarray of shape (len(ends), n_segments * n_features)
    """
    total = np.vstack([np.zeros((1, features.shape[1])), np.cumsum(features, axis=0)])
    first = np.asarray(ends) - n_segments * segment + 1
    return np.hstack(
        [
            (total[first + (k + 1) * segment] - total[first + k * segment]) / segment
            for k in range(n_segments)
        ]
    )


CONTEXT_FOLDS = 3  # folds of training takes for the second readout's out-of-fold inputs


def _clipped_log(proba, first):
    """``log(max(p, 1e-12))`` of each frame's probabilities, zeros before frame ``first`` (no
    full window yet): the second readout's inputs, as :func:`context_scores` computes them."""
    out = np.log(np.maximum(proba, 1e-12))
    out[:first] = 0.0
    return out


def lagged(log_proba, ends, lags):
    """Per end ``t``: the rows ``t - lag`` of ``log_proba`` for each lag side by side (zeros
    before the take's start).

    Returns
    -------
    rows : ndarray of shape (len(ends), len(lags) * log_proba.shape[1])
    """
    padded = np.vstack([np.zeros((int(max(lags)), log_proba.shape[1])), log_proba])
    at = np.asarray(ends)[:, None] - np.asarray(lags)[None, :] + int(max(lags))
    return padded[at].reshape(len(at), -1)


def _readout(means, targets, C, none_label):
    """A logistic regression on standardised ``means``; returns it, the standardisation, and
    its coefficients and intercepts on the raw means (one row per class, also for two)."""
    # StandardScaler leaves constant columns (up to rounding: a root joint) unscaled
    scaler = StandardScaler().fit(means)
    classifier = LogisticRegression(C=C, max_iter=3000)
    classifier.fit((means - scaler.mean_) / scaler.scale_, targets)
    if none_label not in classifier.classes_:
        raise ValueError(f"no window of the rejection class {none_label!r}: raise n_negatives.")
    coef, intercept = classifier.coef_, classifier.intercept_
    if len(classifier.classes_) == 2:  # binary: predict_proba is the softmax of (0, decision)
        coef, intercept = np.vstack([np.zeros_like(coef), coef]), np.r_[0.0, intercept]
    coef = coef / scaler.scale_
    return classifier, scaler.mean_, scaler.scale_, coef, intercept - coef @ scaler.mean_


class LinearGestureDetector(ClipEstimatorMixin, BaseEstimator):
    """Detect motions in a stream at a few microseconds per frame: segment means, a linear readout.

    The window of the last ``n_segments * segment`` frames is described by the
    mean *frame feature* of each of its ``n_segments`` consecutive segments
    (in order: the start of a motion, its middle, its end), and a multinomial
    logistic regression scores it against the rejection class ``none_label``.
    It is trained, as :class:`GestureDetector`, on windows ending at action
    points (and ``jitter`` frames around them) against windows ending
    elsewhere. A frame feature is the frame's joints relative to the ``root``
    joint, divided by the distance between the two ``size_joints`` (the
    body's size; people and their distance to the sensor differ), the
    change of that from the previous frame, and its soft assignment to
    ``n_poses`` reference poses (k-means centres of the training frames'
    poses): a segment's mean of those says which poses it holds, which its
    mean pose alone does not (two different motions can pass through the
    same average).

    Because the readout is linear in the segment means, a window's score is a
    sum over its frames of one weight row per frame and segment: each new
    frame is featurised once and its rows enter a ring of the last window's
    frames, from which the window's score is summed, in a compiled loop. A
    window is scored at every frame for a few microseconds, in constant
    memory; the batch :meth:`scores` run the same loop, so stream and batch
    agree to the last bit. The events come from the decision rule of
    :class:`GestureDetector` (``trigger``, ``threshold``, ``refractory``,
    ``delay``).

    Parameters
    ----------
    n_segments : int, default=5
        Segments per window.
    segment : int, default=4
        Frames per segment (the window: ``n_segments * segment`` frames, 1.3 s at 15 frames/s).
    n_poses : int, default=64
        Reference poses of the soft assignment (k-means on at most
        ``20,000`` training frames' poses); 0: none.
    root : int, default=None
        The joint whose position is subtracted from every joint (channels
        ``3 * root`` to ``3 * root + 2``); None: channels as they are.
        Needs channels in joint order, three per joint.
    size_joints : (int, int), default=None
        Two joints whose distance divides the positions; None: no division.
    C : float, default=0.01
        Inverse regularisation of the logistic regression (on standardised segment means).
    threshold : float, default=0.45
        The probability of the best motion that starts (``"rise"``) or whose
        loss ends (``"fall"``) an event.
    refractory : int, default=15
        The fewest frames between two events.
    trigger : {"fall", "maximum", "peak", "rise"}, default="maximum"
        As for :class:`GestureDetector`. The defaults of the rule (``"maximum"``,
        look-ahead 3 frames, threshold 0.45, refractory period 15 frames) are
        the choice of ``GroupKFold(3)`` over the MSRC-12 training people
        (``benchmarks/bench_live.py --only detection``).
    delay : int, default=3
        With ``trigger="maximum"``: the frames of look-ahead that confirm a
        maximum (an event comes ``delay`` frames after the window it names).
    jitter : int or (int, int), default=1
        Positive windows also end up to this many frames before and after each
        action point; a pair ``(before, after)`` gives the two sides apart:
        ``(0, 2)`` teaches a score that rises as the motion completes, not
        before (a window ending before the action point holds an unfinished
        motion, and may be drawn as a negative).
    n_negatives : int, default=80
        Windows ending away from action points drawn per training take.
    hard_negatives : int, default=0
        Per training take, a second round of training adds this many windows
        to the rejection class: those the first readout scores highest
        (gesture probability) among the windows ending more than
        ``negative_gap`` frames from every positive window's end.
    negative_gap : int, default=1
        A negative window ends more than this many frames from every positive
        window's end.
    context_lags : int, default=0
        A second readout, a logistic regression on the first readout's
        log-probabilities (clipped at ``1e-12``) of this many windows, ending
        ``0, context_step, 2 * context_step, ...`` frames back: a longer
        context than the window, at ``context_lags x n_classes x n_classes``
        products per frame. It learns from out-of-fold first-readout
        probabilities (three folds of the training takes). 0: none.
    context_step : int, default=2
        Frames between two lags of the second readout.
    context_C : float, default=0.01
        Inverse regularisation of the second readout (on standardised inputs).
    none_label : str, default="none"
        The rejection class.
    random_state : int, RandomState instance or None, default=None
        Draws the negative windows and seeds the k-means of the reference poses.

    Attributes
    ----------
    classifier_ : LogisticRegression
        The readout, on standardised segment means.
    poses_ : ndarray of shape (n_poses, n_features_in_)
        The reference poses (root-centred, size-normalised).
    pose_width_ : float
        The squared distance scaling the soft assignment: the median squared
        distance of a training frame to its nearest reference pose.
    mean_, scale_ : ndarray of shape (n_segments * n_frame_features,)
        The standardisation of the segment means (``n_frame_features =
        2 * n_features_in_ + n_poses``).
    weights_ : ndarray of shape (n_segments, n_frame_features, n_classes)
        The readout per frame and segment: a frame feature times
        ``weights_[k]`` is that frame's part of the decision when it lies in segment ``k``.
    bias_ : ndarray of shape (n_classes,)
    context_classifier_ : LogisticRegression or None
        The second readout (None when ``context_lags=0``).
    context_weights_ : ndarray of shape (context_lags, n_classes, n_classes) or None
        Its weights on the raw log-probabilities: ``[l, d, c]`` weighs class
        ``d``'s log-probability ``l * context_step`` frames back for class ``c``.
    context_bias_ : ndarray of shape (n_classes,) or None
    context_mean_, context_scale_ : ndarray of shape (context_lags * n_classes,) or None
        The standardisation of the second readout's inputs.
    classes_ : ndarray
        The classes, ``none_label`` among them.
    none_index_ : int
        The column of ``none_label`` in ``classes_``.
    n_features_in_ : int
        Channels per frame.

    See Also
    --------
    GestureDetector : the same events from any clip recogniser.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.live import LinearGestureDetector
    >>> rng = np.random.default_rng(0)
    >>> take = rng.normal(0, 0.05, (400, 2))
    >>> points = np.arange(49, 400, 70)                  # a repetition completes at 49, 119, ...
    >>> for end in points:                               # a rise over 20 frames, then a drop
    ...     take[end - 19 : end + 1] += np.linspace(0, 1, 20)[:, None]
    >>> detector = LinearGestureDetector(random_state=0)
    >>> detector = detector.fit([take], ["rise"], action_points=[points])
    >>> # trigger="maximum": ``delay`` (3) frames after the window of the highest score
    >>> [event.frame for event in detector.detect([take])[0]]
    [49, 122, 192, 262, 332]
    >>> stream = detector.stream()                       # the same, one frame at a time
    >>> [event.frame for frame in take for event in stream.update(frame)]
    [49, 122, 192, 262, 332]
    >>> # trigger="fall": when the score drops below the threshold after its run above it
    >>> detector = detector.set_params(trigger="fall")
    >>> [event.frame for event in detector.detect([take])[0]]
    [52, 122, 192, 262, 332]
    """

    _parameter_constraints = {
        "n_segments": [Interval(Integral, 1, None, closed="left")],
        "segment": [Interval(Integral, 1, None, closed="left")],
        "n_poses": [Interval(Integral, 0, None, closed="left")],
        "root": [Interval(Integral, 0, None, closed="left"), None],
        "size_joints": [tuple, list, None],
        "C": [Interval(Real, 0, None, closed="neither")],
        "threshold": [Interval(Real, 0, 1, closed="both")],
        "refractory": [Interval(Integral, 0, None, closed="left")],
        "trigger": [StrOptions(set(TRIGGERS))],
        "delay": [Interval(Integral, 0, None, closed="left")],
        "jitter": [Interval(Integral, 0, None, closed="left"), tuple, list],
        "n_negatives": [Interval(Integral, 0, None, closed="left")],
        "hard_negatives": [Interval(Integral, 0, None, closed="left")],
        "negative_gap": [Interval(Integral, 0, None, closed="left")],
        "context_lags": [Interval(Integral, 0, None, closed="left")],
        "context_step": [Interval(Integral, 1, None, closed="left")],
        "context_C": [Interval(Real, 0, None, closed="neither")],
        "none_label": [str],
        "random_state": ["random_state"],
    }
    _motion_tags = MotionTags(output_kind="segments")

    def __init__(
        self,
        *,
        n_segments=5,
        segment=4,
        n_poses=64,
        root=None,
        size_joints=None,
        C=0.01,
        threshold=0.45,
        refractory=15,
        trigger="maximum",
        delay=3,
        jitter=1,
        n_negatives=80,
        hard_negatives=0,
        negative_gap=1,
        context_lags=0,
        context_step=2,
        context_C=0.01,
        none_label="none",
        random_state=None,
    ):
        self.n_segments = n_segments
        self.segment = segment
        self.n_poses = n_poses
        self.root = root
        self.size_joints = size_joints
        self.C = C
        self.threshold = threshold
        self.refractory = refractory
        self.trigger = trigger
        self.delay = delay
        self.jitter = jitter
        self.n_negatives = n_negatives
        self.hard_negatives = hard_negatives
        self.negative_gap = negative_gap
        self.context_lags = context_lags
        self.context_step = context_step
        self.context_C = context_C
        self.none_label = none_label
        self.random_state = random_state

    @property
    def window(self):
        """Frames per window: ``n_segments * segment``."""
        return self.n_segments * self.segment

    def _joints(self):
        """``(root, size_a, size_b)`` for the kernel, -1 for none; checked against the channels."""
        n_joints = self.n_features_in_ // 3
        joints = [-1 if self.root is None else self.root]
        if self.size_joints is not None:
            if len(self.size_joints) != 2:
                raise ValueError(f"size_joints: two joints are needed, got {self.size_joints!r}.")
            joints += [int(j) for j in self.size_joints]
            if min(joints[1:]) < 0:
                raise ValueError(f"size_joints: joint indices are >= 0, got {self.size_joints!r}.")
        else:
            joints += [-1, -1]
        used = [j for j in joints if j >= 0]
        if used and (self.n_features_in_ % 3 or max(used) >= n_joints):
            raise ValueError(
                f"root={self.root}, size_joints={self.size_joints}: joints need three channels "
                f"each; the frames have {self.n_features_in_} channels ({n_joints} joints)."
            )
        return tuple(joints)

    def _jitter(self):
        """``(before, after)``: the frames around an action point at which positive windows end."""
        jitter = self.jitter
        pair = (jitter, jitter) if isinstance(jitter, Integral) else tuple(jitter)
        if len(pair) != 2 or not all(isinstance(j, Integral) and j >= 0 for j in pair):
            raise ValueError(
                "jitter: a number of frames >= 0 or a pair (before, after) of them, "
                f"got {jitter!r}."
            )
        return pair

    def _features(self, take):
        take = np.ascontiguousarray(take, dtype=float)
        return frame_features(take, *self._joints(), self.poses_, self.pose_width_)

    def _fit_poses(self, clips, rng):
        """``poses_`` and ``pose_width_``: k-means of the training frames' normalised poses."""
        width = self.n_features_in_
        self.poses_, self.pose_width_ = np.zeros((0, width)), 1.0
        if self.n_poses == 0:
            return
        poses = np.vstack([self._features(c)[:, :width] for c in clips])
        poses = poses[:: -(-len(poses) // 20000)]  # at most 20,000 frames: k-means stays quick
        if len(np.unique(poses, axis=0)) < self.n_poses:
            raise ValueError(
                f"n_poses={self.n_poses}: the training takes hold fewer distinct frames "
                f"({len(np.unique(poses, axis=0))}); lower n_poses."
            )
        kmeans = KMeans(self.n_poses, n_init=1, random_state=rng.integers(2**31)).fit(poses)
        nearest = kmeans.transform(poses).min(axis=1) ** 2
        width = float(np.median(nearest))
        self.poses_ = np.ascontiguousarray(kmeans.cluster_centers_)
        self.pose_width_ = width if width > 0 else 1.0

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y, *, action_points=None):
        """Train the readout on windows ending at action points (± ``jitter``) and elsewhere.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Long takes, each holding repetitions of motions.
        y : array-like of shape (n_takes,)
            The motion of each take, or per take an array with the motion of
            each of its action points.
        action_points : list of array-like of int, default=None
            Per take, the frames at which a repetition is complete. None: each
            take is one repetition, complete at its last frame.

        Returns
        -------
        self : LinearGestureDetector
            The fitted detector.
        """
        clips, points, labels = training_takes(self, X, y, action_points)
        self._joints()
        # each positive window also ends up to `jitter` frames from its action point
        before, after = self._jitter()
        shifts = np.arange(-before, after + 1)
        moved = [np.clip(p[:, None] + shifts, 0, len(c) - 1).ravel() for p, c in zip(points, clips)]
        moved_labels = [np.repeat(n, len(shifts)) for n in labels]
        rng = np.random.default_rng(check_random_state(self.random_state).randint(2**31))
        self._fit_poses(clips, rng)
        ends, targets = training_ends(
            clips,
            moved,
            moved_labels,
            window=self.window,
            none_label=self.none_label,
            n_negatives=self.n_negatives,
            gap=self.negative_gap,
            rng=rng,
        )
        if len(set(np.concatenate(targets)) - {self.none_label}) == 0:
            raise ValueError(
                f"no action point ends a full window of {self.window} frames: shorten the window."
            )
        features = [self._features(c) for c in clips]
        means = [segment_means(f, e, self.n_segments, self.segment) for f, e in zip(features, ends)]
        self.context_weights_ = None  # the first readout alone scores the hard negatives
        self._fit_readout(np.vstack(means), np.concatenate(targets))
        if self.hard_negatives:
            # a second round: the windows the first readout scores highest away from every
            # positive end (false alarms, and the frames just before or after a completion)
            # join the rejection class
            for k, (clip, f, positive) in enumerate(zip(clips, features, moved)):
                hard = self._hard_ends(clip, positive, ends[k])
                ends[k] = np.r_[ends[k], hard]
                means[k] = np.vstack(
                    [means[k], segment_means(f, hard, self.n_segments, self.segment)]
                )
                targets[k] = np.r_[targets[k], np.full(len(hard), self.none_label, dtype=object)]
            self._fit_readout(np.vstack(means), np.concatenate(targets))
        self._fit_context(means, targets, features, ends)
        return self

    def _hard_ends(self, clip, positive, taken):
        """The ``hard_negatives`` window ends of ``clip`` the readout scores highest, more than
        ``negative_gap`` frames from every ``positive`` end and not among ``taken``."""
        proba, score, _ = self.stream()._score(np.ascontiguousarray(clip, dtype=float))
        ends = np.arange(self.window - 1, len(clip))
        if len(positive) and len(ends):
            far = np.abs(ends[:, None] - positive[None, :]).min(axis=1) > self.negative_gap
            ends = ends[far]
        ends = np.setdiff1d(ends, taken)
        order = np.argsort(-score[ends], kind="stable")[: self.hard_negatives]
        return np.sort(ends[order])

    def _fit_readout(self, means, targets):
        """The logistic regression on standardised segment means, and its per-frame weights."""
        found = _readout(means, targets, self.C, self.none_label)
        self.classifier_, self.mean_, self.scale_, coef, self.bias_ = found
        self.classes_ = self.classifier_.classes_
        self.none_index_ = int(np.flatnonzero(self.classes_ == self.none_label)[0])
        n_features = 2 * self.n_features_in_ + len(self.poses_)
        self.weights_ = np.ascontiguousarray(
            (coef / self.segment).T.reshape(self.n_segments, n_features, len(coef))
        )

    def _fit_context(self, means, targets, features, ends):
        """The second readout: on out-of-fold first-readout log-probabilities at the lags.

        Per training take: its windows' segment ``means``, their ``targets``,
        its frame ``features`` and the windows' ``ends``. The first readout of
        each of ``CONTEXT_FOLDS`` folds of takes (trained on the other takes)
        scores the fold's takes at every frame, so that the second readout
        learns from probabilities as wrong as those of takes it never saw.
        """
        self.context_classifier_ = self.context_weights_ = self.context_bias_ = None
        self.context_mean_ = self.context_scale_ = None
        if not self.context_lags:
            return
        lags = self.context_step * np.arange(self.context_lags)
        rows = [None] * len(means)
        for held in np.array_split(np.arange(len(means)), min(CONTEXT_FOLDS, len(means))):
            others = np.setdiff1d(np.arange(len(means)), held)
            others = others if len(others) else held  # one take: its in-sample probabilities
            found = _readout(
                np.vstack([means[i] for i in others]),
                np.concatenate([targets[i] for i in others]),
                self.C,
                self.none_label,
            )
            classifier, mean, scale = found[:3]
            columns = np.searchsorted(self.classes_, classifier.classes_)
            for i in held:
                every = np.arange(self.window - 1, len(features[i]))
                window_means = segment_means(features[i], every, self.n_segments, self.segment)
                proba = np.zeros((len(features[i]), len(self.classes_)))
                if len(every):
                    proba[np.ix_(every, columns)] = classifier.predict_proba(
                        (window_means - mean) / scale
                    )
                rows[i] = lagged(_clipped_log(proba, self.window - 1), ends[i], lags)
        found = _readout(np.vstack(rows), np.concatenate(targets), self.context_C, self.none_label)
        self.context_classifier_, self.context_mean_, self.context_scale_ = found[:3]
        coef, self.context_bias_ = found[3:]
        n_classes = len(self.classes_)
        self.context_weights_ = np.ascontiguousarray(
            coef.T.reshape(len(lags), n_classes, n_classes)
        )

    def stream(self):
        """A stream fed frame by frame, emitting the events of :meth:`detect`.

        Returns
        -------
        stream : LinearDetectorStream
        """
        check_is_fitted(self)
        return LinearDetectorStream(self)

    def scores(self, X):
        """The scored frames of each take and the class probabilities of their windows.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        scores : list of (ndarray of int, ndarray of shape (n_windows_i, n_classes))
            Per take, the frame each window ends at (every frame from
            ``window - 1``) and its probabilities (columns in the order of ``classes_``).
        """
        check_is_fitted(self)
        out = []
        for take in check_clips(X, estimator=self):
            proba, _, _ = self.stream()._score(np.ascontiguousarray(take, dtype=float))
            ends = np.arange(self.window - 1, len(take), dtype=np.intp)
            out.append((ends, proba[self.window - 1 :]))
        return out

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
        rule = dict(
            threshold=self.threshold,
            refractory=self.refractory,
            trigger=self.trigger,
            delay=self.delay,
        )
        return [
            next_events(ends, proba, self.classes_, self.none_index_, state=TriggerState(), **rule)[
                0
            ]
            for ends, proba in self.scores(X)
        ]


class LinearDetectorStream:
    """The live side of :class:`LinearGestureDetector` (made by its ``stream()``).

    Holds the last window's per-frame weight rows (``window x n_segments x
    n_classes`` numbers), the last pose and the decision rule's state: its
    memory does not grow with the stream. A frame whose best motion is below
    the threshold while no run above it is open cannot emit (the decision
    rule would return no event and the same state), so it costs the compiled
    update alone.

    Attributes
    ----------
    n_frames : int
        Frames seen since the start (or the last :meth:`reset`).
    last_proba : ndarray of shape (n_classes,)
        The probabilities of the last full window (zeros before the first).
    """

    def __init__(self, detector):
        d = detector
        n_features = d.weights_.shape[1]
        # per feature, its rows for every segment side by side: the kernel's contiguous loop
        rows = np.ascontiguousarray(d.weights_.transpose(1, 0, 2).reshape(n_features, -1))
        self._args = (
            rows, d.bias_, *d._joints(), d.poses_, d.pose_width_, d.segment, d.none_index_
        )  # fmt: skip
        self._classes, self._none = d.classes_, d.none_index_
        self._rule = dict(
            threshold=d.threshold, refractory=d.refractory, trigger=d.trigger, delay=d.delay
        )
        self._threshold, self._fall = d.threshold, d.trigger == "fall"
        self._runs = d.trigger in ("fall", "peak")  # the triggers that follow runs of windows
        self._maximum = d.trigger == "maximum"
        self._step = dict(threshold=d.threshold, refractory=d.refractory, delay=d.delay)
        n_classes = len(d.classes_)
        self._ring = np.zeros((d.window, d.n_segments, n_classes))
        self._previous = np.zeros(d.n_features_in_)
        self._feature = np.zeros(d.weights_.shape[1])
        self._one = (np.zeros((1, n_classes)), np.zeros(1), np.zeros(1, dtype=np.intp))
        self.last_proba = self._one[0][0]
        self._context = None
        if getattr(d, "context_weights_", None) is not None:
            lags = d.context_step * np.arange(d.context_lags, dtype=np.intp)
            self._history = np.zeros((lags[-1] + 1, n_classes))  # the last frames' inputs
            self._context = (lags, d.context_weights_, d.context_bias_, d.none_index_)
            self._first = (np.zeros((1, n_classes)), np.zeros(1), np.zeros(1, dtype=np.intp))
        self.reset()

    def reset(self):
        """Forget every frame: the stream starts again."""
        self.n_frames = 0
        self._state = TriggerState()
        self._ring[:] = 0.0
        self.last_proba[:] = 0.0
        if self._context is not None:
            self._history[:] = 0.0

    def _score(self, frames, out=None):
        """The compiled update over ``frames``: per frame, probabilities, best score and class
        (of the second readout when there is one)."""
        n = len(frames)

        def buffers():
            return np.zeros((n, len(self._classes))), np.empty(n), np.empty(n, np.intp)

        proba, score, best = out or buffers()
        first = proba, score, best
        if self._context is not None:  # the first readout's rows go to the second
            first = self._first if out is not None else buffers()
        bad = window_scores(
            frames, self._previous, self._feature, self._ring, self.n_frames, *self._args, *first
        )
        taken = n if bad < 0 else bad
        if self._context is not None:
            # the frames taken before a bad one (their rows: views, made only then)
            rows = (*first[:2], proba, score, best) if bad < 0 else (
                first[0][:taken], first[1][:taken], proba[:taken], score[:taken], best[:taken]
            )  # fmt: skip
            context_scores(
                rows[0], rows[1], self._history, self.n_frames, *self._context, *rows[2:]
            )
        self.n_frames += taken
        if bad >= 0:
            raise ValueError(f"update: frame {self.n_frames} holds NaN or infinity.")
        return proba, score, best

    def update(self, frames):
        """Add one frame (or a chunk of frames) and return the events they complete.

        Parameters
        ----------
        frames : array-like of shape (n_channels,) or (n_frames, n_channels)

        Returns
        -------
        events : list of Event
            The events emitted at these frames (usually none).
        """
        frames = np.ascontiguousarray(frames, dtype=float)
        width = len(self._previous)
        if frames.shape == (width,):  # the one-frame path: no copies, one compiled call
            proba, score, best = self._score(frames.reshape(1, width), self._one)
            state, top = self._state, float(score[0])
            # the two cases in which next_events would emit nothing, said in scalars
            if state.run_best is None and top < self._threshold:
                # below the threshold, no run open and no maximum waiting for its look-ahead
                # (rows are decided in order: the last one's flag says all): no event, and
                # the windows kept can decide nothing more (they are dropped at the next call)
                if state.recent is None or state.recent[-1, 3] == 1.0:
                    return []
            if self._runs and state.run_best is not None and top >= self._threshold:
                if state.run_score == np.inf:  # "peak" has fired in this run: nothing until it ends
                    return []
                if top > state.run_score:  # a run goes on: it keeps its best motion
                    self._state = state._replace(run_best=best[0], run_score=top)
                    return []
                if self._fall or top == state.run_score:
                    return []
            if self._maximum:  # the same rule in scalars: a few rows, no array operations
                events, self._state = maximum_step(
                    state, self.n_frames - 1, top, int(best[0]), self._classes, **self._step
                )
                return events
            start = self.n_frames - 1
        else:
            if frames.ndim != 2 or frames.shape[1] != width:
                raise ValueError(
                    f"update: frames must have {width} channels, got an array of shape "
                    f"{frames.shape}."
                )
            if not len(frames):
                return []
            start = self.n_frames
            proba, score, _ = self._score(frames)
            self.last_proba[:] = proba[-1] if score[-1] >= 0 else self.last_proba
        full = score >= 0
        ends = np.arange(start, start + len(score))[full]
        events, self._state = next_events(
            ends, proba[full], self._classes, self._none, state=self._state, **self._rule
        )
        return events
