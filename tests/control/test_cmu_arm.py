"""The right arm of real CMU data: eigenmovements, and the arm model of an ASF skeleton."""

import numpy as np
import pytest

from skmotion.control import ArmModel, KMeansPrimitiveController, simulate_arm
from skmotion.decomposition import EigenMovementPCA
from skmotion.io import read_amc, read_asf
from skmotion.kinematics import forward_kinematics


@pytest.fixture
def cmu_punch(shared_data):
    skeleton = read_asf(shared_data / "cmu-asfamc" / "02" / "02.asf")
    motion = read_amc(shared_data / "cmu-asfamc" / "02" / "02_05.amc", skeleton)
    return skeleton, motion


def test_eigenmovements_of_a_real_right_arm(cmu_punch):
    skeleton, motion = cmu_punch
    arm = ArmModel.from_skeleton(skeleton, ["rhumerus", "rradius"], dofs=["XYZ", "X"], end="rhand")
    idx = [motion.channel_names.index(n) for n in arm.dof_names]
    degrees = np.degrees(np.unwrap(motion.channels[:, idx], axis=0))
    clips = np.array_split(degrees, 6)  # six pieces of one long trial
    pca = EigenMovementPCA(10, frame_rate=motion.frame_rate, min_movement=2.0).fit(clips)
    vectors = np.concatenate(pca.segment_vectors(clips))
    codes = pca.transform(clips)
    rebuilt = np.concatenate(
        [n.transpose(0, 2, 1).reshape(len(n), -1) for n in pca.inverse_transform(codes)]
    )
    np.testing.assert_allclose(
        np.mean(np.sum((vectors - rebuilt) ** 2, axis=1)), pca.projection_mse_, rtol=1e-9
    )
    controller = KMeansPrimitiveController(8, random_state=0).fit(codes)
    quantized = np.concatenate(
        [
            n.transpose(0, 2, 1).reshape(len(n), -1)
            for n in pca.inverse_transform(controller.quantize(codes))
        ]
    )
    np.testing.assert_allclose(
        np.mean(np.sum((vectors - quantized) ** 2, axis=1)),
        pca.projection_mse_ + controller.clustering_mse_,
        rtol=1e-9,
    )


def test_the_arm_of_an_asf_skeleton_follows_its_bone_axes(cmu_punch):
    # ASF joints rotate about their bone axes (C M C^T): the simulated hand must be
    # where forward kinematics puts it, for angles far from the rest pose.
    pytest.importorskip("mujoco")
    skeleton, motion = cmu_punch
    arm = ArmModel.from_skeleton(skeleton, ["rhumerus", "rradius"], dofs=["XYZ", "X"], end="rhand")
    assert arm.dof_names == (
        "rhumerus_Zrotation",
        "rhumerus_Yrotation",
        "rhumerus_Xrotation",
        "rradius_Xrotation",
    )
    idx = [motion.channel_names.index(n) for n in arm.dof_names]
    target = np.unwrap(motion.channels[600:660, idx], axis=0)
    sim = simulate_arm(target, arm=arm, frame_rate=motion.frame_rate, kp=400.0, kd=40.0)
    channels = np.zeros((len(target), skeleton.n_channels))
    channels[:, idx] = sim.angles
    fk = forward_kinematics(skeleton, channels).positions * skeleton.meters_per_unit
    hand = fk[:, skeleton.joint_index("rhand")] - fk[:, skeleton.joint_index("rhumerus")]
    np.testing.assert_allclose(sim.tip, hand, atol=1e-9)
    assert np.degrees(sim.rms_error) < 2.0
