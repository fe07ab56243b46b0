"""find_occurrences against brute-force references (z-normalised windows, subsequence DTW).

The agreement with the peers (stumpy's ``match``, tslearn's ``dtw_subsequence_path``) is
checked by benchmarks/bench_matching.py: their JIT compilation alone takes tens of seconds.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.neighbors import _occurrences, find_occurrences
from skmotion.neighbors._occurrences import sliding_dots


def _znorm_reference(query, take):
    """The distance of every window, z-normalising each window and channel explicitly."""
    m = len(query)
    out = []
    for i in range(len(take) - m + 1):
        window = take[i : i + m]
        per_channel = []
        for c in range(query.shape[1]):
            q, w = query[:, c], window[:, c]
            q_const, w_const = np.ptp(q) == 0, np.ptp(w) == 0
            if q_const or w_const:
                per_channel.append(0.0 if q_const and w_const else np.sqrt(m))
                continue
            diff = (q - q.mean()) / q.std() - (w - w.mean()) / w.std()
            per_channel.append(np.sqrt(np.sum(diff**2)))
        out.append(np.mean(per_channel))
    return np.array(out)


def _dtw(a, b):
    """Full DTW (squared Euclidean frame cost) between two sequences, square-rooted."""
    acc = np.full((len(a) + 1, len(b) + 1), np.inf)
    acc[0, 0] = 0.0
    for i in range(1, len(a) + 1):
        for j in range(1, len(b) + 1):
            cost = np.sum((a[i - 1] - b[j - 1]) ** 2)
            acc[i, j] = cost + min(acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
    return np.sqrt(acc[-1, -1])


def _dtw_reference(query, take):
    """Per end frame, the best DTW distance over all start frames, and that start."""
    best, starts = [], []
    for end in range(len(take)):
        costs = [_dtw(query, take[s : end + 1]) for s in range(end + 1)]
        best.append(min(costs))
        starts.append(int(np.argmin(costs)))
    return np.array(best), np.array(starts)


def _greedy_reference(profiles, spans, k, overlap):
    """Pick the smallest distance, drop what it excludes, repeat (one candidate list)."""
    candidates = [(d, t, i, spans[t][i]) for t, p in enumerate(profiles) for i, d in enumerate(p)]
    chosen = []
    while candidates and len(chosen) < k:
        best = min(candidates, key=lambda c: c[0])
        chosen.append(best)
        _, t, i, (s, e) = best
        candidates = [c for c in candidates if c[1] != t or not overlap(c, best)]
    return [(t, s, e, d) for d, t, _, (s, e) in chosen]


takes_strategy = st.lists(
    st.lists(st.integers(-20, 20), min_size=12, max_size=40).map(
        # Values on a 0.1 grid with two channels: constant windows occur, near-constant ones do not.
        lambda v: np.column_stack([np.array(v) / 10.0, np.roll(np.array(v), 3) / 5.0])
    ),
    min_size=1,
    max_size=3,
)


@given(takes=takes_strategy, m=st.integers(2, 8), k=st.integers(1, 6), pick=st.integers(0, 100))
def test_znorm_equals_brute_force(takes, m, k, pick):
    source = takes[pick % len(takes)]
    query = source[pick % (len(source) - m + 1) :][:m] * 2.0 + 1.0
    found = find_occurrences(query, takes, n_occurrences=k)
    profiles = [_znorm_reference(query, t) for t in takes]
    spans = [[(i, i + m) for i in range(len(p))] for p in profiles]
    zone = int(np.ceil(m / 4))
    expected = _greedy_reference(profiles, spans, k, lambda c, b: abs(c[2] - b[2]) <= zone)
    assert len(found) == len(expected)
    np.testing.assert_allclose(found.distance, [e[3] for e in expected], atol=1e-7)
    # Where windows tie, either may come first; an untied first pick must be the same.
    everything = np.concatenate(profiles)
    if len(found) and np.sum(np.abs(everything - expected[0][3]) < 1e-7) == 1:
        assert (found["take"][0], found.start[0], found.end[0]) == expected[0][:3]


@settings(max_examples=30)
@given(takes=takes_strategy.map(lambda ts: [t[:14] for t in ts]), m=st.integers(1, 4))
def test_dtw_equals_brute_force(takes, m):
    query = takes[0][2 : 2 + m] + 0.05
    found = find_occurrences(query, takes, metric="dtw", n_occurrences=4)
    profiles, spans = [], []
    for take in takes:
        best, starts = _dtw_reference(query, take)
        profiles.append(best)
        spans.append([(s, e + 1) for e, s in enumerate(starts)])
    overlap = lambda c, b: c[3][1] > b[3][0] and c[3][0] < b[3][1]  # noqa: E731
    expected = _greedy_reference(profiles, spans, 4, overlap)
    np.testing.assert_allclose(found.distance, [e[3] for e in expected], atol=1e-9)
    for row in found.itertuples():
        # Each reported stretch is at the reported DTW distance from the query.
        window = takes[row.take][row.start : row.end]
        assert _dtw(query, window) == pytest.approx(row.distance, abs=1e-9)


@pytest.mark.parametrize("block", [None, 128, 1024])
def test_sliding_dots_is_the_direct_product(block, rng):
    q, x = rng.normal(size=37), rng.normal(size=3001)
    direct = np.lib.stride_tricks.sliding_window_view(x, 37) @ q
    np.testing.assert_allclose(sliding_dots(q, x, block), direct, atol=1e-10)
    # Several channels at once, one query each.
    qs, xs = rng.normal(size=(3, 37)), rng.normal(size=(3, 3001))
    many = np.stack([np.lib.stride_tricks.sliding_window_view(x, 37) @ q for q, x in zip(qs, xs)])
    np.testing.assert_allclose(sliding_dots(qs, xs, block), many, atol=1e-10)


def test_far_offset_and_scale_do_not_change_the_answer(rng):
    take = np.cumsum(rng.normal(size=(5000, 2)), axis=0)
    query = take[1234:1294]
    near = find_occurrences(query, [take], n_occurrences=3)
    far = find_occurrences(query, [take * 1e3 + 1e6], n_occurrences=3)
    assert near.start.tolist() == far.start.tolist() and near.start[0] == 1234
    np.testing.assert_allclose(near.distance[1:], far.distance[1:], rtol=1e-6)


def test_max_distance_and_short_takes(rng):
    take = rng.normal(size=(100, 2))
    found = find_occurrences(take[10:20], [take[:5], take], n_occurrences=None, max_distance=2.0)
    assert found["take"].tolist() == [1] * len(found) and (found.distance <= 2.0).all()
    assert found.distance.is_monotonic_increasing


def test_bad_input_is_named(rng):
    take = rng.normal(size=(50, 2))
    bad = take.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="take 1 has a non-finite value at frame 7, channel 1"):
        find_occurrences(take[:10], [take, bad])
    with pytest.raises(ValueError, match="take 0 has 3 channels and the query 2"):
        find_occurrences(take[:10], [rng.normal(size=(50, 3))])
    with pytest.raises(ValueError, match="2 frames or more"):
        find_occurrences(take[:1], [take])


def test_threads_split_the_take_and_agree_with_one(rng, monkeypatch):
    # Stretches of one FFT block (2048 - 19 windows): the take's 4,081 windows are
    # three stretches over two threads, each thread writing its own windows; the
    # reference is the explicit z-normalisation of every window.
    monkeypatch.setattr(_occurrences, "CHUNK_BLOCKS", 1)
    take = np.cumsum(rng.normal(size=(4100, 3)), axis=0)
    query = take[150:170] + rng.normal(scale=0.05, size=(20, 3))
    one = find_occurrences(query, [take], n_occurrences=4)
    two = find_occurrences(query, [take], n_occurrences=4, n_jobs=2)
    assert two.start.tolist() == one.start.tolist()
    np.testing.assert_allclose(two.distance, one.distance, atol=1e-9)
    profile = _znorm_reference(query, take)
    assert one.start[0] == int(np.argmin(profile)) == 150
    np.testing.assert_allclose(one.distance[0], profile.min(), atol=1e-9)
    # Every window, across the stretches' seams, on one thread and on two.
    for n_threads in (1, 2):
        searched = _occurrences._znorm_profile(query, take, n_threads)
        np.testing.assert_allclose(searched, profile, atol=1e-7)
