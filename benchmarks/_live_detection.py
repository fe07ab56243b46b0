"""MSRC-12 studies of bench_live.py: detection in the stream and frame labelling of long takes.

Protocol: people with odd ids train, people with even ids test (the release's
cross-subject split); every choice (the event threshold and refractory
period) by GroupKFold over the training people only, on out-of-fold scores.
"""

import time
from pathlib import Path

import numpy as np
from _common import SHARED_DATA
from _msrc12 import msrc12_takes
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.ensemble import VotingClassifier
from sklearn.linear_model import LogisticRegression, RidgeClassifierCV
from sklearn.model_selection import GroupKFold
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from skmotion.live import ActivitySegmenter, GestureDetector, LinearGestureDetector
from skmotion.live._events import TRIGGERS, TriggerState, next_events
from skmotion.live._segmenter import path_labels, runs
from skmotion.metrics import detection_counts
from skmotion.preprocessing import FlattenClips, ResampleClips, VirtualMarkerTransform
from skmotion.recognition import MotionClassifier
from skmotion.tree import MotionTreeEncoder

RATE = 15  # frames per second of the stored MSRC-12
FIGURE = Path(__file__).resolve().parents[1] / "docs" / "images" / "live_detection.png"
LABELLING_FIGURE = FIGURE.with_name("live_labelling.png")
LATENCIES = (0.2, 0.5, 1.0)  # seconds after (and before) an action point
THRESHOLDS = np.r_[np.round(np.linspace(0.05, 0.95, 19), 2), 0.97, 0.99]
REFRACTORY = (8, 15, 23)  # frames: 0.5, 1 and 1.5 s
DELAYS = (1, 2, 3, 4)  # frames of look-ahead of trigger="maximum" (0.07 to 0.27 s)
# LinearGestureDetector's settings, chosen with the event rule by the same GroupKFold: its
# defaults (segments of 4 frames, 64 reference poses, C=0.01, positives at the action point and
# the 4 frames after it, negatives more than 3 frames away) and the previous positive band (the
# action point +- 1, negatives more than 1 frame away). In benchmarks/study_live_linear_settings.py
# (out-of-fold F1 at 0.5 s on half the training takes) the band (0, 4) gave 0.761 against 0.733
# for +- 1; 0 / 64 / 128 poses 0.645 / 0.729 / 0.715; C 0.03 lost to 0.01 in the last two runs
LINEAR_GRID = ({}, {"jitter": 1, "negative_gap": 1})
GESTURES = (
    "lift arms", "duck", "push right", "goggles", "wind it up", "shoot",
    "bow", "throw", "had enough", "change weapon", "beat both", "kick",
)  # fmt: skip


def msrc12():
    """Takes (float positions), action points, gestures, person ids; empty takes left out
    (the takes and their action points as :func:`_msrc12.msrc12_takes` reads them)."""
    takes, points, gesture, person = msrc12_takes(SHARED_DATA / "msrc12" / "msrc12_sequences.npz")
    keep = [i for i, take in enumerate(takes) if len(take) >= 2]
    return (
        [takes[i] for i in keep],
        [points[i] for i in keep],
        np.array([GESTURES[int(gesture[i]) - 1] for i in keep], dtype=object),
        np.array([int(person[i]) for i in keep]),
    )


class MiniRocketWindows(ClassifierMixin, BaseEstimator):
    """The sliding-window peer: aeon's MiniRocket on each window, a ridge classifier's margins.

    MiniRocket (Dempster et al. 2021) with its default 10,000 kernels and its
    usual classifier (standardised columns, ``RidgeClassifierCV``); the
    detector turns the margins into probabilities with a softmax (its
    threshold is chosen on them, as for the recogniser).
    """

    def fit(self, X, y):
        from aeon.transformations.collection.convolution_based import MiniRocket

        self.rocket_ = MiniRocket(random_state=0).fit(self._array(X))
        self.ridge_ = make_pipeline(StandardScaler(), RidgeClassifierCV(np.logspace(-3, 3, 10)))
        self.ridge_.fit(self.rocket_.transform(self._array(X)), y)
        self.classes_ = self.ridge_.classes_
        return self

    @staticmethod
    def _array(X):
        return np.stack(X).transpose(0, 2, 1)  # channels first

    def decision_function(self, X, chunk=4096):
        # a chunk of windows at a time: the same margins, without holding 10,000 features of
        # every window of every take at once (135,000 windows: 10 GB)
        return np.vstack(
            [
                self.ridge_.decision_function(self.rocket_.transform(self._array(X[i : i + chunk])))
                for i in range(0, len(X), chunk)
            ]
        )


def recognisers():
    """The recommended recogniser, an ordered one and the peer, all on virtual markers.

    The recommended MotionTreeEncoder describes which poses a window holds, not
    in which order; the second keeps the order: the window resampled to 10
    frames, flattened, standardised, a logistic regression (its C fixed, not tuned).
    """
    markers = dict(layout="kinect_v1", frame_rate=RATE)
    return {
        "skmotion: VirtualMarkerTransform + MotionTreeEncoder + LogisticRegression": make_pipeline(
            VirtualMarkerTransform(**markers),
            MotionTreeEncoder(),
            LogisticRegression(max_iter=2000),
        ),
        "skmotion: VirtualMarkerTransform + ResampleClips(10) + FlattenClips + LR": (
            make_pipeline(
                VirtualMarkerTransform(**markers),
                ResampleClips(n_frames=10),
                FlattenClips(),
                StandardScaler(),
                LogisticRegression(C=0.05, max_iter=2000),
            )
        ),
        "aeon MiniRocket (last window) + ridge": make_pipeline(
            VirtualMarkerTransform(**markers), MiniRocketWindows()
        ),
    }


def _events(scores, classes, none_index, **rule):
    return [
        next_events(ends, proba, classes, none_index, state=TriggerState(), **rule)[0]
        for ends, proba in scores
    ]


def _f1(counts):
    tp, fp, fn = (sum(c[i] for c in counts.values()) for i in range(3))
    return 2 * tp / (2 * tp + fp + fn) if tp else 0.0


def rules():
    """The event rules the cross-validation chooses among: trigger, threshold, refractory
    period and, for ``"maximum"``, its look-ahead delay."""
    for trigger in TRIGGERS:
        for delay in DELAYS if trigger == "maximum" else (0,):
            for refractory in REFRACTORY:
                for threshold in THRESHOLDS:
                    yield dict(
                        trigger=trigger, threshold=threshold, refractory=refractory, delay=delay
                    )


def _choose(detector, takes, aps, labels, people):
    """Per latency of LATENCIES, the rule (of :func:`rules`) of the best F1 at that latency on
    out-of-fold scores: ``{latency: (f1, rule)}`` (the benchmark's rule is the one at 0.5 s)."""
    scores = [None] * len(takes)
    for fit_idx, held in GroupKFold(3).split(takes, groups=people):
        model = clone(detector).fit(
            [takes[i] for i in fit_idx], labels[fit_idx], action_points=[aps[i] for i in fit_idx]
        )
        for i, s in zip(held, model.scores([takes[i] for i in held])):
            scores[i] = s
    names = [np.full(len(a), g, dtype=object) for a, g in zip(aps, labels)]
    best = {latency: (-1.0, None) for latency in LATENCIES}
    for rule in rules():
        events = _events(scores, model.classes_, model.none_index_, **rule)
        for latency in LATENCIES:
            counts = detection_counts(aps, names, events, latency=int(round(latency * RATE)))
            if _f1(counts) > best[latency][0]:
                best[latency] = (_f1(counts), rule)
    return best


def _cost_per_frame(detector, take, rounds=3):
    """Microseconds per frame: the stream one frame per call (mean per frame, median of
    rounds), the median single call (most frames score no window), the thread's CPU time
    per frame one per call (median of rounds: what a shared machine disturbs least), and
    detect()."""
    per_frame, calls, cpu = [], [], []
    for _ in range(rounds):
        stream = detector.stream()
        started = time.thread_time()
        for frame in take:
            start = time.perf_counter()
            stream.update(frame)
            calls.append(time.perf_counter() - start)
        cpu.append((time.thread_time() - started) / len(take))
        per_frame.append(float(np.sum(calls[-len(take) :])) / len(take))
    start = time.perf_counter()
    detector.detect([take])
    batched = (time.perf_counter() - start) / len(take)
    return tuple(
        1e6 * float(v) for v in (np.median(per_frame), np.median(calls), np.median(cpu), batched)
    )


LINEAR = (
    "skmotion: LinearGestureDetector (segment means of hip-centred frames and their soft "
    "assignment to 64 poses, compiled)"
)


def detectors(step, window, chosen=None):
    """The detectors compared: GestureDetector over each recogniser, and LinearGestureDetector.

    ``chosen``: names (or parts of names) to keep; None keeps all.
    """
    found = {
        name: GestureDetector(
            recognizer=recogniser, window=window, step=step, n_negatives=10, random_state=0
        )
        for name, recogniser in recognisers().items()
    }
    # Kinect v1: joint 0 is the hip centre, joint 2 the shoulder centre (the size); the rest
    # are the detector's defaults (positive windows end at the action point and the 4 frames
    # after it, 80 negatives per take end anywhere more than 3 frames from them)
    found[LINEAR] = LinearGestureDetector(root=0, size_joints=(0, 2), random_state=0)
    if chosen:
        found = {k: v for k, v in found.items() if any(c.lower() in k.lower() for c in chosen)}
    return found


def detection(quick, step=2, window=30, chosen=None):
    """F1 per gesture and latency, every detector, with the event rule chosen by CV."""
    takes, aps, gestures, people = msrc12()
    train = np.flatnonzero(people % 2 == 1)
    test = np.flatnonzero(people % 2 == 0)
    if quick:
        train, test = train[::6], test[::6]
    Xtr, Xte = [takes[i] for i in train], [takes[i] for i in test]
    names = [np.full(len(aps[i]), gestures[i], dtype=object) for i in test]
    rows, fitted = [], {}
    for name, detector in detectors(step, window, chosen).items():
        start = time.perf_counter()
        # the linear detector's setting is chosen with its event rule, on the same folds
        grid = LINEAR_GRID if isinstance(detector, LinearGestureDetector) else [{}]
        found = []
        for extra in grid:
            chosen_rules = _choose(
                clone(detector).set_params(**extra),
                Xtr,
                [aps[i] for i in train],
                gestures[train],
                people[train],
            )
            found.append((chosen_rules[0.5][0], extra, chosen_rules))
        cv_f1, extra, chosen_rules = max(found, key=lambda triple: triple[0])
        rule = chosen_rules[0.5][1]
        detector.set_params(**extra, **rule)
        detector.fit(Xtr, gestures[train], action_points=[aps[i] for i in train])
        fit_s = time.perf_counter() - start
        # detect() is the rule on these scores: scored once, then each latency's rule
        test_scores = detector.scores(Xte)
        events = _events(test_scores, detector.classes_, detector.none_index_, **rule)
        fitted[name] = detector
        stream = detector.stream()  # the stream gives the batch's events (one take checked)
        streamed = [e for frame in Xte[0] for e in stream.update(frame)]
        same = [(e.frame, e.label) for e in streamed] == [(e.frame, e.label) for e in events[0]]
        per_call, median_call, cpu, batched = _cost_per_frame(detector, Xte[0][:300])
        for latency in LATENCIES:
            # the rule chosen at 0.5 s (events within the latency either side, or after only),
            # and the rule chosen by the same cross-validation for this latency
            own_rule = chosen_rules[latency][1]
            own = _events(test_scores, detector.classes_, detector.none_index_, **own_rule)
            for early_name, early, found_events, used in (
                ("+-", None, events, rule),
                ("after only", 0, events, rule),
                ("+-, rule chosen for this latency", None, own, own_rule),
            ):
                frames = int(round(latency * RATE))
                counts = detection_counts(
                    [aps[i] for i in test], names, found_events, latency=frames, early=early
                )
                row = {
                    "recogniser": name,
                    "latency s": latency,
                    "window": early_name,
                    "F1": _f1(counts),
                }
                row.update({g: _f1({g: counts.get(g, (0, 0, 0))}) for g in GESTURES})
                row.update(
                    {
                        "trigger (CV)": used["trigger"],
                        "delay frames (CV)": used["delay"] if used["trigger"] == "maximum" else "",
                        "threshold (CV)": used["threshold"],
                        "refractory frames (CV)": used["refractory"],
                        "setting (CV)": str(extra or "defaults"),
                        "CV F1 at 0.5 s": cv_f1,
                        "CV F1 at this latency (its rule)": chosen_rules[latency][0],
                        "CV F1 at 0.5 s of each setting": "; ".join(
                            f"{e or 'defaults'}: {f1:.3f}" for f1, e, _ in found
                        ),
                        "stream events = batch": same,
                        "us per frame, one per call": per_call,
                        "us per call, median": median_call,
                        "CPU us per frame, one per call": cpu,
                        "us per frame, batched": batched,
                        "fit + CV s": fit_s,
                    }
                )
                rows.append(row)
                print({k: row[k] for k in ("recogniser", "latency s", "window", "F1")}, flush=True)
    figure(fitted, Xte[0], aps[test[0]], gestures[test[0]], FIGURE)
    return rows


def figure(detectors, take, points, gesture, path):
    """Each recogniser's score over one held-out take, its events and the action points."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    height = 2.1 * len(detectors) + 0.4  # and a strip for the legend below the axes
    fig, axes = plt.subplots(len(detectors), 1, figsize=(9, height), sharex=True)
    for ax, (name, detector) in zip(np.atleast_1d(axes), detectors.items()):
        ((ends, proba),) = detector.scores([take])
        score = np.delete(proba, detector.none_index_, axis=1).max(axis=1)
        ax.plot(ends / RATE, score, color="tab:blue", lw=1, label="best gesture's probability")
        ax.axhline(detector.threshold, color="grey", ls=":", lw=1, label="threshold")
        for k, a in enumerate(points):
            ax.axvline(a / RATE, color="tab:green", lw=1, label="action point" if k == 0 else None)
        events = detector.detect([take])[0]
        right = [e for e in events if e.label == gesture]
        wrong = [e for e in events if e.label != gesture]
        ax.plot(
            [e.frame / RATE for e in right],
            [e.score for e in right],
            "v",
            color="tab:orange",
            label=f"event: {gesture}",
        )
        ax.plot(
            [e.frame / RATE for e in wrong],
            [e.score for e in wrong],
            "x",
            color="tab:red",
            label="event: another gesture",
        )
        ax.set_ylim(0, 1.05)
        ax.set_ylabel("probability")
        short = name.split(" (")[0]  # the detector, without its description
        ax.set_title(f"{short} (trigger {detector.trigger!r})", fontsize=9)
    ax.set_xlabel("time (s)")
    # below the axes: a legend inside would hide the events near the top
    fig.legend(*ax.get_legend_handles_labels(), loc="lower center", fontsize=7, ncol=5)
    fig.tight_layout(rect=(0, 0.35 / height, 1, 1))
    path.parent.mkdir(exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


SWITCH_PENALTIES = (0.0, 10.0, 30.0, 100.0, 200.0, 300.0, 500.0, 700.0, 1000.0, 1500.0, 3000.0)
# the recogniser's settings: its defaults, and the standardised columns it had before its
# defaults study; the labelling chooses one of them or both averaged (soft voting)
RECOGNISER_SETTINGS = {
    "defaults": {},
    "standardised columns, C=0.1": {"column_power": 1.0, "C": 0.1},
}
RECOGNISER_CHOICES = (("defaults",), ("standardised columns, C=0.1",), tuple(RECOGNISER_SETTINGS))


def labelling_recogniser(choice):
    """A MotionClassifier of one setting, or sklearn's soft vote (mean probabilities) of several."""
    members = [
        (name, MotionClassifier(layout="kinect_v1", frame_rate=RATE, **RECOGNISER_SETTINGS[name]))
        for name in choice
    ]
    return members[0][1] if len(members) == 1 else VotingClassifier(members, voting="soft")


def concatenated_takes(takes, gestures, people, idx, seed=0):
    """Per person of ``idx``, their takes in a shuffled order, four at a time, end to end.

    Returns the long takes and each frame's truth: the gesture of the take it comes from.
    """
    rng = np.random.default_rng(seed)
    long_takes, truth = [], []
    for person in np.unique(people[idx]):
        own = rng.permutation(idx[people[idx] == person])
        for k in range(0, len(own) - 3, 4):
            parts = own[k : k + 4]
            long_takes.append(np.concatenate([takes[i] for i in parts]))
            truth.append(np.concatenate([np.full(len(takes[i]), gestures[i]) for i in parts]))
    return long_takes, truth


def _path_accuracy(probas, truth, classes, penalty):
    labels = [
        path_labels(p, classes, switch_penalty=penalty, threshold=0.0, none_label="none")
        for p in probas
    ]
    return float(np.mean(np.concatenate(labels) == np.concatenate(truth))), labels


def _choose_recogniser_and_penalty(segmenter, takes, gestures, people, train):
    """The recogniser (of RECOGNISER_CHOICES) and the switch penalty of the best frame accuracy
    on out-of-fold concatenated takes of the training people (GroupKFold(3) over them): the
    test people never enter the choice. Each setting is fitted once per fold; a soft vote's
    frame probabilities are the mean of its members' (a frame's probabilities are a mean of
    window probabilities, so averaging the members' frames is averaging their windows)."""
    hits, n_frames = np.zeros((len(RECOGNISER_CHOICES), len(SWITCH_PENALTIES))), 0
    for fit_idx, held in GroupKFold(3).split(train, groups=people[train]):
        fit_idx, held = train[fit_idx], train[held]
        long_takes, truth = concatenated_takes(takes, gestures, people, held)
        n_frames += sum(len(t) for t in truth)
        probas = {}
        for name in RECOGNISER_SETTINGS:
            model = clone(segmenter).set_params(recognizer=labelling_recogniser((name,)))
            model.fit([takes[k] for k in fit_idx], gestures[fit_idx])
            probas[name] = model.predict_proba_frames(long_takes)
        for i, choice in enumerate(RECOGNISER_CHOICES):
            mean = [np.mean(frames, axis=0) for frames in zip(*(probas[n] for n in choice))]
            for j, penalty in enumerate(SWITCH_PENALTIES):
                accuracy = _path_accuracy(mean, truth, model.classes_, penalty)[0]
                hits[i, j] += accuracy * sum(len(t) for t in truth)
    i, j = np.unravel_index(int(np.argmax(hits)), hits.shape)
    return RECOGNISER_CHOICES[i], SWITCH_PENALTIES[j], hits[i, j] / n_frames


def labelling(quick, window=60):
    """Frame accuracy of ActivitySegmenter on held-out takes of different gestures, concatenated.

    Four takes of one held-out person end to end (mostly different gestures);
    every frame's truth is the gesture of its take. The recogniser is the
    recommended MotionClassifier on windows of ``window`` frames (4 s): its defaults,
    its former standardised columns, or both averaged (RECOGNISER_CHOICES); that and
    the switch penalty are chosen by GroupKFold(3) over the training people; the frames'
    labels without the path (penalty 0) are given beside it, from the same probabilities.
    """
    takes, _, gestures, people = msrc12()
    train = np.flatnonzero(people % 2 == 1)
    test = np.flatnonzero(people % 2 == 0)
    if quick:
        train, test = train[::6], test[::6]
    long_takes, truth = concatenated_takes(takes, gestures, people, test)
    frames = int(sum(len(t) for t in long_takes))
    segmenter = ActivitySegmenter(window=window, step=5, train_step=15)
    start = time.perf_counter()
    choice, penalty, cv_accuracy = _choose_recogniser_and_penalty(
        segmenter, takes, gestures, people, train
    )
    cv_s = time.perf_counter() - start
    start = time.perf_counter()
    segmenter.set_params(switch_penalty=penalty, recognizer=labelling_recogniser(choice))
    segmenter.fit([takes[i] for i in train], gestures[train])
    fit_s = time.perf_counter() - start
    start = time.perf_counter()
    probas = segmenter.predict_proba_frames(long_takes)
    accuracy, predicted = _path_accuracy(probas, truth, segmenter.classes_, penalty)
    predict_s = time.perf_counter() - start
    # predict_frames gives these labels (one long take checked: it scores the windows again)
    assert np.array_equal(segmenter.predict_frames(long_takes[:1])[0], predicted[0])
    # the same probabilities without the path: what the switch penalty adds
    plain, plain_labels = _path_accuracy(probas, truth, segmenter.classes_, 0.0)
    rows = []
    for name, labels, acc, chosen in (
        (
            f"MotionClassifier windows ({' + '.join(choice)}), best path (by CV)",
            predicted,
            accuracy,
            penalty,
        ),
        (
            f"MotionClassifier windows ({' + '.join(choice)}), most probable class per frame",
            plain_labels,
            plain,
            0.0,
        ),
    ):
        rows.append(
            {
                "segmenter": name,
                "long takes": len(long_takes),
                "frames": frames,
                "frame accuracy": acc,
                "segments per take (true: 4)": float(np.mean([len(runs(p)) for p in labels])),
                "switch penalty": chosen,
                "out-of-fold accuracy of the choice (training people)": cv_accuracy,
                "fit s": fit_s,
                "penalty CV s": cv_s,
                "us per frame (batch)": 1e6 * predict_s / frames,
            }
        )
        print(rows[-1], flush=True)
    figure_labelling(long_takes[0], truth[0], predicted[0], plain_labels[0], LABELLING_FIGURE)
    return rows


def figure_labelling(take, truth, path, plain, path_file):
    """One held-out long take: the true gesture per frame, the per-frame argmax and the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = sorted(set(truth) | set(path) | set(plain))
    rows = (("truth", truth), ("most probable class per frame", plain), ("best path", path))
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(names) + 1.2))
    seconds = np.arange(len(take)) / RATE
    for offset, (label, labels), colour in zip(
        (-0.25, 0.0, 0.25), rows, ("k", "tab:red", "tab:blue")
    ):
        y = np.array([names.index(n) for n in labels]) + offset
        ax.plot(seconds, y, ".", ms=1.5, color=colour, label=label)
    ax.set_yticks(range(len(names)), names)
    ax.set_xlabel("time (s)")
    ax.set_title("frame labels of four held-out MSRC-12 takes end to end", fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, fontsize=8, markerscale=6)
    fig.tight_layout()
    path_file.parent.mkdir(exist_ok=True)
    fig.savefig(path_file, dpi=100)
    plt.close(fig)


def decoder_stream(quick):
    """The decoder's online posterior on MSRC-12: MotionTreeHMM().stream() per frame.

    Fitted on the training repetitions (two per take, virtual markers); streamed
    over held-out takes of virtual markers one frame per call. The label the
    stream holds at each held-out action point is compared with the take's gesture
    (the posterior accumulates from the take's start: one gesture per take).
    """
    from bench_live import msrc12_repetitions

    from skmotion.tree import MotionTreeHMM

    Xtr, ytr, _, _ = msrc12_repetitions()
    model = MotionTreeHMM().fit(Xtr, ytr)
    takes, aps, gestures, people = msrc12()
    test = np.flatnonzero(people % 2 == 0)[:: 12 if quick else 3]
    markers = VirtualMarkerTransform(layout="kinect_v1", frame_rate=RATE).fit(takes[:1])
    hits, per_frame = [], []
    for i in test:
        take = markers.transform([takes[i]])[0]
        stream = model.stream()
        start = time.perf_counter()
        labels = [stream.update(frame).label for frame in take]
        per_frame.append((time.perf_counter() - start) / len(take))
        hits += [labels[a] == gestures[i] for a in aps[i]]
    return [
        {
            "decoder": "MotionTreeHMM().stream() (online, compiled)",
            "held-out takes": len(test),
            "label at the action points = the take's gesture": float(np.mean(hits)),
            "us per frame, one per call (median over takes)": 1e6 * float(np.median(per_frame)),
        }
    ]
