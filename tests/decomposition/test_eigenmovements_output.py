"""EigenMovementPCA in pipelines: pandas output, feature names, the error before a table
estimator, scale invariance and progress."""

import numpy as np
import pandas as pd
import pytest
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline

from skmotion.control import KMeansPrimitiveController
from skmotion.datasets import make_motions
from skmotion.decomposition import EigenMovementPCA


@pytest.fixture(scope="module")
def arm():
    data = make_motions(n_clips_per_class=3, classes=["wave", "punch", "walk"], random_state=0)
    return [np.rad2deg(c[:, [33, 34, 35, 37]]) for c in data.clips], data.target


def test_pandas_output_holds_the_same_codes_by_clip_and_segment(arm):
    clips, _ = arm
    pca = EigenMovementPCA(4).fit(clips)
    codes = pca.transform(clips)
    frame = EigenMovementPCA(4).set_output(transform="pandas").fit(clips).transform(clips)
    assert list(frame.columns) == list(pca.get_feature_names_out())
    assert list(pca.get_feature_names_out()) == [f"eigenmovementpca{i}" for i in range(4)]
    assert frame.index.names == ["clip", "segment"]
    np.testing.assert_allclose(frame.to_numpy(), np.concatenate(codes))
    counts = frame.groupby(level="clip").size().to_numpy()
    assert counts.tolist() == [len(c) for c in codes]
    # a DataFrame input keeps its clip labels
    named = pd.concat({f"take{k}": pd.DataFrame(c) for k, c in enumerate(clips)})
    named.index.names = ["take", "frame"]
    out = EigenMovementPCA(4).set_output(transform="pandas").fit_transform(named)
    assert out.index.names == ["take", "segment"]
    assert out.index.get_level_values(0)[0] == "take0"


def test_pandas_output_refuses_a_clip_without_segments(arm):
    clips, _ = arm
    still = np.zeros((60, 4))  # no movement: no segment
    pca = EigenMovementPCA(4).set_output(transform="pandas").fit(clips)
    assert len(EigenMovementPCA(4).fit(clips).transform([still])[0]) == 0
    with pytest.raises(ValueError, match="clip 1 has no segments"):
        pca.transform([clips[0], still])


def test_table_estimator_right_after_says_what_to_put_between(arm):
    clips, y = arm
    with pytest.raises(TypeError, match="KMeansPrimitiveController"):
        make_pipeline(EigenMovementPCA(5), LogisticRegression()).fit(clips, y)
    model = make_pipeline(
        EigenMovementPCA(5),
        KMeansPrimitiveController(6, n_init=2, random_state=0),
        LogisticRegression(max_iter=2000),
    ).fit(clips, y)
    # the same as composing the steps by hand
    pca = EigenMovementPCA(5).fit(clips)
    kmeans = KMeansPrimitiveController(6, n_init=2, random_state=0).fit(pca.transform(clips))
    logistic = LogisticRegression(max_iter=2000).fit(kmeans.transform(pca.transform(clips)), y)
    expected = logistic.predict(kmeans.transform(pca.transform(clips)))
    np.testing.assert_array_equal(model.predict(clips), expected)


@pytest.mark.parametrize("factor", [1e100, 1e-100, 3.7e140])
def test_scaled_clips_give_scaled_results(arm, factor):
    clips, _ = arm
    reference = EigenMovementPCA(6).fit(clips)
    scaled = [c * factor for c in clips]
    pca = EigenMovementPCA(6).fit(scaled)
    np.testing.assert_allclose(pca.components_, reference.components_, atol=1e-9)
    np.testing.assert_allclose(pca.explained_variance_ratio_, reference.explained_variance_ratio_)
    np.testing.assert_allclose(pca.explained_variance_ / factor**2, reference.explained_variance_)
    np.testing.assert_allclose(pca.mean_ / factor, reference.mean_)
    for a, b in zip(pca.transform(scaled), reference.transform(clips)):
        np.testing.assert_allclose(a / factor, b, atol=1e-9 * np.abs(b).max())
    assert pca.score(scaled) / factor == pytest.approx(reference.score(clips))
    assert [s.tolist() for s in pca.segment(scaled)] == [
        s.tolist() for s in reference.segment(clips)
    ]


def test_clips_beyond_float_range_are_refused_by_clip(arm):
    clips, _ = arm
    huge = [c.copy() for c in clips]
    huge[2] = huge[2] * 1e300
    with pytest.raises(ValueError, match=r"clip 2 reaches .* Rescale"):
        EigenMovementPCA(4).fit(huge)
    fitted = EigenMovementPCA(4).fit(clips)
    with pytest.raises(ValueError, match="clip 2 reaches"):
        fitted.transform(huge)


def test_verbose_reports_the_steps(arm, capsys):
    clips, _ = arm
    EigenMovementPCA(4).fit(clips)
    assert capsys.readouterr().err == ""
    EigenMovementPCA(4, verbose=1).fit(clips)
    err = capsys.readouterr().err
    assert f"segmenting {len(clips)} clips" in err and "PCA of" in err and "fitted in" in err
