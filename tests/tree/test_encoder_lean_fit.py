"""The encoder's lean fit: the tree built from the caller's clips, without a stacked copy.

The truths: the in-memory build over the stacked, standardised frames
(``MotionTree.from_params``, what the fit did before and still does below
``_LEAN_FROM_FRAMES``), which the lean build must equal to the bit, node by node; NumPy's
stacking, ``mean``/``std`` and boolean masks; the tree's own node counts, which routing the
training frames as ``transform`` does must reproduce (a training frame routes to the node
the build put it in); and tracemalloc's peak for the memory the fit saves.
"""

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skmotion.tree._build._node_passes import moment_chunk_rows, shifted_moments
from skmotion.tree._build._permute import scatter_rows

import skmotion.tree._encoder as encoder_module
from skmotion.tree import MotionTree, MotionTreeEncoder
from skmotion.tree._build import TreeParams
from skmotion.tree._build._clip_build import build_from_clips
from skmotion.tree._build._standardise import (
    StackedClips,
    column_mean_std,
    standardise_in_place,
)

_TREE_ARRAYS = (
    "parent",
    "left",
    "right",
    "depth",
    "count",
    "mean",
    "covariance",
    "axis",
    "threshold",
    "principal_axes",
)


def _clips(n_clips, d, seed, longest=200):
    """Clips of random lengths from a few clusters with unequal spreads per channel."""
    rng = np.random.default_rng(seed)
    spread = rng.uniform(0.1, 10.0, d)
    return [
        (rng.normal(size=(int(rng.integers(1, longest)), d)) + 3 * rng.integers(0, 3, (1, d)))
        * spread
        + 5.0
        for _ in range(n_clips)
    ]


def _assert_same_tree(a, b):
    for name in _TREE_ARRAYS:
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name
    assert a.reg == b.reg
    assert len(a.layers) == len(b.layers)
    assert all(np.array_equal(x, y) for x, y in zip(a.layers, b.layers))


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 40), st.integers(2, 6), st.integers(1, 50), st.integers(0, 2**32 - 1))
def test_stacked_clips_are_the_stacked_arrays_doubles(n_clips, d, rows, seed):
    clips = _clips(n_clips, d, seed, longest=30)
    frames = np.concatenate(clips)
    stacked = StackedClips(clips)
    assert (stacked.n_frames, stacked.n_channels) == frames.shape
    blocks = list((start, block.copy()) for start, block in stacked.blocks(rows))
    assert [start for start, _ in blocks] == list(range(0, len(frames), rows))
    assert np.array_equal(np.concatenate([block for _, block in blocks]), frames)
    mean, std = stacked.mean_std()
    expected_mean, expected_std = column_mean_std(frames)
    assert np.array_equal(mean, expected_mean) and np.array_equal(std, expected_std)
    stacked.center, stacked.scale = mean, std
    z = standardise_in_place(frames, mean, std)
    for start, view in stacked.blocks(rows, spare_row=True):
        assert np.array_equal(view[1:], z[start : start + rows])
    for start, block in stacked.blocks(rows, raw=True):  # raw: the clips' own values
        assert np.array_equal(block, np.concatenate(clips)[start : start + rows])


@pytest.mark.parametrize("scatter", [True, False])
def test_shifted_moments_added_block_by_block_are_one_calls_doubles(scatter):
    rng = np.random.default_rng(1)
    d = 7
    rows = rng.normal(size=(30_001, d)) * rng.uniform(0.1, 10, d)
    shift = rows.mean(axis=0)
    sums, products = shifted_moments(rows, shift, scatter)
    block = moment_chunk_rows(d) * 3
    out = (np.zeros(d), np.zeros((d, d)) if scatter else np.zeros(d))
    for start in range(0, len(rows), block):
        assert shifted_moments(rows[start : start + block], shift, scatter, out=out) is not None
    assert np.array_equal(out[0], sums) and np.array_equal(out[1], products)
    centred = rows - shift  # and they are the centred sums
    expected = centred.T @ centred if scatter else (centred**2).sum(axis=0)
    assert np.allclose(out[1], expected, rtol=1e-12)
    with pytest.raises(ValueError, match="do not match"):
        shifted_moments(rows[:5], shift, scatter, out=(np.zeros(d + 1), out[1]))


def test_scatter_rows_is_the_masked_gather():
    rng = np.random.default_rng(2)
    block = rng.normal(size=(500, 4))
    place = rng.permutation(800)[:500]
    out = np.zeros((300, 4))
    scatter_rows(block, place, 100, 400, out)
    mine = (place >= 100) & (place < 400)
    expected = np.zeros((300, 4))
    expected[place[mine] - 100] = block[mine]
    assert np.array_equal(out, expected)
    with pytest.raises(ValueError, match="do not match"):
        scatter_rows(block, place, 0, 10, out)


@pytest.mark.parametrize(
    "n_clips, d, split, depth, leaf",
    [
        (900, 8, "median", 3, 4),  # about 90,000 frames: several blocks of 32,768 rows
        (300, 5, "min_error", 6, 4),  # unequal children, the larger first or second
        (300, 12, "two_means", 4, 16),
        (30, 3, "median", None, 2),  # deep: the children's scatters derived and direct
        (4, 30, "median", 8, 1),  # fewer frames per node than channels below the root
    ],
)
def test_build_from_clips_is_the_in_memory_build_to_the_bit(n_clips, d, split, depth, leaf):
    clips = _clips(n_clips, d, seed=n_clips + d)
    params = TreeParams(
        max_depth=depth, min_samples_leaf=leaf, split=split, covariance_type="spherical"
    )
    stacked = StackedClips(clips)
    stacked.center, stacked.scale = stacked.mean_std()
    z = standardise_in_place(np.concatenate(clips), stacked.center, stacked.scale)
    expected = MotionTree.from_params(z, params, copy=False)
    tree = build_from_clips(stacked, params)
    assert tree.n_layers > 2
    _assert_same_tree(tree, expected)
    for layer in range(tree.n_layers):  # the training frames route to their nodes' counts
        counts = np.bincount(tree.apply(z, layer), minlength=tree.n_nodes[layer])
        assert np.array_equal(counts, tree.count[tree.layers[layer]])


def test_build_from_clips_a_root_that_does_not_split_and_refusals():
    clips = [np.ones((5, 3)), np.ones((4, 3))]  # no spread: no axis
    stacked = StackedClips(clips)
    stacked.center, stacked.scale = np.zeros(3), np.ones(3)
    tree = build_from_clips(stacked, TreeParams(max_depth=3, covariance_type="diag"))
    expected = MotionTree.from_params(np.concatenate(clips), TreeParams(max_depth=3))
    assert tree.n_nodes.tolist() == expected.n_nodes.tolist() == [1]
    assert np.array_equal(tree.mean, expected.mean)
    with pytest.raises(ValueError, match="diagonal or spherical"):
        build_from_clips(stacked, TreeParams(covariance_type="full"))


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        dict(residual_order=2, layers="all", transition_layers=[1], max_depth=5),
        dict(split="min_error", residual_layers=[1, 4], max_depth=4, standardize=False),
    ],
)
def test_the_lean_fit_is_the_stacked_fit(monkeypatch, kwargs):
    clips = _clips(400, 9, seed=7, longest=150)
    stacked_fit = MotionTreeEncoder(**kwargs).fit(clips)  # below the lean path's size
    monkeypatch.setattr(encoder_module, "_LEAN_FROM_FRAMES", 0)  # every fit lean
    lean = MotionTreeEncoder(**kwargs).fit(clips)
    _assert_same_tree(lean.tree_, stacked_fit.tree_)
    for name in ("moment_center_", "moment_scale_", "center_", "scale_"):
        assert np.array_equal(getattr(lean, name), getattr(stacked_fit, name))
    for a, b in zip(lean._residual_variances, stacked_fit._residual_variances, strict=True):
        assert np.array_equal(a, b)
    features = lean.transform(clips)
    expected = stacked_fit.transform(clips)
    assert np.array_equal(
        getattr(features, "toarray", lambda: features)(),
        getattr(expected, "toarray", lambda: expected)(),
    )
    # transform routes each training frame to the node the build put it in
    nodes = lean._router.route(np.concatenate(clips))
    for layer in range(1, lean.tree_.n_layers):
        counts = np.bincount(nodes[:, layer], minlength=lean.tree_.n_nodes[layer])
        assert np.array_equal(counts, lean.tree_.count[lean.tree_.layers[layer]])


def test_clips_the_lean_fit_leaves_to_the_stacked_one(monkeypatch):
    monkeypatch.setattr(encoder_module, "_LEAN_FROM_FRAMES", 0)
    clips = _clips(60, 4, seed=8)
    single = [clip[:, :1] for clip in clips]  # one channel: NumPy sums it pairwise
    as_float32 = [clip.astype(np.float32) for clip in clips]
    for data in (single, as_float32):
        lean = MotionTreeEncoder(max_depth=3).fit(data)
        monkeypatch.setattr(encoder_module, "_LEAN_FROM_FRAMES", 1 << 40)
        stacked_fit = MotionTreeEncoder(max_depth=3).fit(data)
        monkeypatch.setattr(encoder_module, "_LEAN_FROM_FRAMES", 0)
        _assert_same_tree(lean.tree_, stacked_fit.tree_)


def test_the_lean_fit_holds_half_the_frames_besides_the_callers(monkeypatch):
    monkeypatch.setattr(encoder_module, "_LEAN_FROM_FRAMES", 100_000)
    rng = np.random.default_rng(0)
    frames = rng.normal(size=(200_000, 20)) + 3 * rng.integers(0, 2, size=(200_000, 1))
    clips = [frames[s : s + 100] for s in range(0, len(frames), 100)]
    tracemalloc.start()
    MotionTreeEncoder().fit(clips)
    peak = tracemalloc.get_traced_memory()[1] / frames.nbytes
    tracemalloc.stop()
    # one child's frames (half of them, median cuts), 8-24 bytes a frame and blocks of
    # 32,768 rows (0.16x of these frames): 0.77 measured; the stacked fit's copy of all
    # frames alone is 1.0 (1.17 measured)
    assert peak < 0.85
