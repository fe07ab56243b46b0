"""Pruning efficiency and recall of the interval index (Li & Prabhakaran, Figures 7-14).

Default run (``python benchmarks/bench_neighbors_pruning.py``: the default
levels, 7 capped by the data; ``--levels 5,7,9`` for others): on every
development set, held-out queries against an index fitted on the rest, for the
learned widths (``target_recall`` 0.99 and 0.95) and the paper's rule (epsilon
1.0 and 0.8). ``--grid``: the leave-one-out sweep below.

Grid (``--grid``): every clip of a collection queries the index built on the
collection and is left
out of its own counts (the paper's protocol). Similar = same label. Swept:
``epsilon`` 0.5-1.2 and ``n_levels`` 5-12, for the first and the weighted first
two singular vectors.

The tree for ``n_levels`` uses the first ``n_levels`` SVD feature components,
which do not depend on how many are kept, so the features are computed once per
collection and the trees are built on them (feature-vector input); the
candidate sets are what the clip estimator would return.

``--discriminant``: the tree's levels on discriminant axes of the SVD features
(learned on the training labels) instead of their leading components, held out.
"""

import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, SHARED_DATA, write_results  # noqa: E402
from _motion_data import search_datasets  # noqa: E402

from skmotion.datasets import load_uea  # noqa: E402
from skmotion.decomposition import SVDFeatureExtractor  # noqa: E402
from skmotion.metrics import pruning_efficiency, recall  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402
from skmotion.neighbors._interval_index import IntervalIndex, entry_edges  # noqa: E402
from skmotion.neighbors._interval_neighbors import learn_delta  # noqa: E402

EPSILONS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2)
LEVELS = (5, 6, 7, 8, 10, 12)
MAX_PAIRS = 10_000_000  # leaf entries; a larger tree is skipped (memory)


def leaf_entries(features, labels, n_levels, epsilon, max_entries=64):
    """How many (leaf, clip) pairs the tree would hold, without building it."""
    tree = features[:, :n_levels]
    radius = epsilon * learn_delta(tree, np.unique(labels, return_inverse=True)[1], 1.0)
    edges = [
        entry_edges(tree[:, i].min(), tree[:, i].max(), radius[i], max_entries)
        for i in range(n_levels)
    ]
    first, last = IntervalIndex(edges, radius).covering_entries(tree)
    return float(np.prod((last - first + 1).astype(float), axis=1).sum())


def delta_rows(name, features, labels):
    """Which labels set the paper's delta_i (the largest within-label range)?

    Per label, its range on each component relative to the component's range
    over the collection, averaged over the components; the paper's rule takes
    the largest per component, so one spread-out label widens every entry.
    """
    spreads = {
        g: (features[labels == g].max(axis=0) - features[labels == g].min(axis=0))
        / (features.max(axis=0) - features.min(axis=0))
        for g in np.unique(labels)
        if np.count_nonzero(labels == g) > 1
    }
    mean = {g: float(s.mean()) for g, s in spreads.items()}
    widest = sorted(mean, key=mean.get, reverse=True)
    stacked = np.stack(list(spreads.values()))
    return {
        "dataset": name,
        "labels": len(spreads),
        "delta_over_range_max": float(stacked.max(axis=0).mean()),
        "delta_over_range_q0.75": float(np.quantile(stacked, 0.75, axis=0).mean()),
        "delta_over_range_median": float(np.median(stacked, axis=0).mean()),
        "widest_labels": ", ".join(f"{g} ({mean[g]:.2f})" for g in widest[:3]),
    }


def held_out_sets():
    """name -> (train clips, train labels, query clips, query labels).

    Repetition sets: the last repetition of each motion (or trial) queries, the
    others are stored; UEA sets: their own train/test split.
    """
    sets = {}
    for name, (clips, labels) in search_datasets().items():
        if name in ("JapaneseVowels", "BasicMotions"):
            train = load_uea(name, subset="train", data_home=SHARED_DATA)
            test = load_uea(name, subset="test", data_home=SHARED_DATA)
            sets[name] = (train.clips, train.target, test.clips, test.target)
            continue
        sets[name] = hold_out_last(clips, labels)
    return sets


def hold_out_last(clips, labels):
    """(train clips, train labels, query clips, query labels): each label's last clip queries.

    A label with one clip stays stored (it has nothing similar to find).
    """
    labels = np.asarray(labels)
    last = np.zeros(len(labels), bool)
    for g in np.unique(labels):
        at = np.flatnonzero(labels == g)
        if len(at) > 1:
            last[at[-1]] = True
    train = [c for c, q in zip(clips, last) if not q]
    query = [c for c, q in zip(clips, last) if q]
    return train, labels[~last], query, labels[last]


RULES = (
    ("target_recall 0.99", {"target_recall": 0.99}),
    ("target_recall 0.95", {"target_recall": 0.95}),
    ("paper: epsilon 1.0", {"epsilon": 1.0}),
    ("paper: epsilon 0.8", {"epsilon": 0.8}),
)


def main(levels=(None,)):
    rows = []
    for name, (train, y_train, query, y_query) in held_out_sets().items():
        for weighting in ("first", "first_two"):
            for n_levels in levels:
                for rule, params in RULES:
                    start = time.perf_counter()
                    index = IntervalIndexNeighbors(
                        n_levels=n_levels,
                        features=SVDFeatureExtractor(weighting=weighting),
                        random_state=0,
                        **params,
                    )
                    try:
                        index.fit(train, y_train)
                    except ValueError as exc:  # too few channels for the levels
                        print(f"{name}: {exc}")
                        continue
                    fit_s = time.perf_counter() - start
                    found = index.candidates(query)
                    own = index.candidates()  # the training clips, leave-one-out
                    ids = np.arange(len(train))
                    rows.append(
                        {
                            "dataset": name,
                            "stored": len(train),
                            "queries": len(query),
                            "features": weighting,
                            "n_levels": index.n_levels_,
                            "rule": rule,
                            "pruning": pruning_efficiency(found, y_query, y_train),
                            "recall": recall(found, y_query, y_train),
                            "train_pruning": pruning_efficiency(
                                own, y_train, y_train, query_ids=ids
                            ),
                            "train_recall": recall(own, y_train, y_train, query_ids=ids),
                            "leaves_per_clip": index.index_.n_stored() / len(train),
                            "fit_s": fit_s,
                        }
                    )
                    print(rows[-1], flush=True)
    write_results(
        "neighbors_pruning",
        rows,
        notes="Held-out queries: the last repetition of each motion/trial (synthetic, CMU) or "
        "the UEA "
        "test split query an index fitted on the rest (the training split). Similar = same label. "
        "pruning = irrelevant stored clips pruned / irrelevant stored clips; recall = similar "
        "stored "
        "clips returned / similar stored clips (means over the queries); train_* = the training "
        "clips querying their own index, leaving themselves out. target_recall rows learn the "
        "radii "
        "on the training clips only.",
    )
    return rows


def grid():
    rows, deltas = [], []
    for name, (clips, labels) in search_datasets().items():
        ids = np.arange(len(clips))
        n_channels = clips[0].shape[1]
        for weighting in ("first", "first_two"):
            r = min(max(LEVELS), len(clips), n_channels * (1 if weighting == "first" else 2))
            features = SVDFeatureExtractor(n_components=r, weighting=weighting).fit_transform(clips)
            if weighting == "first_two":
                deltas.append(delta_rows(name, features[:, :7], labels))
            for n_levels in (lv for lv in LEVELS if lv <= r):
                for epsilon in EPSILONS:
                    pairs = leaf_entries(features, labels, n_levels, epsilon)
                    row = {
                        "dataset": name,
                        "clips": len(clips),
                        "features": weighting,
                        "n_levels": n_levels,
                        "epsilon": epsilon,
                    }
                    if pairs > MAX_PAIRS:
                        rows.append(
                            {
                                **row,
                                "pruning": float("nan"),
                                "recall": float("nan"),
                                "leaves_per_clip": pairs / len(clips),
                            }
                        )
                        continue
                    index = IntervalIndexNeighbors(n_levels=n_levels, epsilon=epsilon).fit(
                        features, labels
                    )
                    found = index.candidates()
                    rows.append(
                        {
                            **row,
                            "pruning": pruning_efficiency(found, labels, labels, query_ids=ids),
                            "recall": recall(found, labels, labels, query_ids=ids),
                            "leaves_per_clip": index.index_.n_stored() / len(clips),
                        }
                    )
                    print(rows[-1], flush=True)
    write_results(
        "neighbors_pruning_grid",
        rows,
        notes="Leave-one-out queries; pruning = irrelevant clips pruned / irrelevant clips; "
        "recall = similar clips "
        f"returned / similar clips (similar = same label). Trees over {MAX_PAIRS:,} leaf "
        "entries are not built (nan).",
    )
    summary = []
    for name, weighting in sorted({(r["dataset"], r["features"]) for r in rows}):
        mine = [
            r
            for r in rows
            if r["dataset"] == name and r["features"] == weighting and r["recall"] == r["recall"]
        ]
        for bound in (0.99, 1.0):
            ok = [r for r in mine if r["recall"] >= bound - 1e-12]
            best = max(ok, key=lambda r: r["pruning"]) if ok else None
            summary.append(
                {
                    "dataset": name,
                    "features": weighting,
                    "recall_at_least": bound,
                    "best_pruning": best["pruning"] if best else float("nan"),
                    "its_recall": best["recall"] if best else float("nan"),
                    "n_levels": best["n_levels"] if best else "",
                    "epsilon": best["epsilon"] if best else "",
                }
            )
        at7 = {r["epsilon"]: r for r in mine if r["n_levels"] == 7}
        summary.append(
            {
                "dataset": name,
                "features": weighting,
                "recall_at_least": "7 levels, eps 0.8",
                "best_pruning": at7[0.8]["pruning"] if 0.8 in at7 else float("nan"),
                "its_recall": at7[0.8]["recall"] if 0.8 in at7 else float("nan"),
                "n_levels": 7,
                "epsilon": 0.8,
            }
        )
    write_results(
        "neighbors_pruning_delta",
        deltas,
        notes="Weighted first two singular vectors, 7 components. delta_over_range: delta_i "
        "(the within-label range "
        "of component i: the maximum over the labels = the paper's rule, or a quantile) over "
        "the component's range, "
        "averaged over the components; widest_labels: the labels with the largest mean "
        "relative range.",
    )
    write_results(
        "neighbors_pruning_summary",
        summary,
        notes="Best pruning over the grid at a recall bound; the paper reports ~90% (body) to "
        "95% (hand) at ~100% recall with eps 0.8-1.0, 7 levels.",
    )
    try:
        from skmotion.plotting import plot_pruning_recall
    except ImportError:
        return
    try:
        figure = plot_pruning_recall(rows)
    except ImportError as exc:
        print(exc)
        return
    figure.savefig(RESULTS / "neighbors_pruning.png", dpi=110)
    print(f"figure: {RESULTS / 'neighbors_pruning.png'}")


def quantile_sweep():
    """The robust delta (a quantile over the labels) at 7 levels.

    Where the paper's maximum prunes little.
    """
    rows = []
    for name, (clips, labels) in search_datasets().items():
        ids = np.arange(len(clips))
        features = SVDFeatureExtractor(n_components=7, weighting="first_two").fit_transform(clips)
        for quantile in (0.5, 0.75, 0.9, 1.0):
            for epsilon in (0.8, 1.0, 1.2, 1.5):
                index = IntervalIndexNeighbors(
                    n_levels=7, epsilon=epsilon, delta_quantile=quantile
                ).fit(features, labels)
                found = index.candidates()
                rows.append(
                    {
                        "dataset": name,
                        "delta_quantile": quantile,
                        "epsilon": epsilon,
                        "pruning": pruning_efficiency(found, labels, labels, query_ids=ids),
                        "recall": recall(found, labels, labels, query_ids=ids),
                    }
                )
                print(rows[-1], flush=True)
    write_results(
        "neighbors_pruning_quantile",
        rows,
        notes="7 levels, weighted first two singular vectors; delta_i = this quantile over the "
        "labels of the "
        "within-label range (1.0 = the paper's maximum). Leave-one-out queries.",
    )


SHRINKAGES = (0.5, 0.8, 0.9, 0.97)


def discriminant_axes(features, labels, shrinkage):
    """Axes ordered by between-label over (shrunk) within-label variance.

    The generalised eigenvectors of ``(S_b, (1 - s) S_w + s tr(S_w)/p I)``
    (Fisher's discriminant, shrunk toward a scaled identity), largest first.
    """
    codes = np.unique(labels, return_inverse=True)[1].ravel()
    counts = np.bincount(codes)
    means = np.zeros((len(counts), features.shape[1]))
    np.add.at(means, codes, features)
    means /= counts[:, None]
    within = features - means[codes]
    s_w = within.T @ within / len(features)
    between = (means - features.mean(axis=0)) * np.sqrt(counts)[:, None]
    s_b = between.T @ between / len(features)
    p = len(s_w)
    s_w = (1 - shrinkage) * s_w + shrinkage * np.trace(s_w) / p * np.eye(p)
    return scipy.linalg.eigh(s_b, s_w)[1][:, ::-1]


def discriminant_study():
    """Tree levels on discriminant axes of the SVD features instead of their leading components.

    Held-out protocol of :func:`main`. The axes are learned on the training clips'
    labels from their first ``2 * n_levels`` SVD components (shrinkage ``s``);
    the tree indexes the first ``n_levels`` axes, queries are projected alike,
    and the widths are learned for the recall on the projected training clips.
    """
    rows = []
    for name, (train, y_train, query, y_query) in held_out_sets().items():
        y_train, y_query = np.asarray(y_train), np.asarray(y_query)
        for weighting in ("first", "first_two"):
            limit = min(len(train), (1 if weighting == "first" else 2) * train[0].shape[1])
            extractor = SVDFeatureExtractor(n_components=limit, weighting=weighting)
            stored, queries = extractor.fit_transform(train), extractor.transform(query)
            n_levels = min(7, limit)
            inputs = min(2 * n_levels, limit)
            variants = [("svd (leading components)", stored, queries)]
            for shrinkage in SHRINKAGES:
                axes = discriminant_axes(stored[:, :inputs], y_train, shrinkage)[:, :n_levels]
                variants.append(
                    (
                        f"discriminant, shrinkage {shrinkage}",
                        stored[:, :inputs] @ axes,
                        queries[:, :inputs] @ axes,
                    )
                )
            # sklearn's Ledoit-Wolf shrinkage on every component, for comparison.
            lda = LinearDiscriminantAnalysis(solver="eigen", shrinkage="auto").fit(stored, y_train)
            axes = lda.scalings_[:, :n_levels]
            variants.append(("discriminant, Ledoit-Wolf", stored @ axes, queries @ axes))
            for axes_name, fitted, queried in variants:
                for target in (0.99, 0.95):
                    index = IntervalIndexNeighbors(
                        n_levels=n_levels, target_recall=target, random_state=0
                    ).fit(fitted, y_train)
                    found = index.candidates(queried)
                    rows.append(
                        {
                            "dataset": name,
                            "features": weighting,
                            "n_levels": n_levels,
                            "axes": axes_name,
                            "target_recall": target,
                            "pruning": pruning_efficiency(found, y_query, y_train),
                            "recall": recall(found, y_query, y_train),
                        }
                    )
                    print(rows[-1], flush=True)
    write_results(
        "neighbors_pruning_discriminant",
        rows,
        notes="Held-out queries as in the default run. The tree's levels are the leading SVD "
        "feature components (svd) or the leading discriminant axes of the first 2 * n_levels "
        "components (between-label over within-label variance, within shrunk toward a scaled "
        "identity by the shrinkage), learned on the training clips; candidate sets only (the "
        "psi re-ranking does not change them).",
    )


if __name__ == "__main__":
    if "--quantiles" in sys.argv:
        quantile_sweep()
    elif "--discriminant" in sys.argv:
        discriminant_study()
    elif "--grid" in sys.argv:
        grid()
    else:
        main(tuple(int(v) for v in sys.argv[2].split(",")) if "--levels" in sys.argv else (None,))
