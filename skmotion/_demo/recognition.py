"""Demo section: recognising motions, estimating the state and predicting it with MotionTreeHMM."""

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline

from skmotion._demo._figures import save_figure
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM

TITLE = "Recognition: the motion database (MotionTreeHMM)"


def _confusion(names, truth, predicted):
    width = max(len(n) for n in names)
    lines = [
        "confusion (rows: true, columns: predicted):",
        " " * (width + 2) + " ".join(n[:5].rjust(5) for n in names),
    ]
    for name in names:
        row = [int(np.sum((truth == name) & (predicted == other))) for other in names]
        lines.append(f"  {name.rjust(width)} " + " ".join(str(v).rjust(5) for v in row))
    return lines


def _split(data, names):
    """Train and test clips: the last subject held out, or every third clip of each class."""
    groups = np.asarray(data.groups)
    if len(np.unique(groups)) >= 2:
        held_out = groups.max()
        name = data.get("subject_names")
        label = f"subject {name[held_out] if name is not None else held_out}"
        return np.flatnonzero(groups != held_out), np.flatnonzero(groups == held_out), label
    rank = np.zeros(len(names), dtype=int)
    for value in np.unique(names):
        members = np.flatnonzero(names == value)
        rank[members] = np.arange(len(members))
    test = rank % 3 == 2
    return np.flatnonzero(~test), np.flatnonzero(test), "every third clip of each class"


def _beside_the_decoder(model, X_train, y_train, X_test, y_test):
    """The tree as a vocabulary (MotionTreeEncoder) into a linear model; probabilities; novelty."""
    encoder = make_pipeline(MotionTreeEncoder(), LogisticRegression(max_iter=5000))
    encoder.fit(X_train, y_train)
    proba = model.predict_proba(X_test)
    right = model.classes_[proba.argmax(axis=1)] == y_test
    typical = model.novelty_score(X_test)
    scale = model.scale_ * 10  # every channel moved by ten standard deviations
    moved = model.novelty_score([x + scale for x in X_test])
    lines = [
        f"MotionTreeEncoder + LogisticRegression (the recommended recogniser) on the same split: "
        f"accuracy {encoder.score(X_test, y_test):.3f}",
        f"MotionTreeHMM probabilities (temperature {model.temperature_:.3g}): mean top probability "
        f"{proba.max(axis=1)[right].mean():.2f} when right"
        + (f", {proba.max(axis=1)[~right].mean():.2f} when wrong" if (~right).any() else ""),
        f"novelty score (mean log density per frame): test clips {np.median(typical):.1f}, "
        f"the same moved 10 standard deviations {np.median(moved):.1f} "
        "(lower: unlike the training data)",
    ]
    return lines


def run(context):
    data = context.data
    # Virtual markers (left by the markers section): every skeleton in one feature space, and the
    # root's travel and heading removed, which say where a subject walked, not how it moved.
    clips = context.marker_clips
    names = np.asarray(data.target_names)[data.target]
    train, test, held_out = _split(data, names)
    if len(np.unique(names[train])) < 2 or len(test) == 0:
        return [
            f"{len(clips)} clips in {len(np.unique(names))} classes: "
            "too few to train and test a classifier"
        ]
    model = MotionTreeHMM().fit([clips[i] for i in train], names[train])
    context.motion_tree = model
    predicted = model.predict([clips[i] for i in test])
    accuracy = float(np.mean(predicted == names[test]))
    tree = model.tree_
    clip = clips[test[0]]
    half_second = max(2, int(round(0.5 * data.frame_rate)))
    states = model.decode([clip[:half_second]])[0]
    ahead = model.predict_next([clip[:half_second]], n_steps=5, n_best=1)
    n_markers = clip.shape[1] // 6
    lines = [
        f"MotionTreeHMM (defaults: {model.split} splits, max_depth={model.max_depth}, "
        f"min_samples_leaf={model.min_samples_leaf}) on {n_markers} virtual markers "
        f"({clip.shape[1]} channels)",
        f"trained on {len(train)} clips, tested on {held_out} ({len(test)} clips): "
        f"accuracy {accuracy:.3f}",
        *_confusion(
            [str(c) for c in model.classes_], names[test].astype(str), predicted.astype(str)
        ),
        f"tree: {int(tree.count[0]):,} frames, {tree.n_layers} layers, {tree.n_tree_nodes} nodes, "
        f"{int(tree.n_nodes[-1])} in the bottom layer",
        "nodes per layer: " + " ".join(str(int(n)) for n in tree.n_nodes),
        f"state estimation, first {half_second} frames of a test {names[test[0]]}: "
        "bottom-layer nodes " + " ".join(str(int(n)) for n in states[-6:]) + " (last six)",
        f"prediction 5 frames ahead: node {int(ahead.nodes[0, 0])} "
        f"with probability {ahead.probabilities[0, 0]:.2f}",
        *_beside_the_decoder(
            model, [clips[i] for i in train], names[train], [clips[i] for i in test], names[test]
        ),
    ]
    plot_dir = getattr(context, "plot_dir", None)
    if plot_dir:
        lines += save_figure(
            plot_dir,
            "motion_tree_layers.png",
            lambda plotting: plotting.plot_motion_tree_layers(model.tree_, model.global_graph_),
            "nodes on the first principal axes with the global transition graph",
        )
    else:
        lines.append(
            "(skmotion demo --plots DIR draws the tree's nodes and transition graphs, "
            "as the paper's Figures 3-5)"
        )
    return lines
