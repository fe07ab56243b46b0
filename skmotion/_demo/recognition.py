"""Demo section: recognising motions, estimating the state and predicting it with MotionTreeHMM."""

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline

from skmotion._demo._figures import save_figure
from skmotion._demo._split import confusion_lines, evaluation_of
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM
from skmotion.utils import say

TITLE = "Recognition: the motion database (MotionTreeHMM)"


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
    if clips is None:
        return ["not run: the clips have no virtual markers (the markers section says why)"]
    names = np.asarray(data.target_names)[data.target]
    evaluation = evaluation_of(context)
    if evaluation.kind is None:
        return [f"not run: {evaluation.reason}"]
    train, test, held_out = evaluation.holdout(names)
    say(getattr(context, "verbose", 0), f"demo: fitting MotionTreeHMM on {len(train)} clips ...")
    model = MotionTreeHMM().fit([clips[i] for i in train], names[train])
    context.motion_tree = model
    predicted = model.predict([clips[i] for i in test])
    accuracy = float(np.mean(predicted == names[test]))
    tree = model.tree_
    clip = clips[test[0]]
    half_second = max(2, int(round(0.5 * data.frame_rate)))
    states = model.decode([clip[:half_second]])[1][0]
    ahead = model.predict_next([clip[:half_second]], n_steps=5, n_best=1)
    n_markers = clip.shape[1] // 6
    lines = [
        f"MotionTreeHMM (defaults: {model.split} splits, max_depth={model.max_depth}, "
        f"min_samples_leaf={model.min_samples_leaf}) on {n_markers} virtual markers "
        f"({clip.shape[1]} channels)",
        f"trained on {len(train)} clips, tested on {held_out} ({len(test)} clips): "
        f"accuracy {accuracy:.3f}",
        *confusion_lines(names[test], predicted),
        f"tree: {int(tree.count[0]):,} frames, {tree.n_layers} layers, {tree.n_tree_nodes} nodes, "
        f"{int(tree.n_nodes[-1])} in the bottom layer",
        "nodes per layer: " + " ".join(str(int(n)) for n in tree.n_nodes),
        f"state estimation, first {half_second} frames of a test {names[test[0]]}: "
        "bottom-layer nodes " + " ".join(str(int(n)) for n in states[-6:]) + " (last six)",
        f"prediction 5 frames ahead: node {int(ahead.nodes[0, 0])} with probability "
        f"{ahead.probabilities[0, 0]:.2f}",
        *_beside_the_decoder(
            model, [clips[i] for i in train], names[train], [clips[i] for i in test], names[test]
        ),
    ]
    return lines + save_figure(
        context,
        "motion_tree_layers.png",
        lambda plotting: plotting.plot_motion_tree_layers(model.tree_, model.global_graph_),
        "nodes on the first principal axes with the global transition graph",
    )
