import inspect
import pickle

import numpy as np
import pytest
from sklearn.decomposition import PCA

from skmotion.datasets import make_motions
from skmotion.decomposition import EigenMovementPCA
from skmotion.preprocessing import energy_segments, lowpass_filter, resample_clip, segment_clip
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks
from tests.preprocessing.test_segment import minimum_jerk

RIGHT_ARM = [33, 34, 35, 37]  # RightArm Z, X, Y and RightForeArm X rotations


def stroke_clips(n_clips=12, seed=0):
    """Clips of 3-channel strokes between random rest poses (known, smooth)."""
    rng = np.random.default_rng(seed)
    clips = []
    for _ in range(n_clips):
        poses = rng.uniform(-1, 1, size=(5, 3))
        parts = [poses[:1]]
        for k in range(4):
            n = int(rng.integers(18, 30))
            parts.append(parts[-1][-1] + (poses[k + 1] - parts[-1][-1]) * minimum_jerk(n)[:, None])
        clips.append(
            np.concatenate(parts) + 0.002 * rng.normal(size=(1 + sum(len(p) for p in parts[1:]), 3))
        )
    return clips


def _strokes():
    return stroke_clips(9), None


@parametrize_with_clip_checks([ClipCase(EigenMovementPCA(n_components=3, n_samples=20), _strokes)])
def test_conformance(check):
    check()


@pytest.fixture(scope="module")
def arm_degrees():
    data = make_motions(n_clips_per_class=6, random_state=0)
    return [np.rad2deg(c[:, RIGHT_ARM]) for c in data.clips]


def _flat(normalised):
    """(n_segments, n_samples, n_channels) back to channel-major vectors."""
    n_segments, n_samples, n_channels = normalised.shape
    return normalised.transpose(0, 2, 1).reshape(n_segments, n_samples * n_channels)


@pytest.mark.parametrize("segmentation", ["energy", "zvc"])
@pytest.mark.parametrize("n_components", [5, 20])
def test_projection_mse_is_the_sum_of_dropped_eigenvalues(arm_degrees, segmentation, n_components):
    # The key identity: measured mean squared reconstruction error of the training
    # segments == sum of the eigenvalues of the dropped eigenmovements.
    pca = EigenMovementPCA(n_components, segmentation=segmentation, frame_rate=30, min_movement=2.0)
    codes = pca.fit_transform(arm_degrees)
    vectors = np.concatenate(pca.segment_vectors(arm_degrees))
    rebuilt = np.concatenate([_flat(n) for n in pca.inverse_transform(codes)])
    measured = np.mean(np.sum((vectors - rebuilt) ** 2, axis=1))
    eigenvalues = np.linalg.eigvalsh(np.cov(vectors.T, bias=True))[::-1]
    np.testing.assert_allclose(pca.projection_mse_, eigenvalues[n_components:].sum(), rtol=1e-9)
    np.testing.assert_allclose(measured, pca.projection_mse_, rtol=1e-9)
    np.testing.assert_allclose(pca.explained_variance_, eigenvalues[:n_components], rtol=1e-9)
    np.testing.assert_allclose(pca.total_variance_, eigenvalues.sum(), rtol=1e-9)
    assert pca.projection_rms_ == pytest.approx(np.sqrt(measured / vectors.shape[1]))
    assert pca.n_segments_ == len(vectors) > n_components


def test_fewer_segments_than_dimensions_and_rank_deficient_data():
    # N < D takes the Gram route; duplicated segments leave fewer directions than
    # components, and the basis is completed (orthonormal) all the same.
    clips = stroke_clips(4)
    pca = EigenMovementPCA(None, segmentation="energy").fit(clips + clips)
    assert pca.n_segments_ < pca.components_.shape[1]
    gram = pca.components_ @ pca.components_.T
    np.testing.assert_allclose(gram, np.eye(len(gram)), atol=1e-9)
    vectors = np.concatenate(pca.segment_vectors(clips))
    back = np.concatenate([_flat(n) for n in pca.inverse_transform(pca.transform(clips))])
    np.testing.assert_allclose(back, vectors, atol=1e-8)
    assert pca.projection_mse_ == pytest.approx(0.0, abs=1e-10)


def test_components_match_sklearn_pca(arm_degrees):
    pca = EigenMovementPCA(6).fit(arm_degrees)
    vectors = np.concatenate(pca.segment_vectors(arm_degrees))
    reference = PCA(6, svd_solver="full").fit(vectors)
    np.testing.assert_allclose(
        np.abs(pca.components_ @ reference.components_.T), np.eye(6), atol=1e-6
    )
    n = len(vectors)
    np.testing.assert_allclose(
        pca.explained_variance_, reference.explained_variance_ * (n - 1) / n, rtol=1e-8
    )
    np.testing.assert_allclose(pca.mean_, reference.mean_)
    # Deterministic signs: the largest entry of each eigenmovement is positive.
    rows = np.arange(6)
    assert (pca.components_[rows, np.abs(pca.components_).argmax(axis=1)] > 0).all()


def test_cubic_segments_are_rebuilt_exactly_with_every_component():
    # A not-a-knot cubic spline reproduces cubic polynomials, so resampling to
    # n_samples and re-timing back loses nothing, whatever the clip lengths.
    rng = np.random.default_rng(1)
    clips = []
    for n in (17, 23, 40, 55, 31, 64, 12, 29):
        t = np.linspace(0, 1, n)[:, None]
        a, b, c, d = rng.normal(size=(4, 2))
        clips.append(a + b * t + c * t**2 + d * t**3)
    pca = EigenMovementPCA(None, n_samples=10, segmentation="none").fit(clips)
    rebuilt = pca.reconstruct(clips)
    for clip, back in zip(clips, rebuilt):
        np.testing.assert_allclose(back, clip, atol=1e-9)
    assert pca.score(clips) == pytest.approx(0.0, abs=1e-9)


def test_vectors_are_laid_out_channel_after_channel():
    t = np.linspace(0, 1, 30)
    clip = np.c_[t, 10 + t, 20 + t]
    pca = EigenMovementPCA(1, n_samples=5, segmentation="none").fit([clip, 2 * clip])
    vector = pca.segment_vectors([clip])[0][0]
    expected = np.r_[np.linspace(0, 1, 5), 10 + np.linspace(0, 1, 5), 20 + np.linspace(0, 1, 5)]
    np.testing.assert_allclose(vector, expected, atol=1e-12)


def test_segments_come_from_the_filtered_clip(arm_degrees):
    pca = EigenMovementPCA(5, energy_ratio=0.2).fit(arm_degrees)
    for clip, segments in zip(arm_degrees[:6], pca.segment(arm_degrees[:6])):
        np.testing.assert_array_equal(segments, energy_segments(lowpass_filter(clip), ratio=0.2))
    codes = pca.transform(arm_degrees[:6])
    assert [len(c) for c in codes] == [len(s) for s in pca.segment(arm_degrees[:6])]


def test_inverse_transform_retimes_and_places_segments():
    clips = stroke_clips(6)
    pca = EigenMovementPCA(8, n_samples=50).fit(clips)
    codes, segments = pca.transform(clips), pca.segment(clips)
    normalised = pca.inverse_transform(codes)
    placed = pca.inverse_transform(codes, segments, n_frames=[len(c) + 5 for c in clips])
    for clip, norm, seg, back in zip(clips, normalised, segments, placed):
        assert norm.shape == (len(seg), 50, 3) and back.shape == (len(clip) + 5, 3)
        covered = np.zeros(len(back), dtype=bool)
        for k, (a, b) in enumerate(seg):
            covered[a:b] = True
            inside = slice(a + 1, b - 1)  # boundary frames are shared with neighbours
            expected = resample_clip(norm[k], np.linspace(0, 49, b - a), kind="cubic")
            np.testing.assert_allclose(back[inside], expected[1:-1], atol=1e-12)
        assert np.isnan(back[~covered]).all() and not np.isnan(back[covered]).any()
    # by default the clip ends at the last segment's stop
    assert [len(b) for b in pca.inverse_transform(codes, segments)] == [
        int(s[-1, 1]) for s in segments
    ]


def test_a_shared_boundary_frame_is_the_mean_of_its_two_segments():
    clip = np.r_[np.linspace(0, 1, 21), np.linspace(1, 0, 21)[1:]][:, None] * [1.0, 2.0]
    pca = EigenMovementPCA(None, n_samples=21, segmentation="none").fit([clip[:21], clip[20:]])
    codes = pca.transform([clip[:21], clip[20:]])
    both = [np.vstack(codes)]
    segments = [np.array([[0, 21], [20, 41]])]
    rebuilt = pca.inverse_transform(both, segments)[0]
    ends = pca.inverse_transform(both)[0]
    np.testing.assert_allclose(rebuilt[20], (ends[0, -1] + ends[1, 0]) / 2)
    np.testing.assert_allclose(rebuilt, clip, atol=1e-9)


def test_score_is_minus_the_rms_over_covered_frames(arm_degrees):
    pca = EigenMovementPCA(10).fit(arm_degrees)
    rebuilt = pca.reconstruct(arm_degrees)
    diff = np.concatenate([c - r for c, r in zip(arm_degrees, rebuilt)])
    diff = diff[~np.isnan(diff)]
    assert pca.score(arm_degrees) == pytest.approx(-np.sqrt(np.mean(diff**2)))
    # More eigenmovements never fit the training segments worse.
    assert EigenMovementPCA(30).fit(arm_degrees).score(arm_degrees) > pca.score(arm_degrees)


def test_transform_is_the_projection_of_the_segment_vectors(arm_degrees):
    pca = EigenMovementPCA(4).fit(arm_degrees)
    vectors = pca.segment_vectors(arm_degrees[:5])
    for code, vec in zip(pca.transform(arm_degrees[:5]), vectors):
        np.testing.assert_allclose(code, (vec - pca.mean_) @ pca.components_.T)


def test_pickle_round_trip_gives_identical_codes(arm_degrees):
    pca = EigenMovementPCA(4).fit(arm_degrees)
    again = pickle.loads(pickle.dumps(pca))
    for a, b in zip(pca.transform(arm_degrees), again.transform(arm_degrees)):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    "params, match",
    [
        ({"segmentation": "zvc"}, "segmentation='zvc' needs frame_rate"),
        ({"energy_threshold": 1.0}, "explicit energy_threshold needs frame_rate"),
        ({"n_components": 500}, r"n_components=500 must be at most min\(n_segments, n_features\)"),
        ({"min_movement": 1e9}, "No segments were found in the 9 training clips"),
    ],
)
def test_fit_errors(params, match):
    with pytest.raises(ValueError, match=match):
        EigenMovementPCA(**params).fit(stroke_clips(9))


def test_inverse_transform_errors():
    clips = stroke_clips(6)
    pca = EigenMovementPCA(3).fit(clips)
    codes, segments = pca.transform(clips), pca.segment(clips)
    with pytest.raises(ValueError, match="codes have 2 columns"):
        pca.inverse_transform([c[:, :2] for c in codes])
    with pytest.raises(ValueError, match="clip 1 has 1 segments but"):
        pca.inverse_transform(codes, [segments[0], segments[1][:1], *segments[2:]])
    bad = [s.copy() for s in segments]
    bad[2][0] = [5, 5]
    with pytest.raises(ValueError, match=r"clip 2, segment 0 is \[5, 5\]"):
        pca.inverse_transform(codes, bad)
    with pytest.raises(ValueError, match="n_frames: clip 0 is given 3 frames"):
        pca.inverse_transform(codes, segments, n_frames=3)
    with pytest.raises(ValueError, match="n_frames needs segments"):
        pca.inverse_transform(codes, n_frames=10)


def test_clips_without_segments_give_empty_codes():
    clips = stroke_clips(6)
    still = np.zeros((60, 3))
    pca = EigenMovementPCA(3).fit(clips)
    codes = pca.transform([still, clips[0]])
    assert codes[0].shape == (0, 3) and len(codes[1]) > 0
    rebuilt = pca.inverse_transform(
        codes, pca.segment([still, clips[0]]), n_frames=[60, len(clips[0])]
    )
    assert np.isnan(rebuilt[0]).all()
    with pytest.raises(ValueError, match="No segments were found in the 1 clips"):
        pca.score([still])


def test_segmentation_defaults_are_segment_clips():
    """EigenMovementPCA repeats segment_clip's parameters in its signature (sklearn wants
    them spelled out): their defaults must stay the same."""
    mine = inspect.signature(EigenMovementPCA).parameters
    theirs = inspect.signature(segment_clip).parameters
    assert mine["segmentation"].default == theirs["rule"].default
    shared = [name for name in theirs if name not in ("clip", "rule")]
    assert len(shared) == 8
    for name in shared:
        assert mine[name].default == theirs[name].default, name
