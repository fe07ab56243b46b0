"""Peers and measures of bench_tree.py's recognition tables: MiniRocket, calibration, defaults."""

import numpy as np
from _tree_readouts import TreeReadout  # benchmarks/ is on the path
from sklearn.linear_model import LogisticRegression, RidgeClassifierCV
from sklearn.metrics import log_loss
from sklearn.model_selection import cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from skmotion.preprocessing import ResampleClips
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM

ENCODER_GRID = {
    "motiontreeencoder__layers": [(), "all"],
    "motiontreeencoder__residual_layers": [(1, 3), (0, 1, 2, 3), (2, 4)],
    "motiontreeencoder__moments": [2, 1, 0],
    "logisticregression__C": [1.0, 10.0],
}
QUICK_ENCODER_GRID = {
    "motiontreeencoder__residual_layers": [(1, 3), (0, 1, 2, 3)],
    "motiontreeencoder__moments": [2, 0],
    "logisticregression__C": [1.0, 10.0],
}


def encoder_pipeline(**params):
    """The recommended recogniser: the tree's histograms and residuals, a logistic regression.

    For the defaults study, ``readout`` swaps the encoder for a candidate
    :class:`TreeReadout` and ``classifier="ridge"`` the logistic regression for
    MiniRocket's classifier (standardised columns, ``RidgeClassifierCV``).
    """
    params = dict(params)
    C = params.pop("C", 1.0)
    classifier = LogisticRegression(C=C, max_iter=5000)
    if params.pop("classifier", None) == "ridge":
        classifier = make_pipeline(StandardScaler(), RidgeClassifierCV(np.logspace(-3, 3, 10)))
    encoder = TreeReadout(**params) if "readout" in params else MotionTreeEncoder(**params)
    return make_pipeline(encoder, classifier)


class MiniRocket:
    """aeon's MiniRocketClassifier on clips resampled to the training set's median length.

    MiniRocket needs equal lengths; its ridge classifier picks its regularisation
    by leave-one-out CV on the training set (RidgeClassifierCV), its kernels are
    the defaults (10,000).
    """

    def fit(self, X, y):
        from aeon.classification.convolution_based import MiniRocketClassifier

        length = max(9, int(np.median([len(x) for x in X])))  # MiniRocket needs 9 points
        self.resample_ = ResampleClips(n_frames=length).fit(X)
        self.model_ = MiniRocketClassifier(random_state=0, n_jobs=1).fit(self._array(X), y)
        self.classes_ = self.model_.classes_
        return self

    def _array(self, X):
        return np.stack(self.resample_.transform(X)).transpose(0, 2, 1)  # channels first

    def predict(self, X):
        return self.model_.predict(self._array(X))

    def predict_proba(self, X):
        return self.model_.predict_proba(self._array(X))


def softmax_scores(scores):
    scores = scores - scores.max(axis=1, keepdims=True)
    p = np.exp(scores)
    return p / p.sum(axis=1, keepdims=True)


def expected_calibration_error(y, proba, classes, n_bins=10):
    """Top-label ECE: |accuracy - confidence| over 10 bins of the top probability, weighted."""
    confidence = proba.max(axis=1)
    correct = classes[proba.argmax(axis=1)] == y
    bins = np.minimum((confidence * n_bins).astype(int), n_bins - 1)
    ece = 0.0
    for b in range(n_bins):
        inside = bins == b
        if inside.any():
            ece += inside.mean() * abs(correct[inside].mean() - confidence[inside].mean())
    return float(ece)


def probability_scores(y, proba, classes):
    """Log loss (probabilities clipped at 1e-15, as sklearn does) and ECE of class probabilities."""
    proba = np.clip(proba, 1e-15, 1.0)
    proba = proba / proba.sum(axis=1, keepdims=True)
    return float(log_loss(y, proba, labels=classes)), expected_calibration_error(y, proba, classes)


# -- the defaults study -----------------------------------------------------------------

HMM_CANDIDATES = {
    "min_error, depth 10, leaf 16, score_layers=1 (former defaults)": dict(
        split="min_error", max_depth=10, score_layers=1, min_samples_leaf=16
    ),
    "median, depth 8, leaf 16, all layers": dict(
        split="median", max_depth=8, score_layers="all", min_samples_leaf=16
    ),
    "median, depth 8, leaf 4, all layers": dict(
        split="median", max_depth=8, score_layers="all", min_samples_leaf=4
    ),
    "median, depth 6, leaf 16, all layers": dict(
        split="median", max_depth=6, score_layers="all", min_samples_leaf=16
    ),
    "two_means, depth 8, leaf 4, all layers (defaults)": dict(
        split="two_means", max_depth=8, score_layers="all", min_samples_leaf=4
    ),
    "two_means, depth 8, leaf 4, 3 layers": dict(
        split="two_means", max_depth=8, score_layers=3, min_samples_leaf=4
    ),
}
# "moments" is 2 by default: the candidates without it say moments=0.
ENCODER_CANDIDATES = {
    "occupancy, depth 8, pyramid 1-2-3": dict(layers="all", residual_layers=(), moments=0),
    "occupancy, depth 8, pyramid 1": dict(
        layers="all", pyramid=(1,), residual_layers=(), moments=0
    ),
    "occupancy, depth 8, graph-smoothed (a = 0.5)": dict(readout="graph"),
    "occupancy depth 8, pyramid 1-2-3 + residuals 1, 3": dict(layers="all", moments=0),
    "occupancy depth 8, pyramid 1 + residuals 1, 3": dict(layers="all", pyramid=(1,), moments=0),
    "residuals of layers 1, 3 (former defaults)": dict(moments=0),
    "residuals of layers 0-3": dict(residual_layers=(0, 1, 2, 3), moments=0),
    "residuals of layers 2, 4": dict(residual_layers=(2, 4), moments=0),
    "residuals 1, 3, soft assignment (T = 1)": dict(readout="soft"),
    "residuals 1, 3 + second order (Fisher)": dict(readout="fisher"),
    "residuals 1, 3, pyramid 1-2-3": dict(readout="pyramid"),
    "residuals 1, 3, 5 trees (bootstrap)": dict(readout="ensemble"),
    "moments 1, 2 alone": dict(residual_layers=(), moments=2),
    "residuals 1, 3 + moment 1": dict(moments=1),
    "residuals 1, 3 + mean, mean square": dict(readout="meansquare"),
    "residuals 1, 3 + mean, root mean square (defaults)": dict(),
    "defaults, soft assignment (T = 1)": dict(readout="soft", moments=2),
    "defaults + second order (Fisher)": dict(residual_order=2),
    "defaults, 5 trees (bootstrap)": dict(readout="ensemble", moments=2),
    "defaults, LogisticRegression(C=10)": dict(C=10.0),
    "defaults, StandardScaler + RidgeClassifierCV": dict(classifier="ridge"),
}


def defaults_study(name, data, splits, quick):
    """Test and CV accuracy of each candidate default (MotionTreeHMM: no CV in a quick run)."""
    Xtr, ytr, Xte, yte, _ = data
    rows = []
    candidates = [("MotionTreeHMM", k, v) for k, v in HMM_CANDIDATES.items()]
    candidates += [
        ("MotionTreeEncoder + LogisticRegression", k, v) for k, v in ENCODER_CANDIDATES.items()
    ]
    for model_name, label, params in candidates:
        if model_name == "MotionTreeHMM":
            model = MotionTreeHMM(calibration_cv=None, **params)
        else:
            model = encoder_pipeline(**params)
        skip_cv = quick and model_name == "MotionTreeHMM"
        cv = "" if skip_cv else float(cross_val_score(model, Xtr, ytr, cv=splits, n_jobs=2).mean())
        rows.append(
            {
                "dataset": name,
                "model": model_name,
                "candidate": label,
                "CV accuracy (train)": cv,
                "test accuracy": float(model.fit(Xtr, ytr).score(Xte, yte)),
            }
        )
        print(rows[-1], flush=True)
    return rows
