"""ActivitySegmenter: frame labels of concatenated clips with known boundaries."""

import numpy as np
import pytest

from skmotion.datasets import make_motions
from skmotion.estimator_checks import ClipCase, parametrize_with_clip_checks
from skmotion.live import ActivitySegmenter
from skmotion.live._segmenter import _covering_mean, path_labels, runs, switch_path


def concatenated(X, y, idx, seed):
    """Takes of four clips each, one after another: frame labels known to the frame."""
    order = np.random.default_rng(seed).permutation(idx)
    takes, truth = [], []
    for k in range(0, len(order) - 3, 4):
        parts = order[k : k + 4]
        takes.append(np.concatenate([X[i] for i in parts]))
        truth.append(np.concatenate([np.full(len(X[i]), y[i], dtype=object) for i in parts]))
    return takes, truth


def test_held_out_subjects_concatenated_clips_are_labelled_frame_by_frame():
    data = make_motions(n_clips_per_class=8, classes=["walk", "jump", "wave"], random_state=0)
    X, y, groups = [c[:, 6:] for c in data.clips], data.target_names[data.target], data.groups
    train, test = np.flatnonzero(groups < 2), np.flatnonzero(groups >= 2)
    model = ActivitySegmenter(window=20).fit([X[i] for i in train], y[train])
    takes, truth = concatenated(X, y, test, seed=0)
    predicted = model.predict_frames(takes)
    accuracy = np.mean(np.concatenate(predicted) == np.concatenate(truth))
    assert accuracy >= 0.9
    for take, segments in zip(takes, model.segments(takes)):  # contiguous, every frame once
        starts, ends = [s for s, _, _ in segments], [e for _, e, _ in segments]
        assert starts[0] == 0 and ends[-1] == len(take) and starts[1:] == ends[:-1]


def test_per_frame_labels_in_training_and_the_rejection_threshold(rng):
    low, high = rng.normal(0, 0.1, (300, 2)), rng.normal(1, 0.1, (300, 2))
    take = np.concatenate([low[:100], high[:100], low[100:200]])
    labels = np.repeat(np.array(["low", "high", "low"], dtype=object), 100)
    model = ActivitySegmenter(window=10, step=2).fit([take], [labels])
    test = np.concatenate([low[200:260], high[200:240], low[260:300]])
    assert model.segments([test])[0] == [(0, 60, "low"), (60, 100, "high"), (100, 140, "low")]
    # nothing is sure of itself above 1: every frame is "nothing known"
    model.set_params(threshold=1.0, none_label="rest")
    assert set(model.predict_frames([test])[0]) == {"rest"}


def test_a_soft_vote_of_recognisers_labels_with_their_mean_frame_probabilities(rng):
    """Two recognisers averaged by sklearn's soft VotingClassifier (the labelling study's
    choice on MSRC-12): each frame's probabilities are the mean of the two segmenters'
    (a frame's probabilities are a mean of window probabilities, linear in them)."""
    from sklearn.ensemble import VotingClassifier
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline

    from skmotion.preprocessing import FlattenClips, ResampleClips

    members = [
        ("flat", make_pipeline(FlattenClips(), LogisticRegression(C=0.1))),
        ("coarse", make_pipeline(ResampleClips(n_frames=3), FlattenClips(), LogisticRegression())),
    ]
    low, high = rng.normal(0, 0.5, (300, 2)), rng.normal(0.5, 0.5, (300, 2))
    X, y = [low[:200], high[:200]], ["low", "high"]
    test = [np.concatenate([low[200:], high[200:], low[250:]])]
    vote = VotingClassifier(members, voting="soft")
    got = ActivitySegmenter(vote, window=12, step=3).fit(X, y).predict_proba_frames(test)[0]
    alone = [
        ActivitySegmenter(m, window=12, step=3).fit(X, y).predict_proba_frames(test)[0]
        for _, m in members
    ]
    np.testing.assert_allclose(got, (alone[0] + alone[1]) / 2)
    assert not np.allclose(alone[0], alone[1])  # the members differ: the mean is a real mix


@pytest.mark.parametrize("n_frames, window, step", [(50, 10, 3), (50, 10, 1), (12, 5, 20)])
def test_covering_mean_is_the_mean_of_the_windows_over_each_frame(n_frames, window, step, rng):
    ends = np.arange(window - 1, n_frames, step)
    proba = rng.random((len(ends), 3))
    got = _covering_mean(proba, ends, n_frames, window)
    for f in range(n_frames):
        over = [i for i, e in enumerate(ends) if e - window + 1 <= f <= e]
        nearest = min(np.searchsorted(ends, f), len(ends) - 1)
        expected = proba[over].mean(axis=0) if over else proba[nearest]
        np.testing.assert_allclose(got[f], expected)


def test_runs_by_hand():
    assert runs(["a", "a", "b", "a"]) == [(0, 2, "a"), (2, 3, "b"), (3, 4, "a")]
    assert runs([]) == []


def test_bad_labels_are_named(rng):
    take = rng.normal(size=(30, 2))
    with pytest.raises(ValueError, match="take 0 has 3 frame labels for 30 frames"):
        ActivitySegmenter().fit([take], [["a", "b", "c"]])
    with pytest.raises(ValueError, match="2 labels for 1 takes"):
        ActivitySegmenter().fit([take], ["a", "b"])


def motion_clips():
    data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


@parametrize_with_clip_checks(
    [
        ClipCase(
            ActivitySegmenter(window=8),
            motion_clips,
            skip={
                "check_cross_val_score": "frame labels are no clip score",
                "check_grid_search": "frame labels are no clip score",
            },
        )
    ]
)
def test_conformance(check):
    check()


def _path_value(score, path, penalty):
    path = np.asarray(path)
    return score[np.arange(len(path)), path].sum() - penalty * np.count_nonzero(np.diff(path))


def test_switch_path_is_the_best_path_of_all(rng):
    # brute force over every path of small trellises
    import itertools

    for _ in range(200):
        n, k = rng.integers(1, 7), rng.integers(1, 4)
        score, penalty = rng.normal(size=(n, k)), rng.uniform(0, 2)
        best = max(_path_value(score, p, penalty) for p in itertools.product(range(k), repeat=n))
        got = switch_path(score, penalty)
        assert got.dtype == np.intp and got.shape == (n,)
        assert _path_value(score, got, penalty) == pytest.approx(best, abs=1e-12)


def test_switch_path_by_hand():
    # one frame favours "b" by 1: worth a detour when two switches cost less than 1
    score = np.log([[0.9, 0.1], [0.9, 0.1], [0.2, 0.8], [0.9, 0.1]])
    gain = np.log(0.8) - np.log(0.2)  # 1.386: what "b" at frame 2 gains
    assert switch_path(score, 0.0).tolist() == [0, 0, 1, 0]
    assert switch_path(score, gain / 2 - 0.01).tolist() == [0, 0, 1, 0]
    assert switch_path(score, gain / 2 + 0.01).tolist() == [0, 0, 0, 0]
    assert switch_path(np.zeros((0, 3)), 1.0).tolist() == []


def test_switch_penalty_removes_short_flips_and_keeps_long_segments():
    classes = np.array(["a", "b"], dtype=object)
    proba = np.full((100, 2), [0.7, 0.3])
    proba[50:] = [0.2, 0.8]  # a long "b" segment
    proba[20:23] = [0.4, 0.6]  # a short, weak flip to "b" inside "a"
    plain = path_labels(proba, classes, switch_penalty=0, threshold=0, none_label="-")
    assert [(s, e, c) for s, e, c in runs(plain)] == [
        (0, 20, "a"), (20, 23, "b"), (23, 50, "a"), (50, 100, "b")
    ]  # fmt: skip
    # the flip gains 3 * log(0.6 / 0.4) = 1.2 against two switches
    smooth = path_labels(proba, classes, switch_penalty=1.0, threshold=0, none_label="-")
    assert runs(smooth) == [(0, 50, "a"), (50, 100, "b")]
    # a label below the threshold is nothing known
    low = path_labels(proba, classes, switch_penalty=1.0, threshold=0.75, none_label="-")
    assert runs(low) == [(0, 50, "-"), (50, 100, "b")]


def test_switch_penalty_in_predict_frames_labels_a_noisy_take(rng):
    low, high = rng.normal(0, 0.1, (300, 2)), rng.normal(1, 0.1, (300, 2))
    model = ActivitySegmenter(window=10, step=2, switch_penalty=5.0).fit([low, high], ["lo", "hi"])
    take = np.concatenate([low[:120], high[:120]])
    take[50:53] = 1.0  # a blip of "hi" inside "lo": three frames, less than a window
    assert model.segments([take])[0] == [(0, 120, "lo"), (120, 240, "hi")]
