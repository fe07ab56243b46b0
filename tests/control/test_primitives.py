import numpy as np
import pytest
from sklearn.cluster import KMeans
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.control import KMeansPrimitiveController
from skmotion.datasets import make_motions
from skmotion.decomposition import EigenMovementPCA
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks
from tests.decomposition.test_eigenmovements import RIGHT_ARM, stroke_clips


def _codes():
    clips = stroke_clips(12, seed=2)
    codes = EigenMovementPCA(4, n_samples=20).fit_transform(clips)
    return codes, np.array([0, 1, 2] * 4)


@parametrize_with_clip_checks(
    [ClipCase(KMeansPrimitiveController(4, n_init=2, random_state=0), _codes)]
)
def test_conformance(check):
    check()


@pytest.fixture(scope="module")
def arm_model():
    data = make_motions(n_clips_per_class=6, random_state=1)
    arm = [np.rad2deg(c[:, RIGHT_ARM]) for c in data.clips]
    pca = EigenMovementPCA(12).fit(arm)
    return arm, pca, pca.transform(arm)


def _flat(normalised):
    n_segments, n_samples, n_channels = normalised.shape
    return normalised.transpose(0, 2, 1).reshape(n_segments, n_samples * n_channels)


@pytest.mark.parametrize("n_clusters", [5, 40])
def test_total_error_is_projection_plus_clustering(arm_model, n_clusters):
    # Rebuilding each training segment from its primitive misses it by exactly
    # the projection MSE plus the clustering MSE: the two errors are orthogonal.
    arm, pca, codes = arm_model
    controller = KMeansPrimitiveController(n_clusters, random_state=0).fit(codes)
    vectors = np.concatenate(pca.segment_vectors(arm))
    rebuilt = np.concatenate([_flat(n) for n in pca.inverse_transform(controller.quantize(codes))])
    total = np.mean(np.sum((vectors - rebuilt) ** 2, axis=1))
    np.testing.assert_allclose(total, pca.projection_mse_ + controller.clustering_mse_, rtol=1e-9)
    assert controller.score(codes) == pytest.approx(-controller.clustering_mse_)


def test_clustering_mse_is_sklearn_inertia_per_segment(arm_model):
    _, _, codes = arm_model
    stacked = np.concatenate(codes)
    controller = KMeansPrimitiveController(8, random_state=3).fit(codes)
    reference = KMeans(8, n_init=10, random_state=controller.kmeans_.random_state).fit(stacked)
    np.testing.assert_allclose(controller.cluster_centers_, reference.cluster_centers_)
    np.testing.assert_allclose(
        controller.clustering_mse_, reference.inertia_ / len(stacked), rtol=1e-6
    )
    assert controller.n_segments_ == len(stacked)


def test_predict_is_the_nearest_centre(arm_model):
    _, _, codes = arm_model
    controller = KMeansPrimitiveController(6, random_state=0).fit(codes)
    labels = controller.predict(codes)
    assert [len(lab) for lab in labels] == [len(c) for c in codes]
    stacked = np.concatenate(codes)
    brute = np.argmin(
        ((stacked[:, None, :] - controller.cluster_centers_[None]) ** 2).sum(-1), axis=1
    )
    np.testing.assert_array_equal(np.concatenate(labels), brute)
    quantized = np.concatenate(controller.quantize(codes))
    np.testing.assert_array_equal(quantized, controller.cluster_centers_[brute])


def test_transform_is_the_usage_histogram(arm_model):
    _, _, codes = arm_model
    with_empty = [np.empty((0, codes[0].shape[1])), *codes[:5]]
    controller = KMeansPrimitiveController(6, random_state=0).fit(codes)
    counts = (
        KMeansPrimitiveController(6, random_state=0, normalize=False)
        .fit(codes)
        .transform(with_empty)
    )
    usage = controller.transform(with_empty)
    expected = np.array([np.bincount(lab, minlength=6) for lab in controller.predict(with_empty)])
    np.testing.assert_array_equal(counts, expected)
    np.testing.assert_allclose(usage[1:], expected[1:] / expected[1:].sum(axis=1, keepdims=True))
    np.testing.assert_array_equal(usage[0], 0.0)


def test_pipeline_classifies_clips_by_primitive_usage():
    data = make_motions(n_clips_per_class=8, random_state=0)
    angles = [c[:, 6:] for c in data.clips]  # joint angles, not the root's heading and travel
    model = make_pipeline(
        EigenMovementPCA(10),
        KMeansPrimitiveController(20, n_init=3, random_state=0),
        LogisticRegression(max_iter=2000),
    )
    scores = cross_val_score(model, angles, data.target, groups=data.groups, cv=GroupKFold(4))
    # 7 classes: chance is 0.14.
    assert scores.mean() > 0.75


def test_fit_errors():
    codes, _ = _codes()
    with pytest.raises(ValueError, match="n_clusters=500 needs at least as many segments"):
        KMeansPrimitiveController(500).fit(codes)
    with pytest.raises(ValueError, match="channels"):
        KMeansPrimitiveController(3).fit(codes).predict([c[:, :2] for c in codes])
    with pytest.raises(ValueError, match="no segment codes"):
        KMeansPrimitiveController(3).fit(codes).score([np.empty((0, 4))])
