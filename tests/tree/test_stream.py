"""The streams: the exact one gives the batch answers; the online one its causal recursions."""

import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeHMM, exhaustive_viterbi
from skmotion.tree._calibration import sum_of_paths as _sum_of_paths
from skmotion.tree._decoder._decode import _log_normaliser


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
    stream = model.stream(lag=3, n_best=2, mode="exact")
    for t in range(len(clip)):
        state = stream.update(clip[t])
        if t % 7 and t != len(clip) - 1:
            continue
        prefix = [clip[: t + 1]]
        path = model.decode(prefix)[1][0]
        assert state.frame == t and state.node == path[-1]
        assert state.lagged_node == (path[-4] if t >= 3 else -1)
        np.testing.assert_array_equal(state.proba, model.predict_proba(prefix)[0])
        assert state.label == model.predict(prefix)[0]
        nxt = model.predict_next(prefix, n_best=2)
        np.testing.assert_array_equal(state.next_nodes, nxt.nodes[0])
        np.testing.assert_array_equal(state.next_proba, nxt.probabilities[0])
    np.testing.assert_array_equal(stream.path(), model.decode([clip])[1][0])


@settings(max_examples=20)
@given(
    clip_index=st.integers(0, len(CLIPS) - 1),
    cuts=st.lists(st.integers(1, 20), min_size=1, max_size=12),
    name=st.sampled_from(list(MODELS)),
)
def test_any_chunking_ends_with_the_batch_decode_and_prediction(clip_index, cuts, name):
    model, clip = MODELS[name], CLIPS[clip_index]
    stream = model.stream(mode="exact")
    start = 0
    for size in cuts + [len(clip)]:
        if start >= len(clip):
            break
        state = stream.update(clip[start : start + size])
        start += size
    assert state.frame == len(clip) - 1
    path = model.decode([clip])[1][0]
    np.testing.assert_array_equal(stream.path(), path)
    assert state.node == path[-1]
    assert state.label == model.predict([clip])[0]
    np.testing.assert_array_equal(state.proba, model.predict_proba([clip])[0])


def test_window_gives_the_sliding_window_profile():
    model, clip, width = MODELS["class"], CLIPS[5], 12
    stream = model.stream(window=width, mode="exact")
    profile = [stream.update(frame).proba for frame in clip]
    expected = model.predict_proba_windows([clip], width)[0]
    np.testing.assert_array_equal(np.array(profile[width - 1 :]), expected)


def test_nodes_are_the_ancestors_of_the_current_node():
    model = MODELS["class"]
    state = model.stream(mode="exact").update(CLIPS[0][:20])
    tree = model.tree_
    assert len(state.nodes) == model.layer_ + 1 and state.nodes[-1] == state.node
    for layer in range(1, model.layer_ + 1):
        assert tree.parents(layer)[state.nodes[layer]] == state.nodes[layer - 1]
    # an upper layer's ancestor holds the node's frames: its Gaussian's mean is its parent's region
    assert state.nodes[0] == 0


def test_reset_starts_a_new_clip():
    model = MODELS["class"]
    stream = model.stream(mode="exact")
    stream.update(CLIPS[0])
    state = stream.reset().update(CLIPS[6])
    assert state.frame == len(CLIPS[6]) - 1
    assert state.label == model.predict(CLIPS[6:7])[0]


def test_bad_frames_and_parameters():
    model = MODELS["class"]
    stream = model.stream(mode="exact")
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
            model.stream(**kwargs, mode="exact")


@pytest.mark.parametrize("name", ["class", "clip, graph prior"])
def test_an_upper_layer_streams_its_own_decode(name):
    model, clip = MODELS[name], CLIPS[7]
    stream = model.stream(layer=2, lag=4, mode="exact")
    for t in range(0, len(clip), 9):
        state = stream.update(clip[t : t + 9])
        prefix = [clip[: t + 9]]
        path = model.decode(prefix, layer=2)[1][0]
        assert state.node == path[-1] and state.lagged_node == path[-5]
        np.testing.assert_array_equal(state.proba, model.predict_proba(prefix)[0])
    np.testing.assert_array_equal(stream.path(), model.decode([clip], layer=2)[1][0])


def test_a_stream_refuses_a_model_fit_again():
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    stream = model.stream(mode="exact")
    stream.update(CLIPS[0][:5])
    model.partial_fit(CLIPS[6:], LABELS[6:])
    with pytest.raises(ValueError, match="start a new stream"):
        stream.update(CLIPS[0][5:10])


# -- mode="online": the causal beam ------------------------------------------------------

SMALL = {
    "class, layer prior": MotionTreeHMM(max_depth=3, min_samples_leaf=8).fit(CLIPS, LABELS),
    "clip, graph prior, 2 scored layers": MotionTreeHMM(
        max_depth=3, min_samples_leaf=8, graph="clip", node_prior="graph", score_layers=2
    ).fit(CLIPS, LABELS),
    "full": MotionTreeHMM(max_depth=3, min_samples_leaf=8, covariance_type="full").fit(
        CLIPS, LABELS
    ),
}


def _standardised(model, frames):
    return (frames - model.center_) / model.scale_


@pytest.mark.parametrize("name", list(SMALL))
def test_online_with_every_node_kept_is_the_exhaustive_forward_viterbi(name):
    """A beam as wide as the widest layer keeps every node: the recursions are exhaustive."""
    model = SMALL[name]
    tree, layer, lag = model.tree_, model.layer_, 3
    wide = int(tree.n_nodes.max())
    clip = CLIPS[4][:40]
    stream = model.stream(mode="online", beam=wide, lag=lag)
    std = _standardised(model, clip)
    for t in range(len(clip)):
        state = stream.update(clip[t])
        if t % 6 and t != len(clip) - 1:
            continue
        prefix = std[: t + 1]
        path, _ = exhaustive_viterbi(tree, model.global_graph_, layer, prefix, node_prior="layer")
        assert state.node == path[0, -1]
        assert state.lagged_node == (path[0, -1 - lag] if t >= lag else -1)
        # each graph's n_paths best scores over all node sequences, summed, per scored layer; under
        # node_prior="layer" the online scores leave out the normaliser common to all graphs
        expected = np.zeros(model.graphs_.n_graphs)
        for depth in model.score_layers_:
            for g in range(len(expected)):
                _, score = exhaustive_viterbi(
                    tree,
                    model.graphs_,
                    depth,
                    prefix,
                    g,
                    n_paths=model.n_paths,
                    node_prior=model.node_prior,
                )
                expected[g] += _sum_of_paths(score)
            if model.node_prior == "layer":
                log_po = tree.log_likelihood(prefix, depth)
                expected += _log_normaliser(log_po, np.ones((1, log_po.shape[1]), bool)).sum()
        np.testing.assert_allclose(stream.class_log_likelihood(), expected, rtol=1e-9, atol=1e-7)


def _reference(model, frames, beam, layer):
    """The online recursions written plainly in numpy, keeping every frame's candidates.

    Returns the best path's backtrace at ``layer`` (the node of every frame
    given all frames), each graph's running log-likelihood, and the kept nodes
    and weights of the last frame.
    """
    tree, std = model.tree_, _standardised(model, frames)
    depth_max = max(layer, model.layer_)
    history = {depth: [] for depth in range(1, depth_max + 1)}  # (candidates, back-pointers)
    delta = {depth: None for depth in history}
    alpha = {depth: None for depth in history}
    n_graphs, n_paths = model.graphs_.n_graphs, model.n_paths
    for x in std:
        kept = np.array([0])
        for depth in range(1, depth_max + 1):
            children = tree.children(depth - 1)[kept].ravel()
            cand = children[children >= 0]
            emit = tree.log_likelihood(x[None], depth, cand)[0]
            prev = history[depth][-1][0] if history[depth] else None
            if prev is None:
                new, back = emit.copy(), np.full(len(cand), -1)
            else:
                step = delta[depth][:, None] + (
                    model.global_graph_.log_prob(depth, 0, prev[:, None], cand[None]) + emit
                )
                new, back = step.max(axis=0), step.argmax(axis=0)
            if depth in model.score_layers_:
                log_ps = np.repeat(emit[None], n_graphs, axis=0)
                if model.node_prior == "graph":
                    allowed = model.graphs_.visits(depth) > 0
                    norm = _log_normaliser(tree.log_likelihood(x[None], depth), allowed)[0]
                    log_ps = np.where(allowed[:, cand], log_ps - norm[:, None], -np.inf)
                if prev is None:  # (graph, candidate, rank)
                    alpha[depth] = np.full((n_graphs, len(cand), n_paths), -np.inf)
                    alpha[depth][:, :, 0] = log_ps
                else:
                    g = np.arange(n_graphs)[:, None, None]
                    moves = model.graphs_.log_prob(depth, g, prev[None, :, None], cand[None, None])
                    # (graph, previous candidate, candidate, rank) -> the n_paths best per candidate
                    step = alpha[depth][:, :, None, :] + (moves + log_ps[:, None])[..., None]
                    step = np.moveaxis(step, 2, 1).reshape(n_graphs, len(cand), -1)
                    alpha[depth] = -np.sort(-step, axis=2)[:, :, :n_paths]
            history[depth].append((cand, back))
            delta[depth] = new
            order = np.argsort(-new, kind="stable")[:beam]
            kept = cand[order[np.isfinite(new[order])]]
    slot, path = int(np.argmax(delta[layer])), []
    for cand, back in reversed(history[layer]):
        path.append(cand[slot])
        slot = back[slot]
    order = np.argsort(-delta[layer], kind="stable")[:beam]
    weights = np.exp(delta[layer][order] - delta[layer][order[0]])
    log_lik = 0.0
    for d in model.score_layers_[model.score_layers_ > 0]:
        best = -np.sort(-alpha[d].reshape(n_graphs, -1), axis=1)[:, :n_paths]
        log_lik = log_lik + _sum_of_paths(best)
    return np.array(path[::-1]), log_lik, history[layer][-1][0][order], weights / weights.sum()


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("layer", [None, 2])
def test_online_equals_its_numpy_reference(name, layer):
    model, clip, lag = MODELS[name], CLIPS[2][:30], 4
    stream = model.stream(mode="online", lag=lag, layer=layer, n_best=3)
    depth = model.layer_ if layer is None else layer
    for t in range(len(clip)):
        state = stream.update(clip[t])
        if t % 5 and t != len(clip) - 1:
            continue
        path, log_lik, kept, weights = _reference(model, clip[: t + 1], model.n_paths, depth)
        assert state.node == path[-1]
        assert state.lagged_node == (path[-1 - lag] if t >= lag else -1)
        np.testing.assert_array_equal(state.nodes[-1], state.node)
        np.testing.assert_allclose(stream.class_log_likelihood(), log_lik, rtol=1e-9, atol=1e-7)
        current = np.zeros(model.tree_.n_nodes[depth])
        current[kept] = weights
        future = model.global_graph_.propagate(depth, 0, current[None], 1)[0]
        np.testing.assert_array_equal(state.next_nodes, np.argsort(-future, kind="stable")[:3])
        np.testing.assert_allclose(state.next_proba, np.sort(future)[::-1][:3], rtol=1e-9)
        per_class = np.full(len(model.classes_), -np.inf)
        np.maximum.at(per_class, model.graph_classes_, log_lik)
        proba = np.exp(per_class - per_class.max())
        np.testing.assert_allclose(state.proba, proba / proba.sum(), rtol=1e-9, atol=1e-300)
        assert state.label == model.classes_[np.argmax(per_class)]


def _online_states(model, clip, cuts, **kwargs):
    stream, states, start = model.stream(mode="online", **kwargs), [], 0
    for size in cuts:
        if start >= len(clip):
            break
        states.append(stream.update(clip[start : start + size]))
        start += size
    return stream, states


@settings(max_examples=25)
@given(
    clip_index=st.integers(0, len(CLIPS) - 1),
    cuts=st.lists(st.integers(1, 15), min_size=1, max_size=10),
    name=st.sampled_from(list(MODELS)),
)
def test_online_answers_do_not_depend_on_the_chunking(clip_index, cuts, name):
    model, clip = MODELS[name], CLIPS[clip_index]
    cuts = cuts + [len(clip)]
    _, by_chunk = _online_states(model, clip, cuts, lag=2)
    _, by_frame = _online_states(model, clip, [1] * len(clip), lag=2)
    for state in by_chunk:
        same = by_frame[state.frame]
        assert state.keys() == same.keys()
        for key in state:
            np.testing.assert_array_equal(state[key], same[key])


def test_online_pickle_and_reset():
    model, clip = MODELS["class"], CLIPS[3]
    stream = model.stream(mode="online", lag=3)
    stream.update(clip[:20])
    copy = pickle.loads(pickle.dumps(stream))
    a, b = stream.update(clip[20:]), copy.update(clip[20:])
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])
    again = stream.reset().update(clip)
    fresh = model.stream(mode="online", lag=3).update(clip)
    for key in fresh:
        np.testing.assert_array_equal(again[key], fresh[key])
    assert stream.n_frames == len(clip)


def test_online_bad_input():
    model = MODELS["class"]
    stream = model.stream(mode="online")
    with pytest.raises(ValueError, match="no frame yet"):
        stream.state()
    with pytest.raises(ValueError, match=f"{model.n_features_in_} channels.*got shape \\(3,\\)"):
        stream.update(np.zeros(3))
    bad = CLIPS[0][:4].copy()
    bad[2, 5] = np.inf
    with pytest.raises(ValueError, match="frame 2 .* channel 5 is inf"):
        stream.update(bad)
    assert stream.n_frames == 0  # a chunk with a bad value is refused whole
    with pytest.raises(ValueError, match="mode"):
        model.stream(mode="causal")
    with pytest.raises(ValueError, match="window"):
        model.stream(mode="online", window=10)
    with pytest.raises(ValueError, match="beam"):
        model.stream(mode="exact", beam=4)
    with pytest.raises(ValueError, match="beam"):
        model.stream(mode="online", beam=0)


def test_online_is_the_default_and_refuses_a_model_fit_again():
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    stream = model.stream()
    assert stream.beam == model.n_paths and not hasattr(stream, "window")
    stream.update(CLIPS[0][:5])
    model.partial_fit(CLIPS[6:], LABELS[6:])
    with pytest.raises(ValueError, match="start a new stream"):
        stream.update(CLIPS[0][5:10])
    with pytest.raises(ValueError, match="start a new stream"):
        stream.update(CLIPS[0][5])  # a single frame too (the compiled path)


def test_online_single_frames_take_the_compiled_path_with_the_same_answers():
    model, clip = MODELS["class"], CLIPS[4][:40]
    fast, general = model.stream(lag=2), model.stream(lag=2)
    for frame in clip:
        # a 1-D float64 frame goes through the kernel's step; a list through the general path
        assert fast._step(frame.copy()) is not None
        fast_state = fast.state()
        general_state = general.update(frame.tolist())
        for key in fast_state:
            np.testing.assert_array_equal(fast_state[key], general_state[key])
    # other dtypes, strides and shapes: the general path, the same answers
    for frames in (clip[:5].astype(np.float32), clip[:5, ::-1][:, ::-1], clip[:1]):
        a = model.stream().update(frames)
        b = model.stream().update(np.ascontiguousarray(frames, dtype=np.float64))
        for key in a:
            np.testing.assert_array_equal(a[key], b[key])
    strided = np.asfortranarray(clip[:3])[1]  # a non-contiguous single frame
    assert not strided.flags.c_contiguous
    assert model.stream().update(strided).node == model.stream().update(clip[1]).node


def test_online_single_frame_errors_leave_the_stream_unchanged():
    model, clip = MODELS["class"], CLIPS[0]
    stream = model.stream()
    stream.update(clip[0])
    for value, name in ((np.nan, "nan"), (-np.inf, "-inf")):
        frame = clip[1].copy()
        frame[7] = value
        with pytest.raises(ValueError, match=f"frame 1 .* channel 7 is {name}"):
            stream.update(frame)
    with pytest.raises(ValueError, match=f"{model.n_features_in_} channels.*got shape"):
        stream.update(clip[1][:-1])
    with pytest.raises(ValueError, match=f"{model.n_features_in_} channels.*got shape"):
        stream.update(np.zeros((2, 3, model.n_features_in_)))
    assert stream.n_frames == 1
    after = stream.update(clip[1])
    fresh = model.stream().update(clip[:2])
    for key in fresh:
        np.testing.assert_array_equal(after[key], fresh[key])


def test_online_state_is_a_fixed_mapping_that_pickles():
    model, clip = MODELS["class"], CLIPS[1]
    stream = model.stream(lag=1)
    first = stream.update(clip[0])
    expected = {key: np.copy(first[key]) for key in first}
    for frame in clip[1:10]:
        stream.update(frame)  # later updates do not change an earlier state (read lazily)
    assert first.keys() == tuple(expected) and len(first) == 8 and "proba" in first
    for key in expected:
        np.testing.assert_array_equal(first[key], expected[key])
        np.testing.assert_array_equal(getattr(first, key), expected[key])
    assert dict(first.items()).keys() == expected.keys() and first.get("nope", 3) == 3
    with pytest.raises(KeyError):
        first["nope"]
    again = pickle.loads(pickle.dumps(first))
    for key in expected:
        np.testing.assert_array_equal(again[key], expected[key])
    assert "label=" in repr(again) and first.frame == 0 and first.lagged_node == -1


def test_streams_share_the_models_tables_until_it_is_fit_again():
    """The tables are made once per fitted model: a stream made after partial_fit answers as
    one of a model that never made a stream (no stale table)."""
    first = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    fresh = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    a, b = first.stream(), first.stream()
    assert all(x[2] is y[2] for x, y in zip(a._layers, b._layers))  # shared, not remade
    first.partial_fit(CLIPS[6:], LABELS[6:])
    fresh.partial_fit(CLIPS[6:], LABELS[6:])
    for mode in ("online", "exact"):
        s, t = first.stream(mode=mode), fresh.stream(mode=mode)
        for frame in CLIPS[7]:
            x, y = s.update(frame), t.update(frame)
        assert x.label == y.label and np.array_equal(x.proba, y.proba)
        assert np.array_equal(x.nodes, y.nodes)
