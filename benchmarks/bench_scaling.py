"""Scale-out: the wall time of a grid search, serial, on 2 local (loky) workers and on a Dask
LocalCluster.

Two searches, each on its own data, each run in every configuration in one run:

- ``IntervalIndexNeighbors`` over ``epsilon`` x ``n_levels`` (3 x 3), and
- ``MotionTreeHMM`` over ``max_depth`` (3 values),

with subject-wise ``GroupKFold(4)`` on the synthetic motions (7 classes x 4
subjects; joint angles without the root) and, when ``../shared/data`` is present,
the index search on the CMU repeated segments too (grouped by CMU subject).

Configurations (the estimator's own ``n_jobs`` in brackets):

- ``serial``: ``GridSearchCV(n_jobs=1)`` [n_jobs=1];
- ``loky x2``: ``GridSearchCV(n_jobs=2)`` [n_jobs=1];
- ``dask x2``: ``joblib.parallel_backend("dask", scatter=[X, y])`` on a
  ``LocalCluster`` of 2 worker processes [n_jobs=1];
- ``dask x2, nested``: the same with the estimator's ``n_jobs=None``, which under
  the Dask backend means "the cluster" for the estimator's own loops too.

Every configuration must give the same ``cv_results_`` scores as the serial one
(checked). The cluster's start-up time is reported apart. Run:
``python benchmarks/bench_scaling.py`` (``--quick`` for a smoke run). Needs the
``distributed`` extra for the Dask rows.
"""

import argparse
import importlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import joblib  # noqa: E402
from _common import SHARED_DATA, write_results  # noqa: E402
from sklearn.base import clone  # noqa: E402
from sklearn.model_selection import GridSearchCV, GroupKFold  # noqa: E402

from skmotion.datasets import make_motions  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402
from skmotion.tree import MotionTreeHMM  # noqa: E402


def datasets(quick):
    data = make_motions(n_clips_per_class=4 if quick else 12, random_state=0)
    sets = {"synthetic": ([c[:, 6:] for c in data.clips], data.target, data.groups)}
    if not quick and (SHARED_DATA / "cmu-asfamc").is_dir():
        from _motion_data import cmu_repeats

        segments, trials = cmu_repeats()["CMU repeats, joint angles"]
        sets["CMU repeats"] = (segments, trials, np.array([t.split("_")[0] for t in trials]))
    return sets


def searches(quick):
    index_grid = {"epsilon": [0.5, 1.0, 1.5], "n_levels": [3, 5, 7]}
    tree_grid = {"max_depth": [4, 6, 8]}
    if quick:
        index_grid, tree_grid = {"epsilon": [0.5, 1.0], "n_levels": [3]}, {"max_depth": [3]}
    return {
        "IntervalIndexNeighbors": (IntervalIndexNeighbors(), index_grid),
        "MotionTreeHMM": (MotionTreeHMM(min_samples_leaf=16), tree_grid),
    }


def timed_search(estimator, grid, X, y, groups, *, n_jobs=1, backend=None):
    search = GridSearchCV(
        estimator, grid, cv=GroupKFold(min(4, len(np.unique(groups)))), n_jobs=n_jobs
    )
    start = time.perf_counter()
    if backend is None:
        search.fit(X, y, groups=groups)
    else:
        with joblib.parallel_backend(backend, scatter=[X, y]):
            search.fit(X, y, groups=groups)
    return time.perf_counter() - start, search.cv_results_


def start_cluster():
    try:
        import distributed
    except ImportError:
        print('Dask rows left out: pip install "skmotion[distributed]"')
        return None, None, None
    start = time.perf_counter()
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    )
    client = distributed.Client(cluster)
    client.wait_for_workers(2, timeout=120)
    return cluster, client, time.perf_counter() - start


def warm_loky():
    """Start the 2 loky workers and import skmotion in them, outside the timings."""
    modules = ["skmotion.neighbors", "skmotion.tree"] * 2
    joblib.Parallel(n_jobs=2)(joblib.delayed(importlib.import_module)(m) for m in modules)


def main(quick=False):
    warm_loky()
    cluster, client, startup = start_cluster()
    rows = []
    try:
        for data_name, (X, y, groups) in datasets(quick).items():
            for name, (estimator, grid) in searches(quick).items():
                if data_name != "synthetic" and name != "IntervalIndexNeighbors":
                    continue
                configs = {
                    "serial": dict(params={"n_jobs": 1}, n_jobs=1),
                    "loky x2": dict(params={"n_jobs": 1}, n_jobs=2),
                }
                if client is not None:
                    configs["dask x2"] = dict(params={"n_jobs": 1}, n_jobs=None, backend="dask")
                    configs["dask x2, nested"] = dict(
                        params={"n_jobs": None}, n_jobs=None, backend="dask"
                    )
                serial_time, reference = None, None
                for config, spec in configs.items():
                    est = clone(estimator).set_params(**spec["params"])
                    seconds, results = timed_search(
                        est, grid, X, y, groups, n_jobs=spec["n_jobs"], backend=spec.get("backend")
                    )
                    if reference is None:
                        serial_time, reference = seconds, results
                    same = np.array_equal(results["mean_test_score"], reference["mean_test_score"])
                    if not same:
                        raise AssertionError(
                            f"{name} on {data_name}: {config} differs from the serial search"
                        )
                    n_fits = len(results["params"]) * min(4, len(np.unique(groups)))
                    rows.append(
                        {
                            "data": data_name,
                            "search": name,
                            "clips": len(X),
                            "fits": n_fits,
                            "config": config,
                            "seconds": seconds,
                            "speed-up vs serial": serial_time / seconds,
                            "scores equal": same,
                        }
                    )
    finally:
        if client is not None:
            client.close()
            cluster.close()
    notes = (
        "GroupKFold grid searches (4 folds; 3 on CMU's 3 subjects); one run per configuration, "
        "timed in the same process. The machine has 2 cores shared with other work, so 2 "
        "workers can at best halve the time."
    )
    if startup is not None:
        notes += (
            " Dask LocalCluster (2 worker processes) start-up, not included above: "
            f"{startup:.1f} s."
        )
    write_results("scaling_search", rows, notes=notes)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="tiny data and grids (a smoke run)")
    main(parser.parse_args().quick)
