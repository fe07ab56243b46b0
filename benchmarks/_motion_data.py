"""Data sets shared by the neighbors benchmarks (nothing here is timed)."""

import numpy as np
from _common import SHARED_DATA

from skmotion.datasets import load_cmu_asfamc, load_uea, make_repeated_motions
from skmotion.preprocessing import to_markers

_ROOT_CHANNELS = 6  # CMU ASF root: TX TY TZ RX RY RZ (where the subject is and faces)


def cut_repeats(clips, frame_rate, *, n_repeats=5, duration=(1.0, 2.0), random_state=0):
    """The first ``n_repeats`` consecutive segments of each clip, of random durations.

    Returns the segments and, per segment, the index of the clip it was cut
    from (its label). A clip too short for ``n_repeats`` segments gives fewer.
    """
    rng = np.random.default_rng(random_state)
    segments, labels = [], []
    for label, clip in enumerate(clips):
        lengths = np.round(rng.uniform(*duration, size=n_repeats) * frame_rate).astype(int)
        ends = np.cumsum(lengths)
        for start, end in zip(ends - lengths, ends[ends <= len(clip)]):
            segments.append(clip[start:end])
            labels.append(label)
    return segments, np.asarray(labels)


def cmu_repeats():
    """name -> (segments, labels): CMU trials cut into repeated segments.

    The 28 trials of CMU subjects 01-03 in ``../shared/data/cmu-asfamc``; each
    trial's first five consecutive segments of 1-2 s are its "repetitions"
    (similar = the same trial, the paper's set-up of a motion performed five
    times). Two representations of the same segments: joint angles without the
    root's six channels (56 channels, radians), and virtual markers (192
    channels: body-frame positions and velocities of 32 markers). A third set
    keeps the joint angles of the 14 trials of subjects 02 and 03, each one
    activity (walk, run, punch, swordplay, ...).
    """
    folder = SHARED_DATA / "cmu-asfamc"
    if not folder.is_dir():
        print(f"CMU: not found in {SHARED_DATA}, left out")
        return {}
    data = load_cmu_asfamc(folder, index=SHARED_DATA / "cmu-index.csv")
    markers, _ = to_markers(data.motions)
    angles = [c[:, _ROOT_CHANNELS:] for c in data.clips]
    # Subject 01's playground trials change activity every few seconds (climb,
    # hang, swing, jump down): their segments are not repetitions of one motion.
    steady = [k for k, t in enumerate(data.trials) if not t.startswith("01_")]

    def by_trial(clips, trials):  # labelled by trial id ("02_05")
        segments, labels = cut_repeats(clips, data.frame_rate)
        return segments, np.asarray(trials)[labels]

    return {
        "CMU repeats, joint angles": by_trial(angles, data.trials),
        "CMU repeats, virtual markers": by_trial(markers, data.trials),
        "CMU repeats, joint angles, one-activity trials": by_trial(
            [angles[k] for k in steady], data.trials[steady]
        ),
    }


def search_datasets():
    """name -> (clips, labels): the collections the pruning study queries.

    "synthetic repeated": 63 motions x 5 repetitions, pelvis-relative joint
    positions (similar = the same motion, the paper's set-up); "synthetic by
    class": the same clips, similar = the same class (7 classes); the CMU
    trials cut into repeated segments (:func:`cmu_repeats`); the UEA sets
    with similar = the same class (JapaneseVowels: the speaker).
    """
    data = make_repeated_motions(random_state=0)
    sets = {
        "synthetic repeated": (data.clips, data.target),
        "synthetic by class": (data.clips, data.motion_class),
    }
    sets.update(cmu_repeats())
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
