"""What the recogniser's vocabulary gains from each candidate addition, on MSRC-12.

Issue 26 asked for a study of ways to capture the motion beyond the poses: a
frame's change over +-k frames (local motion), trees per body part, a second
tree on local motion, mirror augmentation (left <-> right), random crops of the
training clips, transitions between nodes, finer temporal pyramids, a larger
velocity weight, and a second model on the resampled trajectory fused with the
first. Each variant is MotionClassifier's chain (markers, block scaling, the
tree vocabulary, standardised columns, a logistic regression, C 0.1) with one
thing changed, scored two ways:

- ``cv``: 3-fold cross-validation grouped by person over the training people
  only (odd person ids), the number a choice is made by;
- ``test``: trained on all odd people, scored on the even people (reported,
  never used to choose).

Fused variants multiply the two models' probabilities. MiniRocket (aeon) on the
same markers' positions resampled to 32 frames is the reference row.

Usage::

    python benchmarks/study_recognition_vocabulary.py [--only NAME ...]

Writes ``results/recognition_vocabulary.{csv,md}`` and, with matplotlib, the figure
``docs/images/recognition_vocabulary.png``. Needs ``../shared/data/msrc12``.
"""

import argparse
import csv
import time
from pathlib import Path

import numpy as np
from _common import RESULTS, SHARED_DATA, write_results
from _msrc12 import msrc12_repetitions
from scipy.interpolate import interp1d
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold
from sklearn.preprocessing import StandardScaler

from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.recognition._motion_classifier import block_scales
from skmotion.tree import MotionTreeEncoder

ENCODER = dict(
    max_depth=6,
    layers="all",
    residual_layers=(1, 3),
    moment_pyramid=(1, 2, 4),
    standardize=False,
    sparse_output=False,
)
PARTS = {
    "left arm": ("left_shoulder", "left_elbow", "left_wrist", "left_hand"),
    "right arm": ("right_shoulder", "right_elbow", "right_wrist", "right_hand"),
    "legs": ("left_hip", "left_knee", "left_ankle", "left_toe")
    + ("right_hip", "right_knee", "right_ankle", "right_toe"),
    "torso": ("head", "chest", "spine", "pelvis"),
}


class Markers:
    """The MSRC-12 repetitions as body-frame markers, with the channel roles the variants need."""

    def __init__(self):
        data = msrc12_repetitions(SHARED_DATA / "msrc12" / "msrc12_sequences.npz")
        step = VirtualMarkerTransform(layout="kinect_v1", frame_rate=15)
        self.clips = step.fit_transform(data.clips)
        self.y, self.person = np.asarray(data.gesture), np.asarray(data.person)
        names = [str(n) for n in step.get_feature_names_out()]
        self.velocity = np.array([n.rsplit("_", 1)[-1].startswith("v") for n in names])
        self.marker = np.array([n.rsplit("_", 1)[0] for n in names])
        swap = {"left_": "right_", "right_": "left_"}
        mirrored = [
            next((n.replace(a, b, 1) for a, b in swap.items() if n.startswith(a)), n) for n in names
        ]
        self.mirror_columns = np.array([names.index(n) for n in mirrored])
        self.mirror_sign = np.array([-1.0 if n.endswith(("_py", "_vy")) else 1.0 for n in names])

    def mirror(self, clip):
        """Left and right swapped: the subject's left axis (body-frame y) negated."""
        return clip[:, self.mirror_columns] * self.mirror_sign

    def local_motion(self, clip, k):
        """Each marker position's change from frame t - k to t + k (ends clamped)."""
        index = np.arange(len(clip))
        positions = clip[:, ~self.velocity]
        later = positions[np.minimum(index + k, len(clip) - 1)]
        return later - positions[np.maximum(index - k, 0)]


def block_scaled(train, other, blocks, weights):
    frames = np.vstack(train)
    center = frames.mean(axis=0)
    scale = block_scales(frames, blocks, weights)
    return [(c - center) / scale for c in train], [(c - center) / scale for c in other]


def encode(train, other, **changes):
    encoder = MotionTreeEncoder(**{**ENCODER, **changes}).fit(train)
    return encoder.transform(train), encoder.transform(other)


def probabilities(train_features, y, other_features):
    scaler = StandardScaler().fit(train_features)
    model = LogisticRegression(C=0.1, max_iter=1000).fit(scaler.transform(train_features), y)
    return model.predict_proba(scaler.transform(other_features))


def resampled(clips, n_frames):
    out = []
    for clip in clips:
        t = np.linspace(0.0, 1.0, len(clip))
        out.append(interp1d(t, clip, axis=0)(np.linspace(0.0, 1.0, n_frames)).ravel())
    return np.array(out)


def variants(data):
    """name -> function(train clips, train labels, other clips) -> class probabilities."""
    blocks = data.velocity.astype(int)

    def chain_once(**kwargs):
        def run(train, y, other):
            augment = kwargs.get("augment")
            if augment is not None:
                train = train + [augment(c) for c in train]
                y = np.concatenate([y, y])
            a, b = block_scaled(train, other, blocks, kwargs.get("weights", (1.0, 1.0)))
            fa, fb = encode(a, b, **kwargs.get("changes", {}))
            return probabilities(fa, y, fb)

        return run

    def parts(train, y, other):
        a, b = block_scaled(train, other, blocks, (1.0, 1.0))
        fa, fb = [], []
        for columns in [slice(None)] + [np.isin(data.marker, m) for m in PARTS.values()]:
            sa, sb = encode([c[:, columns] for c in a], [c[:, columns] for c in b])
            fa.append(sa)
            fb.append(sb)
        return probabilities(np.hstack(fa), y, np.hstack(fb))

    def local_motion_tree(train, y, other):
        motion = [data.local_motion(c, 3) for c in train]
        one_block = np.zeros(motion[0].shape[1], dtype=int)
        a, b = block_scaled(motion, [data.local_motion(c, 3) for c in other], one_block, (1.0,))
        fa, fb = encode(a, b)
        return probabilities(fa, y, fb)

    def trajectory(train, y, other):
        a, b = block_scaled(train, other, blocks, (1.0, 1.0))
        return probabilities(resampled(a, 16), y, resampled(b, 16))

    def local_motion_appended(train, y, other):
        extend = lambda c: np.hstack([c, data.local_motion(c, 3)])  # noqa: E731
        train, other = [extend(c) for c in train], [extend(c) for c in other]
        width = train[0].shape[1] - len(blocks)
        run_blocks = np.concatenate([blocks, np.full(width, 2)])
        a, b = block_scaled(train, other, run_blocks, (1.0, 1.0, 1.0))
        fa, fb = encode(a, b)
        return probabilities(fa, y, fb)

    rng = np.random.default_rng(0)

    def crop(clip, keep=0.85):
        length = max(4, int(round(len(clip) * keep)))
        start = rng.integers(0, len(clip) - length + 1)
        return clip[start : start + length]

    base = chain_once()
    return {
        "MotionClassifier chain (baseline)": base,
        "velocity weight 2": chain_once(weights=(1.0, 2.0)),
        "local motion (+-3 frames) appended to the frames": local_motion_appended,
        "body-part trees (arms, legs, torso) beside the whole body": parts,
        "mirror augmentation (left <-> right copies)": chain_once(augment=data.mirror),
        "random crops (85 %) of the training clips": chain_once(augment=crop),
        "transitions of layer 3": chain_once(changes=dict(transition_layers=(3,))),
        "occupancy pyramid (1, 2, 4)": chain_once(changes=dict(pyramid=(1, 2, 4))),
        "moment pyramid (1, 2, 4, 8)": chain_once(changes=dict(moment_pyramid=(1, 2, 4, 8))),
        "fused: baseline x local-motion tree": ("fuse", base, local_motion_tree),
        "fused: baseline x resampled trajectory (16 frames)": ("fuse", base, trajectory),
    }


def minirocket(train, y, other, data):
    from aeon.classification.convolution_based import MiniRocketClassifier

    def series(clips):
        return np.array([resampled([c[:, ~data.velocity]], 32)[0].reshape(32, -1).T for c in clips])

    return MiniRocketClassifier(random_state=0).fit(series(train), y).predict_proba(series(other))


def score(run, data):
    """Grouped 3-fold CV over the odd people, then odd -> even."""
    odd = np.flatnonzero(data.person % 2 == 1)
    even = np.flatnonzero(data.person % 2 == 0)
    classes = np.unique(data.y)

    def accuracy(train, test):
        clips = lambda idx: [data.clips[i] for i in idx]  # noqa: E731
        if isinstance(run, tuple):
            _, first, second = run
            proba = np.log(first(clips(train), data.y[train], clips(test)) + 1e-12)
            proba = proba + np.log(second(clips(train), data.y[train], clips(test)) + 1e-12)
        else:
            proba = run(clips(train), data.y[train], clips(test))
        return float(np.mean(classes[proba.argmax(axis=1)] == data.y[test]))

    start = time.perf_counter()
    folds = GroupKFold(3).split(odd, data.y[odd], data.person[odd])
    cv = np.mean([accuracy(odd[a], odd[b]) for a, b in folds])
    test = accuracy(odd, even)
    return round(float(cv), 4), round(test, 4), round(time.perf_counter() - start, 1)


def draw(rows, path):
    """CV and test accuracy of each variant, the baseline's CV as a line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [row["variant"] for row in rows][::-1]
    cv = np.array([row["cv (odd people)"] for row in rows][::-1])
    test = np.array([row["test (even people)"] for row in rows][::-1])
    y = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(9, 0.42 * len(names) + 1.8))
    ax.barh(y + 0.2, cv, height=0.4, label="grouped CV, training people (choices by this)")
    ax.barh(y - 0.2, test, height=0.4, label="test people (reported only)", alpha=0.6)
    baseline = next(row for row in rows if "baseline" in row["variant"])
    ax.axvline(baseline["cv (odd people)"], color="k", lw=0.8, ls="--", label="baseline's CV")
    ax.set_yticks(y, names, fontsize=8)
    ax.set_xlim(min(cv.min(), test.min()) - 0.01, max(cv.max(), test.max()) + 0.005)
    ax.set_xlabel("accuracy on MSRC-12 repetitions")
    ax.set_title("MSRC-12: one change each to MotionClassifier's chain", fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="variants whose name contains one of these")
    parser.add_argument("--redraw", action="store_true", help="the figure from the last results")
    args = parser.parse_args()
    if args.redraw:
        with open(RESULTS / "recognition_vocabulary.csv") as fh:
            rows = [
                {k: (v if k == "variant" else float(v)) for k, v in r.items()}
                for r in csv.DictReader(fh)
            ]
        return draw_figure(rows)
    data = Markers()
    runs = variants(data)
    runs["MiniRocket (aeon), reference"] = lambda a, y, b: minirocket(a, y, b, data)
    rows = []
    for name, run in runs.items():
        if args.only and not any(word in name for word in args.only):
            continue
        cv, test, seconds = score(run, data)
        row = {"variant": name, "cv (odd people)": cv, "test (even people)": test, "s": seconds}
        rows.append(row)
        print(rows[-1], flush=True)
    write_results(
        "recognition_vocabulary",
        rows,
        notes="MSRC-12 repetitions. cv: 3-fold grouped CV over the odd people (choices are made "
        "by it); test: odd -> even people (reported only).",
    )
    draw_figure(rows)


def draw_figure(rows):
    figure = Path(__file__).resolve().parents[1] / "docs" / "images" / "recognition_vocabulary.png"
    try:
        draw(rows, figure)
    except ImportError:
        print("matplotlib is not installed: no figure")
        return
    print(f"figure: {figure}")


if __name__ == "__main__":
    main()
