"""n_jobs: every estimator's parallel path really runs, and gives bit-identical results to the
serial one.

Work is split into tasks of a fixed size (clips per chunk, leaves per task, frames
per decoding group) that depend on the data only. The sizes are made small here so
that a small collection is split into many tasks and the parallel path runs; a
recording ``Parallel`` proves that it did.
"""

import inspect

import numpy as np
import pytest
from sklearn.base import clone

from skmotion.datasets import humanoid_skeleton, make_motions, make_position_motions
from skmotion.decomposition import EigenMovementPCA, SVDFeatureExtractor, _clip_svd
from skmotion.neighbors import IntervalIndexNeighbors, _interval_neighbors, _psi, pairwise_psi
from skmotion.preprocessing import FillGaps, LowPassFilter, VirtualMarkerTransform
from skmotion.recognition import MotionClassifier
from skmotion.tree import MotionTreeHMM
from skmotion.tree._decoder import _batch
from skmotion.utils import _parallel
from tests.clip_conformance import _as_list, assert_outputs_equal, outputs
from tests.decomposition.test_eigenmovements import stroke_clips
from tests.preprocessing.test_fill_gaps import _holed_case as _holed_positions
from tests.test_persistence import _motions, skmotion_estimators


class RecordingParallel(_parallel.Parallel):
    """sklearn's Parallel, noting how many tasks each call ran."""

    calls = []

    def __call__(self, iterable):
        tasks = list(iterable)
        type(self).calls.append((self.n_jobs, len(tasks)))
        return super().__call__(tasks)


@pytest.fixture
def small_tasks(monkeypatch):
    """Tiny task sizes, and a record of the parallel calls."""
    monkeypatch.setattr(_clip_svd, "_CHUNK", 3)
    monkeypatch.setattr(_interval_neighbors, "_LEAVES_PER_TASK", 1)
    monkeypatch.setattr(_psi, "_ROWS", 2)
    original = _batch.length_groups
    monkeypatch.setattr(
        _batch, "length_groups", lambda lengths, n_graphs: original(lengths, n_graphs, budget=400)
    )
    monkeypatch.setattr(RecordingParallel, "calls", [])
    monkeypatch.setattr(_parallel, "Parallel", RecordingParallel)
    return RecordingParallel.calls


def _joint_angles():
    data = make_motions(
        n_clips_per_class=2, classes=["walk", "squat", "wave"], duration=(0.6, 1.0), random_state=0
    )
    return data.clips, data.target


def _positions():
    data = make_position_motions("kinect_v2", n_clips_per_class=2, random_state=0)
    return data.clips, data.target


def _logprob_and_paths(logprob, paths):
    return [logprob, *paths]


CASES = {
    "MotionTreeHMM": (
        MotionTreeHMM(max_depth=3, min_samples_leaf=4),
        _motions,
        lambda est, X: {
            "decode": _logprob_and_paths(*est.decode(X)),
            "windows": _as_list(est.predict_proba_windows(X, 20, 7)),
        },
    ),
    "MotionTreeHMM-clip-graphs": (
        MotionTreeHMM(max_depth=3, min_samples_leaf=4, graph="clip", node_prior="graph"),
        _motions,
        None,
    ),
    "IntervalIndexNeighbors": (
        IntervalIndexNeighbors(n_levels=3, n_neighbors=2, epsilon=0.5),
        _motions,
        lambda est, X: {"kneighbors": list(est.kneighbors(X)), "self": list(est.kneighbors())},
    ),
    "SVDFeatureExtractor": (
        SVDFeatureExtractor(n_components=3, weighting="first_two"),
        _motions,
        None,
    ),
    "EigenMovementPCA": (
        EigenMovementPCA(n_components=3, n_samples=20),
        lambda: (stroke_clips(9), None),
        lambda est, X: {
            "reconstruct": _as_list(est.reconstruct(X)),
            "segment": _as_list(est.segment(X)),
        },
    ),
    "VirtualMarkerTransform": (
        VirtualMarkerTransform(humanoid_skeleton(), frame_rate=30.0),
        _joint_angles,
        None,
    ),
    "LowPassFilter": (LowPassFilter(order=4), _motions, None),
    "MotionClassifier": (
        MotionClassifier(layout="kinect_v2", frame_rate=30.0, max_depth=3),
        _positions,
        lambda est, X: {"novelty": [est.novelty_score(X)]},
    ),
    "FillGaps": (FillGaps(layout="kinect_v1"), _holed_positions, None),
}


def _run(estimator, X, y, extra):
    fitted = estimator.fit(X, y) if y is not None else estimator.fit(X)
    results = outputs(fitted, X, y)
    if extra is not None:
        results.update({k: [np.asarray(v) for v in vs] for k, vs in extra(fitted, X).items()})
    return results


@pytest.mark.parametrize("name", sorted(CASES))
def test_n_jobs_results_are_bit_identical(name, small_tasks):
    estimator, data, extra = CASES[name]
    X, y = data()
    serial = _run(clone(estimator).set_params(n_jobs=1), X, y, extra)
    assert not any(n_jobs == 2 for n_jobs, _ in small_tasks), "n_jobs=1 must not start workers"
    parallel = _run(clone(estimator).set_params(n_jobs=2), X, y, extra)
    ran = [tasks for n_jobs, tasks in small_tasks if n_jobs == 2]
    assert ran and max(ran) > 1, f"{name}: n_jobs=2 never split the work into several tasks"
    # assert_outputs_equal(exact=True) compares floats with assert_array_equal: bit for bit.
    assert_outputs_equal(serial, parallel, exact=True, context=f"{name}: n_jobs=1 vs 2")


def test_pairwise_psi_n_jobs_bit_identical(small_tasks):
    X, _ = _motions()
    serial = pairwise_psi(X[:7], X, n_jobs=1)
    parallel = pairwise_psi(X[:7], X, n_jobs=2)
    assert max(tasks for n_jobs, tasks in small_tasks if n_jobs == 2) > 1
    assert np.array_equal(serial, parallel)


def test_every_estimator_with_n_jobs_has_a_case():
    with_jobs = {
        n
        for n, cls in skmotion_estimators().items()
        if "n_jobs" in inspect.signature(cls).parameters
    }
    missing = with_jobs - {name.split("-")[0] for name in CASES}
    assert not missing, f"add an n_jobs case to tests/test_n_jobs.py for {sorted(missing)}"
