"""Demo section: recognising motions, estimating the state and predicting it with MotionTreeHMM."""

from pathlib import Path

import numpy as np

from skmotion.tree import MotionTreeHMM

TITLE = "Recognition: the motion database (MotionTreeHMM)"


def _confusion(names, truth, predicted):
    width = max(len(n) for n in names)
    lines = ["confusion (rows: true, columns: predicted):", " " * (width + 2) + " ".join(n[:5].rjust(5) for n in names)]
    for name in names:
        row = [int(np.sum((truth == name) & (predicted == other))) for other in names]
        lines.append(f"  {name.rjust(width)} " + " ".join(str(v).rjust(5) for v in row))
    return lines


def _plots(model, plot_dir):
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError:
        return ['plots: matplotlib is not installed (pip install "skmotion[plot]")']
    from skmotion.plotting import plot_motion_tree_layers

    path = Path(plot_dir) / "motion_tree_layers.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plot_motion_tree_layers(model.tree_, model.global_graph_)
    fig.savefig(path, dpi=100)
    return [f"plot: nodes on the first principal axes with the global transition graph -> {path}"]


def run(context):
    data = context.data
    # The root's travel and heading say where a subject walked, not how it moved.
    clips = [c[:, 6:] for c in data.clips]
    names = data.target_names[data.target]
    held_out = data.groups.max()
    train = np.flatnonzero(data.groups != held_out)
    test = np.flatnonzero(data.groups == held_out)
    model = MotionTreeHMM().fit([clips[i] for i in train], names[train])
    context.motion_tree = model
    predicted = model.predict([clips[i] for i in test])
    accuracy = float(np.mean(predicted == names[test]))
    tree = model.tree_
    clip = clips[test[0]]
    half_second = max(2, int(round(0.5 * data.frame_rate)))
    states = model.decode([clip[:half_second]])[0]
    ahead = model.predict_next([clip[:half_second]], n_steps=5, n_best=1)
    lines = [
        f"MotionTreeHMM (defaults: minimum-error splits, max_depth={model.max_depth}, "
        f"min_samples_leaf={model.min_samples_leaf}) on the 60 joint angles without the root",
        f"trained on subjects {sorted(set(data.groups[train].tolist()))} ({len(train)} clips), "
        f"tested on subject {held_out} ({len(test)} clips): accuracy {accuracy:.3f}",
        *_confusion(list(model.classes_), names[test], predicted),
        f"tree: {int(tree.count[0]):,} frames, {tree.n_layers} layers, {tree.n_tree_nodes} nodes, "
        f"{int(tree.n_nodes[-1])} in the bottom layer",
        "nodes per layer: " + " ".join(str(int(n)) for n in tree.n_nodes),
        f"state estimation, first {half_second} frames of a test {names[test[0]]}: bottom-layer nodes "
        + " ".join(str(int(n)) for n in states[-6:]) + " (last six)",
        f"prediction 5 frames ahead: node {int(ahead.nodes[0, 0])} with probability {ahead.probabilities[0, 0]:.2f}",
    ]
    plot_dir = getattr(context, "plot_dir", None)
    if plot_dir:
        lines += _plots(model, plot_dir)
    else:
        lines.append("(skmotion demo --plots DIR draws the tree's nodes and transition graphs, as the paper's Figures 3-5)")
    return lines
