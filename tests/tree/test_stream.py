"""MotionStream: fed frame by frame or in chunks, the batch answers exactly."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeHMM


def _data():
    data = make_motions(
        n_clips_per_class=4, classes=["walk", "jump", "wave"], duration=(0.8, 1.2), random_state=3
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


CLIPS, LABELS = _data()
MODELS = {
    "class": MotionTreeHMM(max_depth=5, min_samples_leaf=8).fit(CLIPS, LABELS),
    "clip, graph prior": MotionTreeHMM(
        max_depth=4, min_samples_leaf=8, graph="clip", node_prior="graph", n_paths=2
    ).fit(CLIPS, LABELS),
    "full, 2 scored layers": MotionTreeHMM(
        max_depth=4, min_samples_leaf=8, covariance_type="full", score_layers=2
    ).fit(CLIPS, LABELS),
}


@pytest.mark.parametrize("name", list(MODELS))
def test_every_prefix_gives_the_batch_answers(name):
    model = MODELS[name]
    clip = CLIPS[1][::2]  # a walk, every other frame
    stream = model.stream(lag=3, n_best=2)
    for t in range(len(clip)):
        state = stream.update(clip[t])
        if t % 7 and t != len(clip) - 1:
            continue
        prefix = [clip[: t + 1]]
        path = model.decode(prefix)[0]
        assert state.frame == t and state.node == path[-1]
        assert state.lagged_node == (path[-4] if t >= 3 else -1)
        np.testing.assert_array_equal(state.proba, model.predict_proba(prefix)[0])
        assert state.label == model.predict(prefix)[0]
        nxt = model.predict_next(prefix, n_best=2)
        np.testing.assert_array_equal(state.next_nodes, nxt.nodes[0])
        np.testing.assert_array_equal(state.next_proba, nxt.probabilities[0])
    np.testing.assert_array_equal(stream.path(), model.decode([clip])[0])


@settings(max_examples=20)
@given(
    clip_index=st.integers(0, len(CLIPS) - 1),
    cuts=st.lists(st.integers(1, 20), min_size=1, max_size=12),
    name=st.sampled_from(list(MODELS)),
)
def test_any_chunking_ends_with_the_batch_decode_and_prediction(clip_index, cuts, name):
    model, clip = MODELS[name], CLIPS[clip_index]
    stream = model.stream()
    start = 0
    for size in cuts + [len(clip)]:
        if start >= len(clip):
            break
        state = stream.update(clip[start : start + size])
        start += size
    assert state.frame == len(clip) - 1
    path = model.decode([clip])[0]
    np.testing.assert_array_equal(stream.path(), path)
    assert state.node == path[-1]
    assert state.label == model.predict([clip])[0]
    np.testing.assert_array_equal(state.proba, model.predict_proba([clip])[0])


def test_window_gives_the_sliding_window_profile():
    model, clip, width = MODELS["class"], CLIPS[5], 12
    stream = model.stream(window=width)
    profile = [stream.update(frame).proba for frame in clip]
    expected = model.predict_proba_windows([clip], width)[0]
    np.testing.assert_array_equal(np.array(profile[width - 1 :]), expected)


def test_nodes_are_the_ancestors_of_the_current_node():
    model = MODELS["class"]
    state = model.stream().update(CLIPS[0][:20])
    tree = model.tree_
    assert len(state.nodes) == model.layer_ + 1 and state.nodes[-1] == state.node
    for layer in range(1, model.layer_ + 1):
        assert tree.parents(layer)[state.nodes[layer]] == state.nodes[layer - 1]
    # an upper layer's ancestor holds the node's frames: its Gaussian's mean is its parent's region
    assert state.nodes[0] == 0


def test_reset_starts_a_new_clip():
    model = MODELS["class"]
    stream = model.stream()
    stream.update(CLIPS[0])
    state = stream.reset().update(CLIPS[6])
    assert state.frame == len(CLIPS[6]) - 1
    assert state.label == model.predict(CLIPS[6:7])[0]


def test_bad_frames_and_parameters():
    model = MODELS["class"]
    stream = model.stream()
    with pytest.raises(ValueError, match="no frame yet"):
        stream.state()
    with pytest.raises(ValueError, match="channels"):
        stream.update(np.zeros(3))
    bad = CLIPS[0][:4].copy()
    bad[2, 5] = np.nan
    with pytest.raises(ValueError, match="frame 2 .* channel 5"):
        stream.update(bad)
    for kwargs in ({"lag": -1}, {"window": 0}, {"n_best": 0}):
        with pytest.raises(ValueError, match=next(iter(kwargs))):
            model.stream(**kwargs)


@pytest.mark.parametrize("name", ["class", "clip, graph prior"])
def test_an_upper_layer_streams_its_own_decode(name):
    model, clip = MODELS[name], CLIPS[7]
    stream = model.stream(layer=2, lag=4)
    for t in range(0, len(clip), 9):
        state = stream.update(clip[t : t + 9])
        prefix = [clip[: t + 9]]
        path = model.decode(prefix, layer=2)[0]
        assert state.node == path[-1] and state.lagged_node == path[-5]
        np.testing.assert_array_equal(state.proba, model.predict_proba(prefix)[0])
    np.testing.assert_array_equal(stream.path(), model.decode([clip], layer=2)[0])


def test_a_stream_refuses_a_model_fit_again():
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    stream = model.stream()
    stream.update(CLIPS[0][:5])
    model.partial_fit(CLIPS[6:], LABELS[6:])
    with pytest.raises(ValueError, match="start a new stream"):
        stream.update(CLIPS[0][5:10])
