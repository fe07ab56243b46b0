"""MSRC-12 (Fothergill et al., CHI 2012) as the benchmarks use it: repetitions as clips.

The shared copy (``msrc12/msrc12_sequences.npz``) holds 593 Kinect v1 sequences of
about ten repetitions of one gesture by one person, 15 frames/s, with the frame at
which each repetition completes (its action point). The clip-classification
protocol cuts a sequence at its action points: repetition ``k`` runs from the frame
after action point ``k - 1`` up to and including action point ``k`` (the first
from the sequence's start). Cross-subject: odd person ids train, even ids test.
"""

from types import SimpleNamespace

import numpy as np

FRAME_RATE = 15.0
GESTURES = (
    "lift outstretched arms",
    "duck",
    "push right",
    "goggles",
    "wind it up",
    "shoot",
    "bow",
    "throw",
    "had enough",
    "change weapon",
    "beat both",
    "kick",
)
MIN_FRAMES = 4  # a repetition shorter than this is an annotation slip


def msrc12_takes(path):
    """Every sequence as a take ``(n_frames, 60)``, float64, with its action points inside it.

    The stored takes lost their untracked (all-zero) frames, so a few action points
    fall before a take's first frame or past its last: they are left out.

    Returns
    -------
    takes, action_points : list of ndarray
    gesture, person : ndarray of int, one per take (gesture 1-12, person 1-30)
    """
    d = np.load(path)
    positions, offsets = d["positions"], d["offsets"]
    points, point_offsets = d["action_points"], d["action_point_offsets"]
    takes, inside = [], []
    for i in range(len(offsets) - 1):
        take = positions[offsets[i] : offsets[i + 1]].astype(np.float64)
        found = points[point_offsets[i] : point_offsets[i + 1]].astype(np.intp)
        takes.append(take)
        inside.append(found[(found >= 0) & (found < len(take))])
    return takes, inside, np.asarray(d["gesture"]), np.asarray(d["person"])


def msrc12_repetitions(path, *, gestures=None, max_per_sequence=None):
    """The repetitions of every sequence as clips ``(n_frames, 60)``, float64, metres.

    Parameters
    ----------
    path : path-like
        ``msrc12_sequences.npz``.
    gestures : sequence of int, default=None
        Keep these gestures (1-12) only.
    max_per_sequence : int, default=None
        Keep the first repetitions of each sequence only (quick tests).

    Returns
    -------
    data : SimpleNamespace
        ``clips``, ``gesture`` (1-12), ``person`` (1-30), ``sequence`` (index of the
        sequence), one per clip; ``frame_rate``; ``names`` (gesture names).
        Action points before the first tracked frame (negative) start no clip.
    """
    takes, action_points, take_gesture, take_person = msrc12_takes(path)
    clips, gesture, person, sequence = [], [], [], []
    for i, (frames, ends) in enumerate(zip(takes, action_points)):
        if gestures is not None and take_gesture[i] not in gestures:
            continue
        start, kept = 0, 0
        for end in ends:
            if end + 1 - start >= MIN_FRAMES:
                if max_per_sequence is None or kept < max_per_sequence:
                    clips.append(frames[start : end + 1])
                    gesture.append(take_gesture[i])
                    person.append(take_person[i])
                    sequence.append(i)
                    kept += 1
            start = max(start, end + 1)
    return SimpleNamespace(
        clips=clips,
        gesture=np.asarray(gesture),
        person=np.asarray(person),
        sequence=np.asarray(sequence),
        frame_rate=FRAME_RATE,
        names=GESTURES,
    )
