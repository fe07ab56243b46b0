"""GestureDetector and its stream: events at planted ends, batch == stream, bounded memory."""

import numpy as np
import pytest
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.frozen import FrozenEstimator
from sklearn.pipeline import make_pipeline
from sklearn.svm import LinearSVC

from skmotion.estimator_checks import ClipCase, parametrize_with_clip_checks
from skmotion.live import DetectorStream, GestureDetector
from skmotion.metrics import detection_f1
from skmotion.tree import MotionTreeEncoder
from tests.conftest import SHARED_DATA


def planted_take(seed, n_reps=6, gap=45, ramp=20):
    """Noise with motions planted in it: a rise of channel 0 ("a") or of channel 1 ("b").

    Each motion rises for ``ramp`` frames and drops back at once; its action point is
    its last frame. Returns the take, the action points and their labels.
    """
    rng = np.random.default_rng(seed)
    take = rng.normal(0, 0.05, (gap * (n_reps + 1), 3))
    labels = rng.choice(np.array(["a", "b"], dtype=object), n_reps)
    points = gap * np.arange(1, n_reps + 1) + rng.integers(-5, 6, n_reps)
    for end, label in zip(points, labels):
        take[end - ramp + 1 : end + 1, "ab".index(label)] += np.linspace(0, 1, ramp)
    return take, points, labels


@pytest.fixture(scope="module", params=["fall", "maximum", "rise"])
def planted(request):
    takes, points, labels = zip(*(planted_take(seed) for seed in range(6)))
    detector = GestureDetector(
        window=12, step=1, refractory=10, trigger=request.param, random_state=0
    )
    detector.fit(list(takes[:4]), list(labels[:4]), action_points=list(points[:4]))
    return detector, takes[4:], points[4:], labels[4:]


def test_events_come_at_the_planted_ends_with_their_labels(planted):
    detector, takes, points, labels = planted
    # "rise": as the window starts to match, a few frames before the end; "fall": when it
    # stops matching, a few frames after; "maximum": ``delay`` (2) frames after the best window
    low, high = (-4, 0) if detector.trigger == "rise" else (1, 6)
    events = detector.detect(list(takes))
    for found, ends, names in zip(events, points, labels):
        assert len(found) == len(ends)  # one event per planted motion, no false alarm
        for event, end, name in zip(found, ends, names):
            assert low <= event.frame - end <= high and event.label == name
            assert detector.threshold <= event.score <= 1
    assert detection_f1(list(points), list(labels), events, latency=6) == 1.0


@pytest.mark.parametrize("chunk", [1, 7, 1000])
def test_the_stream_emits_the_batch_events(planted, chunk):
    detector, takes, _, _ = planted
    (batch,) = detector.detect([takes[0]])
    stream = detector.stream()
    streamed = []
    for start in range(0, len(takes[0]), chunk):
        streamed += stream.update(takes[0][start : start + chunk])
    assert [(e.frame, e.label) for e in streamed] == [(e.frame, e.label) for e in batch]
    np.testing.assert_allclose([e.score for e in streamed], [e.score for e in batch])
    stream.reset()  # starts again: the same events
    again = [e for frame in takes[0] for e in stream.update(frame)]
    assert [e.frame for e in again] == [e.frame for e in batch]


def test_the_stream_scores_the_last_window_in_constant_memory(rng):
    take = rng.normal(size=(500, 2))
    seen = []

    def score(window):
        seen.append(window.copy())
        return np.array([[0.0, 1.0]])

    stream = DetectorStream(
        score,
        n_channels=2,
        window=7,
        step=3,
        classes=np.array(["g", "none"]),
        none_index=1,
        threshold=0.5,
        refractory=0,
    )
    buffer = stream._buffer
    for frame in take:
        stream.update(frame)
    ends = np.arange(6, 500, 3)
    assert len(seen) == len(ends)
    for window, end in zip(seen, ends):
        np.testing.assert_array_equal(window, take[end - 6 : end + 1])
    assert stream._buffer is buffer and buffer.shape == (14, 2)  # no growth with the stream


class Constant(ClassifierMixin, BaseEstimator):
    """Every window: probability ``p`` for "g", the rest for "none"."""

    def __init__(self, p=0.9):
        self.p = p

    def fit(self, X, y):
        self.classes_ = np.array(["g", "none"], dtype=object)
        return self

    def predict_proba(self, X):
        return np.tile([self.p, 1 - self.p], (len(X), 1))


@pytest.mark.parametrize(
    "refractory, threshold, p, expected",
    [
        (5, 0.5, 0.9, [4, 10, 16, 22, 28]),  # windows end at 4, 6, 8, ...: 6 frames >= 5 apart
        (6, 0.5, 0.9, [4, 10, 16, 22, 28]),
        (7, 0.5, 0.9, [4, 12, 20, 28]),
        (0, 0.5, 0.9, list(range(4, 30, 2))),  # every scored window
        (5, 0.95, 0.9, []),  # never sure enough
    ],
)
def test_threshold_and_refractory_period_by_hand(refractory, threshold, p, expected, rng):
    take = rng.normal(size=(30, 2))
    detector = GestureDetector(
        Constant(p), window=5, step=2, threshold=threshold, refractory=refractory, trigger="rise"
    )
    detector.fit([take], ["g"], action_points=[[20]])
    assert [e.frame for e in detector.detect([take])[0]] == expected
    stream = detector.stream()
    assert [e.frame for f in take for e in stream.update(f)] == expected


class Scripted(Constant):
    """Window ``k`` (in scoring order) gets ``scores[k]`` for "g"."""

    def __init__(self, scores=()):
        self.scores = scores

    def predict_proba(self, X):
        p = np.asarray(self.scores, dtype=float)[: len(X)]
        return np.column_stack([p, 1 - p])


def test_the_fall_trigger_by_hand(rng):
    # windows end at frames 2, 3, ..., 11; runs at or above 0.5: windows 1-3 and 6-7
    scores = [0.1, 0.6, 0.9, 0.7, 0.2, 0.4, 0.8, 0.5, 0.3, 0.1]
    take = rng.normal(size=(12, 1))
    detector = GestureDetector(Scripted(scores), window=3, step=1, refractory=0)
    detector.fit([take], ["g"], action_points=[[5]])
    events = detector.detect([take])[0]
    # each run ends at its first window below 0.5 (frames 6 and 10), with the run's best score
    assert [(e.frame, e.label, e.score) for e in events] == [(6, "g", 0.9), (10, "g", 0.8)]
    detector.set_params(refractory=5)  # the second comes 4 frames after the first: dropped
    assert [e.frame for e in detector.detect([take])[0]] == [6]


def test_the_peak_trigger_by_hand(rng):
    # windows end at frames 2, 3, ..., 13; runs at or above 0.5: windows 1-3, 5-8 and 10-11
    scores = [0.1, 0.6, 0.9, 0.7, 0.2, 0.5, 0.5, 0.8, 0.8, 0.3, 0.6, 0.7]
    take = rng.normal(size=(14, 1))
    detector = GestureDetector(Scripted(scores), window=3, step=1, refractory=0, trigger="peak")
    detector.fit([take], ["g"], action_points=[[5]])
    events = detector.detect([take])[0]
    # run 1 turns down at window 3 (frame 5); run 2 never turns down (equal scores do not
    # count), so it fires at its end (frame 11); run 3 climbs to its end (frame 13 is the
    # take's last window: still open, no event)
    assert [(e.frame, e.score) for e in events] == [(5, 0.9), (11, 0.8)]
    detector.set_params(refractory=7)  # the second comes 6 frames after the first: dropped
    assert [e.frame for e in detector.detect([take])[0]] == [5]


def test_a_recogniser_with_decision_function_only_and_a_prefitted_one(planted):
    _, takes, points, labels = planted
    svm = make_pipeline(MotionTreeEncoder(max_depth=3), LinearSVC())  # no predict_proba
    detector = GestureDetector(svm, window=12, step=1, refractory=10, threshold=0.4)
    detector.fit(list(takes), list(labels), action_points=list(points))
    assert detector.detect(list(takes))[0]
    # a recogniser trained elsewhere plugs in frozen: fit leaves it as it was
    frozen = GestureDetector(FrozenEstimator(detector.recognizer_), window=12, step=1)
    frozen.fit(list(takes[:1]), list(labels[:1]), action_points=list(points[:1]))
    np.testing.assert_array_equal(frozen.classes_, detector.classes_)


def test_bad_input_is_named(planted, rng):
    detector, takes, points, labels = planted
    take = takes[0]
    with pytest.raises(ValueError, match="take 0 has frame 999 outside its"):
        GestureDetector().fit([take], ["a"], action_points=[[10, 999]])
    with pytest.raises(ValueError, match="take 0 has 1 labels for its 2 action points"):
        GestureDetector().fit([take], [["a"]], action_points=[[30, 60]])
    with pytest.raises(ValueError, match="one array per take is needed"):
        GestureDetector().fit([take, take], ["a", "a"], action_points=[[30]])
    with pytest.raises(ValueError, match="rejection class 'none' labels an action point"):
        GestureDetector().fit([take], ["none"], action_points=[[30]])
    with pytest.raises(ValueError, match="lack the rejection class"):
        GestureDetector(FrozenEstimator(Constant().fit(None, None)), none_label="rest").fit(
            [take], ["a"], action_points=[[30]]
        )
    stream = detector.stream()
    with pytest.raises(ValueError, match="frames must have 3 channels"):
        stream.update(np.zeros(4))
    with pytest.raises(ValueError, match="frame 2 holds NaN"):
        stream.update(np.array([[0, 0, 0], [0, 0, 0], [0, np.nan, 0]]))


def motion_clips():
    from skmotion.datasets import make_motions

    data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


@parametrize_with_clip_checks(
    [
        ClipCase(
            GestureDetector(window=8, random_state=0),
            motion_clips,
            skip={
                "check_cross_val_score": "events are no score: benchmarks/bench_live.py scores F1",
                "check_grid_search": "events are no score: thresholds are chosen on F1",
            },
        )
    ]
)
def test_conformance(check):
    check()


@pytest.mark.skipif(not (SHARED_DATA / "msrc12").is_dir(), reason="MSRC-12 data absent")
def test_msrc12_two_gestures_are_detected_near_their_action_points():
    from sklearn.linear_model import LogisticRegression
    from sklearn.preprocessing import StandardScaler

    from skmotion.preprocessing import FlattenClips, ResampleClips, VirtualMarkerTransform

    data = np.load(SHARED_DATA / "msrc12" / "msrc12_sequences.npz")
    positions, offsets = data["positions"], data["offsets"]
    aps, ap_offsets = data["action_points"], data["action_point_offsets"]
    # lift outstretched arms (1) and duck (2), people 1-4: odd people train, even test
    chosen = np.flatnonzero(np.isin(data["gesture"], [1, 2]) & (data["person"] <= 4))
    takes = [positions[offsets[i] : offsets[i + 1]].astype(float) for i in chosen]
    points = [aps[ap_offsets[i] : ap_offsets[i + 1]] for i in chosen]
    points = [p[(p >= 0) & (p < len(t))] for p, t in zip(points, takes)]  # in the stored frames
    labels = data["gesture"][chosen].astype(str).astype(object)
    train = data["person"][chosen] % 2 == 1
    recogniser = make_pipeline(  # windows resampled to 10 frames: their order kept
        VirtualMarkerTransform(layout="kinect_v1", frame_rate=15),
        ResampleClips(n_frames=10),
        FlattenClips(),
        StandardScaler(),
        LogisticRegression(C=0.05, max_iter=1000),
    )
    detector = GestureDetector(recogniser, random_state=0)

    def pick(seq, mask):
        return [s for s, m in zip(seq, mask) if m]

    detector.fit(pick(takes, train), labels[train], action_points=pick(points, train))
    held_out = pick(takes, ~train)
    events = detector.detect(held_out)
    names = [np.full(len(p), g, dtype=object) for p, g in zip(pick(points, ~train), labels[~train])]
    # measured 0.86 (one person, two training people); chance is far below
    assert detection_f1(pick(points, ~train), names, events, latency=15) >= 0.8
    stream = detector.stream()  # the stream's events on a real take are the batch's
    part = held_out[0][:150]
    streamed = [e for frame in part for e in stream.update(frame)]
    assert [e[:2] for e in streamed] == [e[:2] for e in detector.detect([part])[0]]
