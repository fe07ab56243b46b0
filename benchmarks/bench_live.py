"""A live motion database: incremental updates, streaming recognition, synthesis.

Result tables, all measured in one run:

- ``live_update_cost``: seconds per ``partial_fit`` call adding one clip
  (without splits or rebuilds) against the tree's depth, split into a cost per added frame
  (the slope between clips of 20 and 1000 frames) and a fixed cost per call, and
  the ratio to rebuilding the database with ``fit``; also the per-frame work
  alone (routing, moment merges, transition counts of a 1000-frame clip); 60
  joint-angle channels of the synthetic motions.
- ``live_growth``: test accuracy of a database grown clip by clip
  (``partial_fit``; the first call holds one clip per class, the rest arrive
  one at a time in a shuffled order) against one rebuilt from all training
  clips (``fit``), with the same (default) hyperparameters, for three growth
  settings (the defaults, also over three clip orders; leaves only; no
  splits), with the number of clips
  held at the grown database's last whole build; and the accuracy of ``fit``
  on twenty random 90% subsets of the training clips (how much a rebuild moves
  itself: its 10th and 90th percentiles, and whether the grown database lies
  between them): BasicMotions and JapaneseVowels (the archive's split), the
  synthetic motions (subject 3 held out), CMU subject 02 in 1 s windows of
  virtual markers (split by time inside each trial, as in ``bench_tree.py``)
  and MSRC-12 repetitions (two per take, odd people train).
- ``live_detection`` (MSRC-12): detection F1 at 0.2, 0.5 and 1.0 s, per
  gesture and overall, of ``GestureDetector`` with the recommended recogniser,
  an ordered one and aeon's MiniRocket on the same windows (same step), and of
  ``LinearGestureDetector``; the event rule (trigger, look-ahead, threshold,
  refractory period) chosen by GroupKFold over the training people for F1 at
  0.5 s, and again for each latency (rows "rule chosen for this latency");
  microseconds per frame, one frame per call and batched (``_live_detection.py``).
- ``live_labelling`` (MSRC-12): frame accuracy of ``ActivitySegmenter`` (windows
  of ``MotionClassifier``: its defaults, its standardised columns or both averaged,
  chosen with the switch penalty by GroupKFold over the training people) on
  held-out takes of one person concatenated four at a time, with and without the
  best label path; a figure of one long take.
- ``live_stream_cost``: microseconds per frame of ``stream().update`` on a clip
  of 32 virtual markers (192 channels), for the exact stream (window of 30
  frames, or all frames) and the online one, against the chunk size; the ratio
  to the batch ``predict`` + ``decode`` of the same frames (timed in
  alternation) and to the exact stream with a 30-frame window; also the fastest
  of five more runs (the cost with the least interference from other jobs), and
  the online stream's single-frame cost after 3000 frames (the same frames
  again: a cost that does not grow with the stream). "CPU us" columns are the
  thread's CPU time (``time.thread_time``), which a shared machine disturbs
  far less than the wall clock.
- ``live_stream_baseline`` (with ``--baseline DIR``): the online stream's cost
  per frame, fed frame by frame and in one chunk, of this checkout and of an
  older built skmotion in ``DIR``, in alternating subprocesses.
- ``live_online_agreement``: the online (causal) stream against the batch
  answers, per data set: the share of frames whose current node (and node
  ``lag`` = 5 frames back) equals the batch ``decode`` of the whole clip at the
  bottom layer, the share of clips whose final label equals the batch
  ``predict``, and the frames to a settled correct decision of the online and
  the exact streams.
- ``live_latency``: streaming every test clip frame by frame, the share of the
  clip after which the class decision is correct and stays so (median), and
  the share of clips whose decision is correct at the end (the batch accuracy).
- ``live_synthesis``: the share of sampled clips recognised as the class they
  were sampled from, per data set (chance = 1 / n_classes), for three
  smoothing widths (0: independent frames).

Run: ``python benchmarks/bench_live.py`` (``--quick`` for a smoke run). The UEA
and CMU rows need ``../shared/data`` (or ``SKMOTION_SHARED_DATA``) and are left
out, with a message, without it. The machine may be shared: compare ratios within one run.
"""

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, cmu_windows, interleaved, time_call, write_results  # noqa: E402

if os.environ.get("SKMOTION_BENCH_BASELINE"):  # a --baseline worker: that folder's skmotion,
    sys.path.insert(0, os.environ["SKMOTION_BENCH_BASELINE"])  # ahead of this checkout

# A worktree outside the project folder finds the data through the tests' variable.
SHARED_DATA = Path(os.environ.get("SKMOTION_SHARED_DATA", SHARED_DATA))

from _live_detection import decoder_stream, detection, labelling  # noqa: E402

from skmotion.datasets import load_uea, make_motions  # noqa: E402
from skmotion.tree import MotionTreeHMM  # noqa: E402
from skmotion.tree._growth._live import clip_counts, node_moments  # noqa: E402

# -- data ------------------------------------------------------------------------------


def uea(name):
    train = load_uea(name, subset="train", data_home=SHARED_DATA)
    test = load_uea(name, subset="test", data_home=SHARED_DATA)
    return train.clips, train.target, test.clips, test.target


def synthetic():
    data = make_motions(random_state=0)
    clips = [c[:, 6:] for c in data.clips]
    names = data.target_names[data.target]
    train = data.groups < 3
    return (
        [c for c, m in zip(clips, train) if m],
        names[train],
        [c for c, m in zip(clips, train) if not m],
        names[~train],
    )


def msrc12_repetitions(per_take=2):
    """MSRC-12 repetitions (from the frame after one action point to the next) as clips of
    virtual markers; the first ``per_take`` of each take (a subset: the growth study makes
    one ``partial_fit`` call per clip). Odd people train, even people test."""
    from _live_detection import RATE, msrc12

    from skmotion.preprocessing import VirtualMarkerTransform

    takes, aps, gestures, people = msrc12()
    clips, labels, person = [], [], []
    for take, points, gesture, who in zip(takes, aps, gestures, people):
        starts = np.r_[0, points[:-1] + 1]
        for start, end in list(zip(starts, points))[:per_take]:
            if end - start >= 5:
                clips.append(take[start : end + 1])
                labels.append(gesture)
                person.append(who)
    markers = VirtualMarkerTransform(layout="kinect_v1", frame_rate=RATE).fit(clips)
    clips, labels, train = markers.transform(clips), np.array(labels), np.array(person) % 2 == 1
    return (
        [c for c, m in zip(clips, train) if m],
        labels[train],
        [c for c, m in zip(clips, train) if not m],
        labels[~train],
    )


def datasets(quick):
    sets = {"synthetic, subject 3 held out": synthetic}
    if quick:
        return sets
    if (SHARED_DATA / "uea").is_dir():
        sets["BasicMotions"] = lambda: uea("BasicMotions")
        sets["JapaneseVowels"] = lambda: uea("JapaneseVowels")
    else:
        print(f"UEA: not found in {SHARED_DATA}, left out")
    if (SHARED_DATA / "cmu-asfamc").is_dir():
        sets["CMU 02, 1 s windows"] = cmu_windows
    else:
        print(f"CMU: not found in {SHARED_DATA}, left out")
    if (SHARED_DATA / "msrc12").is_dir():
        sets["MSRC-12 repetitions (2 per take)"] = msrc12_repetitions
    else:
        print(f"MSRC-12: not found in {SHARED_DATA}, left out")
    return sets


# -- the studies -----------------------------------------------------------------------


def grow(model, X, y, *, seed=0, **kwargs):
    """partial_fit: one clip per class first, then the others one by one in a shuffled order.

    Returns the model and the number of clips held at its last whole build
    (the first call, or a rebuild of the root: a new standardisation).
    """
    y = np.asarray(y)
    first = [int(np.flatnonzero(y == c)[0]) for c in np.unique(y)]
    rest = [i for i in np.random.default_rng(seed).permutation(len(X)) if i not in first]
    model.partial_fit([X[i] for i in first], y[first], **kwargs)
    last_build = len(first)
    for n, i in enumerate(rest, start=len(first) + 1):
        center = model.center_
        model.partial_fit([X[i]], y[i : i + 1], **kwargs)
        if model.center_ is not center:
            last_build = n
    return model, last_build


def _seconds_per_call(model, clip, label, n_calls):
    """Median seconds of ``partial_fit`` adding ``clip`` (no splits), over ``n_calls`` calls."""
    times = []
    for _ in range(n_calls):
        start = time.perf_counter()
        model.partial_fit([clip], [label], split_growth=None, rebuild_growth=None)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def update_cost(quick):
    data = make_motions(n_clips_per_class=4 if quick else 10, random_state=0)
    clips, y = [c[:, 6:] for c in data.clips], data.target_names[data.target]
    rng = np.random.default_rng(0)
    short, long_ = (clips[0][rng.integers(0, len(clips[0]), n)] for n in (20, 1000))
    n_calls = 5 if quick else 15
    rows = []
    for depth in (2, 4, 6) if quick else (2, 4, 6, 8, 10, 12):
        params = dict(max_depth=depth, split="median", min_samples_leaf=4)
        model = MotionTreeHMM(**params).partial_fit(clips, y)
        nodes, frames = model.tree_.n_tree_nodes, int(model.tree_.count[0])
        # alternate short and long clips so that both see the same load and database size
        t_short, t_long = [], []
        for _ in range(n_calls):
            t_short.append(_seconds_per_call(model, short, y[0], 1))
            t_long.append(_seconds_per_call(model, long_, y[0], 1))
        t_short, t_long = float(np.median(t_short)), float(np.median(t_long))
        per_frame = (t_long - t_short) / (len(long_) - len(short))
        t_fit = time_call(lambda params=params: MotionTreeHMM(**params).fit(clips, y), repeats=3)[0]
        # the per-frame work alone: routing, the moment merges and the transition counts
        std = (long_ - model.center_) / model.scale_
        offsets = np.array([0, len(std)])

        def per_frame_work(model=model, std=std, offsets=offsets):
            tree = model.tree_
            node_moments(tree, std, tree.covariance_type)
            clip_counts(tree, std, offsets, np.zeros(1, np.intp), 1)

        t_work = time_call(per_frame_work, repeats=7)[0]
        rows.append(
            {
                "max_depth": depth,
                "layers": model.n_layers_,
                "tree nodes": nodes,
                "frames in database": frames,
                "us per added frame": 1e6 * per_frame,
                "us per frame, routing + merges alone": 1e6 * t_work / len(long_),
                "ms per call (fixed)": 1e3 * (t_short - per_frame * len(short)),
                "ms per 20-frame clip": 1e3 * t_short,
                "ms per 1000-frame clip": 1e3 * t_long,
                "rebuild (fit) ms": 1e3 * t_fit,
                "rebuild / add a 20-frame clip": t_fit / t_short,
            }
        )
    return rows


GROWTH_SETTINGS = (  # (label, partial_fit keyword arguments)
    ("grown (defaults: split_growth=2, rebuild_growth=2)", {}),
    ("grown, leaves only (rebuild_growth=None)", {"rebuild_growth": None}),
    ("grown, no splits (both None)", {"split_growth": None, "rebuild_growth": None}),
)


def growth(sets, n_subsets=20, n_orders=3):
    rows = []
    for name, loader in sets.items():
        Xtr, ytr, Xte, yte = loader()
        ytr = np.asarray(ytr)
        rebuilt = MotionTreeHMM().fit(Xtr, ytr)
        row = {
            "data": name,
            "train clips": len(Xtr),
            "test clips": len(Xte),
            "rebuilt accuracy": rebuilt.score(Xte, yte),
            "rebuilt, nodes": rebuilt.tree_.n_tree_nodes,
        }
        start = time.perf_counter()
        MotionTreeHMM().fit(Xtr, ytr)
        row["rebuild (fit) s"] = time.perf_counter() - start
        for label, kwargs in GROWTH_SETTINGS:
            start = time.perf_counter()
            model, last_build = grow(MotionTreeHMM(), Xtr, ytr, **kwargs)
            row[label] = model.score(Xte, yte)
            row[label + " - rebuilt"] = row[label] - row["rebuilt accuracy"]
            row[label + ", nodes"] = model.tree_.n_tree_nodes
            row[label + ", clips at the last whole build"] = last_build
            row[label + ", s"] = time.perf_counter() - start
        # the defaults again, clips in other orders: the gap is not one order's chance
        label = GROWTH_SETTINGS[0][0]
        scores = orders = [row[label]] + [
            grow(MotionTreeHMM(), Xtr, ytr, seed=seed)[0].score(Xte, yte)
            for seed in range(1, n_orders)
        ]
        row[f"defaults, {n_orders} orders: mean - rebuilt"] = (
            float(np.mean(scores)) - row["rebuilt accuracy"]
        )
        row[f"defaults, {n_orders} orders: min"] = float(np.min(scores))
        row[f"defaults, {n_orders} orders: max"] = float(np.max(scores))
        # how much a rebuild itself moves when a tenth of the clips is left out: the
        # spread of accuracies that differently grown trees of the same data may have
        rng = np.random.default_rng(0)
        scores = []
        for _ in range(n_subsets):
            keep = np.sort(rng.permutation(len(Xtr))[: int(0.9 * len(Xtr))])
            sub = MotionTreeHMM().fit([Xtr[i] for i in keep], ytr[keep])
            scores.append(sub.score(Xte, yte))
        row["rebuilt on 90% of the clips: mean"] = float(np.mean(scores))
        row["rebuilt on 90%: min"] = float(np.min(scores))
        row["rebuilt on 90%: max"] = float(np.max(scores))
        low, high = np.percentile(scores, [10, 90])
        row["rebuilt on 90%: 10th percentile"] = float(low)
        row["rebuilt on 90%: 90th percentile"] = float(high)
        grown = row[GROWTH_SETTINGS[0][0]]
        row["grown (defaults) within 10th-90th"] = bool(low <= grown <= high)
        row["grown (defaults), 3 orders within 10th-90th"] = int(
            sum(low <= a <= high for a in orders)
        )
        rows.append(row)
        print(row)
    return rows


def stream_clip(quick):
    """A model of 32 virtual markers (192 channels) and a long test clip."""
    if (SHARED_DATA / "cmu-asfamc").is_dir() and not quick:
        Xtr, ytr, Xte, _ = cmu_windows()
        clip = np.concatenate(Xte[:10])
        return MotionTreeHMM().fit(Xtr, ytr), clip, "CMU 02 virtual markers"
    from skmotion.datasets import make_walks
    from skmotion.io import as_motions
    from skmotion.preprocessing import VirtualMarkerTransform

    walks = make_walks(2, random_state=0)
    X = VirtualMarkerTransform().fit_transform(
        as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    )
    return MotionTreeHMM().fit(X[1:], walks.target[1:]), X[0], "synthetic walks, virtual markers"


STREAM_SETTINGS = (  # (label, stream keyword arguments)
    ("exact, window 30", {"mode": "exact", "window": 30}),
    ("exact, all frames", {"mode": "exact"}),
    ("online", {"mode": "online"}),
    ("online, n_best=0", {"mode": "online", "n_best": 0}),
)


def stream_cost(quick):
    model, clip, source = stream_clip(quick)
    n = min(len(clip), 120 if quick else 300)
    clip = clip[:n]

    def batch():
        model.predict([clip])
        model.decode([clip])

    rows = []
    for label, kwargs in STREAM_SETTINGS:
        for chunk in (1, 10, 30):
            if kwargs.get("mode") == "exact" and "window" not in kwargs and chunk == 10:
                continue  # the slowest setting: two chunk sizes tell its trend

            made = model.stream(**kwargs)  # made once: its tables are not per-frame work

            def run(stream=made, chunk=chunk):
                stream.reset()
                for start in range(0, n, chunk):
                    stream.update(clip[start : start + chunk])

            # in alternation with the batch calls, so both see the same load
            seconds, batch_s = interleaved([run, batch], rounds=3)
            # the least-disturbed run: the cost on an idle core, as near as a shared machine gets
            fastest = min(time_call(run, repeats=1, warmup=0)[0] for _ in range(5))
            cpu = _cpu_seconds(run)
            rows.append(
                {
                    "data": source,
                    "channels": clip.shape[1],
                    "layers": model.n_layers_,
                    "frames": n,
                    "stream": label,
                    "chunk": chunk,
                    "us per frame": 1e6 * seconds / n,
                    "us per frame, fastest of 5": 1e6 * fastest / n,
                    "CPU us per frame": 1e6 * cpu / n,
                    "us per update": 1e6 * seconds / -(-n // chunk),
                    "batch predict+decode, us per frame": 1e6 * batch_s / n,
                    "stream / batch": seconds / batch_s,
                }
            )
    rows.append(_online_after(model, clip, source, batch))
    # the exact stream (window 30) against the online one, same chunk, same run
    exact = {r["chunk"]: r["us per frame"] for r in rows if r["stream"] == "exact, window 30"}
    for row in rows:
        row["exact (window 30) / this"] = exact[row["chunk"]] / row["us per frame"]
    return rows


def _cpu_seconds(run, repeats=5):
    """Median CPU seconds of this thread in ``run()``: the work itself, without the waits for
    a core that a shared machine adds to the wall clock (caches are still shared)."""
    times = []
    for _ in range(repeats):
        start = time.thread_time()
        run()
        times.append(time.thread_time() - start)
    return float(np.median(times))


def _single_frame_cost(quick):
    """The online stream fed frame by frame (and in one chunk), in this process's skmotion."""
    model, clip, source = stream_clip(quick)
    clip = np.ascontiguousarray(clip[: min(len(clip), 120 if quick else 300)])
    stream = model.stream()

    def frames():
        stream.reset()
        for frame in clip:
            stream.update(frame)

    def chunk():
        stream.reset().update(clip)

    wall = interleaved([frames, chunk], rounds=5)
    n = len(clip)
    return {
        "data": source,
        "channels": clip.shape[1],
        "layers": model.n_layers_,
        "frames": n,
        "CPU us per frame, 1 frame per update": 1e6 * _cpu_seconds(frames, 7) / n,
        "CPU us per frame, one chunk": 1e6 * _cpu_seconds(chunk, 7) / n,
        "us per frame, 1 frame per update (wall)": 1e6 * wall[0] / n,
        "us per frame, one chunk (wall)": 1e6 * wall[1] / n,
    }


def baseline_cost(quick, baseline, rounds=3):
    """The single-frame cost of this checkout against an older one, alternating in subprocesses.

    ``baseline`` is a folder holding an importable, built ``skmotion`` (a wheel
    unpacked, or a checkout built in place); each round runs one worker per
    version, one after the other, so both see the same load.
    """
    import json
    import subprocess

    here = Path(__file__).resolve()
    rows = []
    for r in range(rounds):
        for version, path in (("this checkout", None), ("baseline", baseline)):
            env = dict(os.environ)
            env.pop("SKMOTION_BENCH_BASELINE", None)
            if path is not None:
                env["SKMOTION_BENCH_BASELINE"] = str(Path(path).resolve())
            cmd = [sys.executable, str(here), "--single-frame-worker"] + (["--quick"] * quick)
            out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            row = {"version": version, "round": r + 1} | json.loads(out.stdout.splitlines()[-1])
            rows.append(row)
            print(row)
    return rows


def _online_after(model, clip, source, batch, n_before=3000):
    """The online stream's single-frame cost after ``n_before`` frames: the same as at the start."""
    n = len(clip)
    stream = model.stream()
    before = np.resize(clip, (n_before, clip.shape[1]))  # the clip again and again
    times, cpu = [], []
    for _ in range(3):
        stream.reset().update(before)
        start, start_cpu = time.perf_counter(), time.thread_time()
        for frame in clip:
            stream.update(frame)
        times.append(time.perf_counter() - start)
        cpu.append(time.thread_time() - start_cpu)
    batch_s = time_call(batch, repeats=3)[0]
    seconds, fastest = float(np.median(times)), min(times)
    return {
        "data": source,
        "channels": clip.shape[1],
        "layers": model.n_layers_,
        "frames": n,
        "stream": f"online, after {n_before} frames",
        "chunk": 1,
        "us per frame": 1e6 * seconds / n,
        "us per frame, fastest of 5": 1e6 * fastest / n,  # of 3 here
        "CPU us per frame": 1e6 * float(np.median(cpu)) / n,
        "us per update": 1e6 * seconds / n,
        "batch predict+decode, us per frame": 1e6 * batch_s / n,
        "stream / batch": seconds / batch_s,
    }


def _settled(decisions):
    """Frames until the decision is correct and stays so (None when wrong at the end)."""
    if not decisions[-1]:
        return None
    wrong = np.flatnonzero(~decisions)
    return (0 if not len(wrong) else wrong[-1] + 1) + 1


def agreement(sets, lag=5):
    """The online stream against the batch answers and the exact stream, per data set."""
    rows = []
    for name, loader in sets.items():
        Xtr, ytr, Xte, yte = loader()
        model = MotionTreeHMM().fit(Xtr, ytr)
        (_, batch_paths), batch_labels = model.decode(Xte), model.predict(Xte)
        same_node, same_lagged, same_label, correct, settled = [], [], [], [], {}
        for clip, label, path, batch_label in zip(Xte, yte, batch_paths, batch_labels):
            for mode in ("online", "exact"):
                stream = model.stream(mode=mode, lag=lag, n_best=1)
                states = [stream.update(frame) for frame in clip]
                decisions = np.array([s.label == label for s in states])
                settled.setdefault(mode, []).append((_settled(decisions), len(clip)))
                if mode == "exact":
                    continue
                nodes = np.array([s.node for s in states])
                lagged = np.array([s.lagged_node for s in states])[lag:]
                same_node.append(nodes == path)
                same_lagged.append(lagged == path[: len(lagged)])
                same_label.append(states[-1].label == batch_label)
                correct.append(states[-1].label == label)
        row = {
            "data": name,
            "test clips": len(Xte),
            "frames": int(sum(len(c) for c in Xte)),
            "node = batch decode (filtered)": float(np.mean(np.concatenate(same_node))),
            f"node = batch decode (lag {lag})": float(np.mean(np.concatenate(same_lagged))),
            "final label = batch predict": float(np.mean(same_label)),
            "online accuracy": float(np.mean(correct)),
            "batch accuracy": float(np.mean(batch_labels == np.asarray(yte))),
        }
        for mode, pairs in settled.items():
            frames = [f for f, _ in pairs if f is not None]
            shares = [f / n for f, n in pairs if f is not None]
            row[f"{mode}: median frames to a settled correct decision"] = float(np.median(frames))
            row[f"{mode}: median share of clip"] = float(np.median(shares))
        for beam in (6, 12):  # wider online beams (the default is n_paths = 3)
            nodes, labels = [], []
            for clip, path in zip(Xte, batch_paths):
                stream = model.stream(beam=beam, n_best=0)
                nodes.append(np.array([stream.update(frame).node for frame in clip]) == path)
                labels.append(stream.state().label)
            row[f"beam {beam}: node = batch decode"] = float(np.mean(np.concatenate(nodes)))
            row[f"beam {beam}: final label = batch predict"] = float(
                np.mean(np.array(labels) == batch_labels)
            )
        rows.append(row)
        print(row)
    return rows


def latency(sets):
    rows = []
    for name, loader in sets.items():
        Xtr, ytr, Xte, yte = loader()
        model = MotionTreeHMM().fit(Xtr, ytr)
        shares, frames, correct = [], [], []
        for clip, label in zip(Xte, yte):
            stream = model.stream(mode="exact")
            decisions = np.array([stream.update(frame).label == label for frame in clip])
            correct.append(decisions[-1])
            if decisions[-1]:
                wrong = np.flatnonzero(~decisions)
                first = 0 if not len(wrong) else wrong[-1] + 1
                shares.append((first + 1) / len(clip))
                frames.append(first + 1)
        rows.append(
            {
                "data": name,
                "test clips": len(Xte),
                "correct at the end": float(np.mean(correct)),
                "batch accuracy": model.score(Xte, yte),
                "median share of clip to a settled correct decision": float(np.median(shares)),
                "median frames": float(np.median(frames)),
                "90th percentile share": float(np.percentile(shares, 90)),
            }
        )
        print(rows[-1])
    return rows


def synthesis(sets):
    rows = []
    for name, loader in sets.items():
        Xtr, ytr, _, _ = loader()
        model = MotionTreeHMM().fit(Xtr, ytr)
        length = int(np.median([len(c) for c in Xtr]))
        row = {"data": name, "classes": len(model.classes_), "chance": 1 / len(model.classes_)}
        for smoothness in (0.0, 1.0, 2.0):
            hits = []
            for label in model.classes_:
                samples = [
                    model.sample(length, y=label, random_state=s, smoothness=smoothness).frames
                    for s in range(10)
                ]
                hits.append(np.mean(model.predict(samples) == label))
            row[f"recognised, smoothness {smoothness:g}"] = float(np.mean(hits))
            row[f"worst class, smoothness {smoothness:g}"] = float(np.min(hits))
        row["frames per sample"] = length
        rows.append(row)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, synthetic data only")
    parser.add_argument(
        "--only",
        nargs="*",
        help="update, growth, stream, latency, agreement, synthesis, detection, labelling, decoder "
        "(default: all; the last two need MSRC-12 in ../shared/data)",
    )
    parser.add_argument(
        "--baseline",
        help="with the stream study: a folder holding an older built skmotion whose "
        "single-frame cost is measured in alternation with this one (live_stream_baseline)",
    )
    parser.add_argument(
        "--detectors",
        nargs="*",
        help="with the detection study: the detectors to run, by part of their name "
        "(e.g. Linear MiniRocket; default: all)",
    )
    parser.add_argument("--single-frame-worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.single_frame_worker:
        import json

        print(json.dumps(_single_frame_cost(args.quick)))
        return
    only = set(
        args.only
        or ["update", "growth", "stream", "latency", "agreement", "synthesis", "detection"]
        + ["labelling", "decoder"]
    )
    if {"detection", "labelling", "decoder"} & only and not (SHARED_DATA / "msrc12").is_dir():
        print(f"MSRC-12: not found in {SHARED_DATA}, its studies left out")
        only -= {"detection", "labelling", "decoder"}
    sets = datasets(args.quick)
    note = "Shared machine: compare ratios within one run. Default MotionTreeHMM parameters."
    if "update" in only:
        write_results("live_update_cost", update_cost(args.quick), notes=note)
    if "stream" in only:
        write_results("live_stream_cost", stream_cost(args.quick), notes=note)
        if args.baseline:
            rows = baseline_cost(args.quick, args.baseline)
            write_results("live_stream_baseline", rows, notes=note)
    if "growth" in only:
        write_results("live_growth", growth(sets), notes=note)
    if "latency" in only:
        write_results("live_latency", latency(sets), notes=note)
    if "agreement" in only:
        write_results("live_online_agreement", agreement(sets), notes=note)
    if "synthesis" in only:
        write_results("live_synthesis", synthesis(sets), notes=note)
    msrc_note = (
        "MSRC-12, odd people train, even people test; trigger, threshold and refractory period by "
        "GroupKFold(3) over the training people (out-of-fold F1 at 0.5 s). Detection: window "
        "30 frames (2 s), step 2 (the linear detector: every frame, its C "
        "by the same CV); labelling: window 60 frames (4 s), step 5, the recogniser and the "
        "switch penalty by the same CV. F1: one event "
        "per repetition, extra events false; '+-': an event "
        "within the latency before or after the action point, 'after only': at or after it."
    )
    if "detection" in only:
        write_results(
            "live_detection", detection(args.quick, chosen=args.detectors), notes=msrc_note
        )
    if "labelling" in only:
        write_results("live_labelling", labelling(args.quick), notes=msrc_note)
    if "decoder" in only:
        write_results("live_decoder_stream", decoder_stream(args.quick), notes=msrc_note)


if __name__ == "__main__":
    main()
