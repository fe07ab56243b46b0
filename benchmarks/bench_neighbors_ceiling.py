"""How much any search that keeps a query's nearest clips could prune (the ceiling).

``python benchmarks/bench_neighbors_ceiling.py``: on every development set of
``bench_neighbors_pruning.py`` (same held-out queries, similar = same label),
the index's own pruning and recall with ``target_recall=0.99``, beside the
ceiling of :func:`skmotion.metrics.pruning_ceiling` for four distances:

- ``psi``: ``1 - psi`` (k = 6), the ranking the index's candidates go to;
- ``svd``: Euclidean on every component of the index's SVD feature vectors;
- ``box``: the index's own shape, ``max_i |x_i - q_i| / radius_i`` over its
  levels (the learned radii, any scale per query);
- ``encoder``: Euclidean on ``MotionTreeEncoder()`` features, a representation
  learned for recognition (a check that the ceiling is not psi's alone).

The ceiling lets each query choose its radius knowing the answer, so it is
above what any fixed widths reach with that distance. ``one_miss`` is the
smallest recall one lost similar clip costs: where it is above 0.01, a
recall of 0.99 means keeping every similar clip, and the ceiling at 0.99 is
the exact one at recall 1.

``--segmentations N``: psi's ceiling on the CMU joint angles for N random
cuts of the trials into segments (``cut_repeats(random_state=0 .. N-1)``;
the development set is cut 0), to show it is not one cut's accident.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, write_results  # noqa: E402
from _motion_data import _ROOT_CHANNELS, cut_repeats  # noqa: E402
from bench_neighbors_pruning import held_out_sets, hold_out_last  # noqa: E402

from skmotion.datasets import load_cmu_asfamc  # noqa: E402
from skmotion.decomposition import SVDFeatureExtractor  # noqa: E402
from skmotion.decomposition._svd_projection import max_svd_components  # noqa: E402
from skmotion.metrics import pruning_ceiling, pruning_efficiency, recall  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors, pairwise_psi  # noqa: E402
from skmotion.tree import MotionTreeEncoder  # noqa: E402

RECALLS = (1.0, 0.99, 0.95)


def euclidean(queries, stored):
    return np.linalg.norm(queries[:, None, :] - stored[None, :, :], axis=2)


def shared_distances(train, query):
    """name -> distances that do not depend on the index's features (psi, the encoder)."""
    encoder = MotionTreeEncoder().fit(train)
    return {
        "psi": 1.0 - pairwise_psi(query, train),
        "encoder": euclidean(encoder.transform(query), encoder.transform(train)),
    }


def feature_distances(train, query, weighting, index):
    """name -> distances on the index's SVD features: all components, and its own box."""
    n = max_svd_components(len(train), train[0].shape[1], weighting)
    svd = SVDFeatureExtractor(n_components=n, weighting=weighting).fit(train)
    levels = index.feature_extractor_
    box = np.abs(levels.transform(query)[:, None, :] - levels.transform(train)[None, :, :])
    return {
        "svd": euclidean(svd.transform(query), svd.transform(train)),
        "box": (box / index.radius_).max(axis=2),
    }


def one_miss(y_query, y_train):
    """The smallest drop in mean recall that losing one similar clip causes."""
    similar = np.array([np.count_nonzero(y_train == y) for y in y_query])
    return 1.0 / (similar.max() * np.count_nonzero(similar))


def main():
    rows = []
    for name, (train, y_train, query, y_query) in held_out_sets().items():
        y_train, y_query = np.asarray(y_train), np.asarray(y_query)
        shared = shared_distances(train, query)  # shown on the first row of the set
        for weighting in ("first", "first_two"):
            index = IntervalIndexNeighbors(
                target_recall=0.99,
                features=SVDFeatureExtractor(weighting=weighting),
                random_state=0,
            ).fit(train, y_train)
            found = index.candidates(query)
            row = {
                "dataset": name,
                "stored": len(train),
                "queries": len(query),
                "one_miss": one_miss(y_query, y_train),
                "features": weighting,
                "index_pruning": pruning_efficiency(found, y_query, y_train),
                "index_recall": recall(found, y_query, y_train),
            }
            own = feature_distances(train, query, weighting, index)
            kinds = {**shared, **own} if weighting == "first" else own
            for kind, dist in kinds.items():
                for r in RECALLS:
                    row[f"{kind}@{r}"] = pruning_ceiling(dist, y_query, y_train, min_recall=r)
            rows.append(row)
            print(row, flush=True)
    columns = sorted({c for row in rows for c in row}, key=lambda c: list(rows[0]).index(c))
    rows = [{c: row.get(c, float("nan")) for c in columns} for row in rows]
    write_results(
        "neighbors_ceiling",
        rows,
        notes="Held-out queries as in neighbors_pruning (similar = same label). index_*: "
        "IntervalIndexNeighbors(target_recall=0.99) with these features. kind@r: the most "
        "pruning any per-query ball of that distance reaches at mean recall r "
        "(skmotion.metrics.pruning_ceiling; exact at r = 1, an upper bound below). psi and "
        "encoder do not depend on the features column (NaN on the second row).",
    )
    return rows


def segmentations(n):
    """psi's ceiling on the CMU repetitions (joint angles) for ``n`` random cuts."""
    data = load_cmu_asfamc(SHARED_DATA / "cmu-asfamc", index=SHARED_DATA / "cmu-index.csv")
    angles = [clip[:, _ROOT_CHANNELS:] for clip in data.clips]
    rows = []
    for seed in range(n):
        segments, trial = cut_repeats(angles, data.frame_rate, random_state=seed)
        train, y_train, query, y_query = hold_out_last(segments, np.asarray(data.trials)[trial])
        dist = 1.0 - pairwise_psi(query, train)
        row = {"cut": seed, "stored": len(train), "queries": len(query)}
        for r in RECALLS:
            row[f"psi@{r}"] = pruning_ceiling(dist, y_query, y_train, min_recall=r)
        rows.append(row)
    write_results(
        "neighbors_ceiling_cuts",
        rows,
        notes="CMU 01-03 trials (joint angles without the root) cut into 5 consecutive "
        "segments of 1-2 s by cut_repeats(random_state=cut); the last segment of each trial "
        "queries the rest. psi@r: pruning_ceiling of 1 - psi at mean recall r.",
    )
    return rows


if __name__ == "__main__":
    if "--segmentations" in sys.argv:
        segmentations(int(sys.argv[sys.argv.index("--segmentations") + 1]))
    else:
        main()
