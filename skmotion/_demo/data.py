"""Demo section: what the built-in synthetic data holds."""

import numpy as np
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline

from skmotion._demo._figures import save_animation, save_figure
from skmotion._demo._split import choose_evaluation
from skmotion.datasets import make_motions
from skmotion.preprocessing import FlattenClips, ResampleClips

TITLE = "Data: built-in synthetic motions"


def body_figures(context, clip, skeleton, frame_rate, what):
    """A pose, the clip as poses over time, and a short animation of one clip."""
    lines = save_figure(
        context,
        "pose.png",
        lambda plotting: plotting.plot_pose(clip[0], skeleton, title=f"first pose of {what}"),
        f"the first pose of {what} "
        + (
            "(forward kinematics of its joint angles)"
            if hasattr(skeleton, "forward_kinematics")
            else f"(joint positions, bones of the {skeleton.name} layout)"
        ),
    )
    lines += save_figure(
        context,
        "clip.png",
        lambda plotting: plotting.plot_clip(clip, skeleton, frame_rate=frame_rate),
        f"{what} as poses over time",
    )
    return lines + save_animation(
        context, "clip.gif", clip, skeleton, frame_rate, f"{what}, animated (first 3 s)"
    )


def run(context):
    data = make_motions(random_state=context.random_state)
    context.data = data
    lengths = np.array([len(c) for c in data.clips])
    seconds = lengths.sum() / data.frame_rate
    counts = np.bincount(data.target)
    subjects = np.bincount(data.groups)
    names = data.target_names[data.target]
    evaluation = choose_evaluation(names, data.groups, random_state=context.random_state)
    context.evaluation = evaluation
    baseline = make_pipeline(ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1))
    scores = evaluation.scores(baseline, data.clips, names, verbose=context.verbose)
    context.baseline_accuracy = scores.mean()
    sk = data.skeleton
    lines = [
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
        f"evaluation: {evaluation.reason}",
        f"baseline, 1-NN on resampled raw clips, {evaluation.name}: "
        f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}",
    ]
    what = f"clip 0 ({names[0]}, subject #{data.groups[0]})"
    return lines + body_figures(context, data.clips[0], data.skeletons[0], data.frame_rate, what)
