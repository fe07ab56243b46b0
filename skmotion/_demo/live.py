"""Demo section: a database that grows live, a stream decoded frame by frame, a sampled clip."""

import tempfile
from pathlib import Path

import numpy as np

from skmotion._demo._figures import save_figure
from skmotion.datasets import make_motions, make_walks
from skmotion.io import as_motions, write_bvh
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM

TITLE = "A live database: clips added one by one, a stream, a sampled motion"

_CLASSES = ["walk", "jog", "jump", "kick", "squat"]
_WINDOW = 30  # frames (1 s): the stream's class posterior follows a change of motion


def _grow(data, clips, names, train, lines):
    """Start with walk and jog, add clips one at a time, then a new class; report test accuracy."""
    test = np.flatnonzero(~train)
    X_test, y_test = [clips[i] for i in test], names[test]
    order = np.flatnonzero(train)
    first = [int(order[names[order] == c][0]) for c in ("walk", "jog")]
    model = MotionTreeHMM(max_depth=8).partial_fit([clips[i] for i in first], names[first])
    known = set(names[first])
    for i in order:
        if i in first:
            continue
        model.partial_fit([clips[i]], names[i : i + 1])
        if names[i] not in known:
            known.add(names[i])
            lines.append(
                f"  clip {i} brings the new class '{names[i]}': {len(model.classes_)} classes, "
                f"{model.tree_.n_tree_nodes} tree nodes"
            )
    rebuilt = MotionTreeHMM(max_depth=8).fit([clips[i] for i in order], names[order])
    lines.append(
        f"grown clip by clip from {len(first)} clips to {len(order)}: test accuracy "
        f"{model.score(X_test, y_test):.3f} (subject 3 held out); rebuilt from all clips: "
        f"{rebuilt.score(X_test, y_test):.3f}"
    )
    return model, X_test, y_test


def _stream(model, X_test, y_test, lines):
    """Two test clips back to back, decoded frame by frame; the posterior over time."""
    a = int(np.flatnonzero(y_test == "walk")[0])
    b = int(np.flatnonzero(y_test == "jump")[0])
    clip = np.concatenate([X_test[a], X_test[b]])
    switch = len(X_test[a])
    stream = model.stream(mode="exact", window=_WINDOW, lag=5)
    states = [stream.update(frame) for frame in clip]
    proba = np.array([s.proba for s in states])
    labels = np.array([s.label for s in states])
    right = np.where(np.arange(len(clip)) < switch, "walk", "jump")
    settled = np.flatnonzero(labels[switch:] != "jump")
    after = 0 if not len(settled) else int(settled[-1]) + 1
    lines.append(
        f"stream of a walk then a jump ({len(clip)} frames, {_WINDOW}-frame window): decision "
        f"right at {np.mean(labels == right):.0%} of frames; 'jump' for good {after} frames "
        "after the switch"
    )
    whole = model.stream(mode="exact")
    for start in range(0, len(X_test[b]), 7):  # chunks of 7 frames
        last = whole.update(X_test[b][start : start + 7])
    same = bool((whole.path() == model.decode([X_test[b]])[1][0]).all())
    lines.append(
        f"the jump alone, in chunks of 7 frames: final decision '{last.label}' "
        f"(batch predict: '{model.predict([X_test[b]])[0]}'), node path equal to the batch "
        f"decode: {same}"
    )
    return proba, switch


def _draw_posterior(model, proba, switch, frame_rate):
    def draw(plotting):
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 3.2))
        t = np.arange(len(proba)) / frame_rate
        for k, name in enumerate(model.classes_):
            ax.plot(t, proba[:, k], label=name)
        ax.axvline(switch / frame_rate, color="k", linestyle="--", linewidth=1)
        ax.text(switch / frame_rate, 1.02, " walk -> jump", va="bottom", fontsize=8)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("class posterior")
        ax.set_ylim(-0.02, 1.1)
        ax.set_title(f"Streaming recognition ({_WINDOW}-frame window)", fontsize=10)
        ax.legend(loc="center right", fontsize=8)
        fig.tight_layout()
        return fig

    return draw


def _sample_bvh(context, lines):
    """A walking database of virtual markers; a sampled walk, through IK, to BVH."""
    walks = make_walks(2, directions=["forward", "left"], random_state=context.random_state)
    X = VirtualMarkerTransform().fit_transform(
        as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    )
    model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
    transformer = VirtualMarkerTransform(walks.skeleton, frame_rate=walks.frame_rate).fit(
        walks.clips[:1]
    )
    label = walks.target[0]
    sample = model.sample(
        60,
        y=label,
        random_state=context.random_state,
        transformer=transformer,
        frame_rate=walks.frame_rate,
    )
    folder = getattr(context, "out", None) or tempfile.mkdtemp(prefix="skmotion-demo-")
    path = Path(folder) / "sampled_walk.bvh"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_bvh(sample.motion, path)
    context.sample = sample
    lines.append(
        f"sampled 60 frames from class '{walks.target_names[label]}': "
        f"{len(set(sample.nodes.tolist()))} nodes, recognised as "
        f"'{walks.target_names[model.predict([sample.frames])[0]]}'; IK marker error "
        f"{100 * np.median(sample.ik_rms):.1f}% of the body size (median) -> {path}"
    )


def run(context):
    folder = getattr(context, "data_folder", None)
    if folder:
        return [
            f"not run on {folder}: this walk-through adds the built-in motion classes one by one, "
            "streams a walk into a jump and samples a walk for the humanoid skeleton; run "
            "`skmotion demo` without --data to see it (MotionTreeHMM.partial_fit, stream and "
            "sample work on any clips: docs/live-database.md)"
        ]
    data = make_motions(n_clips_per_class=8, classes=_CLASSES, random_state=context.random_state)
    clips = [c[:, 6:] for c in data.clips]  # joint angles without the root
    names = data.target_names[data.target]
    lines = []
    model, X_test, y_test = _grow(data, clips, names, data.groups < 3, lines)
    proba, switch = _stream(model, X_test, y_test, lines)
    context.live_model, context.live_posterior = model, proba
    lines += save_figure(
        context,
        "stream_posterior.png",
        _draw_posterior(model, proba, switch, data.frame_rate),
        "the class posterior of the stream over time",
    )
    _sample_bvh(context, lines)
    return lines
