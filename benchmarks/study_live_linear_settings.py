"""LinearGestureDetector's settings on MSRC-12: out-of-fold F1 over the training people only.

Issue 27 asks for better detection. Each candidate is the benchmark's
``LinearGestureDetector`` (``_live_detection.detectors``: root-centred, size-normalised
frames, 80 negatives per take) with a few parameters changed; its windows are scored
out of fold by ``GroupKFold(3)`` over the training people (odd ids; every ``--subsample``-th
take), the event rule (trigger, look-ahead delay, threshold, refractory period) chosen
for the best F1 at 0.5 s on those scores, and that rule's F1 at 0.2, 0.5 and 1.0 s reported.
The test people never enter it; ``bench_live.py --only detection`` reports them for the settings
kept in its grid.

Usage::

    python benchmarks/study_live_linear_settings.py --subsample 2 \\
        --candidates '{"negative_gap": 1}' '{"segment": 4, "negative_gap": 1}'

Writes ``results/live_linear_settings.{csv,md}`` (``--output NAME``: ``results/NAME.*``, so
that two studies can run at once); needs ``../shared/data/msrc12`` (or ``SKMOTION_SHARED_DATA``).
"""

import argparse
import json
import time

import numpy as np
from _common import write_results
from _live_detection import (
    LATENCIES,
    LINEAR,
    RATE,
    _events,
    _f1,
    detectors,
    msrc12,
    rules,
)
from sklearn.base import clone
from sklearn.model_selection import GroupKFold

from skmotion.metrics import detection_counts


def out_of_fold_f1(params, takes, aps, gestures, people):
    """The F1 at each latency of the rule chosen at 0.5 s on out-of-fold window scores."""
    detector = clone(detectors(2, 30, ["Linear"])[LINEAR]).set_params(**params)
    scores = [None] * len(takes)
    for fit_idx, held in GroupKFold(3).split(takes, groups=people):
        model = clone(detector).fit(
            [takes[i] for i in fit_idx], gestures[fit_idx], action_points=[aps[i] for i in fit_idx]
        )
        for i, s in zip(held, model.scores([takes[i] for i in held])):
            scores[i] = s
    names = [np.full(len(a), g, dtype=object) for a, g in zip(aps, gestures)]
    best = (-1.0, None, None)
    for rule in rules():
        events = _events(scores, model.classes_, model.none_index_, **rule)
        f1 = [
            _f1(detection_counts(aps, names, events, latency=int(round(s * RATE))))
            for s in LATENCIES
        ]
        if f1[1] > best[0]:
            best = (f1[1], f1, rule)
    return best[1], best[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subsample", type=int, default=1, help="every n-th training take")
    parser.add_argument("--candidates", nargs="+", required=True, help="JSON parameter dicts")
    parser.add_argument(
        "--output", default="live_linear_settings", help="results table (two studies at once)"
    )
    args = parser.parse_args()
    takes, aps, gestures, people = msrc12()
    train = np.flatnonzero(people % 2 == 1)[:: args.subsample]
    data = ([takes[i] for i in train], [aps[i] for i in train], gestures[train], people[train])
    rows = []
    for text in args.candidates:
        start = time.perf_counter()
        f1, rule = out_of_fold_f1(json.loads(text), *data)
        rows.append(
            {
                "setting": text,
                "training takes": len(train),
                **{f"out-of-fold F1 at {s} s": v for s, v in zip(LATENCIES, f1)},
                "rule (chosen at 0.5 s)": str(rule),
                "s": time.perf_counter() - start,
            }
        )
        print(rows[-1], flush=True)
    write_results(
        args.output,
        rows,
        notes="MSRC-12 training people only (odd ids), GroupKFold(3) over them.",
    )


if __name__ == "__main__":
    main()
