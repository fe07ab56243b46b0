"""The defaults study behind MotionTreeHMM(): grouped CV on the training part of every set.

Issue 26 (point 5) asks for the generative decoder with defaults within 0.10 of the
recommended recogniser on MSRC-12. Each candidate here is ``MotionTreeHMM`` with one
or two parameters changed, fitted on the same input as ``bench_recognition.py``'s
``MotionTreeHMM()`` row (``VirtualMarkerTransform`` markers on the skeleton sets, the
channels as they are elsewhere) and scored by 3-fold cross-validation over the
*training* part only: grouped by person on MSRC-12 (odd person ids) and by subject on
the synthetic sets, stratified elsewhere (``bench_recognition.folds``). The test
people never enter it; ``bench_recognition.py`` reports them.

``calibration_cv=None`` here: the temperature of ``predict_proba`` does not change a
label, and leaving it out makes every fit a few seconds shorter.

Usage::

    python benchmarks/study_hmm_defaults.py [--only SET] [--candidates NAME ...]

Writes ``results/hmm_defaults.{csv,md}``. The real sets need ``../shared/data`` (or
``SKMOTION_SHARED_DATA``); a set whose data is missing is left out with a message.
"""

import argparse
import time

import numpy as np
from _common import SHARED_DATA, write_results
from bench_recognition import SETS, folds

from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM

CANDIDATES = {  # name -> MotionTreeHMM parameters changed from today's defaults
    "defaults (depth 12, leaf 8, smoothing 1)": {},
    "former defaults (depth 8, leaf 4)": {"max_depth": 8, "min_samples_leaf": 4},
    "depth 10": {"max_depth": 10},
    "depth 14": {"max_depth": 14},
    "leaf 4": {"min_samples_leaf": 4},
    "leaf 16": {"min_samples_leaf": 16},
    "smoothing 10": {"smoothing": 10.0},
    "n_paths 5": {"n_paths": 5},
    "median splits": {"split": "median"},
}


def markers(Xtr, kwargs):
    """The marker step of bench_recognition's ``MotionTreeHMM()`` row (None where it has none)."""
    if not kwargs and not hasattr(Xtr[0], "skeleton"):
        return None
    keep = {k: v for k, v in kwargs.items() if k in ("layout", "skeleton", "frame_rate")}
    return VirtualMarkerTransform(**keep)


def cv_accuracy(Xtr, ytr, groups, kwargs, params):
    """Mean accuracy over the grouped (or stratified) folds of the training part."""
    accuracies = []
    for a, b in folds(ytr, groups):
        train, held_out = [Xtr[i] for i in a], [Xtr[i] for i in b]
        step = markers(Xtr, kwargs)
        if step is not None:
            train = step.fit_transform(train)
            held_out = step.transform(held_out)
        model = MotionTreeHMM(calibration_cv=None, **params).fit(train, ytr[a])
        accuracies.append(model.score(held_out, ytr[b]))
    return float(np.mean(accuracies))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="a set's name (or its first word)")
    parser.add_argument("--candidates", nargs="*", help="names from CANDIDATES (all by default)")
    args = parser.parse_args()
    chosen = {k: v for k, v in CANDIDATES.items() if not args.candidates or k in args.candidates}
    rows = []
    for name, loader in SETS.items():
        if args.only and not name.lower().startswith(args.only.lower()):
            continue
        loaded = loader()
        if loaded is None:
            print(f"{name}: data not found under {SHARED_DATA}; left out")
            continue
        Xtr, ytr, _, _, groups, kwargs = loaded
        for candidate, params in chosen.items():
            start = time.perf_counter()
            accuracy = cv_accuracy(Xtr, ytr, groups, kwargs, params)
            rows.append(
                {
                    "set": name,
                    "candidate": candidate,
                    "cv accuracy": accuracy,
                    "seconds (3 fits and scores)": time.perf_counter() - start,
                }
            )
            print(rows[-1], flush=True)
    if rows:
        write_results(
            "hmm_defaults",
            rows,
            notes="3-fold CV on the training part only (grouped by person or subject where "
            "the set has groups); calibration_cv=None.",
        )


if __name__ == "__main__":
    main()
