"""Demo section: eigenmovements, primitives, and their execution on a simulated arm."""

import numpy as np
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.control import ArmModel, KMeansPrimitiveController
from skmotion.decomposition import EigenMovementPCA

TITLE = "Primitives: eigenmovements of the right arm, K-means controllers"

_ARM_JOINTS = ["RightArm", "RightForeArm"]


def _simulation_lines(controller, pca, codes, segments, data, arm):
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return ['arm simulation: skipped (MuJoCo is not installed: pip install "skmotion[sim]")']
    wave = int(np.flatnonzero(data.target_names[data.target] == "wave")[0])
    lines = []
    for kp in (50.0, 400.0):
        sim = controller.simulate(
            codes[wave : wave + 1], segments[wave : wave + 1], eigenmovements=pca, arm=arm,
            frame_rate=data.frame_rate, degrees=True, kp=kp, kd=kp / 10,
        )[0]
        lines.append(
            f"arm simulation (MuJoCo, PD servos kp={kp:g} N m/rad, kd={kp / 10:g}): a wave clip's "
            f"primitives tracked to RMS {np.degrees(sim.rms_error):.2f} deg"
        )
    return lines


def run(context):
    data = context.data
    sk = data.skeleton
    arm = ArmModel.from_skeleton(sk, _ARM_JOINTS, dofs=["ZXY", "X"], end="RightHand_end")
    idx = [sk.channel_names.index(name) for name in arm.dof_names]
    clips = [np.degrees(c[:, idx]) for c in data.clips]  # the paper's 4 DOF, in degrees

    pca = EigenMovementPCA(10, min_movement=2.0).fit(clips)
    codes, segments = pca.transform(clips), pca.segment(clips)
    controller = KMeansPrimitiveController(20, n_init=3, random_state=context.random_state).fit(codes)
    n_features = pca.components_.shape[1]
    total = pca.projection_mse_ + controller.clustering_mse_
    context.eigenmovements, context.primitives = pca, controller

    angles = [c[:, 6:] for c in data.clips]
    model = make_pipeline(
        EigenMovementPCA(10, n_samples=30),
        KMeansPrimitiveController(20, n_init=3, random_state=context.random_state),
        LogisticRegression(max_iter=2000),
    )
    cv = GroupKFold(len(np.unique(data.groups)))
    scores = cross_val_score(model, angles, data.target, groups=data.groups, cv=cv)
    context.primitive_accuracy = scores.mean()

    lines = [
        f"right arm ({', '.join(arm.dof_names)}), degrees: energy segmentation (SEG-2) of "
        f"{len(clips)} clips gives {pca.n_segments_} segments, "
        f"{pca.n_segments_ / len(clips):.1f} per clip",
        f"10 eigenmovements of {n_features} samples keep "
        f"{100 * pca.explained_variance_ratio_.sum():.2f}% of the variance; projection RMS "
        f"{pca.projection_rms_:.2f} deg per sample (MSE = sum of dropped eigenvalues)",
        f"20 K-means primitives: clustering RMS {np.sqrt(controller.clustering_mse_ / n_features):.2f} "
        f"deg, total {np.sqrt(total / n_features):.2f} deg per sample (projection + clustering)",
        f"clips rebuilt from their segment codes at real timing: RMS {-pca.score(clips):.2f} deg",
        f"classifier on primitive usage (all joint angles, 30 samples per segment, EigenMovementPCA -> "
        f"KMeansPrimitiveController -> LogisticRegression), subject-wise {cv.n_splits}-fold CV: "
        f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}",
    ]
    return lines + _simulation_lines(controller, pca, codes, segments, data, arm)
