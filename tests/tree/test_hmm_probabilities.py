"""MotionTreeHMM's probabilities, decision function, novelty score and progress messages."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.special import log_softmax, softmax
from sklearn.metrics import log_loss

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeHMM
from skmotion.tree._calibration import fit_temperature, log_softmax_rows


@pytest.fixture(scope="module")
def split():
    data = make_motions(n_clips_per_class=8, random_state=0)
    X = [c[:, 6:] for c in data.clips]
    y = data.target_names[data.target]
    train, test = data.groups < 3, data.groups == 3
    pick = lambda mask: [x for x, m in zip(X, mask) if m]  # noqa: E731
    return pick(train), y[train], pick(test), y[test]


@pytest.fixture(scope="module")
def model(split):
    Xtr, ytr, _, _ = split
    return MotionTreeHMM(max_depth=6, split="median").fit(Xtr, ytr)


@pytest.mark.parametrize("transform", [lambda c: c * 1e300, lambda c: c + 1e6, lambda c: -c * 1e12])
def test_rows_sum_to_one_for_extreme_inputs(model, split, transform):
    clips = [transform(c) for c in split[2][:4]]
    proba = model.predict_proba(clips)
    assert np.isfinite(proba).all()
    np.testing.assert_allclose(proba.sum(axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(np.exp(model.predict_log_proba(clips)), proba)


@given(
    st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=6),
    st.sampled_from([0.0, 1e6, -1e20, 1e300, -1e300]),
)
def test_log_softmax_rows_keeps_the_normaliser(values, shift):
    scores = np.array([values]) + shift
    proba = np.exp(log_softmax_rows(scores))
    assert np.isfinite(proba).all()
    np.testing.assert_allclose(proba.sum(), 1.0, rtol=1e-12)
    if shift == 0.0:  # where plain arithmetic is exact, the reference softmax
        np.testing.assert_allclose(proba[0], softmax(values), rtol=1e-9, atol=1e-300)


def test_rows_without_a_finite_score_are_uniform():
    scores = np.array([[-np.inf, -np.inf, -np.inf], [np.nan, 0.0, 1.0], [np.inf, np.inf, 0.0]])
    proba = np.exp(log_softmax_rows(scores))
    np.testing.assert_allclose(proba[0], [1 / 3] * 3)
    np.testing.assert_allclose(proba[1], softmax([-np.inf, 0.0, 1.0]))
    np.testing.assert_allclose(proba[2], [0.5, 0.5, 0.0])


def test_decision_function_predict_and_log_proba_agree(model, split):
    X = split[2]
    scores = model.decision_function(X)
    np.testing.assert_array_equal(model.predict(X), model.classes_[scores.argmax(axis=1)])
    np.testing.assert_allclose(model.predict_log_proba(X), log_softmax(scores, axis=1))


def test_binary_decision_function_is_one_column(split):
    Xtr, ytr, Xte, _ = split
    keep = np.isin(ytr, ["walk", "jump"])
    model = MotionTreeHMM(max_depth=4).fit([x for x, k in zip(Xtr, keep) if k], ytr[keep])
    scores = model.decision_function(Xte)
    assert scores.shape == (len(Xte),)
    np.testing.assert_array_equal(model.predict(Xte), model.classes_[(scores > 0).astype(int)])


def test_fitted_temperature_beats_the_raw_probabilities_on_held_out_subject(split):
    """Held-out log loss with the CV-fitted temperature is below that at temperature 1."""
    Xtr, ytr, Xte, yte = split
    model = MotionTreeHMM(max_depth=6, split="median").fit(Xtr, ytr)
    raw = MotionTreeHMM(max_depth=6, split="median", calibration_cv=None).fit(Xtr, ytr)
    assert raw.temperature_ == 1.0 and model.temperature_ != 1.0
    np.testing.assert_array_equal(model.predict(Xte), raw.predict(Xte))
    calibrated = log_loss(yte, model.predict_proba(Xte), labels=model.classes_)
    uncalibrated = log_loss(yte, raw.predict_proba(Xte), labels=model.classes_)
    assert calibrated < uncalibrated


def test_temperature_recovers_a_known_one():
    # Rows drawn from softmax(z / 2): the fitted temperature for scores z is about 2.
    rng = np.random.default_rng(0)
    z = rng.normal(scale=3.0, size=(20000, 4))
    p = softmax(z / 2.0, axis=1)
    truth = (rng.random((len(z), 1)) > p.cumsum(axis=1)).sum(axis=1)
    assert fit_temperature(z, truth) == pytest.approx(2.0, rel=0.05)


@given(st.floats(8.0, 1e4))
def test_far_shifted_clips_are_more_novel_than_held_out_ones(shift):
    """novelty_score falls for clips moved away from all training frames, at every shift size."""
    model, held_out, direction = _novelty_case()
    scores = model.novelty_score(held_out)
    moved = model.novelty_score([c + shift * direction for c in held_out])
    assert moved.max() < scores.min()


def test_novelty_falls_with_the_distance(split):
    model, held_out, direction = _novelty_case()
    shifts = [0.0, 2.0, 8.0, 32.0, 128.0]
    scores = [model.novelty_score([c + s * direction for c in held_out]).mean() for s in shifts]
    assert np.all(np.diff(scores) < 0)
    # while the generation scores of the shifted clips do not warn: their probabilities stay sure
    assert np.isfinite(model.predict_proba([held_out[0] + 128.0 * direction])).all()


_CASE = {}


def _novelty_case():
    if not _CASE:
        data = make_motions(n_clips_per_class=8, random_state=0)
        X = [c[:, 6:] for c in data.clips]
        y = data.target_names[data.target]
        train = data.groups < 3
        model = MotionTreeHMM(max_depth=6, split="median", calibration_cv=None)
        model.fit([x for x, t in zip(X, train) if t], y[train])
        held_out = [x for x, t in zip(X, train) if not t]
        direction = model.scale_  # one standard deviation of every channel
        _CASE.update(model=model, held_out=held_out, direction=direction)
    return _CASE["model"], _CASE["held_out"], _CASE["direction"]


def test_verbose_reports_the_stages_and_default_is_silent(split, capsys):
    Xtr, ytr, _, _ = split
    MotionTreeHMM(max_depth=3).fit(Xtr[:20], ytr[:20])
    assert capsys.readouterr().err == ""
    MotionTreeHMM(max_depth=3, verbose=1).fit(Xtr, ytr)
    err = capsys.readouterr().err
    assert "building the tree" in err and "transition graphs" in err and "calibration" in err


def test_the_papers_recipe_builds_the_papers_model(split):
    """MotionTreeHMM(**PAPER_SETTINGS): minimum-error splits without depth limit, clip graphs."""
    from skmotion.tree import PAPER_SETTINGS

    Xtr, ytr, Xte, yte = split
    paper = MotionTreeHMM(**PAPER_SETTINGS)
    assert {k: paper.get_params()[k] for k in PAPER_SETTINGS} == PAPER_SETTINGS
    assert MotionTreeHMM().split != paper.split  # the defaults are the measured ones
    paper.fit(Xtr[::2], ytr[::2])
    tree = paper.tree_
    # every split node kept at least 16 frames on each side; one graph per training clip
    split_nodes = tree.left >= 0
    assert (tree.count[tree.left[split_nodes]] >= 16).all()
    assert (tree.count[tree.right[split_nodes]] >= 16).all()
    assert len(paper.graph_classes_) == len(Xtr[::2])
    assert paper.tree_.covariance_type == "full" and (paper.scale_ == 1).all()
    # no depth limit: the tree stops only where a node cannot be cut into two leaves of 16
    leaves = np.flatnonzero(~split_nodes)
    assert paper.n_layers_ - 1 == tree.depth[leaves].max() and paper.n_layers_ > 9
    assert set(paper.predict(Xte)) <= set(paper.classes_)


def test_novelty_of_extreme_clips_is_the_lowest_score_without_warnings(split):
    model, held_out, _ = _novelty_case()
    scores = model.novelty_score(
        [c * 1e300 for c in held_out[:2]] + [c + 1e6 for c in held_out[:2]]
    )
    assert np.isneginf(scores[:2]).all()  # the density underflows: as novel as it gets
    assert np.isfinite(scores[2:]).all() and scores[2:].max() < model.novelty_score(held_out).min()
