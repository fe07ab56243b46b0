"""The "maximum" trigger of the event rule against a brute-force reference and by hand."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.live._events import TriggerState, gesture_scores, maximum_step, next_events

CLASSES = np.array(["a", "b", "none"], dtype=object)


def brute_force_maximum(ends, proba, threshold, refractory, delay):
    """Every window in turn, by the definition: no state, no shortcuts."""
    score = proba[:, :2].max(axis=1)
    best = proba[:, :2].argmax(axis=1)
    events, last = [], None
    for i in range(len(ends)):
        if score[i] < threshold:
            continue
        before = [j for j in range(len(ends)) if 0 < ends[i] - ends[j] <= delay]
        after = [j for j in range(len(ends)) if 0 < ends[j] - ends[i] <= delay]
        if any(score[j] >= score[i] for j in before) or any(score[j] > score[i] for j in after):
            continue
        emit = [j for j in range(len(ends)) if ends[j] >= ends[i] + delay]
        if not emit:
            continue  # the take ends before the look-ahead: undecided
        frame = int(ends[emit[0]])
        if last is None or frame - last >= refractory:
            events.append((frame, CLASSES[best[i]], float(score[i])))
            last = frame
    return events


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(0, 6), min_size=0, max_size=40),
    st.integers(1, 3),
    st.integers(0, 4),
    st.integers(0, 8),
    st.integers(1, 7),
    st.integers(0, 2**31 - 1),
)
def test_maximum_trigger_equals_brute_force_in_any_chunks(
    levels, step, delay, refractory, chunk, seed
):
    # coarse score levels: ties and plateaus are frequent
    rng = np.random.default_rng(seed)
    ends = 3 + step * np.arange(len(levels))
    g = np.array(levels, dtype=float) / 6 * 0.9
    split = rng.uniform(0, 1, len(levels))
    proba = np.column_stack([g * split, g * (1 - split), 1 - g])
    expected = brute_force_maximum(ends, proba, 0.4, refractory, delay)
    rule = dict(threshold=0.4, refractory=refractory, trigger="maximum", delay=delay)
    whole, _ = next_events(ends, proba, CLASSES, 2, state=TriggerState(), **rule)
    assert [tuple(e) for e in whole] == expected
    state, streamed = TriggerState(), []
    for start in range(0, len(ends), chunk):  # the stream's calls: a chunk at a time
        part = slice(start, start + chunk)
        found, state = next_events(ends[part], proba[part], CLASSES, 2, state=state, **rule)
        streamed += found
    assert streamed == whole
    # the stream's one-window path in scalars: the same events
    best, score = gesture_scores(proba, 2)
    state, one_by_one = TriggerState(), []
    for end, column, value in zip(ends, best, score):
        found, state = maximum_step(
            state, int(end), float(value), int(column), CLASSES,
            threshold=0.4, refractory=refractory, delay=delay,
        )  # fmt: skip
        one_by_one += found
    assert one_by_one == whole
    # constant memory: the state keeps at most the windows of the last 2 * delay frames
    assert state.recent is None or len(state.recent) <= 2 * delay + 1


def test_maximum_trigger_by_hand():
    # windows end at frames 0..11 (gesture "a"); at or above 0.5: 1-3, 6-9, 11
    g = np.array([0.1, 0.6, 0.9, 0.7, 0.2, 0.1, 0.5, 0.8, 0.8, 0.6, 0.2, 0.9])
    proba = np.column_stack([g, np.zeros_like(g), 1 - g])
    ends = np.arange(len(g))
    rule = dict(threshold=0.5, refractory=0, trigger="maximum", state=TriggerState())
    events, _ = next_events(ends, proba, CLASSES, 2, delay=2, **rule)
    # frame 2 (0.9) is the highest within 2 frames: emitted 2 frames later, at 4; of the
    # plateau 7-8 the first counts (8 has an equal one before it), emitted at 9; 11 has no
    # window 2 frames after it yet: undecided
    assert [(e.frame, e.label, e.score) for e in events] == [(4, "a", 0.9), (9, "a", 0.8)]
    events, _ = next_events(ends, proba, CLASSES, 2, delay=0, **rule)
    # no look-ahead: every window at or above the threshold is its own maximum
    assert [e.frame for e in events] == [1, 2, 3, 6, 7, 8, 9, 11]
