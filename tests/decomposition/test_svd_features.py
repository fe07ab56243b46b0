"""SVDFeatureExtractor against a numpy SVD reference and the properties it promises."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skmotion.datasets import make_motions
from skmotion.decomposition import (
    SVDFeatureExtractor,
    fit_svd_projection,
    max_svd_components,
    svd_project,
)
from skmotion.decomposition._clip_svd import clip_spectra
from skmotion.decomposition._svd_projection import _composite
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def _data():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "wave", "squat"], duration=(1.0, 1.5), random_state=0
    )
    return [c[:, 6:] for c in data.clips], data.target


@parametrize_with_clip_checks(
    [
        ClipCase(SVDFeatureExtractor(n_components=3), _data, param_grid={"n_components": [2, 3]}),
        ClipCase(SVDFeatureExtractor(n_components=4, weighting="first_two"), _data),
    ]
)
def test_conformance(check):
    check()


def _largest_entry_positive(rows):
    return rows * np.sign(rows[np.arange(len(rows)), np.abs(rows).argmax(axis=1)])[:, None]


def reference_features(train, test, r, weighting):
    """The paper's recipe written directly with np.linalg.svd on every clip."""

    def singular(clips):
        out = [np.linalg.svd(c, full_matrices=False) for c in clips]
        return [s for _, s, _ in out], [vt for _, _, vt in out]

    def composite(clips, axes):
        values, vts = singular(clips)
        rows = []
        for s, vt in zip(values, vts):
            parts = []
            for i, axis in enumerate(axes):
                u = vt[i] if vt[i] @ axis >= 0 else -vt[i]
                parts.append(u if weighting == "first" else s[i] / s.sum() * u)
            rows.append(np.concatenate(parts))
        return np.array(rows)

    _, vts = singular(train)
    n_vectors = 1 if weighting == "first" else 2
    axes = []
    for i in range(n_vectors):
        w, v = np.linalg.eigh(sum(np.outer(vt[i], vt[i]) for vt in vts))
        axes.append(_largest_entry_positive(v[:, -1][None])[0])
    z = _largest_entry_positive(np.linalg.svd(composite(train, axes), full_matrices=False)[2][:r])
    features = composite(test, axes) @ z.T
    return features * np.where(features[:, :1] < 0, -1, 1)


@pytest.mark.parametrize("weighting", ["first", "first_two"])
def test_matches_svd_reference(weighting):
    clips, _ = _data()
    rng = np.random.default_rng(1)
    # Ragged, and two clips with fewer frames than channels (the frames x frames Gram route).
    others = [rng.normal(size=(n, clips[0].shape[1])) for n in (5, 30, 90)]
    extractor = SVDFeatureExtractor(n_components=5, weighting=weighting).fit(clips)
    np.testing.assert_allclose(
        extractor.transform(clips + others),
        reference_features(clips, clips + others, 5, weighting),
        atol=1e-8,
    )


def test_composite_weights_are_singular_value_shares():
    # A clip whose right singular vectors are the axes, singular values 3, 2, 1.
    clip = np.diag([3.0, 2.0, 1.0])
    extractor = SVDFeatureExtractor(n_components=1, weighting="first_two").fit([clip, clip])
    composite = _composite(*clip_spectra([clip], 2), extractor.axes_, "first_two")
    np.testing.assert_allclose(np.abs(composite), [[0.5, 0, 0, 0, 1 / 3, 0]], atol=1e-12)


@pytest.mark.parametrize("weighting", ["first", "first_two"])
def test_public_projection_functions_are_what_the_extractor_computes(weighting):
    clips, _ = _data()
    extractor = SVDFeatureExtractor(n_components=4, weighting=weighting).fit(clips)
    spectra = clip_spectra(clips, 2)
    projection = fit_svd_projection(*spectra, 4, weighting)
    np.testing.assert_allclose(projection.components, extractor.components_, atol=1e-12)
    expected = extractor.transform(clips)
    np.testing.assert_allclose(svd_project(projection, *spectra), expected, atol=1e-12)
    again = SVDFeatureExtractor.from_projection(extractor.projection_, clips[0].shape[1])
    np.testing.assert_array_equal(again.transform(clips), expected)


def test_default_length_is_capped_on_six_channel_data():
    # BasicMotions-shaped: 6 channels (accelerometer + gyroscope), 100 frames.
    rng = np.random.default_rng(0)
    clips = [rng.normal(size=(100, 6)) * rng.uniform(0.5, 2, size=6) for _ in range(12)]
    extractor = SVDFeatureExtractor().fit(clips)
    assert extractor.n_components_ == max_svd_components(12, 6, "first") == 6
    assert extractor.transform(clips).shape == (12, 6)
    assert len(extractor.get_feature_names_out()) == 6
    two = SVDFeatureExtractor(weighting="first_two").fit(clips)
    assert two.n_components_ == 8  # the default fits in 2 x 6
    few = SVDFeatureExtractor().fit(clips[:3])
    assert few.n_components_ == 3  # capped at the training clips
    with pytest.raises(ValueError, match=r"n_components=7 must be at most 6.*Pass n_components=6"):
        SVDFeatureExtractor(n_components=7).fit(clips)


@pytest.mark.parametrize("scale", [1e-300, 1e-100, 1e100, 1e300])
def test_features_do_not_depend_on_the_clips_scale(scale):
    clips, _ = _data()
    extractor = SVDFeatureExtractor(n_components=4, weighting="first_two").fit(clips)
    expected = extractor.transform(clips)
    scaled = [c * scale for c in clips]
    np.testing.assert_allclose(extractor.transform(scaled), expected, atol=1e-10)
    refit = SVDFeatureExtractor(n_components=4, weighting="first_two").fit(scaled)
    np.testing.assert_allclose(refit.transform(scaled), expected, atol=1e-10)


clip_strategy = arrays(
    np.float64, st.tuples(st.integers(8, 30), st.just(4)), elements=st.floats(-3, 3, width=32)
)


@given(clip_strategy, st.integers(2, 4), st.randoms(use_true_random=False))
def test_repeating_or_reordering_frames_keeps_the_features(clip, times, random):
    rng = np.random.default_rng(0)
    train = [rng.normal(size=(20, 4)) * [4, 3, 2, 1] + 1 for _ in range(6)]
    extractor = SVDFeatureExtractor(n_components=3, weighting="first_two").fit(train)
    if (
        np.linalg.svd(clip, compute_uv=False)[:3].min() < 1e-3
        or np.abs(np.diff(np.linalg.svd(clip, compute_uv=False)[:3])).min() < 1e-3
    ):
        return  # repeated or vanishing singular values: the vectors are not unique
    order = list(range(len(clip)))
    random.shuffle(order)
    same = extractor.transform([clip, np.vstack([clip] * times), clip[order]])
    np.testing.assert_allclose(same[1], same[0], atol=1e-6)
    np.testing.assert_allclose(same[2], same[0], atol=1e-6)
    assert same[0, 0] >= 0 and np.all(np.abs(same) <= 1 + 1e-12)


def test_similar_motions_get_close_features():
    data = make_motions(n_clips_per_class=8, random_state=3)
    clips = [c[:, 6:] for c in data.clips]
    features = SVDFeatureExtractor(n_components=6).fit_transform(clips)
    distances = np.linalg.norm(features[:, None] - features[None], axis=-1)
    np.fill_diagonal(distances, np.inf)
    # The nearest feature vector is mostly one of the same class.
    assert (data.target[distances.argmin(axis=1)] == data.target).mean() >= 0.8


def test_errors_name_the_problem():
    clips, _ = _data()
    with pytest.raises(ValueError, match=r"clip 2 is all zeros"):
        SVDFeatureExtractor(n_components=2).fit(clips[:2] + [np.zeros_like(clips[2])])
    with pytest.raises(ValueError, match=r"n_components=61 must be at most 9"):
        SVDFeatureExtractor(n_components=61).fit(clips)
    with pytest.raises(ValueError, match=r"n_components=9 must be at most 4"):
        SVDFeatureExtractor(n_components=9, weighting="first_two").fit([c[:, :2] for c in clips])
    with pytest.raises(ValueError, match="weighting"):
        SVDFeatureExtractor(weighting="second").fit(clips)


def test_feature_names():
    clips, _ = _data()
    names = SVDFeatureExtractor(n_components=3).fit(clips).get_feature_names_out()
    assert names.tolist() == [
        "svdfeatureextractor0",
        "svdfeatureextractor1",
        "svdfeatureextractor2",
    ]
