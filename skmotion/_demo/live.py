"""Demo section: a database that grows live, a stream decoded frame by frame, a sampled clip,
and gestures detected in real MSRC-12 takes (when ../shared/data holds them)."""

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from skmotion._demo._figures import save_figure
from skmotion.datasets import make_motions, make_walks
from skmotion.io import as_motions, write_bvh
from skmotion.live import LinearGestureDetector
from skmotion.metrics import detection_f1
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


_MSRC12_GESTURES = {1: "lift outstretched arms", 2: "duck", 3: "push right"}


def _msrc12_takes():
    """MSRC-12 takes of three gestures by people 1-12 from ``$SKMOTION_SHARED_DATA`` or
    ``../shared/data`` (None when absent): takes, action points, gesture names, people."""
    root = Path(os.environ.get("SKMOTION_SHARED_DATA", Path("..") / "shared" / "data"))
    path = root / "msrc12" / "msrc12_sequences.npz"
    if not path.is_file():
        return None
    d = np.load(path)
    chosen = np.flatnonzero(np.isin(d["gesture"], list(_MSRC12_GESTURES)) & (d["person"] <= 12))
    takes, points = [], []
    for i in chosen:
        take = d["positions"][d["offsets"][i] : d["offsets"][i + 1]].astype(float)
        found = d["action_points"][d["action_point_offsets"][i] : d["action_point_offsets"][i + 1]]
        takes.append(take)
        points.append(found[(found >= 0) & (found < len(take))].astype(np.intp))
    names = np.array([_MSRC12_GESTURES[g] for g in d["gesture"][chosen]], dtype=object)
    return takes, points, names, d["person"][chosen], path


def _msrc12_detection(context, lines):
    """Gestures detected in real Kinect takes, one frame per call: events, F1, cost, a figure."""
    found = _msrc12_takes()
    if found is None:
        lines.append(
            "MSRC-12 not found in ../shared/data (or $SKMOTION_SHARED_DATA): the detection "
            "of gestures in real takes is left out"
        )
        return
    takes, points, names, people, path = found
    train = people % 2 == 1  # odd people train, even people are held out

    def pick(seq, mask):
        return [s for s, m in zip(seq, mask) if m]

    # Kinect v1: joint 0 is the hip centre, joint 2 the shoulder centre (the body's size);
    # the event rule is the detector's default, the one benchmarks/bench_live.py chose by
    # CV over training people (trigger "maximum", look-ahead 1 frame, threshold 0.65)
    detector = LinearGestureDetector(root=0, size_joints=(0, 2), random_state=context.random_state)
    detector.fit(pick(takes, train), names[train], action_points=pick(points, train))
    held, held_points = pick(takes, ~train), pick(points, ~train)
    held_names = [np.full(len(p), g, dtype=object) for p, g in zip(held_points, names[~train])]
    f1 = detection_f1(held_points, held_names, detector.detect(held), latency=8)
    take, gesture = held[0], names[~train][0]
    stream, costs, events = detector.stream(), [], []
    for frame in take:
        start = time.perf_counter()
        events += stream.update(frame)
        costs.append(time.perf_counter() - start)
    lines.append(
        f"MSRC-12 ({path.parent}): {len(_MSRC12_GESTURES)} gestures, {int(train.sum())} "
        f"takes of odd people train; on {len(held)} held-out takes detection F1 at 0.5 s: "
        f"{f1:.2f}; one held-out '{gesture}' take streamed frame by frame: {len(events)} "
        f"events for {len(held_points[0])} repetitions, {1e6 * np.median(costs):.0f} us per "
        "frame (median)"
    )
    ((ends, proba),) = detector.scores([take])
    lines += save_figure(
        context,
        "msrc12_detection.png",
        _draw_detection(detector, ends, proba, held_points[0], events, gesture),
        "a held-out MSRC-12 take: the best gesture's probability, action points and events",
    )


def _draw_detection(detector, ends, proba, points, events, gesture, rate=15.0):
    def draw(plotting):
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 2.8))
        score = np.delete(proba, detector.none_index_, axis=1).max(axis=1)
        ax.plot(ends / rate, score, lw=1, label="best gesture's probability")
        ax.axhline(detector.threshold, color="grey", ls=":", lw=1, label="threshold")
        for k, a in enumerate(points):
            ax.axvline(a / rate, color="tab:green", lw=1, label="action point" if k == 0 else None)
        ax.plot([e.frame / rate for e in events], [e.score for e in events], "v", label="event")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("probability")
        ax.set_ylim(0, 1.1)
        ax.set_title(f"A held-out MSRC-12 take ('{gesture}'), streamed frame by frame", fontsize=10)
        ax.legend(loc="center left", fontsize=7)  # MSRC-12 takes start at rest: room there
        fig.tight_layout()
        return fig

    return draw


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
    _msrc12_detection(context, lines)
    return lines
