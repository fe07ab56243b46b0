"""Demo section: what the built-in synthetic data holds."""

import numpy as np
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline

from skmotion.datasets import make_motions
from skmotion.preprocessing import FlattenClips, ResampleClips

TITLE = "Data: built-in synthetic motions"


def run(context):
    data = make_motions(random_state=context.random_state)
    context.data = data
    lengths = np.array([len(c) for c in data.clips])
    seconds = lengths.sum() / data.frame_rate
    counts = np.bincount(data.target)
    subjects = np.bincount(data.groups)
    baseline = make_pipeline(ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1))
    scores = cross_val_score(
        baseline, data.clips, data.target, groups=data.groups, cv=GroupKFold(len(subjects))
    )
    context.baseline_accuracy = scores.mean()
    sk = data.skeleton
    return [
        f"make_motions(random_state={context.random_state}): {len(data.clips)} clips, "
        f"{lengths.sum():,} frames at {data.frame_rate:g} Hz ({seconds:.1f} s); "
        f"clip length min {lengths.min()}, median {int(np.median(lengths))}, max {lengths.max()}",
        f"channels: {sk.n_channels} joint-angle channels of a {sk.n_joints}-joint humanoid "
        f"({sk.height():.2f} m, {sk.up_axis}-up)",
        f"classes ({len(counts)}): "
        + ", ".join(f"{name} {n}" for name, n in zip(data.target_names, counts)),
        f"subjects ({len(subjects)}): "
        + ", ".join(
            f"#{s} {n} clips (size x{data.subject_scale[s]:.2f})" for s, n in enumerate(subjects)
        ),
        f"baseline, 1-NN on resampled raw clips, subject-wise {len(subjects)}-fold CV: "
        f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}",
    ]
