"""The encoder's compiled readouts give the doubles of the NumPy expressions they replace.

``tree/_encoding/_readout_passes.pyx`` sums each clip's residuals and moments in one pass.
The references here are those NumPy expressions as the encoder computed them before
(sparse-free group sums, ``np.bincount``, ``np.add.reduce``), and the comparisons are
``np.array_equal``: the same doubles, not merely close ones. The features' meaning is
checked against loops over frames in ``test_encoder.py``.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skmotion.tree._encoding._readout_passes import extremes_within, moment_rows, residual_rows
from skmotion.utils._group_sums import group_sums

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeEncoder
from skmotion.tree._encoding._histograms import (
    feature_blocks,
    histogram_features,
    moment_features,
    residual_features,
)


def clips_and_offsets(rng, lengths, d, decades=3):
    """Random clips, stacked, channels of scales ``10 ** -decades`` to ``10 ** decades``."""
    frames = rng.normal(size=(sum(lengths), d)) * 10.0 ** rng.integers(-decades, decades + 1, d)
    return frames, np.concatenate([[0], np.cumsum(lengths)]).astype(np.intp)


def numpy_residuals(frames, node, offsets, mean, center, scale, power):
    """The residual block as NumPy computed it: group sums, bincount shares, row norms."""
    lengths = np.diff(offsets)
    n_clips, k = len(lengths), len(mean)
    clip = np.repeat(np.arange(n_clips), lengths)
    weight = 1.0 / lengths[clip]
    group = clip * k + node
    share = np.bincount(group, weights=weight, minlength=n_clips * k)[:, None]
    sums = group_sums(frames, group, weight, n_clips * k)
    block = ((sums - share * center) / scale).reshape(n_clips, k, -1)
    block = (block - share.reshape(n_clips, k, 1) * mean).reshape(n_clips, -1)
    if power != 1:
        block = np.sign(block) * np.abs(block) ** power
    norm = np.sqrt(np.add.reduce(block * block, axis=1, keepdims=True))
    return block / np.where(norm > 0, norm, 1.0)


def numpy_moments(frames, offsets, center, scale, order, pyramid):
    """The moments as NumPy computed them: a centred copy, cell means by group sums."""
    lengths = np.diff(offsets)
    n_clips = len(lengths)
    clip = np.repeat(np.arange(n_clips), lengths)
    centred = frames - center
    blocks = []
    for parts in pyramid:
        cell = (np.arange(len(clip)) - offsets[clip]) * parts // lengths[clip]
        key = clip * parts + cell
        size = np.bincount(key, minlength=n_clips * parts)
        means = group_sums(centred, key, 1.0 / size[key], n_clips * parts)
        for empty in np.flatnonzero(size == 0):  # the frame that spans the empty cell
            owner, c = divmod(empty, parts)
            means[empty] = centred[offsets[owner] + c * lengths[owner] // parts]
        blocks.append(means.reshape(n_clips, -1) / np.tile(scale, parts))
    if order == 2:
        squares = group_sums(centred * centred, clip, 1.0 / lengths[clip], n_clips)
        blocks.append(np.sqrt(squares) / scale - 1.0)
    return np.concatenate(blocks, axis=1)


@settings(max_examples=60, deadline=None)
@given(
    lengths=st.lists(st.integers(1, 40), min_size=1, max_size=5),
    k=st.integers(1, 9),
    d=st.integers(1, 17),
    power=st.sampled_from([0.5, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_residual_rows_are_the_numpy_doubles(lengths, k, d, power, seed):
    rng = np.random.default_rng(seed)
    frames, offsets = clips_and_offsets(rng, lengths, d)
    node = rng.integers(0, k, size=len(frames)).astype(np.intp)
    mean, center = rng.normal(size=(k, d)), rng.normal(size=d)
    scale = rng.uniform(0.1, 10.0, size=d)
    rows = residual_rows(frames, node, offsets, mean, center, scale, True, power == 0.5)
    expected = numpy_residuals(frames, node, offsets, mean, center, scale, power)
    assert np.array_equal(rows, expected)


@settings(max_examples=60, deadline=None)
@given(
    lengths=st.lists(st.integers(1, 40), min_size=1, max_size=5),
    n_nodes=st.lists(st.integers(1, 9), min_size=1, max_size=3),
    pyramid=st.lists(st.integers(1, 7), min_size=1, max_size=3),
    transitions=st.booleans(),
    power=st.sampled_from([0.5, 1.0, 0.3]),
    seed=st.integers(0, 2**16),
)
def test_dense_histograms_are_the_sparse_matrixs_doubles(
    lengths, n_nodes, pyramid, transitions, power, seed
):
    # the compiled dense pass against the sparse matrix whose duplicates sum: every layer's
    # occupancy over any pyramid (cells without a frame in clips shorter than the level),
    # the transitions, any power
    rng = np.random.default_rng(seed)
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.intp)
    layers = list(range(1, len(n_nodes) + 1))
    nodes = np.column_stack([rng.integers(0, k, size=offsets[-1]) for k in n_nodes])
    counts = np.zeros(len(layers) + 1, dtype=int)
    counts[layers] = n_nodes
    blocks = feature_blocks(layers, counts, pyramid, layers[-1:] if transitions else [])
    sparse = histogram_features(nodes, offsets, layers, blocks, power)
    dense = histogram_features(nodes, offsets, layers, blocks, power, dense=True)
    assert np.array_equal(dense, sparse.toarray())


@pytest.mark.parametrize("width", [1, 7, 8, 9, 127, 128, 129, 255, 960, 1000, 30720, 40001])
def test_row_norms_are_numpys_pairwise_sums(width):
    # every branch of NumPy's pairwise summation: under 8 values, one block of up to 128,
    # and longer rows halved at multiples of 8 (a layer of 256 nodes x 120 channels: 30720)
    rng = np.random.default_rng(width)
    frames, offsets = clips_and_offsets(rng, [3, 5], width, decades=0)  # all values count
    node = np.zeros(len(frames), dtype=np.intp)
    center, scale, mean = np.zeros(width), np.ones(width), rng.normal(size=(1, width))
    rows = residual_rows(frames, node, offsets, mean, center, scale, True, True)
    assert np.array_equal(rows, numpy_residuals(frames, node, offsets, mean, center, scale, 0.5))


def test_residual_rows_by_hand():
    # one channel; a clip of 4 frames: node 0 holds 1 and 3 (share 1/2), node 1 holds 5 and 7
    # (share 1/2); node means 1 and 4 (standardised, center 1, scale 2): node 0's offset is
    # ((1 + 3) / 4 - 1/2 * 1) / 2 - 1/2 * 1 = -1/4, node 1's ((5 + 7) / 4 - 1/2) / 2 - 2 = -3/4
    frames = np.array([[1.0], [5.0], [3.0], [7.0]])
    args = (frames, np.array([0, 1, 0, 1]), np.array([0, 4]), np.array([[1.0], [4.0]]))
    raw = residual_rows(*args, np.ones(1), np.full(1, 2.0), False, False)
    assert raw.tolist() == [[-0.25, -0.75]]
    root = residual_rows(*args, np.ones(1), np.full(1, 2.0), True, True)
    np.testing.assert_allclose(root, [[-0.5, -np.sqrt(0.75)]])  # unit norm: 1/4 + 3/4 = 1


@settings(max_examples=60, deadline=None)
@given(
    lengths=st.lists(st.integers(1, 30), min_size=1, max_size=5),
    d=st.integers(1, 9),
    order=st.sampled_from([1, 2]),
    pyramid=st.lists(st.integers(1, 9), min_size=1, max_size=3),
    seed=st.integers(0, 2**16),
)
def test_moment_rows_are_the_numpy_doubles(lengths, d, order, pyramid, seed):
    # clips shorter than a level leave cells empty, which take the frame that spans them
    rng = np.random.default_rng(seed)
    frames, offsets = clips_and_offsets(rng, lengths, d)
    center, scale = rng.normal(size=d), rng.uniform(0.1, 10.0, size=d)
    rows = moment_rows(frames, offsets, center, scale, order, np.array(pyramid, dtype=np.intp))
    assert np.array_equal(rows, numpy_moments(frames, offsets, center, scale, order, pyramid))


def test_the_wrappers_take_float32_frames_and_other_powers():
    rng = np.random.default_rng(3)
    frames, offsets = clips_and_offsets(rng, [4, 9, 1], 5)
    single = frames.astype(np.float32)
    node = rng.integers(0, 3, size=(len(frames), 1))
    mean, center, scale = rng.normal(size=(3, 5)), rng.normal(size=5), rng.uniform(1, 2, 5)
    for power in (0.3, 0.5, 1.0):  # 0.3: the row by NumPy's power, the sums compiled
        got = residual_features(single, node, offsets, [mean], center, scale, power)
        expected = numpy_residuals(
            single.astype(float), node[:, 0], offsets, mean, center, scale, power
        )
        assert np.array_equal(got, expected)
    got = moment_features(single, offsets, center, scale, 2, (1, 2))
    assert np.array_equal(
        got, numpy_moments(single.astype(float), offsets, center, scale, 2, (1, 2))
    )


def test_extremes_within_is_the_reach_of_the_extremes():
    rng = np.random.default_rng(0)
    frames = rng.normal(size=(50, 4)) * [1.0, 10.0, 100.0, 1000.0]
    centers, scales = rng.normal(size=(3, 4)), rng.uniform(0.5, 2.0, size=(3, 4))
    high, low = frames.max(axis=0), frames.min(axis=0)
    reach = (np.maximum(np.abs(high - centers), np.abs(low - centers)) / scales).max()
    assert extremes_within(frames, centers, scales, reach)
    assert not extremes_within(frames, centers, scales, np.nextafter(reach, 0))
    for value in (np.nan, np.inf, -np.inf):  # not finite: False, the caller looks closer
        for row in (0, 17):
            bad = frames.copy()
            bad[row, 2] = value
            assert not extremes_within(bad, centers, scales, 1e300)


def test_bad_arguments_are_refused():
    frames, offsets = np.ones((3, 2)), np.array([0, 3])
    mean, center, scale = np.zeros((2, 2)), np.zeros(2), np.ones(2)
    with pytest.raises(ValueError, match=r"node\[1\] is 2, outside 0 .. 1"):
        residual_rows(frames, np.array([0, 2, 1]), offsets, mean, center, scale, True, True)
    with pytest.raises(ValueError, match="offsets must run from 0 to the 3 frames"):
        residual_rows(frames, np.zeros(3, np.intp), np.array([0, 2]), mean, center, scale, 1, 1)
    with pytest.raises(ValueError, match="must not decrease"):
        moment_rows(frames, np.array([0, 2, 1, 3]), center, scale, 2, np.array([1]))
    with pytest.raises(ValueError, match="clip 1 has no frames"):
        moment_rows(frames, np.array([0, 3, 3]), center, scale, 2, np.array([1]))
    with pytest.raises(ValueError, match="pyramid levels must be at least 1"):
        moment_rows(frames, offsets, center, scale, 1, np.array([0]))


@pytest.mark.parametrize(
    "params",
    [
        {},
        {"residual_order": 2, "moment_pyramid": (1, 2, 4)},
        {"power": 0.3, "residual_layers": (2,), "layers": "all", "transition_layers": (1,)},
        {"standardize": False, "power": 1.0, "moments": 1},
    ],
)
def test_one_clip_per_call_gives_the_batchs_doubles(params):
    data = make_motions(n_clips_per_class=3, random_state=2)
    X = [clip[:, 6:] for clip in data.clips]
    encoder = MotionTreeEncoder(max_depth=4, sparse_output=False, **params).fit(X[::2])
    test = X[1::2] + [X[1][:2], X[3][:1].astype(np.float32)]  # shorter than the pyramids
    batched = encoder.transform(test)
    one_by_one = np.vstack([encoder.transform([clip]) for clip in test])
    assert np.array_equal(batched, one_by_one)


def test_route_clips_is_the_route_of_the_stacked_clips():
    # groups of clips pass the router's block of 32,768 frames; every frame is routed alone
    rng = np.random.default_rng(5)
    clips = [rng.normal(size=(n, 3)) for n in (1, 20_000, 7, 30_000, 5_000, 1)]
    encoder = MotionTreeEncoder(max_depth=5, residual_layers=(2, 5)).fit(clips)
    router, stacked = encoder._router, np.vstack(clips)
    assert np.array_equal(router.route_clips(clips), router.route(stacked))
    assert np.array_equal(router.route_clips(clips, [2, 5]), router.route(stacked, [2, 5]))


def test_fit_and_transform_make_no_second_copy_of_the_frames():
    # the fit's own stacked, standardised copy is the one frame-sized array it needs; the
    # second order's routing and variances go a block of clips or rows at a time (it once
    # stacked the raw frames again and made three frame-sized temporaries: 3.1x the frames)
    import tracemalloc

    rng = np.random.default_rng(0)
    frames = rng.normal(size=(200_000, 20)) + 3 * rng.integers(0, 2, size=(200_000, 1))
    clips = [frames[s : s + 100] for s in range(0, len(frames), 100)]
    peaks = []
    for order in (1, 2):
        tracemalloc.start()
        encoder = MotionTreeEncoder(residual_order=order).fit(clips)
        peaks.append(tracemalloc.get_traced_memory()[1] / frames.nbytes)
        tracemalloc.stop()
    assert peaks[0] < 1.25  # the stacked copy and the build's few numbers per frame
    assert peaks[1] < 1.6  # and a block's temporaries (0.16x of these 200,000 frames)
    # transform: the stacked clips and the features, no centred copy for the moments (2.2x
    # before the compiled readouts)
    encoder = MotionTreeEncoder().fit(clips[:100])
    tracemalloc.start()
    encoder.transform(clips)
    peak = tracemalloc.get_traced_memory()[1] / frames.nbytes
    tracemalloc.stop()
    assert peak < 1.5
