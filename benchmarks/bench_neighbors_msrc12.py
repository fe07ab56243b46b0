"""The interval index's pruning and recall on MSRC-12 repetitions (Li & Prabhakaran's measure).

``python benchmarks/bench_neighbors_msrc12.py`` (about 10 minutes on 2 shared cores).

Clips: the repetitions of every MSRC-12 sequence (``_msrc12.msrc12_repetitions``,
60 channels of Kinect joint positions). Similar = the same gesture by the same
person. The last repetition of each sequence queries; the others are stored.
The people are split: odd ids are the development collection, on which the
parameters are chosen; even ids a separate test collection (its own index,
fitted on its own stored clips) on which the choice is reported.

The curve: for the tree's levels on the leading SVD components (the paper) and
on discriminant axes (``axes="discriminant"``), each with the first and the
weighted first two singular vectors, 7 levels, ``target_recall`` over a grid
(and the paper's ``epsilon`` rule for the leading components): pruning =
irrelevant stored clips pruned / irrelevant stored clips, recall = similar
stored clips returned / similar stored clips, means over the queries. The
curve's trees index SVD feature vectors computed once per collection
(``SVDFeatureExtractor``, 60 or 64 components): the candidate sets are those of the
clip estimator, which the chosen setting is then run as, on the test clips,
checked equal, and timed against the default index in the same run.
"""

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import RESULTS, SHARED_DATA, write_results  # noqa: E402
from _msrc12 import msrc12_repetitions  # noqa: E402

from skmotion.decomposition import SVDFeatureExtractor  # noqa: E402
from skmotion.metrics import pruning_efficiency, recall  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402

TARGETS = (0.8, 0.9, 0.93, 0.95, 0.96, 0.97, 0.99)
EPSILONS = (0.3, 0.5, 0.8, 1.0)
N_LEVELS = 7
MIN_RECALL, GOAL_PRUNING = 0.95, 0.90


def collections():
    """``{"development": ..., "test": ...}``: (stored clips, labels, query clips, labels)."""
    data = msrc12_repetitions(SHARED_DATA / "msrc12" / "msrc12_sequences.npz")
    label = data.gesture * 100 + data.person
    last = np.r_[data.sequence[1:] != data.sequence[:-1], True]
    out = {}
    for name, parity in (("development", 1), ("test", 0)):
        mine = data.person % 2 == parity
        stored, query = mine & ~last, mine & last
        out[name] = (
            [data.clips[i] for i in np.flatnonzero(stored)],
            label[stored],
            [data.clips[i] for i in np.flatnonzero(query)],
            label[query],
        )
    return out


def settings():
    """(axes, weighting, rule name, estimator parameters) of the curve."""
    for axes in ("svd", "discriminant"):
        for weighting in ("first", "first_two"):
            for target in TARGETS:
                yield axes, weighting, f"target_recall {target}", {"target_recall": target}
            if axes == "svd":
                for epsilon in EPSILONS:
                    yield axes, weighting, f"paper: epsilon {epsilon}", {"epsilon": epsilon}


def curve(sets):
    rows = []
    for name, (stored, y_stored, queries, y_query) in sets.items():
        for weighting in ("first", "first_two"):
            # As many components as the discriminant axes read (64, or all the data allows).
            limit = min(64, len(stored), stored[0].shape[1] * (1 if weighting == "first" else 2))
            extractor = SVDFeatureExtractor(n_components=limit, weighting=weighting).fit(stored)
            table, asked = extractor.transform(stored), extractor.transform(queries)
            for axes, w, rule, params in settings():
                if w != weighting:
                    continue
                start = time.process_time()
                index = IntervalIndexNeighbors(
                    n_levels=N_LEVELS, axes=axes, random_state=0, **params
                ).fit(table, y_stored)
                found = index.candidates(asked)
                rows.append(
                    {
                        "people": name,
                        "stored": len(stored),
                        "queries": len(queries),
                        "axes": axes,
                        "features": weighting,
                        "rule": rule,
                        "pruning": pruning_efficiency(found, y_query, y_stored),
                        "recall": recall(found, y_query, y_stored),
                        "candidates": float(np.mean([len(f) for f in found])),
                        "fit_cpu_s": time.process_time() - start,
                    }
                )
                print(rows[-1], flush=True)
    return rows


def choose(rows):
    """The development row with the most pruning at recall >= MIN_RECALL.

    Among the first singular vector's settings only: the weighted first two need
    every eigenvalue of each query (an exact decomposition), which costs a query
    several times the default's features.
    """
    ok = [
        r
        for r in rows
        if r["people"] == "development" and r["recall"] >= MIN_RECALL and r["features"] == "first"
    ]
    return max(ok, key=lambda r: r["pruning"])


def per_query_us(func, queries, *, single):
    """CPU microseconds per query: one batched call, or one call per query."""
    start = time.process_time()
    if single:
        for q in queries:
            func([q])
    else:
        func(queries)
    return 1e6 * (time.process_time() - start) / len(queries)


def clip_run(sets, chosen):
    """The chosen setting on the test clips against the default index, same run."""
    stored, y_stored, queries, y_query = sets["test"]
    params = {"target_recall": float(chosen["rule"].split()[-1])}
    weighting = SVDFeatureExtractor(weighting=chosen["features"])
    rows = []
    for name, index in (
        ("default IntervalIndexNeighbors()", IntervalIndexNeighbors(random_state=0)),
        (
            f"chosen: axes={chosen['axes']}, {chosen['features']}, {chosen['rule']}",
            IntervalIndexNeighbors(
                n_levels=N_LEVELS,
                axes=chosen["axes"],
                features=weighting,
                random_state=0,
                **params,
            ),
        ),
    ):
        start = time.process_time()
        index.fit(stored, y_stored)
        fit_s = time.process_time() - start
        found = index.candidates(queries)
        rows.append(
            {
                "index": name,
                "pruning": pruning_efficiency(found, y_query, y_stored),
                "recall": recall(found, y_query, y_stored),
                "fit_cpu_s": fit_s,
                "candidates_us_batched": per_query_us(index.candidates, queries, single=False),
                "candidates_us_single": per_query_us(index.candidates, queries, single=True),
                "kneighbors_us_batched": per_query_us(index.kneighbors, queries, single=False),
                "kneighbors_us_single": per_query_us(index.kneighbors, queries, single=True),
            }
        )
        print(rows[-1], flush=True)
    return rows


def figure(rows, chosen, test_row):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        print(f"no figure: {exc}")
        return
    fig, panels = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    styles = {
        ("svd", "first"): ("tab:gray", "o", "leading SVD components, first vector"),
        ("svd", "first_two"): ("tab:brown", "s", "leading SVD components, first two"),
        ("discriminant", "first"): ("tab:blue", "o", "discriminant axes, first vector"),
        ("discriminant", "first_two"): ("tab:green", "s", "discriminant axes, first two"),
    }
    for ax, people in zip(panels, ("development", "test")):
        ax.fill_between(
            [MIN_RECALL, 1.0], GOAL_PRUNING, 1.0, color="gold", alpha=0.25, label="goal"
        )
        for (axes, weighting), (colour, marker, label) in styles.items():
            for kind, line in (("target_recall", "-"), ("paper", ":")):
                mine = [
                    r
                    for r in rows
                    if r["people"] == people
                    and r["axes"] == axes
                    and r["features"] == weighting
                    and r["rule"].startswith(kind)
                ]
                if not mine:
                    continue
                mine.sort(key=lambda r: r["recall"])
                ax.plot(
                    [r["recall"] for r in mine],
                    [r["pruning"] for r in mine],
                    line,
                    color=colour,
                    marker=marker,
                    markersize=4,
                    label=label + (" (paper's epsilon)" if kind == "paper" else ""),
                )
        mark = chosen if people == "development" else test_row
        ax.plot(mark["recall"], mark["pruning"], "r*", markersize=14, label="chosen setting")
        ax.set_title(f"{people} people ({'odd' if people == 'development' else 'even'} ids)")
        ax.set_xlabel("recall (similar clips kept)")
        ax.set_xlim(0.75, 1.005)
        ax.set_ylim(0.0, 1.0)
        ax.grid(alpha=0.3)
    panels[0].set_ylabel("pruning efficiency (irrelevant clips pruned)")
    panels[1].legend(fontsize=7, loc="lower left")
    fig.suptitle("Interval index on MSRC-12 repetitions, 7 levels (similar = gesture and person)")
    fig.tight_layout()
    out = RESULTS / "neighbors_msrc12.png"
    fig.savefig(out, dpi=110)
    print(f"figure: {out}")


def main():
    sets = collections()
    rows = curve(sets)
    chosen = choose(rows)
    test_row = next(
        r
        for r in rows
        if r["people"] == "test" and all(r[k] == chosen[k] for k in ("axes", "features", "rule"))
    )
    notes = (
        "MSRC-12 repetitions; similar = same gesture by the same person; the last repetition "
        "of each sequence queries, the others are stored. Development = odd person ids, test "
        "= even ids, each its own index. 7 levels on SVD feature vectors "
        "(SVDFeatureExtractor, 60 components for the first vector, 64 for the first two); "
        "pruning and recall are means over the queries."
        f" Chosen on development: the most pruning at recall >= {MIN_RECALL}: axes="
        f"{chosen['axes']}, {chosen['features']}, {chosen['rule']} (development pruning "
        f"{chosen['pruning']:.3f} at recall {chosen['recall']:.3f}; test "
        f"{test_row['pruning']:.3f} at {test_row['recall']:.3f})."
    )
    write_results("neighbors_msrc12_curve", rows, notes=notes)
    clip_rows = clip_run(sets, chosen)
    write_results(
        "neighbors_msrc12_clips",
        clip_rows,
        notes="Test people, clips in (the estimator as users call it), the default index and "
        "the setting chosen on the development people, in one run; CPU microseconds per "
        "query, batched (one call) and single (one call per query).",
    )
    figure(rows, chosen, test_row)


if __name__ == "__main__":
    main()
