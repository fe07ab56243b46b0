"""Demo section (with ``skmotion demo --data FOLDER``): real motion files instead of the synthetic data."""

import numpy as np
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline
from sklearn.utils import Bunch

from skmotion.datasets import load_motion_folder
from skmotion.preprocessing import FlattenClips, ResampleClips, resample_clip, to_markers

TITLE = "Data: motion files"


def to_rate(clip, frame_rate, target_rate):
    """A clip resampled from ``frame_rate`` to ``target_rate`` Hz (linear, same duration)."""
    if frame_rate == target_rate:
        return clip
    n_out = int(np.floor((len(clip) - 1) * target_rate / frame_rate + 1e-9)) + 1
    return resample_clip(clip, np.arange(n_out) * frame_rate / target_rate)


def _unwrapped(motion):
    """Channels with rotation angles unwrapped in time, so that interpolation never crosses a +-pi jump."""
    channels = motion.channels.copy()
    rotations = np.array([name.endswith("rotation") for name in motion.channel_names], dtype=bool)
    channels[:, rotations] = np.unwrap(channels[:, rotations], axis=0)
    return channels


def run(context):
    rate = float(getattr(context, "frame_rate", None) or 30.0)
    data = load_motion_folder(context.data_folder)
    motions = data.motions
    layouts = {tuple(m.channel_names) for m in motions}
    if len(layouts) == 1:
        kind = "joint angles"
        clips = [to_rate(_unwrapped(m), m.frame_rate, rate) for m in motions]
        feature_names = list(motions[0].channel_names)
        skeleton = motions[0].skeleton
    else:
        # Different skeletons share no channels: their virtual markers share one feature space.
        kind = "virtual markers (the files hold several skeletons)"
        marker_clips, names = to_markers(motions)
        clips = [to_rate(c, m.frame_rate, rate) for c, m in zip(marker_clips, motions)]
        feature_names = list(names)
        skeleton = None
    context.data = Bunch(
        clips=clips,
        target=data.target,
        target_names=data.target_names,
        groups=data.groups,
        subject_names=data.subject_names,
        frame_rate=rate,
        motions=motions,
        skeletons=data.skeletons,
        skeleton=skeleton,
        feature_names=feature_names,
        filenames=data.filenames,
        DESCR=data.DESCR,
    )
    lengths = np.array([len(c) for c in clips])
    rates = sorted({m.frame_rate for m in motions})
    n_bvh = sum(str(f).lower().endswith(".bvh") for f in data.filenames)
    lines = [
        f"{context.data_folder}: {len(motions)} clips ({n_bvh} BVH, {len(motions) - n_bvh} ASF/AMC), "
        f"{len({m.skeleton for m in motions})} skeletons, recorded at {', '.join(f'{r:g}' for r in rates)} Hz",
        f"resampled to {rate:g} Hz: {lengths.sum():,} frames ({lengths.sum() / rate:.1f} s); clip length min "
        f"{lengths.min()}, median {int(np.median(lengths))}, max {lengths.max()}",
        f"channels: {len(feature_names)} {kind}",
        f"classes ({len(data.target_names)}): "
        + ", ".join(f"{name} {n}" for name, n in zip(data.target_names, np.bincount(data.target))),
        f"subjects ({len(data.subject_names)}): "
        + ", ".join(f"{name} {n}" for name, n in zip(data.subject_names, np.bincount(data.groups))),
    ]
    n_groups = len(data.subject_names)
    if n_groups >= 2:
        baseline = make_pipeline(
            ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1)
        )
        scores = cross_val_score(
            baseline, clips, data.target, groups=data.groups, cv=GroupKFold(min(n_groups, 5))
        )
        context.baseline_accuracy = scores.mean()
        lines.append(
            f"baseline, 1-NN on resampled clips, subject-wise {min(n_groups, 5)}-fold CV: "
            f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}"
        )
    else:
        lines.append("one subject only: no subject-wise baseline")
    return lines
