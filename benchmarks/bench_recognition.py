"""Recognition of people (or takes) never seen in training: MotionClassifier against the peers.

One run, the same splits for every model, hyperparameters chosen on the training
set only:

- ``recognition``: per development set, test accuracy, fit seconds and predict
  microseconds per clip (batched, and one clip per call) of ``MotionClassifier()``
  with its defaults, ``MotionClassifier`` with ``C`` and ``velocity_weight`` chosen by
  grouped cross-validation on the training people, ``MotionTreeHMM()`` with its
  defaults, the former recommended chain (``VirtualMarkerTransform`` ->
  ``MotionTreeEncoder()`` -> ``LogisticRegression``), hmmlearn's ``GaussianHMM`` per
  class, 1-NN Euclidean, aeon's MiniRocket and MultiRocket (and 1-NN DTW with
  ``--dtw``). Peers see what the recogniser sees before its vocabulary: body-frame,
  size-normalised marker positions (skeleton sets), resampled to 32 frames (the
  training clips' median length where shorter).
- ``recognition_defaults``: the study behind MotionClassifier's defaults: grouped
  (or stratified) 3-fold CV accuracy on the training part of every set for each
  candidate, and the candidates' mean rank.

Sets: MSRC-12 repetitions (Kinect v1 positions, odd person ids train, even test),
the synthetic motions as Kinect v2 positions and as joint angles (subject 3 held
out), CMU subject 02's windows of virtual markers, UEA BasicMotions and
JapaneseVowels (the archive's split). The real sets need ``../shared/data`` (or
``SKMOTION_SHARED_DATA``).

Run: ``python benchmarks/bench_recognition.py`` (``--quick``: no study, fewer timing
repeats; ``--only NAME ...`` for some sets; ``--dtw`` adds 1-NN DTW). Needs the ``bench``
extra (aeon, hmmlearn, tslearn).
"""

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import rankdata

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, write_results  # noqa: E402
from _common import cmu_windows as _cmu_windows  # noqa: E402
from _msrc12 import msrc12_repetitions  # noqa: E402
from sklearn.base import clone  # noqa: E402
from sklearn.linear_model import LogisticRegression  # noqa: E402
from sklearn.model_selection import GroupKFold, StratifiedKFold  # noqa: E402
from sklearn.neighbors import KNeighborsClassifier  # noqa: E402
from sklearn.pipeline import make_pipeline  # noqa: E402

from skmotion.datasets import load_uea, make_motions, make_position_motions  # noqa: E402
from skmotion.io import as_motions  # noqa: E402
from skmotion.preprocessing import FlattenClips, ResampleClips, VirtualMarkerTransform  # noqa: E402
from skmotion.recognition import MotionClassifier  # noqa: E402
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM  # noqa: E402

PEER_FRAMES = 32
STUDY = {  # candidate -> MotionClassifier parameters (the defaults are the first)
    "defaults (depth 6, residuals 1 3, means 1 2 4, covariances 0.2, column_power 0.5, C 1)": {},
    "no covariances (covariance_weight 0)": {"covariance_weight": 0.0},
    "covariance_weight 0.3": {"covariance_weight": 0.3},
    "covariance_weight 1": {"covariance_weight": 1.0},
    "standardised columns (column_power 1), C 0.1": {"column_power": 1.0, "C": 0.1},
    "columns in their units (column_power 0)": {"column_power": 0.0},
    "column_power 0.25": {"column_power": 0.25},
    "column_power 0.75": {"column_power": 0.75},
    "C 0.1": {"C": 0.1},
    "C 10": {"C": 10.0},
    "no moment pyramid (means over the whole clip)": {"moment_pyramid": (1,)},
    "means 1 2 4 8": {"moment_pyramid": (1, 2, 4, 8)},
    "depth 4": {"max_depth": 4},
    "depth 8": {"max_depth": 8},
    "velocity weight 0.5": {"velocity_weight": 0.5},
    "velocity weight 2": {"velocity_weight": 2.0},
    "per-channel standardisation": {"scaling": "channels"},
    "split two_means": {"split": "two_means"},
    "class_weight balanced": {"class_weight": "balanced"},
}
CV_GRID = [{"C": c, "column_power": p} for c in (0.3, 1.0, 3.0) for p in (0.5, 1.0)]


# -- the sets: (Xtr, ytr, Xte, yte, groups of the training clips, MotionClassifier kwargs) ------


def msrc12():
    path = SHARED_DATA / "msrc12" / "msrc12_sequences.npz"
    if not path.is_file():
        return None
    data = msrc12_repetitions(path)
    return _split(data.clips, data.gesture, data.person, data.person % 2 == 1) + (
        {"layout": "kinect_v1", "frame_rate": data.frame_rate},
    )


def synthetic_positions():
    data = make_position_motions("kinect_v2", random_state=0)
    return _split(data.clips, data.target, data.groups, data.groups != 3) + (
        {"layout": "kinect_v2", "frame_rate": data.frame_rate},
    )


def synthetic_angles():
    data = make_motions(random_state=0)
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    return _split(motions, data.target, data.groups, data.groups != 3) + ({},)


def cmu_windows():
    if not (SHARED_DATA / "cmu-asfamc").is_dir():
        return None
    return (*_cmu_windows(groups=True), {})


def uea(name):
    def load():
        if not (SHARED_DATA / "uea").is_dir():
            return None
        train = load_uea(name, subset="train", data_home=SHARED_DATA)
        test = load_uea(name, subset="test", data_home=SHARED_DATA)
        return train.clips, train.target, test.clips, test.target, None, {}

    return load


SETS = {
    "MSRC-12 (odd -> even people)": msrc12,
    "synthetic positions (subject 3)": synthetic_positions,
    "synthetic angles (subject 3)": synthetic_angles,
    "CMU 02 windows": cmu_windows,
    "BasicMotions": uea("BasicMotions"),
    "JapaneseVowels": uea("JapaneseVowels"),
}


def _split(clips, y, groups, train):
    pick = lambda mask: [c for c, m in zip(clips, mask) if m]  # noqa: E731
    return pick(train), y[train], pick(~train), y[~train], groups[train]


def folds(ytr, groups):
    if groups is not None:
        return list(GroupKFold(3).split(np.zeros(len(ytr)), ytr, groups))
    return list(StratifiedKFold(3, shuffle=True, random_state=0).split(np.zeros(len(ytr)), ytr))


# -- the peers --------------------------------------------------------------------------


class PeerInput:
    """What the peers see: body-frame marker positions of skeleton clips, resampled.

    The marker step is fitted on the training clips; positions only (no
    velocities), as a tracker's hip-centred, size-normalised joints.
    """

    def __init__(self, kwargs, n_frames):
        self.kwargs, self.n_frames = kwargs, n_frames

    def fit(self, X):
        self.markers_ = None
        if self.kwargs or hasattr(X[0], "skeleton"):
            kw = {k: v for k, v in self.kwargs.items() if k in ("layout", "skeleton")}
            self.markers_ = VirtualMarkerTransform(velocities=False, **kw).fit(X)
        self.resample_ = ResampleClips(n_frames=self.n_frames).fit(self._markers(X))
        return self

    def _markers(self, X):
        return X if self.markers_ is None else self.markers_.transform(X)

    def transform(self, X):
        return np.stack(self.resample_.transform(self._markers(X)))  # (clips, frames, channels)


class Peer:
    """A peer classifier on :class:`PeerInput`'s arrays (``layout``: 3-D time-first or flat)."""

    def __init__(self, make, kwargs, n_frames, layout):
        self.make, self.kwargs, self.n_frames, self.layout = make, kwargs, n_frames, layout

    def fit(self, X, y):
        self.input_ = PeerInput(self.kwargs, self.n_frames).fit(X)
        self.model_ = self.make().fit(self._array(X), y)
        return self

    def _array(self, X):
        array = self.input_.transform(X)
        if self.layout == "channels_first":
            return array.transpose(0, 2, 1)
        if self.layout == "flat":
            return array.reshape(len(array), -1)
        return array

    def predict(self, X):
        return self.model_.predict(self._array(X))


def minirocket():
    from aeon.classification.convolution_based import MiniRocketClassifier

    return MiniRocketClassifier(random_state=0, n_jobs=1)


def multirocket():
    from aeon.classification.convolution_based import MultiRocketClassifier

    return MultiRocketClassifier(random_state=0, n_jobs=1)


def dtw():
    from tslearn.neighbors import KNeighborsTimeSeriesClassifier

    return KNeighborsTimeSeriesClassifier(n_neighbors=1, metric="dtw")


class PerClassHMM:
    """hmmlearn GaussianHMM per class (5 states, diagonal) on standardised peer input."""

    def fit(self, X, y):
        from hmmlearn.hmm import GaussianHMM

        frames = np.vstack(X)
        self.mu_, self.sd_ = frames.mean(0), np.where(frames.std(0) > 0, frames.std(0), 1.0)
        self.classes_ = np.unique(y)
        self.models_ = []
        for c in self.classes_:
            clips = [(x - self.mu_) / self.sd_ for x, label in zip(X, y) if label == c]
            model = GaussianHMM(
                5, covariance_type="diag", n_iter=20, random_state=0, min_covar=1e-3
            )
            self.models_.append(model.fit(np.vstack(clips), [len(x) for x in clips]))
        return self

    def predict(self, X):
        scores = [[m.score((x - self.mu_) / self.sd_) for m in self.models_] for x in X]
        return self.classes_[np.argmax(scores, axis=1)]


def peer_frames(Xtr):
    lengths = [x.n_frames if hasattr(x, "n_frames") else len(x) for x in Xtr]  # Motions too
    return int(min(PEER_FRAMES, max(9, statistics.median(lengths))))  # MiniRocket needs 9


def models(kwargs, Xtr, with_dtw):
    n = peer_frames(Xtr)
    markers = {k: v for k, v in kwargs.items() if k in ("layout", "skeleton", "frame_rate")}
    vm_chain = [VirtualMarkerTransform(**markers)] if kwargs or hasattr(Xtr[0], "skeleton") else []
    out = {
        "MotionClassifier() (defaults)": MotionClassifier(**kwargs),
        "MotionClassifier (C, column_power by CV)": ("cv", MotionClassifier(**kwargs)),
        "MotionTreeHMM() (defaults)": make_pipeline(*vm_chain, MotionTreeHMM())
        if vm_chain
        else MotionTreeHMM(),
        "former: markers -> MotionTreeEncoder() -> LogisticRegression": make_pipeline(
            *vm_chain, MotionTreeEncoder(), LogisticRegression(max_iter=5000)
        ),
        "hmmlearn GaussianHMM per class": Peer(PerClassHMM, kwargs, None, "clips"),
        "1-NN Euclidean": Peer(
            lambda: make_pipeline(FlattenClips(), KNeighborsClassifier(1)), kwargs, n, "time_first"
        ),
        "MiniRocket (aeon)": Peer(minirocket, kwargs, n, "channels_first"),
        "MultiRocket (aeon)": Peer(multirocket, kwargs, n, "channels_first"),
    }
    if with_dtw:
        out["1-NN DTW (tslearn)"] = Peer(dtw, kwargs, n, "time_first")
    return out


def choose(model, Xtr, ytr, groups):
    """The CV_GRID point with the best grouped CV accuracy on the training set, refitted."""
    best = None
    for params in CV_GRID:
        accs = [
            clone(model)
            .set_params(**params)
            .fit([Xtr[i] for i in a], ytr[a])
            .score([Xtr[i] for i in b], ytr[b])
            for a, b in folds(ytr, groups)
        ]
        if best is None or np.mean(accs) > best[1]:
            best = (params, np.mean(accs))
    return clone(model).set_params(**best[0]).fit(Xtr, ytr), best[0]


def _fit(model, Xtr, ytr, groups):
    if isinstance(model, tuple):
        return choose(model[1], Xtr, ytr, groups)
    if isinstance(model, Peer) and model.layout == "clips":
        return RaggedPeer(model).fit(Xtr, ytr), ""
    return model.fit(Xtr, ytr), ""  # a refit starts afresh (fit sets every fitted attribute)


def warm_up():
    """Compile the Rockets' numba kernels before any fit is timed (a one-off cost per process)."""
    X, y = np.random.default_rng(0).normal(size=(8, 3, 16)), np.repeat([0, 1], 4)
    for make in (minirocket, multirocket):
        make().fit(X, y).predict(X)


def timed_fit(name, model, Xtr, ytr, groups):
    """The fitted model and its fit seconds: the median of three fits when one takes under
    2 s, so that a short fit is not decided by one pause of a shared machine."""
    seconds = []
    while True:
        start = time.perf_counter()
        fitted, chosen = _fit(model, Xtr, ytr, groups)
        seconds.append(time.perf_counter() - start)
        if seconds[0] >= 2.0 or len(seconds) == 3:
            return fitted, statistics.median(seconds), chosen


class RaggedPeer:
    """hmmlearn on the peers' marker input without resampling (it takes ragged clips)."""

    def __init__(self, peer):
        self.peer = peer

    def fit(self, X, y):
        self.input_ = PeerInput(self.peer.kwargs, 1).fit(X)
        self.model_ = self.peer.make().fit(self.input_._markers(X), y)
        return self

    def predict(self, X):
        return self.model_.predict(self.input_._markers(X))


def median_seconds(run, repeats):
    """The median wall time of ``repeats`` calls of ``run``, and of more (up to 7) while
    they take under a second together: one pause of a shared machine does not decide a
    sub-second figure (the small sets' batch predicts take milliseconds)."""
    seconds = []
    while len(seconds) < repeats or (sum(seconds) < 1.0 and len(seconds) < 7):
        start = time.perf_counter()
        run()
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)


def per_clip_us(model, Xte, repeats):
    """Predict microseconds per clip: batched, and one clip per call (the first 30 clips),
    each the median of runs (:func:`median_seconds`)."""
    batch = median_seconds(lambda: model.predict(Xte), repeats)
    few = Xte[: min(len(Xte), 30)]
    single = median_seconds(lambda: [model.predict([clip]) for clip in few], repeats)
    return 1e6 * batch / len(Xte), 1e6 * single / len(few)


def recognition(name, loaded, quick, with_dtw, only_models=None):
    Xtr, ytr, Xte, yte, groups, kwargs = loaded
    rows = []
    for model_name, model in models(kwargs, Xtr, with_dtw).items():
        if only_models and not any(model_name.startswith(m) for m in only_models + ["MiniRocket"]):
            continue
        model, fit_s, chosen = timed_fit(model_name, model, Xtr, ytr, groups)
        accuracy = float(np.mean(model.predict(Xte) == yte))
        batch_us, single_us = per_clip_us(model, Xte, 1 if quick else 3)
        rows.append(
            {
                "set": name,
                "model": model_name + (f" {chosen}" if chosen else ""),
                "accuracy": accuracy,
                "fit s": fit_s,
                "predict us/clip (batch)": batch_us,
                "predict us/clip (one per call)": single_us,
            }
        )
        print(rows[-1], flush=True)
    minirocket_row = next(r for r in rows if r["model"].startswith("MiniRocket"))
    for row in rows:
        row["fit / MiniRocket"] = row["fit s"] / minirocket_row["fit s"]
        row["predict / MiniRocket (batch)"] = (
            row["predict us/clip (batch)"] / minirocket_row["predict us/clip (batch)"]
        )
    return rows


def defaults_study(name, loaded, candidates=None):
    Xtr, ytr, _, _, groups, kwargs = loaded
    row = {"set": name}
    for candidate, params in STUDY.items():
        if candidates and candidate != next(iter(STUDY)) and candidate not in candidates:
            continue
        if "scaling" in params and not kwargs and not hasattr(Xtr[0], "skeleton"):
            row[candidate] = float("nan")  # no marker blocks: the same as the defaults
            continue
        if "velocity_weight" in params and not kwargs and not hasattr(Xtr[0], "skeleton"):
            row[candidate] = float("nan")
            continue
        model = MotionClassifier(**kwargs, **params)
        row[candidate] = float(
            np.mean(
                [
                    clone(model).fit([Xtr[i] for i in a], ytr[a]).score([Xtr[i] for i in b], ytr[b])
                    for a, b in folds(ytr, groups)
                ]
            )
        )
        print(name, candidate, round(row[candidate], 4), flush=True)
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only", nargs="+", help="sets' names (or their first words)")
    parser.add_argument("--dtw", action="store_true", help="add 1-NN DTW (slow on MSRC-12)")
    parser.add_argument("--study-only", action="store_true")
    parser.add_argument(
        "--models", nargs="+", help="run only models whose names start so (and MiniRocket)"
    )
    parser.add_argument(
        "--candidates", nargs="+", help="study only these candidates (and the defaults)"
    )
    args = parser.parse_args()
    rows, study = [], []
    if not args.study_only:
        warm_up()
    for name, loader in SETS.items():
        if args.only and not any(name.lower().startswith(o.lower()) for o in args.only):
            continue
        loaded = loader()
        if loaded is None:
            print(f"{name}: data not found under {SHARED_DATA}; left out")
            continue
        if not args.study_only:
            rows += recognition(name, loaded, args.quick, args.dtw, args.models)
        if not args.quick:
            study.append(defaults_study(name, loaded, args.candidates))
    notes = (
        "Peers on body-frame, size-normalised marker positions resampled to "
        f"min({PEER_FRAMES}, median training length) frames; MotionClassifier on the clips as "
        "they are. Fit seconds include the CV search where a model chooses by CV; a fit under 2 s "
        "is the median of three; the Rockets' numba kernels are compiled before any timing."
    )
    if rows:
        write_results("recognition" + ("_models" if args.models else ""), rows, notes=notes)
    if study:
        # rank 1 is the best CV accuracy of a set; a candidate that does not apply ranks with the
        # defaults (it is the same model there)
        names = [c for c in STUDY if c in study[0]]  # --candidates: the ones studied
        defaults = next(iter(STUDY))
        ranks = [
            rankdata([-(row[c] if np.isfinite(row[c]) else row[defaults]) for c in names])
            for row in study
        ]
        study.append({"set": "mean rank (1 best)", **dict(zip(names, np.mean(ranks, axis=0)))})
        results = "recognition_defaults" + ("_candidates" if args.candidates else "")
        write_results(results, study, notes="3-fold CV on the training part only.")


if __name__ == "__main__":
    main()
