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
from skmotion.live._window_kernel import FrameStep, frame_features, window_scores
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
    threshold : float, default=0.65
        The probability of the best motion that starts (``"rise"``) or whose
        loss ends (``"fall"``) an event.
    refractory : int, default=15
        The fewest frames between two events.
    trigger : {"fall", "maximum", "peak", "rise"}, default="maximum"
        As for :class:`GestureDetector`. The defaults of the rule (``"maximum"``,
        look-ahead 1 frame, threshold 0.65, refractory period 15 frames) are
        the choice of ``GroupKFold(3)`` over the MSRC-12 training people
        (``benchmarks/bench_live.py --only detection``).
    delay : int, default=1
        With ``trigger="maximum"``: the frames of look-ahead that confirm a
        maximum (an event comes ``delay`` frames after the window it names).
    jitter : int or (int, int), default=(0, 4)
        Positive windows also end up to this many frames before and after each
        action point; a pair ``(before, after)`` gives the two sides apart.
        The default, positives at the action point and the 4 frames after it,
        teaches a score that rises as the motion completes, not before (a
        window ending before the action point holds an unfinished motion),
        and stays up a little after: a wider peak, more often above the
        threshold. Out of fold on the MSRC-12 training people (with
        ``negative_gap=3``) it gave F1 0.761 at 0.5 s against 0.733 with
        ``jitter=1`` (``benchmarks/study_live_linear_settings.py``).
    n_negatives : int, default=80
        Windows ending away from action points drawn per training take.
    hard_negatives : int, default=0
        Per training take, a second round of training adds this many windows
        to the rejection class: those the first readout scores highest
        (gesture probability) among the windows ending more than
        ``negative_gap`` frames from every positive window's end.
    negative_gap : int, default=3
        A negative window ends more than this many frames from every positive
        window's end (the frames just around the band are neither: their
        windows hold most of a completed motion).
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
    >>> # trigger="maximum": ``delay`` (1) frame after the window of the highest score
    >>> [event.frame for event in detector.detect([take])[0]]
    [51, 121, 191, 261, 331]
    >>> stream = detector.stream()                       # the same, one frame at a time
    >>> [event.frame for frame in take for event in stream.update(frame)]
    [51, 121, 191, 261, 331]
    >>> # trigger="fall": when the score drops below the threshold after its run above it
    >>> detector = detector.set_params(trigger="fall")
    >>> [event.frame for event in detector.detect([take])[0]]
    [54, 124, 195, 264, 334]
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
        threshold=0.65,
        refractory=15,
        trigger="maximum",
        delay=1,
        jitter=(0, 4),
        n_negatives=80,
        hard_negatives=0,
        negative_gap=3,
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
        self._fit_readout(np.vstack(means), np.concatenate(targets))
        if self.hard_negatives:
            # a second round: the windows the first readout scores highest away from every
            # positive end (false alarms, and the frames just before or after a completion)
            # join the rejection class
            for k, (clip, f, positive) in enumerate(zip(clips, features, moved)):
                hard = self._hard_ends(clip, positive, ends[k])
                means.append(segment_means(f, hard, self.n_segments, self.segment))
                targets.append(np.full(len(hard), self.none_label, dtype=object))
            self._fit_readout(np.vstack(means), np.concatenate(targets))
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
        # StandardScaler leaves constant columns (up to rounding: a root joint) unscaled
        scaler = StandardScaler().fit(means)
        self.mean_, self.scale_ = scaler.mean_, scaler.scale_
        classifier = LogisticRegression(C=self.C, max_iter=3000)
        self.classifier_ = classifier.fit((means - self.mean_) / self.scale_, targets)
        self.classes_ = classifier.classes_
        found = np.flatnonzero(self.classes_ == self.none_label)
        if not len(found):
            raise ValueError(
                f"no window of the rejection class {self.none_label!r}: raise n_negatives."
            )
        self.none_index_ = int(found[0])
        coef, intercept = classifier.coef_, classifier.intercept_
        if len(self.classes_) == 2:  # binary: predict_proba is the softmax of (0, decision)
            coef, intercept = np.vstack([np.zeros_like(coef), coef]), np.r_[0.0, intercept]
        coef = coef / self.scale_
        self.bias_ = intercept - coef @ self.mean_
        n_features = 2 * self.n_features_in_ + len(self.poses_)
        self.weights_ = np.ascontiguousarray(
            (coef / self.segment).T.reshape(self.n_segments, n_features, len(self.classes_))
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
        self._rule_step = dict(threshold=d.threshold, refractory=d.refractory, delay=d.delay)
        n_classes = len(d.classes_)
        self._ring = np.zeros((d.window, d.n_segments, n_classes))
        self._previous = np.zeros(d.n_features_in_)
        self._feature = np.zeros(d.weights_.shape[1])
        one = (np.zeros((1, n_classes)), np.zeros(1), np.zeros(1, dtype=np.intp))
        self._one, self.last_proba = one, one[0][0]
        # the one-frame call: the same arrays bound once (the ring, the last pose, last_proba)
        self._step = FrameStep(self._previous, self._feature, self._ring, *self._args, *one)
        self.reset()

    def reset(self):
        """Forget every frame: the stream starts again."""
        self.n_frames = 0
        self._state = TriggerState()
        self._ring[:] = 0.0
        self.last_proba[:] = 0.0

    def _score(self, frames, out=None):
        """The compiled update over ``frames``: per frame, probabilities, best score and class."""
        n = len(frames)
        proba, score, best = out or (
            np.zeros((n, len(self._classes))),
            np.empty(n),
            np.empty(n, np.intp),
        )
        bad = window_scores(
            frames, self._previous, self._feature, self._ring, self.n_frames, *self._args,
            proba, score, best,
        )  # fmt: skip
        if bad >= 0:
            self.n_frames += bad
            raise ValueError(f"update: frame {self.n_frames} holds NaN or infinity.")
        self.n_frames += n
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
            top, best = self._step(frames, self.n_frames)
            if top != top:  # NaN: the frame held NaN or infinity and was not taken
                raise ValueError(f"update: frame {self.n_frames} holds NaN or infinity.")
            self.n_frames += 1
            state = self._state
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
                    self._state = state._replace(run_best=best, run_score=top)
                    return []
                if self._fall or top == state.run_score:
                    return []
            if self._maximum:  # the same rule in scalars: a few rows, no array operations
                events, self._state = maximum_step(
                    state, self.n_frames - 1, top, best, self._classes, **self._rule_step
                )
                return events
            start, (proba, score, _) = self.n_frames - 1, self._one
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
