"""Top-down beam decoding against the exhaustive Viterbi and against enumeration."""

import itertools

import numpy as np
import pytest
from scipy.special import logsumexp

from skmotion.tree import (
    MotionTree,
    TransitionGraphs,
    beam_decode,
    exhaustive_viterbi,
    kbest_viterbi,
    node_log_posterior,
)
from skmotion.tree._decoder._tables import gaussian_arrays, transition_table


@pytest.fixture(scope="module")
def model():
    """A small tree (up to 7 nodes a layer) over three clips, with two graphs."""
    rng = np.random.default_rng(3)
    frames = np.vstack([rng.normal(c, 1.0, size=(n, 2)) for c, n in [(0, 40), (6, 30), (12, 30)]])
    rng.shuffle(frames[:70])
    offsets = np.array([0, 35, 70, 100])
    tree = MotionTree.build(frames, max_depth=3, min_samples_leaf=8, split="median")
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=[0, 0, 1],
        smoothing=0.5,
    )
    return tree, graphs, frames


def brute_force(tree, graphs, layer, clip, graph, prior):
    """log P(N | X) of every node sequence, from the definition."""
    log_ps = node_log_posterior(tree, graphs, layer, clip, prior)[graph]
    k = log_ps.shape[1]
    log_pt = np.log(graphs.matrix(layer, graph))
    out = []
    for seq in itertools.product(range(k), repeat=len(clip)):
        score = sum(log_ps[t, n] for t, n in enumerate(seq)) + sum(
            log_pt[a, b] for a, b in zip(seq[:-1], seq[1:])
        )
        out.append(score)
    return np.sort(np.array(out))[::-1]


@pytest.mark.parametrize("prior", ["graph", "layer"])
@pytest.mark.parametrize("graph", [0, 1])
def test_exhaustive_viterbi_matches_enumeration(model, prior, graph):
    tree, graphs, frames = model
    clip = frames[[0, 50, 80, 5]]
    for layer in range(tree.n_layers):
        expected = brute_force(tree, graphs, layer, clip, graph, prior)
        expected = expected[np.isfinite(expected)][:4]
        _, scores = exhaustive_viterbi(
            tree, graphs, layer, clip, graph, n_paths=4, node_prior=prior
        )
        np.testing.assert_allclose(scores[: len(expected)], expected)


@pytest.mark.parametrize("prior", ["graph", "layer"])
@pytest.mark.parametrize("guided", [False, True])
def test_a_wide_beam_agrees_with_the_exhaustive_viterbi(model, prior, guided):
    tree, graphs, frames = model
    clip = frames[[3, 40, 75, 99, 10, 60]]
    wide = int(tree.n_nodes.max())
    guide = None
    if guided:  # the upper layers searched on a one-graph "global" graph
        guide = TransitionGraphs.count(
            list(tree.iter_apply(frames)), tree.n_nodes, offsets=[0, 100], graph_of_clip=[0]
        )
    for graph in (0, 1):
        for layer in range(tree.n_layers):
            paths, scores = beam_decode(
                tree,
                graphs,
                clip,
                [0, len(clip)],
                [0],
                [graph],
                layer=layer,
                n_paths=wide,
                node_prior=prior,
                guide=guide,
            )
            ex_paths, ex_scores = exhaustive_viterbi(
                tree, graphs, layer, clip, graph, n_paths=wide, node_prior=prior
            )
            np.testing.assert_allclose(scores[0, 0], ex_scores)
            finite = np.isfinite(ex_scores)
            np.testing.assert_array_equal(paths[0][finite], ex_paths[finite])


@pytest.mark.parametrize("covariance_type", ["diag", "spherical", "full"])
@pytest.mark.parametrize("dense", [True, False])
def test_the_compiled_decoder_agrees_for_every_covariance_and_table(
    monkeypatch, covariance_type, dense
):
    """Emissions of each covariance kind and both transition lookups, against exhaustive Viterbi."""
    from skmotion.tree import _transitions

    rng = np.random.default_rng(5)
    frames = np.vstack([rng.normal(c, 1.0, size=(30, 3)) for c in (0, 4, 8)])
    tree = MotionTree.build(
        frames, max_depth=3, min_samples_leaf=6, split="median", covariance_type=covariance_type
    )
    if not dense:
        monkeypatch.setattr(_transitions, "_DENSE_LIMIT", 0)
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=[0, 45, 90],
        graph_of_clip=[0, 1],
        smoothing=0.5,
    )
    assert (len(transition_table(graphs, 1)["dense"]) > 0) == dense
    clip = frames[[2, 33, 61, 80, 14]] + 0.3
    wide = int(tree.n_nodes.max())
    for graph in (0, 1):
        paths, scores = beam_decode(
            tree, graphs, clip, [0, 5], [0], [graph], layer=-1, n_paths=wide, node_prior="layer"
        )
        ex_paths, ex_scores = exhaustive_viterbi(
            tree, graphs, -1, clip, graph, n_paths=wide, node_prior="layer"
        )
        np.testing.assert_allclose(scores[0, 0], ex_scores, rtol=1e-12)
        np.testing.assert_array_equal(paths[0], ex_paths)


def reference_beams(tree, graphs, clip, graph, n_paths, layer):
    """The per-frame beams from their definition, one layer after another.

    A frame's candidates are the children of its kept nodes (slot ``side * width + w``);
    it keeps the ``n_paths`` with the best max-marginal (the numpy reference
    ``max_marginals`` over the candidates' trellis; ties to the lower slot), stored
    in node order, -1 (no finite score) last.
    """
    from skmotion.tree import max_marginals

    beam = np.zeros((len(clip), 1), dtype=int)
    for depth in range(1, layer + 1):
        kids = tree.children(depth - 1)
        cand = np.array(
            [[kids[n, side] if n >= 0 else -1 for side in (0, 1) for n in row] for row in beam]
        )
        if cand.shape[1] <= n_paths:
            beam = cand
            continue
        log_po = tree.log_likelihood(clip, depth)
        emit = np.where(cand >= 0, log_po[np.arange(len(clip))[:, None], cand], -np.inf)
        moves = graphs.log_prob(depth, graph, cand[:-1, :, None], cand[1:, None, :])
        marginals = max_marginals(emit[0][:, None], (moves + emit[1:, None, :])[..., None])[..., 0]
        keep = np.argsort(-marginals, axis=1, kind="stable")[:, :n_paths]
        beam = np.take_along_axis(cand, keep, axis=1)
        beam[np.take_along_axis(marginals, keep, axis=1) == -np.inf] = -1
        beam = np.sort(np.where(beam < 0, np.iinfo(int).max, beam), axis=1)
        beam[beam == np.iinfo(int).max] = -1
    return beam


def reference_kbest_on_beams(tree, graphs, clip, graph, n_paths, layer):
    """The numpy K-best Viterbi over the candidates the reference beams leave at ``layer``."""
    beam = reference_beams(tree, graphs, clip, graph, n_paths, layer - 1)
    kids = tree.children(layer - 1)
    cand = np.array(
        [[kids[n, side] if n >= 0 else -1 for side in (0, 1) for n in row] for row in beam]
    )
    log_ps = node_log_posterior(tree, graphs, layer, clip, "layer")[graph]
    emit = np.where(cand >= 0, log_ps[np.arange(len(clip))[:, None], cand], -np.inf)
    moves = graphs.log_prob(layer, graph, cand[:-1, :, None], cand[1:, None, :])
    slots, scores = kbest_viterbi(emit[0][:, None], (moves + emit[1:, None, :])[..., None], n_paths)
    paths = np.where(slots[0] >= 0, np.take_along_axis(cand.T, np.maximum(slots[0], 0), 0), -1)
    return paths, scores[0]


@pytest.mark.parametrize("n_paths", [1, 2, 3])
def test_the_compiled_beams_follow_their_definition(model, n_paths):
    """At each layer, the sequences decoded are the K best over the children of the beams above.

    The beams are built from their definition (``reference_beams``), so a
    wrong beam at any layer shows in the sequences or their scores.
    """
    tree, graphs, frames = model
    rng = np.random.default_rng(n_paths)
    clip = frames[rng.integers(0, 100, size=12)] + rng.normal(scale=0.5, size=(12, 2))
    for graph in (0, 1):
        for layer in range(1, tree.n_layers):
            paths, scores = beam_decode(
                tree,
                graphs,
                clip,
                [0, 12],
                [0],
                [graph],
                layer=layer,
                n_paths=n_paths,
                node_prior="layer",
            )
            ref_paths, ref_scores = reference_kbest_on_beams(
                tree, graphs, clip, graph, n_paths, layer
            )
            np.testing.assert_allclose(scores[0, 0], ref_scores, rtol=1e-12)
            np.testing.assert_array_equal(paths[0], ref_paths)


@pytest.mark.parametrize("n_paths", [1, 2, 3])
def test_a_narrow_beam_never_beats_the_exhaustive_search(model, n_paths):
    tree, graphs, frames = model
    rng = np.random.default_rng(0)
    for _ in range(5):
        clip = frames[rng.integers(0, 100, size=8)]
        _, scores = beam_decode(tree, graphs, clip, [0, 8], [0], [1], layer=-1, n_paths=n_paths)
        _, best = exhaustive_viterbi(tree, graphs, -1, clip, 1, n_paths=n_paths)
        assert (scores[0, 0] <= best + 1e-9).all()
        # the scores are those of the returned sequences
        paths, _ = beam_decode(tree, graphs, clip, [0, 8], [0], [1], layer=-1, n_paths=n_paths)
        log_ps = node_log_posterior(tree, graphs, -1, clip, "graph")[1]
        log_pt = np.log(graphs.matrix(tree.n_layers - 1, 1))
        for seq, score in zip(paths[0], scores[0, 0]):
            if np.isfinite(score):
                own = log_ps[np.arange(8), seq].sum() + log_pt[seq[:-1], seq[1:]].sum()
                assert own == pytest.approx(score)


def test_node_posteriors_are_normalised(model):
    tree, graphs, frames = model
    for prior in ("graph", "layer"):
        log_ps = node_log_posterior(tree, graphs, -1, frames[::7] * 5, prior)  # far-away frames too
        np.testing.assert_allclose(logsumexp(log_ps, axis=2), 0.0, atol=1e-9)
    unvisited = graphs.visits(tree.n_layers - 1) == 0
    assert np.isneginf(
        node_log_posterior(tree, graphs, -1, frames[:3], "graph").transpose(1, 0, 2)[:, unvisited]
    ).all()


@pytest.mark.parametrize("guided", [False, True])
def test_clips_of_different_lengths_decode_as_if_alone(model, guided):
    tree, graphs, frames = model
    guide = graphs if guided else None  # graph 0 of it guides
    offsets = np.array([0, 1, 9, 30, 33])
    clips, problems = [0, 1, 2, 3, 2, 0], [0, 1, 1, 0, 0, 1]
    paths, scores = beam_decode(
        tree, graphs, frames, offsets, clips, problems, layer=-1, n_paths=3, guide=guide
    )
    for i, (c, g) in enumerate(zip(clips, problems)):
        clip = frames[offsets[c] : offsets[c + 1]]
        alone_paths, alone_scores = beam_decode(
            tree, graphs, clip, [0, len(clip)], [0], [g], layer=-1, n_paths=3, guide=guide
        )
        np.testing.assert_allclose(scores[i], alone_scores[0], atol=1e-12)
        np.testing.assert_array_equal(paths[i][:, : len(clip)], alone_paths[0])
        assert (paths[i][:, len(clip) :] == -1).all()


def test_layer_zero_is_the_root_with_probability_one(model):
    tree, graphs, frames = model
    paths, scores = beam_decode(tree, graphs, frames[:5], [0, 5], [0], [0], layer=0, n_paths=2)
    assert scores[0].tolist() == [[0.0, -np.inf]]
    assert paths[0, 0].tolist() == [0] * 5 and (paths[0, 1] == -1).all()


def test_ten_thousand_frames_keep_finite_probabilities(model):
    tree, graphs, frames = model
    clip = frames[np.arange(10_000) % 100]
    paths, scores = beam_decode(tree, graphs, clip, [0, 10_000], [0], [0], layer=-1, n_paths=2)
    assert np.isfinite(scores).all() and scores[0, 0, 0] < -1000  # far below the smallest double
    assert (paths[0] >= 0).all()


def test_the_normaliser_survives_underflow():
    from skmotion.tree._decoder._decode import _log_normaliser

    log_po = np.array([[0.0, -2000.0, -2001.0], [-5.0, -6.0, -7.0]])
    allowed = np.array([[True, True, True], [False, True, True]])
    expected = [[logsumexp(log_po[i][allowed[g]]) for g in range(2)] for i in range(2)]
    np.testing.assert_allclose(_log_normaliser(log_po, allowed), expected)
    assert np.isfinite(_log_normaliser(log_po, allowed)).all()


def pruning_case(seed, score_layers):
    """Check prune=True against prune=False.

    Say whether clips with one and with several survivors occurred.
    """
    rng = np.random.default_rng(seed)
    n_clips = 8
    # clips in pairs about one centre: the two graphs of a pair compete closely
    centres = np.repeat(rng.normal(scale=2.0, size=(n_clips // 2, 3)), 2, axis=0)
    frames = rng.normal(size=(20 * n_clips, 3)) + np.repeat(centres, 20, axis=0)
    offsets = np.arange(0, 20 * n_clips + 1, 20)
    tree = MotionTree.build(frames, max_depth=4, min_samples_leaf=5, split="median")
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=np.arange(n_clips),
        smoothing=0.5,
    )
    guide = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=np.zeros(n_clips, dtype=int),
    )
    queries = frames + rng.normal(
        scale=0.5, size=frames.shape
    )  # every clip under every clip's graph
    clip_of_problem, graph_of_problem = (
        np.repeat(np.arange(n_clips), n_clips),
        np.tile(np.arange(n_clips), n_clips),
    )
    args = (tree, graphs, queries, offsets, clip_of_problem, graph_of_problem)
    kwargs = dict(
        layer=-1,
        n_paths=3,
        node_prior="layer",
        guide=guide,
        normalise=False,
        score_layers=score_layers,
    )
    full_paths, full = beam_decode(*args, **kwargs)
    paths, pruned = beam_decode(*args, **kwargs, prune=True)
    total, total_full = logsumexp(pruned, axis=2).sum(axis=1), logsumexp(full, axis=2).sum(axis=1)
    live = np.isfinite(total)
    alone = live & (np.bincount(clip_of_problem, weights=live)[clip_of_problem] == 1)
    np.testing.assert_array_equal(pruned[live & ~alone], full[live & ~alone])
    np.testing.assert_array_equal(paths[live & ~alone], full_paths[live & ~alone])
    # a clip's only survivor keeps its best sequences' scores alone
    np.testing.assert_array_equal(pruned[alone, :, 0], full[alone, :, 0])
    assert np.isneginf(pruned[alone, :, 1:]).all() and (paths[alone] == -1).all()
    assert (paths[~live] == -1).all() and np.isneginf(pruned[~live]).all()
    for c in range(n_clips):
        rows = clip_of_problem == c
        assert np.argmax(total[rows]) == np.argmax(total_full[rows])
        assert (total_full[rows][~live[rows]] < total_full[rows].max()).all()
    assert (~live).any()  # the case is not trivial
    return alone.any(), (live & ~alone).any()


@pytest.mark.parametrize("score_layers", [1, 3])
def test_pruning_keeps_the_winner_of_every_clip(score_layers):
    """Problems left out of the K-best passes provably could not have the highest summed score."""
    kinds = np.array([pruning_case(seed, score_layers) for seed in range(10)])
    assert kinds.any(axis=0).all()  # clips with one survivor and clips with several both occurred


def test_pruning_needs_a_guide(model):
    tree, graphs, frames = model
    with pytest.raises(ValueError, match="prune needs a guide"):
        beam_decode(tree, graphs, frames[:5], [0, 5], [0], [0], layer=-1, n_paths=2, prune=True)


@pytest.fixture(scope="module")
def copied_model():
    """A minimum-error tree whose small clusters stop early: leaves copied down to lower layers."""
    rng = np.random.default_rng(7)
    frames = np.vstack(
        [rng.normal(c, s, size=(n, 2)) for c, s, n in [(0, 0.3, 60), (5, 1.0, 12), (9, 0.5, 24)]]
    )
    offsets = np.array([0, 40, 70, 96])
    tree = MotionTree.build(frames, max_depth=4, min_samples_leaf=6, split="min_error")
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=[0, 1, 1],
        smoothing=0.5,
    )
    guide = TransitionGraphs.count(
        list(tree.iter_apply(frames)), tree.n_nodes, offsets=offsets, graph_of_clip=[0, 0, 0]
    )
    copies = [
        bool(np.isin(tree.layers[d], tree.layers[d - 1]).any()) for d in range(2, tree.n_layers)
    ]
    assert any(copies)  # the case this fixture exists for
    return tree, graphs, guide, frames


@pytest.mark.parametrize("prior", ["graph", "layer"])
@pytest.mark.parametrize("guided", [False, True])
def test_every_scored_layer_agrees_with_the_exhaustive_viterbi(copied_model, prior, guided):
    """A wide beam scoring all layers at once gives each layer's exhaustive K-best list.

    Copied leaves too.
    """
    tree, graphs, guide, frames = copied_model
    clip = frames[[3, 61, 80, 90, 10, 65, 30]] + 0.1
    wide = int(tree.n_nodes.max())
    for graph in (0, 1):
        paths, scores = beam_decode(
            tree,
            graphs,
            clip,
            [0, len(clip)],
            [0],
            [graph],
            layer=-1,
            n_paths=wide,
            score_layers=tree.n_layers,
            node_prior=prior,
            guide=guide if guided else None,
        )
        assert scores.shape == (1, tree.n_layers - 1, wide)
        for row, layer in enumerate(range(1, tree.n_layers)):
            ex_paths, ex_scores = exhaustive_viterbi(
                tree, graphs, layer, clip, graph, n_paths=wide, node_prior=prior
            )
            # the normaliser is subtracted as a per-clip sum: rounding is absolute, at the
            # terms' scale
            np.testing.assert_allclose(scores[0, row], ex_scores, rtol=1e-12, atol=1e-9)
        finite = np.isfinite(ex_scores)
        np.testing.assert_array_equal(paths[0][finite], ex_paths[finite])


@pytest.mark.parametrize("n_paths", [1, 2, 3])
def test_scoring_several_layers_equals_scoring_each_alone(copied_model, n_paths):
    """Beams above a layer do not depend on which layers are scored.

    Each row is that layer's own decode.
    """
    tree, graphs, guide, frames = copied_model
    rng = np.random.default_rng(n_paths)
    clips = [
        frames[rng.integers(0, 96, size=n)] + rng.normal(scale=0.4, size=(n, 2)) for n in (9, 1, 14)
    ]
    stacked, offsets = np.vstack(clips), np.array([0, 9, 10, 24])
    problems = dict(clip_of_problem=[0, 0, 1, 1, 2, 2], graph_of_problem=[0, 1, 0, 1, 0, 1])
    for kwargs in (dict(guide=guide, node_prior="layer"), dict(node_prior="graph")):
        paths, scores = beam_decode(
            tree,
            graphs,
            stacked,
            offsets,
            *problems.values(),
            layer=-1,
            n_paths=n_paths,
            score_layers=3,
            **kwargs,
        )
        bottom = tree.n_layers - 1
        for row, layer in enumerate(range(bottom - 2, bottom + 1)):
            alone_paths, alone = beam_decode(
                tree,
                graphs,
                stacked,
                offsets,
                *problems.values(),
                layer=layer,
                n_paths=n_paths,
                **kwargs,
            )
            np.testing.assert_allclose(scores[:, row], alone[:, 0], rtol=1e-12, atol=1e-9)
        np.testing.assert_array_equal(paths, alone_paths)


def test_score_layers_stop_at_layer_one(model):
    tree, graphs, frames = model
    _, scores = beam_decode(
        tree, graphs, frames[:6], [0, 6], [0], [0], layer=2, n_paths=2, score_layers=10
    )
    assert scores.shape == (1, 2, 2)  # layers 1 and 2
    with pytest.raises(ValueError, match="score_layers must be an int >= 1"):
        beam_decode(tree, graphs, frames[:6], [0, 6], [0], [0], layer=2, score_layers=0)


def test_low_rank_covariances_decode_as_the_full_factor():
    """Nodes with fewer frames than channels take the compiled O(r d) form; reference: Cholesky."""
    rng = np.random.default_rng(11)
    d = 48
    frames = np.vstack([rng.normal(c, 1.0, size=(24, d)) for c in (0.0, 2.0, 4.0)])
    tree = MotionTree.build(
        frames, max_depth=3, min_samples_leaf=4, split="median", covariance_type="full"
    )
    low = gaussian_arrays(tree)["lr_start"] >= 0
    assert low.any() and not low.all()  # both forms are exercised
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=[0, 36, 72],
        graph_of_clip=[0, 1],
        smoothing=0.5,
    )
    clip = frames[[2, 30, 50, 70, 5]] + rng.normal(scale=0.3, size=(5, d))
    wide = int(tree.n_nodes.max())
    for graph in (0, 1):
        paths, scores = beam_decode(
            tree,
            graphs,
            clip,
            [0, 5],
            [0],
            [graph],
            layer=-1,
            n_paths=wide,
            score_layers=tree.n_layers,
            node_prior="layer",
        )
        for row, layer in enumerate(range(1, tree.n_layers)):
            ex_paths, ex_scores = exhaustive_viterbi(
                tree, graphs, layer, clip, graph, n_paths=wide, node_prior="layer"
            )
            np.testing.assert_allclose(scores[0, row], ex_scores, rtol=1e-10, atol=1e-8)
        finite = np.isfinite(ex_scores)
        np.testing.assert_array_equal(paths[0][finite], ex_paths[finite])
