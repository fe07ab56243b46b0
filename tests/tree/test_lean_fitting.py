"""Memory-lean fitting and per-call costs: the same doubles as the copying, sparse code.

The truths: NumPy's fancy-index gather (row permutation), ``mean``/``std`` and the
standardisation expression, SciPy's sparse product (group sums) and a plain loop, the
copying build (``copy=True``), which the in-place one must equal bit for bit, NumPy's
centred scatter and boolean masks (the compiled passes of the build), a plain build
written from the method's description (each node's frames gathered, their scatter's
leading eigenvector, the sorted projections cut), and the serial build, which the
threaded one must equal bit for bit.
"""

import pickle

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from skmotion.tree._build._node_passes import partition_rows, shifted_moments
from skmotion.tree._build._permute import permute_rows
from skmotion.utils._group_sums import group_sums

from skmotion.datasets import make_motions
from skmotion.tree import MotionTree, MotionTreeEncoder, MotionTreeHMM
from skmotion.tree._build import _nodes
from skmotion.tree._build._split import best_split
from skmotion.tree._build._standardise import column_mean_std, standardise_in_place
from skmotion.tree._encoding._routing import TreeRouter


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 300), st.integers(1, 5), st.integers(0, 2**32 - 1))
def test_permute_rows_is_the_gather(n, d, seed):
    rng = np.random.default_rng(seed)
    block = rng.normal(size=(n, d))
    order = rng.permutation(n)
    expected = block[order]
    permute_rows(block, order)
    assert np.array_equal(block, expected)


def test_permute_rows_refuses_what_is_not_a_permutation():
    with pytest.raises(ValueError, match="not a permutation"):
        permute_rows(np.zeros((3, 2)), np.array([0, 0, 1]))
    with pytest.raises(ValueError, match="not a permutation"):
        permute_rows(np.zeros((3, 2)), np.array([1, 5, 0]))


@pytest.mark.parametrize("n", [2, 7, 32_768, 100_001])  # one block, and several
def test_column_mean_std_and_standardisation_are_numpys_to_the_bit(n):
    rng = np.random.default_rng(n)
    frames = rng.normal(3.0, 2.0, size=(n, 6)) * rng.uniform(0.1, 10, 6)
    mean, std = column_mean_std(frames)
    assert np.array_equal(mean, frames.mean(axis=0))
    assert np.array_equal(std, frames.std(axis=0))
    expected = (frames - mean) / std
    assert standardise_in_place(frames, mean, std) is frames
    assert np.array_equal(frames, expected)


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 400), st.integers(1, 30), st.integers(0, 2**32 - 1))
def test_group_sums_are_the_sparse_products_doubles(n, n_groups, seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(n, 4))
    group = rng.integers(0, n_groups, n)
    weight = rng.uniform(0.01, 1.0, n)
    sums = group_sums(values, group, weight, n_groups)
    matrix = sp.csr_matrix((weight, (group, np.arange(n))), shape=(n_groups, n))
    assert np.array_equal(sums, matrix @ values)
    loop = np.zeros((n_groups, 4))
    for g, w, row in zip(group, weight, values):
        loop[g] += w * row
    assert np.allclose(sums, loop)


def test_group_sums_bad_groups():
    with pytest.raises(ValueError, match="group\\[1\\] is 3"):
        group_sums(np.ones((2, 1)), np.array([0, 3]), np.ones(2), 2)
    with pytest.raises(ValueError, match="one entry per row"):
        group_sums(np.ones((2, 1)), np.array([0]), np.ones(2), 2)


def _frames(n=40_000, d=9, seed=0):
    rng = np.random.default_rng(seed)
    centers = rng.normal(size=(12, d)) * 3
    return centers[rng.integers(0, 12, n)] + rng.normal(size=(n, d))


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(max_depth=6, split="median"),
        dict(max_depth=5, min_samples_leaf=16),
        dict(max_depth=3, split="two_means", covariance_type="full"),
    ],
)
def test_in_place_build_is_the_copying_build_and_puts_the_frames_back(kwargs):
    frames = _frames()
    original = frames.copy()
    copied = MotionTree.build(frames, **kwargs)
    in_place = MotionTree.build(frames, copy=False, **kwargs)
    assert np.array_equal(frames, original)  # every row back in its place
    for name in ("parent", "left", "count", "mean", "covariance", "axis", "threshold"):
        assert np.array_equal(getattr(copied, name), getattr(in_place, name), equal_nan=True)
    assert all(np.array_equal(a, b) for a, b in zip(copied.layers, in_place.layers))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 300), st.integers(1, 8), st.booleans(), st.integers(0, 2**32 - 1))
def test_shifted_moments_are_the_centred_sums_and_products(n, d, scatter, seed):
    rng = np.random.default_rng(seed)
    rows = rng.normal(2.0, 3.0, size=(n, d))
    shift = rng.normal(size=d)
    centred = rows - shift
    sums, products = shifted_moments(rows, shift, scatter)
    expected = centred.T @ centred if scatter else np.einsum("ij,ij->j", centred, centred)
    scale = 1e-12 * max(1.0, float(np.abs(expected).max(initial=0.0)))
    assert np.allclose(sums, centred.sum(axis=0), rtol=0, atol=1e-12 * max(n, 1) * 10)
    assert np.allclose(products, expected, rtol=0, atol=scale)
    if scatter:
        assert np.array_equal(products, products.T)


def test_shifted_moments_over_many_chunks():
    rows = np.random.default_rng(1).normal(5.0, 1.0, size=(50_001, 3))  # 5 chunks of 10,922 rows
    mean = rows.mean(axis=0)
    sums, products = shifted_moments(rows, mean)
    centred = rows - mean
    assert np.allclose(products, centred.T @ centred, rtol=1e-12)
    assert np.allclose(sums, centred.sum(axis=0), rtol=0, atol=1e-10)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 200), st.integers(0, 4), st.integers(0, 2**32 - 1))
def test_partition_rows_puts_the_rows_below_the_cut_first(n, d, seed):
    rng = np.random.default_rng(seed)
    block = rng.normal(size=(n, d))
    projection = rng.integers(0, 5, n).astype(float)  # ties, and rows on the cut
    cut = float(rng.integers(0, 6))
    original, index = block.copy(), np.arange(n)
    below = partition_rows(block, projection, cut, index)
    assert below == int((projection < cut).sum())
    assert np.array_equal(block, original[index])  # rows moved whole, index with them
    assert np.array_equal(np.sort(index), np.arange(n))
    assert set(index[:below]) == set(np.flatnonzero(projection < cut))


def _plain_build(frames, max_depth, min_samples_leaf, split):
    """The build as the method describes it: per layer, each node's frames (gathered), the
    leading eigenvector of their centred scatter (largest component positive), the
    projections sorted and cut by the rule; a node that is not split is copied down."""
    d = frames.shape[1]
    tol = _nodes._GAP_RESOLUTION * d * np.abs(frames).max()
    layers = [[np.arange(len(frames))]]
    for _ in range(max_depth):
        layer = []
        for members in layers[-1]:
            x = frames[members]
            centred = x - x.mean(axis=0)
            axis = np.linalg.eigh(centred.T @ centred)[1][:, -1]
            axis = -axis if axis[np.argmax(np.abs(axis))] < 0 else axis
            order = np.argsort(x @ axis, kind="stable")
            cut = best_split((x @ axis)[order], split, min_samples_leaf=min_samples_leaf, tol=tol)
            if len(members) < 2 * min_samples_leaf or cut is None:
                layer.append(members)
            else:
                layer += [members[order[:cut]], members[order[cut:]]]
        layers.append(layer)
    return layers


@pytest.mark.parametrize("split", ["median", "two_means", "min_error"])
def test_build_is_the_plain_build(split):
    frames = _frames(3_000, 5, seed=3)
    tree = MotionTree.build(frames, max_depth=4, min_samples_leaf=8, split=split)
    plain = _plain_build(frames, 4, 8, split)
    for layer in range(tree.n_layers):
        labels = tree.apply(frames, layer)
        for node, members in enumerate(plain[layer]):  # the same frames in every node
            assert np.array_equal(np.flatnonzero(labels == node), np.sort(members))
            x = frames[members]
            assert np.allclose(tree.means(layer)[node], x.mean(axis=0), rtol=0, atol=1e-12)
            expected = x.var(axis=0) + tree.reg
            assert np.allclose(tree.covariances(layer)[node], expected, rtol=1e-11)


@pytest.mark.parametrize("covariance_type", ["diag", "full"])
def test_threaded_build_is_the_serial_build(monkeypatch, covariance_type):
    monkeypatch.setattr(_nodes, "_TASK_FRAMES", 500)  # many tasks per layer
    frames = _frames(20_000, 6, seed=4)
    kwargs = dict(max_depth=7, split="two_means", covariance_type=covariance_type)
    serial = MotionTree.build(frames, **kwargs)
    threaded = MotionTree.build(frames, n_jobs=2, **kwargs)
    for name in ("parent", "left", "count", "mean", "covariance", "axis", "threshold"):
        assert np.array_equal(getattr(serial, name), getattr(threaded, name), equal_nan=True)


def test_copy_false_never_touches_an_array_it_cannot_own():
    frames = _frames(2_000)
    view = frames[:, ::2]  # not contiguous: converted, the caller's array is only read
    view.flags.writeable = False
    before = frames.copy()
    tree = MotionTree.build(view, copy=False, max_depth=3)
    assert np.array_equal(frames, before)
    assert tree.count[0] == 2_000


def test_fits_leave_the_callers_clips_alone_and_the_encoder_one_clip_rows_are_the_batch():
    data = make_motions(n_clips_per_class=3, classes=["walk", "jump"], random_state=0)
    clips = [c[:, 6:] for c in data.clips]
    kept = [c.copy() for c in clips]
    encoder = MotionTreeEncoder(
        residual_order=2, layers="all", max_depth=4, sparse_output=True
    ).fit(clips)
    MotionTreeHMM(max_depth=3).fit(clips, data.target)
    assert all(np.array_equal(a, b) for a, b in zip(clips, kept))
    batch = encoder.transform(clips).toarray()
    one = np.vstack([encoder.transform([c]).toarray() for c in clips])
    assert np.array_equal(batch, one)


def test_a_router_pickled_with_the_former_product_tables_routes_the_same():
    frames = _frames(3_000)
    tree = MotionTree.build(frames, max_depth=7, split="median")
    router = TreeRouter(tree, frames.mean(axis=0), frames.std(axis=0))
    # the state a router kept before the compiled walk: its product path's tables, and
    # its arrays as the tree gave them (int64 children, a strided axis)
    state = dict(router.__dict__, axis=np.asfortranarray(router.axis), left=tree.left.astype(int))
    former = ("split_ids", "left_or_self", "right_or_self", "in_product", "walkable", "_products")
    state.update(dict.fromkeys(former))
    old = TreeRouter.__new__(TreeRouter)
    old.__setstate__(state)
    assert not set(former) & set(old.__dict__)
    assert np.array_equal(old.route(frames), router.route(frames))
    assert np.array_equal(pickle.loads(pickle.dumps(router)).route(frames), router.route(frames))
    # the stepwise routing of the tree itself, on the standardised frames
    z = (frames - frames.mean(axis=0)) / frames.std(axis=0)
    plain = TreeRouter(tree).route(z)
    assert all(np.array_equal(plain[:, layer], tree.apply(z, layer)) for layer in range(8))
