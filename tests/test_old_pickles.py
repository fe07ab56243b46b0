"""Pickles written before the tree's sub-packages (issue 25) load and answer as they did.

``data/pickles_before_issue25.pkl`` (48 KB) was written by skmotion 0.1.0 before
``tree/_online``, ``tree/_growth`` and ``tree/_decoder`` existed: it names
``skmotion.tree._online_stream``, ``skmotion.tree._stream``,
``skmotion.tree._incremental``, ``skmotion.tree._moments``,
``skmotion.tree._online._from_values`` and ``skmotion.neighbors._store``. It holds a
small ``MotionTreeHMM`` grown by ``partial_fit`` (its ``LiveDatabase``), an online
and an exact stream after four frames, the last ``OnlineState``, an
``IntervalIndexNeighbors`` grown by ``partial_fit``, and the answers that code gave
next: the streams' updates on the fifth frame, ``predict`` and ``kneighbors``.
The script that wrote it::

    data = make_motions(n_clips_per_class=2, classes=["walk", "jump"],
                        duration=(1.0, 1.0), random_state=0)
    X = [c[::2, 6:20] for c in data.clips]
    model = MotionTreeHMM(max_depth=2, calibration_cv=None).partial_fit(X, data.target)
    online = model.stream(lag=1, n_best=1)
    exact = model.stream(mode="exact", window=6, n_best=1)
    for frame in X[0][:4]:
        state = online.update(frame)
        exact.update(frame)
    index = IntervalIndexNeighbors(n_levels=2).partial_fit(X, data.target)
    (pickled here), then the answers: online.update(X[0][4]), exact.update(X[0][4]),
    model.predict(X), index.kneighbors(X, n_neighbors=1)[1]
"""

import pickle
from pathlib import Path

import numpy as np
import pytest

import skmotion
from skmotion.base import IncompatibleVersionError, compatible_versions

FIXTURE = Path(__file__).parent / "data" / "pickles_before_issue25.pkl"
SAVED_BY = "0.1.0"


def _load():
    data = FIXTURE.read_bytes()
    if not compatible_versions(SAVED_BY, skmotion.__version__):
        # a later minor version refuses these pickles, as designed (and says why)
        with pytest.raises(IncompatibleVersionError, match=f"saved by skmotion {SAVED_BY}"):
            pickle.loads(data)
        pytest.skip(f"skmotion {skmotion.__version__} refuses pickles of {SAVED_BY}, as designed")
    saved = pickle.loads(data)
    return saved["objects"], saved["answers"], saved["X"]


def test_an_incompatible_version_refuses_the_old_pickles(monkeypatch):
    monkeypatch.setattr(skmotion, "__version__", "0.2.0")
    with pytest.raises(IncompatibleVersionError, match=f"saved by skmotion {SAVED_BY}"):
        pickle.loads(FIXTURE.read_bytes())


def _assert_same_answers(got, expected):
    assert set(got) == set(expected)
    for key, value in expected.items():
        np.testing.assert_array_equal(np.asarray(got[key]), np.asarray(value), err_msg=key)


def test_old_streams_go_on_as_before():
    objects, answers, X = _load()
    _assert_same_answers(dict(objects["online"].update(X[0][4])), answers["online_next"])
    _assert_same_answers(dict(objects["exact"].update(X[0][4])), answers["exact_next"])


def test_old_model_and_index_answer_as_before():
    objects, answers, X = _load()
    np.testing.assert_array_equal(objects["model"].predict(X), answers["predict"])
    np.testing.assert_array_equal(
        objects["index"].kneighbors(X, n_neighbors=1)[1], answers["kneighbors"]
    )
    # the old LiveDatabase goes on growing: one more clip joins the database
    model = objects["model"].partial_fit(X[:1], [objects["model"].classes_[0]])
    assert int(model.tree_.count[0]) == sum(len(c) for c in X) + len(X[0])


def test_old_online_state_loads_from_its_old_path():
    objects, _, _ = _load()
    state = objects["state"]
    assert type(state).__name__ == "OnlineState"
    assert state.frame == 3 and len(state.nodes) == 3
    again = pickle.loads(pickle.dumps(state))  # and pickles again under its new path
    _assert_same_answers(dict(again), dict(state))


ENCODER_FIXTURE = Path(__file__).parent / "data" / "encoder_before_encoding.pkl"


def test_old_encoder_loads_from_its_old_routing_module():
    """``data/encoder_before_encoding.pkl`` (23 KB) was written by skmotion 0.1.0 before
    ``tree/_encoding`` existed: its ``TreeRouter`` names ``skmotion.tree._routing``.
    It holds a fitted ``MotionTreeEncoder`` and its transform, written by::

        data = make_motions(n_clips_per_class=2, classes=["walk", "jump"],
                            duration=(1.0, 1.0), random_state=0)
        X = [c[::2, 6:20] for c in data.clips]
        encoder = MotionTreeEncoder(max_depth=3).fit(X)
        (pickled with X), then the answer: encoder.transform(X) (dense)
    """
    if not compatible_versions(SAVED_BY, skmotion.__version__):
        pytest.skip(f"skmotion {skmotion.__version__} refuses pickles of {SAVED_BY}, as designed")
    saved = pickle.loads(ENCODER_FIXTURE.read_bytes())
    encoder, X = saved["objects"]["encoder"], saved["X"]
    assert type(encoder._router).__module__ == "skmotion.tree._encoding._routing"
    got = encoder.transform(X)
    got = got.toarray() if hasattr(got, "toarray") else got
    np.testing.assert_array_equal(got, saved["answers"]["transform"])
