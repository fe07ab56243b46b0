"""Demo section: eigenmovements, primitives, and their execution on a simulated arm."""

from importlib.util import find_spec

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline

from skmotion._demo._split import evaluation_of
from skmotion.control import ArmModel, KMeansPrimitiveController
from skmotion.decomposition import EigenMovementPCA
from skmotion.preprocessing import filter_min_frames, segment_clip

TITLE = "Primitives: eigenmovements of the right arm, K-means controllers"

# The paper's 4 DOF (shoulder 3, elbow flexion) on the skeletons skmotion knows:
# (upper arm, its axes, forearm, its axis, where the hand ends).
_ARMS = (
    ("RightArm", "ZXY", "RightForeArm", "X", "RightHand_end"),  # the built-in humanoid
    ("rhumerus", "XYZ", "rradius", "X", "rhand"),  # CMU ASF
)
_MIN_MOVEMENT = 2.0  # degrees


def _right_arm(data):
    """Channel indices of the right arm's 4 DOF and, when lengths are known, its ArmModel."""
    names = list(data.feature_names)
    for upper, upper_axes, fore, fore_axis, end in _ARMS:  # noqa: B007 (used after break)
        wanted = [f"{upper}_{a}rotation" for a in upper_axes] + [f"{fore}_{fore_axis}rotation"]
        if all(w in names for w in wanted):
            break
    else:
        return None, None
    skeleton = data.get("skeleton")
    if skeleton is None or skeleton.meters_per_unit is None or end not in skeleton.joints:
        return [names.index(w) for w in wanted], None
    arm = ArmModel.from_skeleton(skeleton, [upper, fore], dofs=[upper_axes, fore_axis], end=end)
    return [names.index(w) for w in arm.dof_names], arm


def _classifier_lines(context, data):
    skeleton = data.get("skeleton")
    n_root = len(skeleton.channels[0]) if skeleton is not None else 0
    angles = [c[:, n_root:] for c in data.clips]  # without the root's travel and heading
    evaluation = evaluation_of(context)
    if evaluation.kind is None or len(evaluation.clips) < 20:
        why = evaluation.reason if evaluation.kind is None else f"{len(evaluation.clips)} clips"
        return [f"classifier on primitive usage: not run ({why}; it needs 20 clips or more)"]
    model = make_pipeline(
        EigenMovementPCA(10, n_samples=30, frame_rate=data.frame_rate),
        KMeansPrimitiveController(20, n_init=3, random_state=context.random_state),
        LogisticRegression(max_iter=2000),
    )
    scores = evaluation.scores(
        model, angles, data.target, verbose=getattr(context, "verbose", 0), desc="primitives CV"
    )
    context.primitive_accuracy = scores.mean()
    return [
        "classifier on primitive usage (joint angles, EigenMovementPCA -> "
        f"KMeansPrimitiveController -> LogisticRegression), {evaluation.name}: accuracy "
        f"{scores.mean():.3f} +/- {scores.std():.3f}"
    ]


def _simulation_lines(context, clips, codes, segments, data, arm):
    if arm is None:
        return ["arm simulation: not run (the skeleton's segment lengths are unknown)"]
    if not find_spec("mujoco"):
        return ['arm simulation: not run (MuJoCo is not installed: pip install "skmotion[sim]")']
    lengths = [len(c) for c in codes]
    clip = int(np.argmax(lengths))
    lines = []
    for kp in (50.0, 400.0):
        sim = context.primitives.simulate(
            codes[clip : clip + 1],
            segments[clip : clip + 1],
            eigenmovements=context.eigenmovements,
            arm=arm,
            frame_rate=data.frame_rate,
            degrees=True,
            kp=kp,
            kd=kp / 10,
        )[0]
        lines.append(
            f"arm simulation (MuJoCo, PD servos kp={kp:g} N m/rad, kd={kp / 10:g}): clip {clip}'s "
            f"{lengths[clip]} primitives tracked to RMS {np.degrees(sim.rms_error):.2f} deg"
        )
    return lines


def run(context):
    data = context.data
    idx, arm = _right_arm(data)
    if idx is None:
        return [
            "not run: no right arm (RightArm/RightForeArm or rhumerus/rradius rotations) in "
            "the channels"
        ]
    clips = [np.degrees(c[:, idx]) for c in data.clips]  # the paper's 4 DOF, in degrees
    names = [data.feature_names[i] for i in idx]
    # The paper's order-10 filter needs 34 frames; shorter clips are segmented unfiltered.
    order = 10 if min(len(c) for c in clips) >= filter_min_frames(10, 0.25) else None
    n_segments = sum(
        len(segment_clip(c, filter_order=order, min_movement=_MIN_MOVEMENT)) for c in clips
    )
    if n_segments < 2:
        return [f"not run: the right arm's {len(clips)} clips hold {n_segments} segment(s)"]

    pca = EigenMovementPCA(min(10, n_segments), filter_order=order, min_movement=_MIN_MOVEMENT).fit(
        clips
    )
    codes, segments = pca.transform(clips), pca.segment(clips)
    n_clusters = min(20, n_segments)
    controller = KMeansPrimitiveController(
        n_clusters, n_init=3, random_state=context.random_state
    ).fit(codes)
    context.eigenmovements, context.primitives = pca, controller
    n_features = pca.components_.shape[1]
    total = pca.projection_mse_ + controller.clustering_mse_
    lines = [
        f"right arm ({', '.join(names)}), degrees: energy segmentation (SEG-2) of "
        f"{len(clips)} clips gives {pca.n_segments_} segments, "
        f"{pca.n_segments_ / len(clips):.1f} per clip"
        + ("" if order else " (clips too short for the order-10 low-pass: not filtered)"),
        f"{pca.n_components_} eigenmovements of {n_features} samples keep "
        f"{100 * pca.explained_variance_ratio_.sum():.2f}% of the variance; projection RMS "
        f"{pca.projection_rms_:.2f} deg per sample (MSE = sum of dropped eigenvalues)",
        f"{n_clusters} K-means primitives: clustering RMS "
        f"{np.sqrt(controller.clustering_mse_ / n_features):.2f} deg, total "
        f"{np.sqrt(total / n_features):.2f} deg per sample (projection + clustering)",
        f"clips rebuilt from their segment codes at real timing: RMS {-pca.score(clips):.2f} deg",
    ]
    lines += _classifier_lines(context, data)
    return lines + _simulation_lines(context, clips, codes, segments, data, arm)
