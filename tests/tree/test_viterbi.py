"""K-best Viterbi and max-marginals against brute-force enumeration of every sequence."""

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from skmotion.tree import kbest_viterbi, max_marginals


def all_sequences(initial, steps, b):
    n_states, n_steps = initial.shape[0], len(steps) + 1
    out = []
    for seq in itertools.product(range(n_states), repeat=n_steps):
        score = initial[seq[0], b] + sum(
            steps[t - 1, seq[t - 1], seq[t], b] for t in range(1, n_steps)
        )
        out.append((score, seq))
    return sorted(out, key=lambda item: -item[0])


@st.composite
def trellises(draw):
    n_steps, n_states, n_problems = (
        draw(st.integers(1, 5)),
        draw(st.integers(1, 3)),
        draw(st.integers(1, 3)),
    )
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    initial = np.log(rng.uniform(size=(n_states, n_problems)))
    steps = np.round(
        np.log(rng.uniform(size=(n_steps - 1, n_states, n_states, n_problems))), 1
    )  # ties
    initial[rng.uniform(size=initial.shape) < 0.2] = -np.inf
    steps[rng.uniform(size=steps.shape) < 0.2] = -np.inf
    return initial, steps


@given(trellises(), st.integers(1, 6))
def test_kbest_matches_enumeration(trellis, n_paths):
    initial, steps = trellis
    paths, scores = kbest_viterbi(initial, steps, n_paths)
    for b in range(initial.shape[1]):
        ranked = [s for s, _ in all_sequences(initial, steps, b) if np.isfinite(s)][:n_paths]
        np.testing.assert_allclose(scores[b, : len(ranked)], ranked)
        assert np.isneginf(scores[b, len(ranked) :]).all() and (paths[b, len(ranked) :] == -1).all()
        found = [tuple(p) for p in paths[b, : len(ranked)]]
        assert len(set(found)) == len(found), "sequences repeat"
        for seq, score in zip(found, scores[b]):
            own = initial[seq[0], b] + sum(
                steps[t - 1, seq[t - 1], seq[t], b] for t in range(1, len(seq))
            )
            assert np.isclose(own, score, rtol=1e-12)


@given(trellises())
def test_max_marginals_match_enumeration(trellis):
    initial, steps = trellis
    marginals = max_marginals(initial, steps)
    for b in range(initial.shape[1]):
        ranked = all_sequences(initial, steps, b)
        for t in range(len(steps) + 1):
            for j in range(initial.shape[0]):
                best = max((s for s, seq in ranked if seq[t] == j), default=-np.inf)
                assert marginals[t, j, b] == best or np.isclose(marginals[t, j, b], best)


def test_ten_thousand_steps_do_not_underflow():
    n_steps = 10_000
    initial = np.log([[0.5], [0.5]])
    move = np.log(
        np.array([[0.9, 0.1], [0.1, 0.9]]) * np.array([0.8, 0.2])
    )  # arrival scores included
    steps = np.broadcast_to(move[None, :, :, None], (n_steps - 1, 2, 2, 1))
    paths, scores = kbest_viterbi(initial, steps, 2)
    assert np.isfinite(scores).all()
    np.testing.assert_allclose(scores[0, 0], np.log(0.5) + (n_steps - 1) * np.log(0.72))
    assert (paths[0, 0] == 0).all()
    assert np.isfinite(max_marginals(initial, steps)).all()
