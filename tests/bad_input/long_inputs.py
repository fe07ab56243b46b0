"""Long clips and long motion files, shared by the long-input tests and the benchmark."""

import numpy as np

from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.io import Motion, write_bvh
from skmotion.tree import MotionTreeHMM
from tests.io.test_asf_amc import ASF

# The toy ASF skeleton's AMC frame: its number, then root (6), femur (3), tibia (2), back (1).
_AMC_FRAME = (
    "%d\nroot" + " %.6f" * 6 + "\nfemur" + " %.6f" * 3 + "\ntibia" + " %.6f" * 2 + "\nback %.6f"
)


def fitted_hmm(max_depth=3):
    """A MotionTreeHMM on three classes of synthetic motions, and their frames one after another."""
    data = make_motions(n_clips_per_class=3, classes=["walk", "jog", "jump"], random_state=0)
    X = [c[:, 6:] for c in data.clips]
    model = MotionTreeHMM(max_depth=max_depth).fit(X, data.target_names[data.target])
    return model, np.concatenate(X)


def long_clip(base, n_frames):
    """``base`` repeated until it has ``n_frames`` frames."""
    return np.tile(base, (-(-n_frames // len(base)), 1))[:n_frames]


def humanoid_channels(n_frames):
    data = make_motions(n_clips_per_class=1, classes=["walk", "wave"], n_subjects=1, random_state=0)
    return long_clip(np.concatenate(data.clips), n_frames)


def write_long_bvh(path, n_frames, precision=6):
    """A BVH file of ``n_frames`` humanoid frames; returns the channels written."""
    channels = humanoid_channels(n_frames)
    write_bvh(Motion(humanoid_skeleton(), channels, frame_rate=30.0), path, precision=precision)
    return channels


def write_long_amc(folder, n_frames, seed=0):
    """The toy ASF skeleton and an AMC file of ``n_frames`` frames (degrees).

    Returns (asf, amc, values).
    """
    rng = np.random.default_rng(seed)
    values = np.round(rng.uniform(-60, 60, size=(n_frames, 12)), 6)
    asf, amc = folder / "toy.asf", folder / "long.amc"
    asf.write_text(ASF)
    with open(amc, "w") as fh:
        fh.write(":FULLY-SPECIFIED\n:DEGREES\n")
        np.savetxt(fh, np.c_[np.arange(1, n_frames + 1), values], fmt=_AMC_FRAME)
    return asf, amc, values
