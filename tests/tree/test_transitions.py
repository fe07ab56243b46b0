"""Transition graphs: counts against a plain loop, exact smoothing, rows summing to 1."""

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.tree import TransitionGraphs, _transitions
from skmotion.tree._decoder._tables import transition_table


def loop_counts(labels, offsets, graph_of_clip, n_graphs, k):
    counts = np.zeros((n_graphs, k, k), dtype=int)
    for clip, g in enumerate(graph_of_clip):
        seq = labels[offsets[clip] : offsets[clip + 1]]
        for a, b in zip(seq[:-1], seq[1:]):
            counts[g, a, b] += 1
    return counts


@st.composite
def clip_labels(draw):
    k = draw(st.integers(1, 6))
    lengths = draw(st.lists(st.integers(1, 12), min_size=1, max_size=6))
    n_graphs = draw(st.integers(1, 3))
    graph_of_clip = np.array(
        draw(st.lists(st.integers(0, n_graphs - 1), min_size=len(lengths), max_size=len(lengths)))
    )
    labels = np.array(
        draw(st.lists(st.integers(0, k - 1), min_size=sum(lengths), max_size=sum(lengths)))
    )
    offsets = np.r_[0, np.cumsum(lengths)]
    return labels, offsets, graph_of_clip, n_graphs, k


@given(clip_labels(), st.floats(0.01, 5))
def test_counts_and_probabilities(case, alpha):
    labels, offsets, graph_of_clip, n_graphs, k = case
    graphs = TransitionGraphs.count(
        [labels],
        [k],
        offsets=offsets,
        graph_of_clip=graph_of_clip,
        n_graphs=n_graphs,
        smoothing=alpha,
    )
    expected = loop_counts(labels, offsets, graph_of_clip, n_graphs, k)
    for g in range(n_graphs):
        np.testing.assert_array_equal(graphs.counts(0, g).toarray(), expected[g])
        P = graphs.matrix(0, g)
        np.testing.assert_allclose(P.sum(axis=1), 1.0)
        totals = expected[g].sum(axis=1, keepdims=True)
        unseen = expected[g] == 0
        # never-seen transitions hold exactly the smoothing mass of their row
        mass = (alpha / k) / (totals + alpha)
        np.testing.assert_array_equal(P[unseen], np.broadcast_to(mass, P.shape)[unseen])
        np.testing.assert_allclose(
            P[~unseen], ((expected[g] + alpha / k) / (totals + alpha))[~unseen]
        )
        np.testing.assert_allclose(graphs.unseen_probability(0)[g], mass[:, 0])
        nodes = np.arange(k)
        np.testing.assert_allclose(np.exp(graphs.log_prob(0, g, nodes[:, None], nodes[None])), P)
    visits = np.zeros((n_graphs, k), dtype=int)
    np.add.at(visits, (np.repeat(graph_of_clip, np.diff(offsets)), labels), 1)
    np.testing.assert_array_equal(graphs.visits(0), visits)


def test_no_transition_crosses_a_clip_boundary():
    graphs = TransitionGraphs.count(
        [np.array([0, 0, 1, 1])], [2], offsets=[0, 2, 4], graph_of_clip=[0, 0]
    )
    np.testing.assert_array_equal(graphs.counts(0, 0).toarray(), [[1, 0], [0, 1]])


def test_a_node_never_left_has_a_uniform_row():
    graphs = TransitionGraphs.count(
        [np.array([0, 0, 1])], [3], offsets=[0, 3], graph_of_clip=[0], smoothing=0.5
    )
    np.testing.assert_allclose(graphs.matrix(0, 0)[1], [1 / 3] * 3)


def dense_and_sparse(monkeypatch, labels, n_nodes, **args):
    """The same graphs with a dense log table and with the sparse lookup."""
    dense = TransitionGraphs.count([labels], [n_nodes], **args)
    monkeypatch.setattr(_transitions, "_DENSE_LIMIT", 0)
    sparse = TransitionGraphs.count([labels], [n_nodes], **args)
    assert dense._dense[0] is not None and sparse._dense[0] is None
    return dense, sparse


def test_sparse_lookup_matches_the_dense_table(monkeypatch, rng):
    dense, sparse = dense_and_sparse(
        monkeypatch,
        rng.integers(0, 7, size=200),
        7,
        offsets=[0, 50, 120, 200],
        graph_of_clip=[0, 1, 1],
        smoothing=0.3,
    )
    g, src, dst = rng.integers(0, 2, 300), rng.integers(-1, 8, 300), rng.integers(-1, 8, 300)
    np.testing.assert_array_equal(dense.log_prob(0, g, src, dst), sparse.log_prob(0, g, src, dst))
    assert np.isneginf(dense.log_prob(0, 0, [-1, 7, 2], [3, 3, 7])).all()


def test_propagate_is_a_matrix_power(rng):
    labels = rng.integers(0, 5, size=80)
    graphs = TransitionGraphs.count(
        [labels], [5], offsets=[0, 80], graph_of_clip=[0], smoothing=0.2
    )
    start = rng.dirichlet(np.ones(5), size=3)
    P = graphs.matrix(0, 0)
    np.testing.assert_allclose(
        graphs.propagate(0, 0, start, 3), start @ np.linalg.matrix_power(P, 3)
    )
    np.testing.assert_allclose(graphs.propagate(0, 0, start[0]), start[0] @ P)


def test_smoothing_must_be_positive():
    with pytest.raises(ValueError, match="smoothing must be a positive number"):
        TransitionGraphs.count(
            [np.zeros(3, int)], [1], offsets=[0, 3], graph_of_clip=[0], smoothing=0
        )


def test_the_decoder_table_holds_every_log_probability(monkeypatch, rng):
    """The compiled decoder's lookups give log_prob exactly.

    Both the dense table and, without it, a pair's row of every graph and the unseen rows.
    """
    dense, sparse = dense_and_sparse(
        monkeypatch,
        rng.integers(0, 6, size=150),
        6,
        offsets=[0, 40, 90, 150],
        graph_of_clip=[0, 1, 2],
        smoothing=0.7,
    )
    for graphs, has_dense in ((dense, True), (sparse, False)):
        table = transition_table(graphs, 0)
        k, n_graphs = table["k"], table["n_graphs"]
        assert (k, n_graphs, len(table["dense"]) > 0) == (6, 3, has_dense)
        assert np.isneginf(table["unseen_log"][k]).all()  # "no node"
        for g, src, dst in itertools.product(range(3), range(6), range(6)):
            expected = dense.log_prob(0, g, src, dst)
            start, stop = table["pair_start"][src], table["pair_start"][src + 1]
            stored = table["pair_dst"][start:stop]
            assert (np.diff(stored) > 0).all()
            if dst in stored:
                looked_up = table["pair_log"][start + np.flatnonzero(stored == dst)[0], g]
            else:
                looked_up = table["unseen_log"][src, g]
            assert looked_up == expected
            if has_dense:
                assert table["dense"][(src * (k + 1) + dst) * n_graphs + g] == expected
        # a pair is stored when any graph made that transition
        made = sum(graphs.counts(0, g).toarray() for g in range(3)) > 0
        assert len(table["pair_dst"]) == made.sum()
