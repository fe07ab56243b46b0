"""The motion database: MotionTreeHMM against peer classifiers, and the tree's build-time scaling.

Result tables, all measured in one run on the same splits:

- ``tree_recognition``: test accuracy, log loss, expected calibration error and
  predict time per clip (whole clips, every class scored) of MotionTreeHMM (CV-chosen
  and defaults), MotionTreeEncoder + LogisticRegression (CV-chosen and defaults),
  hmmlearn ``GaussianHMM`` per class, aeon ``MiniRocketClassifier``, 1-NN DTW
  (tslearn) and 1-NN Euclidean on resampled clips, on BasicMotions and
  JapaneseVowels (the archive's train/test split), the synthetic motions as joint
  angles and as body-frame marker positions (subjects 0-2 train, subject 3 test),
  and CMU subject 02's trials cut into 1 s windows of virtual markers (split by
  time inside each trial, see :func:`cmu_windows`). Every model's hyperparameters
  are chosen by cross-validation on the training set only (stratified 5-fold,
  repeated three times unless ``--quick``, or by subject for the synthetic data).
- ``tree_defaults``: the study behind the defaults of MotionTreeHMM and
  MotionTreeEncoder (candidates' test accuracy; also CV accuracy unless ``--quick``).
- ``tree_encoder_speed``: MotionTreeEncoder's transform time per 40-frame clip of
  120 channels.
- ``tree_score_layers``: accuracy against the tree's depth when one, three or all
  layers are scored (``score_layers``), on BasicMotions and JapaneseVowels.
- ``tree_selection`` (only with ``--only selection``, about 25 minutes): the
  CV-chosen model's test accuracy on JapaneseVowels over five shuffles of the
  folds, repeated and single 5-fold.
- ``tree_scaling``: build time and peak memory of the tree against the number of
  frames (60 channels), the fitted growth exponent, and sklearn's
  ``BisectingKMeans`` with the same number of leaves on the same frames.
- ``tree_layers``: the paper's Table I (frames, layers, nodes, bottom-layer nodes
  with ``min_samples_leaf=16``) on the data at hand and on CMU subjects 01-03
  (virtual markers), and the time of one decode at each layer.

Run: ``python benchmarks/bench_tree.py`` (``--quick``: small grids, single 5-fold;
``--only TABLE``). Needs the ``bench`` extra (hmmlearn, tslearn, aeon); the UEA and
CMU rows need ``../shared/data`` (or ``SKMOTION_SHARED_DATA``) and are left out,
with a message, without it.
"""

import argparse
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import (  # noqa: E402
    CMU_RATE,
    SHARED_DATA,
    cmu_markers,
    interleaved,
    time_call,
    write_results,
)
from _common import cmu_windows as _common_cmu_windows  # noqa: E402
from _tree_peers import (  # noqa: E402
    ENCODER_GRID,
    QUICK_ENCODER_GRID,
    MiniRocket,
    defaults_study,
    encoder_pipeline,
    probability_scores,
    softmax_scores,
)
from sklearn.cluster import BisectingKMeans  # noqa: E402
from sklearn.model_selection import (
    GridSearchCV,
    GroupKFold,
    RepeatedStratifiedKFold,
    cross_val_score,
)  # noqa: E402,E501
from sklearn.neighbors import KNeighborsClassifier  # noqa: E402
from sklearn.pipeline import make_pipeline  # noqa: E402

from skmotion.datasets import load_uea, make_motions  # noqa: E402
from skmotion.preprocessing import FlattenClips, ResampleClips  # noqa: E402
from skmotion.tree import MotionTree, MotionTreeEncoder, MotionTreeHMM  # noqa: E402

# n_paths=1 and score_layers=1 come first: among equally accurate settings GridSearchCV keeps the
# first.
TREE_GRID = {
    "n_paths": [1, 3],
    "score_layers": [1, 3, "all"],
    "split": ["min_error", "median", "two_means"],
    "max_depth": [6, 8, 10],
    "min_samples_leaf": [4, 16],
    "covariance_type": ["diag", "full"],
    "smoothing": [1.0, 10.0],
}
# The CMU windows have 192 channels: a smaller grid keeps the run within minutes.
CMU_TREE_GRID = {
    "n_paths": [1, 3],
    "score_layers": [1, "all"],
    "split": ["median", "two_means"],
    "max_depth": [6, 8],
    "covariance_type": ["diag", "full"],
}
QUICK_TREE_GRID = {"split": ["median"], "max_depth": [6], "covariance_type": ["diag", "full"]}
HMM_STATES = (2, 3, 4, 6)
REPEATS = 7  # timings are medians of this many runs (the machine is shared)


# -- data ------------------------------------------------------------------------------


def uea(name):
    train = load_uea(name, subset="train", data_home=SHARED_DATA)
    test = load_uea(name, subset="test", data_home=SHARED_DATA)
    return train.clips, train.target, test.clips, test.target, None


def synthetic():
    data = make_motions(random_state=0)
    clips = [c[:, 6:] for c in data.clips]
    train = data.groups < 3
    pick = lambda mask: [c for c, m in zip(clips, mask) if m]  # noqa: E731
    names = data.target_names[data.target]
    return pick(train), names[train], pick(~train), names[~train], data.groups[train]


def synthetic_positions():
    """The synthetic motions as marker positions: body frame (hip-centred, facing), size-normalised.

    The positions (not the velocities) of VirtualMarkerTransform's 32 markers,
    96 channels, like a Kinect-style tracker's joints after hip-centring and
    size normalisation; subject 3 held out.
    """
    from skmotion.io import as_motions
    from skmotion.preprocessing import VirtualMarkerTransform

    data = make_motions(random_state=0)
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    markers = VirtualMarkerTransform().fit_transform(motions)
    n = markers[0].shape[1] // 6
    positions = [m.reshape(len(m), n, 6)[:, :, :3].reshape(len(m), -1) for m in markers]
    train = data.groups < 3
    pick = lambda mask: [c for c, m in zip(positions, mask) if m]  # noqa: E731
    names = data.target_names[data.target]
    return pick(train), names[train], pick(~train), names[~train], data.groups[train]


def cmu_windows():
    """:func:`_common.cmu_windows`, with no groups (one subject: no subject-wise folds)."""
    return (*_common_cmu_windows(), None)


def cv_for(y, groups, quick=False):
    """Subject-wise folds where subjects are known, else stratified 5-fold repeated three times.

    One 5-fold split leaves the choice among hundreds of near-equal settings to
    the luck of its folds; three shuffles of it average that out (for every model).
    The quick run repeats it once.
    """
    if groups is not None:
        return GroupKFold(3)
    return RepeatedStratifiedKFold(n_splits=5, n_repeats=1 if quick else 3, random_state=0)


# -- the peers ---------------------------------------------------------------------------


class PerClassHMM:
    """hmmlearn GaussianHMM per class; a clip goes to the class whose model scores it highest."""

    def __init__(self, n_states):
        self.n_states = n_states

    def fit(self, X, y):
        from hmmlearn.hmm import GaussianHMM

        frames = np.vstack(X)
        self.mu_, self.sd_ = frames.mean(0), np.where(frames.std(0) > 0, frames.std(0), 1.0)
        self.classes_ = np.unique(y)
        self.models_ = []
        for c in self.classes_:
            clips = [(x - self.mu_) / self.sd_ for x, label in zip(X, y) if label == c]
            n_states = max(1, min(self.n_states, min(len(x) for x in clips)))
            model = GaussianHMM(
                n_states, covariance_type="diag", n_iter=30, random_state=0, min_covar=1e-3
            )
            self.models_.append(model.fit(np.vstack(clips), [len(x) for x in clips]))
        return self

    def scores(self, X):
        return np.array([[m.score((x - self.mu_) / self.sd_) for m in self.models_] for x in X])

    def predict(self, X):
        return self.classes_[self.scores(X).argmax(axis=1)]


def choose_hmm(X, y, cv):
    """The state count with the best cross-validated accuracy on the training set."""
    best = None
    for n in HMM_STATES:
        accs = []
        for train, val in cv:
            model = PerClassHMM(n).fit([X[i] for i in train], y[train])
            accs.append(np.mean(model.predict([X[i] for i in val]) == y[val]))
        if best is None or np.mean(accs) > best[1]:
            best = (n, np.mean(accs))
    return best[0]


def dtw_1nn():
    from tslearn.neighbors import KNeighborsTimeSeriesClassifier

    class DTW1NN:
        def fit(self, X, y):
            from tslearn.utils import to_time_series_dataset

            self.model_ = KNeighborsTimeSeriesClassifier(n_neighbors=1, metric="dtw").fit(
                to_time_series_dataset(X), y
            )
            return self

        def predict(self, X):
            from tslearn.utils import to_time_series_dataset

            return self.model_.predict(to_time_series_dataset(X))

    return DTW1NN()


# -- recognition -----------------------------------------------------------------------


def recognition(name, loader, quick):
    Xtr, ytr, Xte, yte, groups = loader()
    cv = cv_for(ytr, groups, quick)
    splits = list(cv.split(Xtr, ytr, groups))

    grid = QUICK_TREE_GRID if quick else CMU_TREE_GRID if name.startswith("CMU") else TREE_GRID
    search = GridSearchCV(MotionTreeHMM(), grid, cv=splits, n_jobs=2)
    search.fit(Xtr, ytr)
    tree = search.best_estimator_
    # Variants of the chosen model: the defaults, the fastest beam, diagonal covariances (hmmlearn's
    # peer's), the paper's single scored layer, and its node prior.
    changes = [("MotionTreeHMM() defaults", None)]
    if not quick:
        changes += [
            ("MotionTreeHMM, n_paths=1", {"n_paths": 1}),
            ("MotionTreeHMM, covariance_type='diag'", {"covariance_type": "diag"}),
            ("MotionTreeHMM, score_layers=1 (the paper's)", {"score_layers": 1}),
            ("MotionTreeHMM, node_prior='graph' (the paper's)", {"node_prior": "graph"}),
        ]
    variants = [("MotionTreeHMM (CV-chosen)", tree)] + [
        (
            label,
            MotionTreeHMM(**({**search.best_params_, **change} if change else {})).fit(Xtr, ytr),
        )
        for label, change in changes
        if change is None or any(tree.get_params()[k] != v for k, v in change.items())
    ]

    encoder_grid = QUICK_ENCODER_GRID if quick else ENCODER_GRID
    encoder_search = GridSearchCV(encoder_pipeline(), encoder_grid, cv=splits, n_jobs=2)
    encoder_search.fit(Xtr, ytr)
    encoders = [
        ("MotionTreeEncoder + LogisticRegression (CV-chosen)", encoder_search.best_estimator_),
        ("MotionTreeEncoder() + LogisticRegression() defaults", encoder_pipeline().fit(Xtr, ytr)),
    ]

    n_states = choose_hmm(Xtr, ytr, splits)
    hmm = PerClassHMM(n_states).fit(Xtr, ytr)
    rocket = MiniRocket().fit(Xtr, ytr)
    models = variants + encoders
    # Timed in alternation, so that all share the machine's load alike.
    *model_s, hmm_s, rocket_s = interleaved(
        [lambda m=m: m.predict(Xte) for _, m in models]
        + [lambda: hmm.scores(Xte), lambda: rocket.predict(Xte)],
        REPEATS,
    )

    length = int(np.median([len(x) for x in Xtr]))
    euclid = make_pipeline(
        ResampleClips(n_frames=length), FlattenClips(), KNeighborsClassifier(1)
    ).fit(Xtr, ytr)
    euclid_s, _ = time_call(lambda: euclid.predict(Xte), repeats=REPEATS)
    dtw = dtw_1nn().fit(Xtr, ytr)
    dtw_s, _ = time_call(lambda: dtw.predict(Xte), repeats=1)

    chosen = ", ".join(f"{k}={v}" for k, v in sorted(search.best_params_.items()))
    encoder_chosen = ", ".join(
        f"{k.split('__')[1]}={v}" for k, v in sorted(encoder_search.best_params_.items())
    )
    params = {
        "MotionTreeHMM (CV-chosen)": chosen,
        "MotionTreeEncoder + LogisticRegression (CV-chosen)": encoder_chosen,
    }
    hmm_proba = lambda X: softmax_scores(hmm.scores(X))  # noqa: E731
    results = [
        (
            label,
            params.get(label, "defaults" if "defaults" in label else "as above"),
            m,
            s,
            m.predict_proba,
        )
        for (label, m), s in zip(models, model_s)
    ]
    results += [
        ("hmmlearn GaussianHMM per class", f"n_states={n_states}, diag", hmm, hmm_s, hmm_proba),
        (
            "aeon MiniRocketClassifier",
            "10,000 kernels, ridge alpha by LOO",
            rocket,
            rocket_s,
            rocket.predict_proba,
        ),
        ("1-NN DTW (tslearn)", "", dtw, dtw_s, None),
        ("1-NN Euclidean (resampled)", f"n_frames={length}", euclid, euclid_s, None),
    ]
    rows = []
    for method, chosen_params, model, seconds, proba in results:
        loss, ece = probability_scores(yte, proba(Xte), model.classes_) if proba else ("", "")
        rows.append(
            {
                "dataset": name,
                "method": method,
                "chosen by CV on train": chosen_params,
                "test accuracy": float(np.mean(model.predict(Xte) == yte)),
                "log loss": loss,
                "ECE": ece,
                "predict ms per clip": 1e3 * seconds / len(Xte),
                "predict time / MiniRocket's": seconds / rocket_s,
                "throughput vs hmmlearn": hmm_s / seconds,
            }
        )
    return rows, tree


def encoder_speed(quick):
    """Transform time of the default encoder on 40-frame clips of 120 channels."""
    data = make_motions(n_clips_per_class=4 if quick else 12, random_state=0)
    from skmotion.io import as_motions
    from skmotion.preprocessing import VirtualMarkerTransform

    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    markers = [m[:, :120] for m in VirtualMarkerTransform().fit_transform(motions)]  # 20 markers
    windows = [m[s : s + 40] for m in markers for s in range(0, len(m) - 39, 20)]
    encoder = MotionTreeEncoder().fit(windows)
    rows = []
    for n_clips in (1, 100, len(windows)):
        batch = windows[:n_clips]
        frames = np.vstack(batch)
        # A yardstick timed alongside: one multiply over the same frames (the machine is shared).
        seconds, one_pass = interleaved(
            [lambda b=batch: encoder.transform(b), lambda f=frames: f * 2.0], REPEATS
        )
        rows.append(
            {
                "clips per call": n_clips,
                "frames x channels": "40 x 120",
                "tree layers": encoder.tree_.n_layers,
                "output columns": encoder.n_features_out_,
                "µs per clip": 1e6 * seconds / n_clips,
                "one pass over the frames, µs per clip": 1e6 * one_pass / n_clips,
                "transform / one pass": seconds / one_pass,
                "target µs": 100,
            }
        )
    return rows


# -- several scored layers ----------------------------------------------------------------


def score_layers_study(name, loader, quick):
    """Test and CV accuracy against depth, scored at the bottom layer, three layers or all."""
    Xtr, ytr, Xte, yte, groups = loader()
    splits = list(cv_for(ytr, groups).split(Xtr, ytr, groups))
    rows = []
    for covariance_type in ["full"] if quick else ["diag", "full"]:
        for max_depth in [6, 8] if quick else [6, 8, 10, 12]:
            for score_layers in [1, 3, "all"]:
                model = MotionTreeHMM(
                    max_depth=max_depth,
                    score_layers=score_layers,
                    split="two_means",
                    min_samples_leaf=4,
                    covariance_type=covariance_type,
                )
                cv = cross_val_score(model, Xtr, ytr, cv=splits, n_jobs=2)
                rows.append(
                    {
                        "dataset": name,
                        "covariance_type": covariance_type,
                        "max_depth": max_depth,
                        "score_layers": score_layers,
                        "CV accuracy (train)": float(cv.mean()),
                        "test accuracy": float(model.fit(Xtr, ytr).score(Xte, yte)),
                    }
                )
    return rows


# -- how much the choice depends on the folds ----------------------------------------------


def selection_study(name, loader, seeds=range(5)):
    """The CV-chosen model's test accuracy over shuffles of the folds (repeated, single 5-fold)."""
    Xtr, ytr, Xte, yte, _ = loader()
    rows = []
    for repeats in (3, 1):
        for seed in seeds:
            cv = RepeatedStratifiedKFold(n_splits=5, n_repeats=repeats, random_state=seed)
            search = GridSearchCV(MotionTreeHMM(), TREE_GRID, cv=cv, n_jobs=2).fit(Xtr, ytr)
            rows.append(
                {
                    "dataset": name,
                    "folds": f"stratified 5-fold x {repeats}",
                    "seed": seed,
                    "chosen": ", ".join(f"{k}={v}" for k, v in sorted(search.best_params_.items())),
                    "CV accuracy (train)": float(search.best_score_),
                    "test accuracy": float(search.best_estimator_.score(Xte, yte)),
                }
            )
    return rows


# -- build scaling -------------------------------------------------------------------------


def scaling_frames(n_max):
    """Joint angles (60 channels, no root) of synthetic motions at 120 Hz, standardised."""
    clips_needed = int(np.ceil(n_max / 1200 / 7)) + 1
    data = make_motions(
        n_clips_per_class=clips_needed, frame_rate=120.0, duration=(8.0, 12.0), random_state=0
    )
    frames = np.vstack([c[:, 6:] for c in data.clips])[:n_max]
    spread = frames.std(axis=0)
    return (frames - frames.mean(axis=0)) / np.where(spread > 0, spread, 1.0)


def peak_memory(func):
    tracemalloc.start()
    func()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def scaling(quick):
    sizes = [10_000, 30_000, 100_000] if quick else [10_000, 30_000, 100_000, 300_000, 1_000_000]
    frames = scaling_frames(sizes[-1])
    # (label, build arguments, largest size built, largest size given to BisectingKMeans)
    configs = [
        ("default (min_error, max_depth=10)", dict(max_depth=10), sizes[-1], sizes[-1]),
        ("median, no depth limit", dict(split="median"), sizes[-1], 100_000),
        ("min_error, no depth limit", dict(), 100_000, 30_000),
    ]
    rows = []
    for label, kwargs, max_n, max_bkm in configs:
        times = []
        for n in sizes:
            if n > max_n:
                break
            X = frames[:n]
            start = time.perf_counter()
            tree = MotionTree.build(X, min_samples_leaf=16, **kwargs)
            seconds = time.perf_counter() - start
            memory = peak_memory(
                lambda X=X, kwargs=kwargs: MotionTree.build(X, min_samples_leaf=16, **kwargs)
            )
            leaves = int(tree.n_nodes[-1])
            bkm = ""
            if n <= max_bkm:
                start = time.perf_counter()
                BisectingKMeans(n_clusters=leaves, random_state=0).fit(X)
                bkm = time.perf_counter() - start
            times.append(seconds)
            rows.append(
                {
                    "tree": label,
                    "frames": n,
                    "layers": tree.n_layers,
                    "leaves": leaves,
                    "build s": seconds,
                    "peak MB": memory / 2**20,
                    "BisectingKMeans s (same leaves)": bkm,
                    "tree / BisectingKMeans": seconds / bkm if bkm else "",
                    "growth exponent": "",
                }
            )
        exponent = np.polyfit(np.log(sizes[: len(times)]), np.log(times), 1)[0]
        rows[-1]["growth exponent"] = float(exponent)
    return rows


# -- Table I and decode time per layer -------------------------------------------------------------


def cmu_layer_datasets():
    """name -> (clips, labels, clip to decode): CMU subjects 01, 02, 03 and all three (30 Hz)."""
    clips, data = cmu_markers([1, 2, 3])
    if clips is None:
        print(f"CMU: not found in {SHARED_DATA}, its Table I rows are left out")
        return {}
    subjects = np.array([t.split("_")[0] for t in data.trials])
    sets = {}
    for name, mask in [(f"CMU subject {s}", subjects == s) for s in ("01", "02", "03")] + [
        ("CMU subjects 01-03", np.ones(len(clips), dtype=bool))
    ]:
        chosen = [c for c, m in zip(clips, mask) if m]
        # decode a 10 s stretch of the subject's longest trial
        longest = max(chosen, key=len)
        sets[name] = (
            chosen,
            np.asarray(data.description, dtype=str)[mask],
            longest[: 10 * CMU_RATE],
        )
    return sets


def layer_table(datasets, quick):
    rows = []
    for name, (Xtr, ytr, Xte) in datasets.items():
        model = MotionTreeHMM(max_depth=None, min_samples_leaf=16).fit(Xtr, ytr)
        tree, clip = model.tree_, (Xte if isinstance(Xte, np.ndarray) else Xte[0])
        bottom = model.n_layers_ - 1
        layers = sorted({0, bottom} | {2**i for i in range(12) if 2**i < bottom})
        if quick:
            layers = [layer for layer in layers if layer <= 8]
        decode_ms = [
            1e3
            * time_call(
                lambda layer=layer, model=model, clip=clip: model.decode([clip], layer=layer),
                repeats=3,
            )[0]
            for layer in layers
        ]
        rows.append(
            {
                "data": name,
                "frames": int(tree.count[0]),
                "layers": tree.n_layers,
                "nodes": tree.n_tree_nodes,
                "nodes, copies counted": int(tree.n_nodes.sum()),
                "nodes in bottom layer": int(tree.n_nodes[-1]),
                "decoded clip frames": len(clip),
                "decode ms at layer": ", ".join(
                    f"{layer}: {t:.1f}" for layer, t in zip(layers, decode_ms)
                ),
            }
        )
    return rows


RECOGNITION_NOTES = (
    "Hyperparameters of every model chosen by CV on the training set only (stratified 5-fold, "
    "repeated three times unless --quick, the same splits for every model; subject-wise 3-fold "
    "for the synthetic data): MotionTreeHMM by GridSearchCV over n_paths, score_layers, split, "
    "max_depth, min_samples_leaf, covariance_type and smoothing (on CMU a smaller grid; --quick: "
    "split, max_depth, covariance_type); the encoder pipeline over layers, residual_layers, "
    "moments and LogisticRegression's C (--quick: residual_layers, moments and C); hmmlearn's "
    "state count; "
    "MiniRocket: default kernels, its ridge's alpha by leave-one-out on the training set. "
    "Probabilities: MotionTreeHMM's predict_proba (temperature fitted by internal CV), the "
    "encoder's LogisticRegression, hmmlearn's softmax of per-class log-likelihoods, MiniRocket's "
    "predict_proba (one-hot: its ridge classifier gives no probabilities); log loss with "
    "probabilities clipped at 1e-15, ECE over 10 bins of the top probability. Predict time: "
    "median over runs of the whole test set, every model timed in alternation (the machine is "
    "shared: ratios count, not times). CMU subject 02: virtual markers (32 markers, positions "
    "and velocities, 192 channels) at 30 Hz, 1 s windows with a 0.5 s hop; each trial cut at 60% "
    "of its frames, training windows before the cut and test windows after it; 6 classes (walk, "
    "jump, punch, bend, swordplay, wash). Its CV folds share overlapping windows, which can only "
    "flatter the CV scores used to choose, never the test accuracy."
)
DEFAULTS_NOTES = (
    "Candidate defaults of MotionTreeHMM (calibration_cv=None: labels do not depend on it) and of "
    "MotionTreeEncoder (into LogisticRegression(C=1) unless the candidate says otherwise): "
    "accuracy by cross-validation on the training set (the recognition table's folds; for "
    "MotionTreeHMM not in the quick run) and on the test set. Candidate readouts that skmotion "
    "does not offer (soft assignment, second order, residual pyramid, bootstrap trees, "
    "graph-smoothed occupancy, the mean-square moments) are in benchmarks/_tree_readouts.py, "
    "on the same tree and routing."
)
ENCODER_SPEED_NOTES = (
    "MotionTreeEncoder() fit on 40-frame windows (hop 20) of the synthetic motions' first 20 "
    "virtual "
    "markers (120 channels); median time of transform over calls of 1, 100 and all windows, timed "
    "in alternation with one multiply over the same frames (a yardstick of the machine's load)."
)
SCORE_LAYERS_NOTES = (
    "MotionTreeHMM with two-means splits, min_samples_leaf=4, n_paths=3, smoothing=1, scored at "
    "its bottom layer "
    "alone (score_layers=1, the paper's), at the three bottom layers, or at all layers; CV "
    "accuracy on the "
    "training set (the folds of the recognition table) and accuracy on the test set."
)
SELECTION_NOTES = (
    "MotionTreeHMM's grid of the recognition table searched with the folds of five seeds, repeated"
    " three times "
    "(as in the recognition table, seed 0) and single; the chosen model's accuracy on the test set."
)
SCALING_NOTES = (
    "Synthetic joint angles (60 channels, 120 Hz), standardised; min_samples_leaf=16, diagonal "
    "covariances. "
    "Growth exponent: slope of log(build s) on log(frames), on the config's last row. Peak memory: "
    "tracemalloc's peak during a build (the frames themselves not counted). BisectingKMeans "
    "(sklearn, "
    "random_state=0) gets the tree's leaf count; it is left out where it would take many minutes."
)
LAYER_NOTES = (
    "The paper's Table I on the training sets (standardised, min_samples_leaf=16, no depth limit, "
    "minimum-error splits) and the time of one decode of the first test clip at layers 0, 1, 2, 4,"
    " ... and "
    "the bottom (global graph, n_paths=3). CMU rows: all trials of the subject(s) as 30 Hz virtual"
    " markers "
    "(192 channels), labelled by description; the decoded clip is the first 10 s of the longest "
    "trial."
)


def stacking_study(quick):
    """MotionTreeHMM's per-layer class scores (``transform``) as features, on every data set.

    CV accuracy on the training set (the recognition table's folds; for the CMU
    windows also contiguous 5-fold, whose folds do not share overlapping
    windows) and test accuracy and log loss of: the HMM alone, the HMM stacked
    on a logistic regression (out-of-fold ``fit_transform`` rows, or in-sample
    ``fit().transform()`` rows), the encoder pipeline, and both features side
    by side (FeatureUnion). Only with ``--only stacking``.
    """
    from sklearn.linear_model import LogisticRegression
    from sklearn.model_selection import StratifiedKFold
    from sklearn.pipeline import make_union

    class InSample(MotionTreeHMM):  # the training rows a plain fit().transform() gives
        def fit_transform(self, X, y, groups=None):
            return self.fit(X, y).transform(X)

    lr = lambda: LogisticRegression(max_iter=5000)  # noqa: E731
    candidates = {
        "MotionTreeHMM()": MotionTreeHMM,
        "MotionTreeHMM() -> LR, out-of-fold rows": lambda: make_pipeline(MotionTreeHMM(), lr()),
        "MotionTreeHMM() -> LR, in-sample rows": lambda: make_pipeline(InSample(), lr()),
        "MotionTreeEncoder() -> LR": encoder_pipeline,
        "[MotionTreeEncoder(), MotionTreeHMM()] -> LR": lambda: make_pipeline(
            make_union(MotionTreeEncoder(), MotionTreeHMM()), lr()
        ),
    }
    datasets = {"synthetic": synthetic, "synthetic positions": synthetic_positions}
    if (SHARED_DATA / "uea").is_dir():
        datasets = {k: lambda k=k: uea(k) for k in ("BasicMotions", "JapaneseVowels")} | datasets
    if (SHARED_DATA / "cmu-asfamc").is_dir():
        datasets["CMU 02 windows"] = cmu_windows
    rows = []
    for name, loader in datasets.items():
        Xtr, ytr, Xte, yte, groups = loader()
        folds = {"CV (recognition folds)": list(cv_for(ytr, groups, quick).split(Xtr, ytr, groups))}
        if name.startswith("CMU"):
            folds["CV (contiguous 5-fold)"] = list(StratifiedKFold(5).split(Xtr, ytr))
        for method, make in candidates.items():
            row = {"dataset": name, "method": method, "CV (contiguous 5-fold)": ""}
            for label, splits in folds.items():
                row[label] = float(cross_val_score(make(), Xtr, ytr, cv=splits).mean())
            model = make().fit(Xtr, ytr)
            loss, _ = probability_scores(yte, model.predict_proba(Xte), model.classes_)
            row.update({"test accuracy": float(model.score(Xte, yte)), "test log loss": loss})
            rows.append(row)
    return rows


STACKING_NOTES = (
    "MotionTreeHMM.transform: per scored layer, the log-softmax over classes of the clip's "
    "log generation probability per frame; stacked into LogisticRegression(C=1). 'out-of-fold "
    "rows': the training features come from fit_transform (graphs counted without the clip's "
    "internal fold, as StackingClassifier's cross_val_predict); 'in-sample': fit().transform(). "
    "All defaults, nothing tuned; the choice between candidates is by training CV (on CMU by the "
    "contiguous folds: the recognition folds share overlapping windows); the test columns are "
    "reported, not used to choose."
)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="small grids and sizes (a smoke run)")
    parser.add_argument(
        "--only",
        choices=[
            "recognition",
            "defaults",
            "encoder_speed",
            "score_layers",
            "scaling",
            "layers",
            "selection",
            "stacking",
        ],
        help="run one table only (selection, about 25 minutes, runs only when asked)",
    )
    parser.add_argument(
        "--data",
        action="append",
        help="only the data sets whose name contains this (repeatable); results get a suffix",
    )
    args = parser.parse_args()
    loaders = {
        "synthetic (subject 3 held out)": synthetic,
        "synthetic marker positions (subject 3 held out)": synthetic_positions,
    }
    if (SHARED_DATA / "uea").is_dir():
        loaders = {
            "BasicMotions": lambda: uea("BasicMotions"),
            "JapaneseVowels": lambda: uea("JapaneseVowels"),
            **loaders,
        }
    else:
        print(f"UEA: not found in {SHARED_DATA}, its rows are left out")
    if (SHARED_DATA / "cmu-asfamc").is_dir():
        loaders["CMU subject 02, 1 s windows (split by time)"] = cmu_windows
    else:
        print(f"CMU: not found in {SHARED_DATA}, its rows are left out")
    suffix = ""
    if args.data:
        loaders = {k: v for k, v in loaders.items() if any(d in k for d in args.data)}
        suffix = "_" + "_".join(d.replace(" ", "-") for d in args.data)
    if args.only in (None, "recognition"):
        rows = []
        # written after each data set: a long run keeps its rows
        for name, loader in loaders.items():
            rows += recognition(name, loader, args.quick)[0]
            write_results("tree_recognition" + suffix, rows, notes=RECOGNITION_NOTES)
    if args.only in (None, "defaults"):
        rows = []
        for name, loader in loaders.items():
            data = loader()
            splits = list(cv_for(data[1], data[4], args.quick).split(data[0], data[1], data[4]))
            rows += defaults_study(name, data, splits, args.quick)
        write_results("tree_defaults", rows, notes=DEFAULTS_NOTES)
    if args.only in (None, "encoder_speed"):
        write_results("tree_encoder_speed", encoder_speed(args.quick), notes=ENCODER_SPEED_NOTES)
    if args.only in (None, "score_layers"):
        studied = {
            name: loader
            for name, loader in loaders.items()
            if name in ("BasicMotions", "JapaneseVowels")
        }
        rows = [
            row
            for name, loader in studied.items()
            for row in score_layers_study(name, loader, args.quick)
        ]
        if rows:
            write_results("tree_score_layers", rows, notes=SCORE_LAYERS_NOTES)
    if args.only == "selection" and "JapaneseVowels" in loaders:
        write_results(
            "tree_selection",
            selection_study("JapaneseVowels", loaders["JapaneseVowels"]),
            notes=SELECTION_NOTES,
        )
    if args.only == "stacking":
        write_results("tree_stacking", stacking_study(args.quick), notes=STACKING_NOTES)
    if args.only in (None, "scaling"):
        write_results("tree_scaling", scaling(args.quick), notes=SCALING_NOTES)
    if args.only in (None, "layers"):
        tables = {
            name: tuple(loader()[i] for i in (0, 1, 2))
            for name, loader in loaders.items()
            if not name.startswith("CMU")
        }
        tables.update(cmu_layer_datasets())
        write_results("tree_layers", layer_table(tables, args.quick), notes=LAYER_NOTES)


if __name__ == "__main__":
    main()
