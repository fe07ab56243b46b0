"""Demo section: recognising motions, estimating the state and predicting it with MotionTreeHMM."""

import numpy as np

from skmotion._demo._figures import save_figure
from skmotion._demo._split import confusion_lines, evaluation_of
from skmotion.recognition import MotionClassifier
from skmotion.tree import MotionTreeHMM
from skmotion.utils import say

TITLE = "Recognition: the motion database (MotionTreeHMM)"


def _top_probability_text(proba, right):
    """``"1.00 on the 20 clips it gets right, 0.97 on the 1 it gets wrong"``."""
    top = proba.max(axis=1)
    text = f"{top[right].mean():.2f} on the {int(right.sum())} test clips it gets right"
    if (~right).any():
        text += f", {top[~right].mean():.2f} on the {int((~right).sum())} it gets wrong"
    return text


def _trust_text(proba, right):
    """What the top probabilities say about trusting an answer, from what they are here."""
    top = proba.max(axis=1)
    if right.all() or (~right).all():
        return ""
    if top[~right].mean() >= top[right].mean() - 0.05:
        return (
            ": as high when wrong as when right, so here they do not tell a right answer "
            "from a wrong one"
        )
    return ": lower when wrong, so a low top probability marks an answer to doubt"


def _beside_the_decoder(model, X_train, y_train, X_test, y_test):
    """MotionClassifier (the tree as a vocabulary into a linear model); probabilities; novelty."""
    encoder = MotionClassifier()  # the clips are markers already: channels scaled one by one
    encoder.fit(X_train, y_train)
    proba = model.predict_proba(X_test)
    right = model.classes_[proba.argmax(axis=1)] == y_test
    encoder_proba = encoder.predict_proba(X_test)
    encoder_right = encoder.classes_[encoder_proba.argmax(axis=1)] == y_test
    # Novelty as a percentile of the training clips' own scores (in-sample, so even new clips
    # of known motions tend to sit below the middle).
    reference = np.sort(model.novelty_score(X_train))
    typical = model.novelty_score(X_test)
    moved = model.novelty_score([x + model.scale_ * 10 for x in X_test])  # ten std away

    def percentile(scores):
        return 100.0 * np.searchsorted(reference, scores, side="right") / len(reference)

    return [
        f"MotionClassifier (the recommended recogniser: the tree's vocabulary into a logistic "
        f"regression) on the same split: "
        f"accuracy {encoder.score(X_test, y_test):.3f}",
        f"class probabilities: MotionTreeHMM turns its class scores into probabilities by a "
        f"softmax whose temperature ({model.temperature_:.3g}) is fitted by log loss on held-out "
        f"folds of the training clips; its top probability averages "
        f"{_top_probability_text(proba, right)}"
        + _trust_text(proba, right)
        + "; MotionClassifier's logistic regression gives "
        + _top_probability_text(encoder_proba, encoder_right),
        f"novelty (mean log density per frame under the tree's nodes), as a percentile of the "
        f"{len(reference)} training clips' scores (0: stranger than all of them): test clips "
        f"median {np.median(percentile(typical)):.0f}th percentile (lowest "
        f"{percentile(typical).min():.0f}th); the same clips moved by 10 standard deviations "
        f"{np.median(percentile(moved)):.0f}th: flag a clip below, say, the 5th percentile as "
        "unlike anything trained on",
    ]


def _decoded_path(model, clip):
    """The decoded node path of one clip, whether decode returns paths or (log prob, paths)."""
    out = model.decode([clip])
    if isinstance(out, tuple) and len(out) == 2 and not np.isscalar(out[1]):
        out = out[1]  # (log probability, paths)
    path = out[0]
    return np.asarray(path[1] if isinstance(path, tuple) else path)


def _state_lines(model, train_clips, train_names, train_ids, clip, what, frame_rate):
    """The decoded state in words: its node's classes and the nearest training clip and frame."""
    n = max(2, int(round(0.5 * frame_rate)))
    node = int(_decoded_path(model, clip[:n])[-1])
    frames = (np.vstack(train_clips) - model.center_) / model.scale_
    owner = np.repeat(np.arange(len(train_clips)), [len(c) for c in train_clips])
    offset = np.concatenate([np.arange(len(c)) for c in train_clips])
    members = np.flatnonzero(model.tree_.apply(frames, model.layer_) == node)
    query = (clip[n - 1] - model.center_) / model.scale_
    if not len(members):
        return [f"state after {n / frame_rate:.1f} s of {what}: node {node} (holds no frame)"]
    nearest = members[np.argmin(np.linalg.norm(frames[members] - query, axis=1))]
    k, f = int(owner[nearest]), int(offset[nearest])
    classes, counts = np.unique(train_names[owner[members]], return_counts=True)
    share = ", ".join(
        f"{100 * c / counts.sum():.0f}% {name}" for name, c in sorted(
            zip(classes, counts), key=lambda item: -item[1])[:3]
    )  # fmt: skip
    return [
        f"state estimation: after {n / frame_rate:.1f} s of {what}, the decoder puts the motion "
        f"in node {node} of layer {model.layer_}, whose {len(members)} training frames are "
        f"{share}; the nearest of them is frame {f} ({f / frame_rate:.2f} s) of training clip "
        f"{train_ids[k]} ({train_names[k]}, {len(train_clips[k])} frames)"
    ]


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
    ahead = model.predict_next([clip[:half_second]], n_steps=5, n_best=1)
    train_clips = [clips[i] for i in train]
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
        *_state_lines(
            model,
            train_clips,
            names[train],
            train,
            clip,
            f"test clip {test[0]} ({names[test[0]]})",
            data.frame_rate,
        ),
        f"prediction 5 frames ahead: node {int(ahead.nodes[0, 0])} with probability "
        f"{ahead.probabilities[0, 0]:.2f}",
        *_beside_the_decoder(
            model, [clips[i] for i in train], names[train], [clips[i] for i in test], names[test]
        ),
    ]
    return lines + save_figure(
        context,
        "motion_tree_layers.png",
        lambda plotting: plotting.plot_motion_tree_layers(
            model.tree_,
            model.global_graph_,
            frames=(np.vstack(train_clips) - model.center_) / model.scale_,
            labels=np.repeat(names[train], [len(c) for c in train_clips]),
        ),
        "the tree's nodes on the first principal axes, coloured by the class most of their "
        "training frames come from, with the global transition graph",
    )
