"""Data sets shared by the neighbors benchmarks (nothing here is timed)."""

import numpy as np

from _common import SHARED_DATA
from skmotion.datasets import load_uea, make_repeated_motions


def search_datasets():
    """name -> (clips, labels): the collections the pruning study queries.

    "synthetic repeated": 63 motions x 5 repetitions, pelvis-relative joint
    positions (similar = the same motion, the paper's set-up); "synthetic by
    class": the same clips, similar = the same class (7 classes); the UEA sets
    with similar = the same class (JapaneseVowels: the speaker).
    """
    data = make_repeated_motions(random_state=0)
    sets = {
        "synthetic repeated": (data.clips, data.target),
        "synthetic by class": (data.clips, data.motion_class),
    }
    for name in ("JapaneseVowels", "BasicMotions"):
        try:
            uea = load_uea(name, data_home=SHARED_DATA)
        except FileNotFoundError:
            print(f"{name}: not found in {SHARED_DATA}, left out")
            continue
        sets[name] = (uea.clips, uea.target)
    return sets


def crop_pool(n_clips, *, random_state=0):
    """``n_clips`` clips cut at random from long synthetic performances.

    140 motions (20 per class) of 60 s each, pelvis-relative joint positions;
    each clip is a 2-4 s window of one of them (a view, so 100k clips are cheap)
    and its label is that motion.
    """
    rng = np.random.default_rng(random_state)
    source = make_repeated_motions(
        n_motions_per_class=20, n_repeats=1, duration=(60.0, 60.0), random_state=random_state
    )
    motion = rng.integers(0, len(source.clips), size=n_clips)
    length = rng.integers(60, 121, size=n_clips)
    clips = []
    for m, n in zip(motion, length):
        start = rng.integers(0, len(source.clips[m]) - n + 1)
        clips.append(source.clips[m][start : start + n])
    return clips, motion
