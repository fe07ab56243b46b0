"""Grid searches on a real Dask cluster (two worker processes on loopback) equal the serial ones.

The cluster starts once for the module and is always closed. The workers run the
same skmotion, imported from the same path, as a multi-machine cluster would need.
"""

import joblib
import numpy as np
import pytest
from sklearn.model_selection import GridSearchCV, GroupKFold

from skmotion.datasets import make_motions
from skmotion.neighbors import IntervalIndexNeighbors
from skmotion.tree import MotionTreeHMM

distributed = pytest.importorskip("distributed")
dask = pytest.importorskip("dask")


@pytest.fixture(scope="module")
def client():
    # Generous timeouts: the CI box has two cores shared by everything else.
    with dask.config.set(
        {"distributed.comm.timeouts.connect": "60s", "distributed.comm.timeouts.tcp": "120s"}
    ):
        cluster = distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        )
        try:
            # Connect by address, as to a remote scheduler ("tcp://scheduler:8786").
            with distributed.Client(cluster.scheduler_address, timeout="60s") as client:
                client.wait_for_workers(2, timeout=120)
                yield client
        finally:
            cluster.close(timeout=60)


class CountingClips(list):
    """A list of clips that counts how often it is pickled (in this, the client, process).

    ``__slots__ = ()`` keeps it non-weakrefable like a plain list, which joblib's
    Dask backend cannot scatter on its own.
    """

    __slots__ = ()
    pickles = 0

    def __reduce__(self):
        CountingClips.pickles += 1
        return (list, (list(self),))


@pytest.fixture(scope="module")
def motions():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "jump", "wave"], duration=(1.0, 1.5), random_state=1
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target], data.groups


def assert_searches_equal(serial, other, X):
    results, expected = other.cv_results_, serial.cv_results_
    assert results.keys() == expected.keys()
    for key, value in expected.items():
        if "time" in key:
            continue
        if key == "params":
            assert results[key] == value
        else:
            np.testing.assert_array_equal(np.asarray(results[key]), np.asarray(value), err_msg=key)
    assert other.best_params_ == serial.best_params_
    np.testing.assert_array_equal(other.predict(X), serial.predict(X))


@pytest.mark.parametrize(
    "estimator, grid",
    [
        (IntervalIndexNeighbors(n_levels=3), {"epsilon": [0.5, 1.0], "n_levels": [2, 3]}),
        (MotionTreeHMM(min_samples_leaf=4), {"max_depth": [2, 3]}),
    ],
    ids=["IntervalIndexNeighbors", "MotionTreeHMM"],
)
def test_grid_search_on_dask_equals_serial(client, motions, estimator, grid):
    X, y, groups = motions
    serial = GridSearchCV(estimator, grid, cv=GroupKFold(3)).fit(X, y, groups=groups)
    on_dask = GridSearchCV(estimator, grid, cv=GroupKFold(3))
    with (
        distributed.get_task_stream(client) as stream,
        joblib.parallel_backend("dask", scatter=[X, y]),
    ):
        on_dask.fit(X, y, groups=groups)
    workers = {task["worker"] for task in stream.data}
    assert workers and workers <= set(client.scheduler_info(n_workers=-1)["workers"]), (
        "the fits ran on the cluster"
    )
    assert_searches_equal(serial, on_dask, X)


def test_scattered_clips_are_sent_once(client, motions):
    X, y, groups = motions
    search = GridSearchCV(
        IntervalIndexNeighbors(n_levels=3), {"epsilon": [0.5, 1.0, 1.5]}, cv=GroupKFold(3)
    )
    clips = CountingClips(X)
    CountingClips.pickles = 0
    with joblib.parallel_backend("dask", scatter=[clips, y]):
        search.fit(clips, y, groups=groups)
    assert CountingClips.pickles == 1, (
        "scattered clips are pickled once, whatever the number of tasks"
    )
    scattered = search.cv_results_

    CountingClips.pickles = 0
    with joblib.parallel_backend("dask"):
        search.fit(clips, y, groups=groups)
    assert CountingClips.pickles > 1, (
        "without scatter a list of clips is sent again with every batch of tasks"
    )
    np.testing.assert_array_equal(
        search.cv_results_["mean_test_score"], scattered["mean_test_score"]
    )
