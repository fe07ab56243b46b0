"""The tree build of this checkout against another's on the development sets: same splits?

For MSRC-12 repetitions (odd people train, even people test) and UEA JapaneseVowels
(the archive's split), each source tree fits, in its own fresh process,
``MotionClassifier()``, ``MotionTreeHMM()`` (after ``VirtualMarkerTransform`` where the set
has a skeleton layout) and the chain ``MotionTreeEncoder() -> LogisticRegression``, all
with their defaults, as ``bench_recognition.py`` does. Per set and model: the test
accuracy of each, whether the test predictions are identical, and for the HMM's and the
encoder's trees whether every node holds the same number of frames (same parents), with
the largest difference of thresholds, means and encoder features (rounding).

Run: ``python benchmarks/bench_tree_build_dev.py --before /path/to/other/checkout``
(needs ``../shared/data``; the other checkout's compiled modules built). Results:
``results/tree_build_dev.{csv,md}``.
"""

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SETS = ("MSRC-12", "JapaneseVowels")
MODELS = ("MotionClassifier()", "MotionTreeHMM()", "MotionTreeEncoder() -> LogisticRegression")


def worker(source, out):
    """Fit every model from the skmotion of ``source``; save predictions and trees to ``out``."""
    sys.path.insert(0, str(source))
    import skmotion

    if not skmotion.__file__.startswith(str(source)):
        raise RuntimeError(f"skmotion came from {skmotion.__file__}, not {source}")
    sys.path.insert(1, str(HERE))
    import bench_recognition as br
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline

    saved = {}
    for name, loader in zip(SETS, (br.msrc12, br.uea("JapaneseVowels"))):
        loaded = loader()
        if loaded is None:
            raise SystemExit(f"{name}: the data is not at {br.SHARED_DATA}")
        Xtr, ytr, Xte, yte, _, kwargs = loaded
        markers = {k: v for k, v in kwargs.items() if k in ("layout", "skeleton", "frame_rate")}
        vm = [br.VirtualMarkerTransform(**markers)] if kwargs else []
        models = dict(
            zip(
                MODELS,
                (
                    br.MotionClassifier(**kwargs),
                    make_pipeline(*vm, br.MotionTreeHMM()),
                    make_pipeline(*vm, br.MotionTreeEncoder(), LogisticRegression(max_iter=5000)),
                ),
            )
        )
        for label, model in models.items():
            model.fit(Xtr, ytr)
            saved[f"{name}|{label}|pred"] = model.predict(Xte)
            saved[f"{name}|{label}|truth"] = np.asarray(yte)
            tree = {"MotionTreeHMM()": -1, MODELS[2]: -2}.get(label)
            if tree is not None:
                fitted = model[tree]
                for key in ("count", "parent", "threshold", "mean"):
                    saved[f"{name}|{label}|tree_{key}"] = getattr(fitted.tree_, key)
                if label == MODELS[2]:
                    saved[f"{name}|{label}|features"] = model[:-1].transform(Xte)
    np.savez(out, **saved)


def run(source, out):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    subprocess.run(
        [sys.executable, __file__, "--worker", str(source), str(out)], env=env, check=True
    )
    return np.load(out)


def largest_difference(a, b, key):
    """The largest difference of two arrays, whose NaN (a leaf's threshold) must coincide."""
    if key not in a.files:
        return ""
    x, y = a[key], b[key]
    if not np.array_equal(np.isnan(x), np.isnan(y)):
        return float("inf")
    return float(np.max(np.abs(x - y)[~np.isnan(x)], initial=0.0))


def main(before):
    sys.path.insert(0, str(HERE))
    from _common import write_results

    with tempfile.TemporaryDirectory() as folder:
        new = run(HERE.parent, Path(folder) / "new.npz")
        old = run(before, Path(folder) / "old.npz")
        rows = []
        for name in SETS:
            for label in MODELS:
                key = f"{name}|{label}|"
                truth = new[key + "truth"]
                pred_old, pred_new = old[key + "pred"], new[key + "pred"]
                same_tree = ""
                if key + "tree_count" in new.files:
                    same_tree = bool(
                        np.array_equal(new[key + "tree_count"], old[key + "tree_count"])
                        and np.array_equal(new[key + "tree_parent"], old[key + "tree_parent"])
                    )
                rows.append(
                    {
                        "set": name,
                        "model": label,
                        "accuracy before": float(np.mean(pred_old == truth)),
                        "accuracy now": float(np.mean(pred_new == truth)),
                        "same predictions": bool(np.array_equal(pred_old, pred_new)),
                        "same nodes (counts, parents)": same_tree,
                        "max threshold difference": largest_difference(
                            old, new, key + "tree_threshold"
                        ),
                        "max mean difference": largest_difference(old, new, key + "tree_mean"),
                        "max feature difference": largest_difference(old, new, key + "features"),
                    }
                )
    write_results(
        "tree_build_dev",
        rows,
        notes=(
            f"This checkout against {Path(before).name} ({before}); every model with its "
            "defaults, each source tree in its own process. OPENBLAS/OMP/MKL threads = 1."
        ),
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worker", nargs=2, metavar=("SOURCE", "OUT"))
    parser.add_argument("--before", type=Path, help="the other skmotion checkout")
    args = parser.parse_args()
    if args.worker:
        worker(Path(args.worker[0]).resolve(), args.worker[1])
    elif args.before is None:
        parser.error("--before is required")
    else:
        main(args.before.resolve())
