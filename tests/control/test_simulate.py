import numpy as np
import pytest

from skmotion.control import ArmModel, KMeansPrimitiveController, simulate_arm
from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.decomposition import EigenMovementPCA
from skmotion.kinematics import forward_kinematics

mujoco = pytest.importorskip("mujoco")

G = 9.81


def right_arm():
    return ArmModel.from_skeleton(
        humanoid_skeleton(), ["RightArm", "RightForeArm"], dofs=["ZXY", "X"], end="RightHand_end"
    )


def rod(length=0.5, radius=0.04):
    """One link hanging along -y, hinged about z at the top."""
    return ArmModel(links=[[0.0, -length, 0.0]], hinges=[[[0.0, 0.0, 1.0]]], radii=[radius])


def reach(n_frames=60, frame_rate=30.0):
    t = np.arange(n_frames) / frame_rate
    s = np.sin(np.pi * t / t[-1])
    return np.c_[0.3 * s, -1.2 * s, 0.4 * np.sin(2 * np.pi * t / t[-1]), -0.8 * s]


def test_masses_come_from_geometry_and_density():
    arm = right_arm()
    model = mujoco.MjModel.from_xml_string(arm.to_mjcf(kp=1.0, kd=1.0))
    np.testing.assert_allclose(model.body_mass[1:], arm.masses, rtol=1e-9)
    np.testing.assert_allclose(
        arm.masses, 1050 * np.pi * np.array([0.045, 0.035]) ** 2 * [0.29, 0.44]
    )


def test_the_simulated_arm_has_the_skeletons_kinematics():
    sk = humanoid_skeleton()
    arm = right_arm()
    sim = simulate_arm(reach(), arm=arm, frame_rate=30)
    channels = np.zeros((len(sim.angles), sk.n_channels))
    channels[:, [sk.channel_names.index(n) for n in arm.dof_names]] = sim.angles
    fk = forward_kinematics(sk, channels).positions
    hand = fk[:, sk.joint_index("RightHand_end")] - fk[:, sk.joint_index("RightArm")]
    np.testing.assert_allclose(sim.tip, hand, atol=1e-10)


def test_without_gains_the_arm_falls_with_the_acceleration_of_a_rigid_rod():
    # Released horizontal, a uniform rod on a hinge starts to fall with
    # alpha = m g (L/2) / I_hinge, I_hinge = m (L^2/3 + r^2/4) (a solid cylinder).
    length, radius = 0.5, 0.04
    alpha = G * (length / 2) / (length**2 / 3 + radius**2 / 4)
    horizontal = np.full((3, 1), np.pi / 2)
    sim = simulate_arm(
        horizontal, arm=rod(length, radius), frame_rate=50, kp=0.0, kd=0.0, timestep=1e-4
    )
    t = sim.times[2]
    np.testing.assert_allclose(np.pi / 2 - sim.angles[2, 0], 0.5 * alpha * t**2, rtol=0.01)
    # And it keeps falling: a second later it has swung through the bottom.
    later = simulate_arm(
        np.full((31, 1), np.pi / 2), arm=rod(length, radius), frame_rate=30, kp=0.0, kd=0.0
    )
    assert later.angles[:, 0].min() < 0.0
    assert later.rms_error > 0.5


def test_a_held_pose_sags_by_the_gravity_torque_over_the_stiffness():
    # PD without gravity compensation settles where kp * e = m g (L/2) cos(e).
    length, radius, kp = 0.5, 0.04, 300.0
    arm = rod(length, radius)
    torque = arm.masses[0] * G * length / 2
    sag = 0.0
    for _ in range(50):
        sag = torque * np.cos(sag) / kp
    sim = simulate_arm(np.full((91, 1), np.pi / 2), arm=arm, frame_rate=30, kp=kp, kd=30.0)
    np.testing.assert_allclose(np.pi / 2 - sim.angles[-1, 0], sag, rtol=1e-3)
    np.testing.assert_allclose(sim.torques[-1, 0], kp * sag, rtol=1e-3)
    assert np.degrees(sag) < 5


def test_tracking_error_falls_as_the_gains_rise():
    errors = [
        simulate_arm(reach(), arm=right_arm(), frame_rate=30, kp=kp, kd=kp / 10).rms_error
        for kp in (25.0, 100.0, 400.0, 1600.0)
    ]
    assert all(a > b for a, b in zip(errors, errors[1:]))
    assert np.degrees(errors[-1]) < 0.2 and np.degrees(errors[0]) > 2


def test_simulation_errors():
    arm = right_arm()
    with pytest.raises(ValueError, match=r"shape \(n_frames >= 2, 4\)"):
        simulate_arm(np.zeros((10, 3)), arm=arm, frame_rate=30)
    bad = np.zeros((10, 4))
    bad[3, 2] = np.nan
    with pytest.raises(ValueError, match="frame 3, joint 'RightArm_Yrotation'"):
        simulate_arm(bad, arm=arm, frame_rate=30)
    with pytest.raises(ValueError, match="kp must be finite and non-negative"):
        simulate_arm(np.zeros((10, 4)), arm=arm, frame_rate=30, kp=-1.0)
    with pytest.raises(ValueError, match=r"one number per joint \(4\)"):
        simulate_arm(np.zeros((10, 4)), arm=arm, frame_rate=30, kd=[1.0, 2.0])


def test_arm_model_errors():
    sk = humanoid_skeleton()
    with pytest.raises(ValueError, match="no rotation channel"):
        ArmModel.from_skeleton(sk, ["RightArm"], dofs=["W"], end="RightForeArm")
    with pytest.raises(ValueError, match="hinges has 1 entries for 2 links"):
        ArmModel(links=[[0, -1, 0], [0, -1, 0]], hinges=[[[1, 0, 0]]], radii=0.1)
    with pytest.raises(ValueError, match="unit 3-vectors"):
        ArmModel(links=[[0, -1, 0]], hinges=[[[2, 0, 0]]], radii=0.1)


def test_controller_executes_primitives_on_the_arm():
    data = make_motions(n_clips_per_class=3, classes=["wave", "punch", "squat"], random_state=0)
    arm = right_arm()
    idx = [data.skeleton.channel_names.index(n) for n in arm.dof_names]
    clips = [np.rad2deg(c[:, idx]) for c in data.clips]
    pca = EigenMovementPCA(8).fit(clips)
    codes, segments = pca.transform(clips), pca.segment(clips)
    controller = KMeansPrimitiveController(6, random_state=0).fit(codes)
    sims = controller.simulate(
        codes[:2],
        segments[:2],
        eigenmovements=pca,
        arm=arm,
        frame_rate=data.frame_rate,
        degrees=True,
        kp=400.0,
        kd=40.0,
    )
    targets = pca.inverse_transform(
        controller.quantize(codes[:2]), segments[:2], n_frames=[len(c) for c in clips[:2]]
    )
    for sim, target in zip(sims, targets):
        covered = ~np.isnan(target).any(axis=1)
        np.testing.assert_allclose(sim.desired[covered], np.deg2rad(target[covered]))
        assert np.isnan(sim.angles[~covered]).all() and not np.isnan(sim.angles[covered]).any()
        assert np.degrees(sim.rms_error) < 2.0
    exact = controller.simulate(
        codes[:1],
        segments[:1],
        eigenmovements=pca,
        arm=arm,
        frame_rate=data.frame_rate,
        degrees=True,
        quantize=False,
    )[0]
    rebuilt = pca.inverse_transform(codes[:1], segments[:1], n_frames=len(clips[0]))[0]
    covered = ~np.isnan(rebuilt).any(axis=1)
    np.testing.assert_allclose(exact.desired[covered], np.deg2rad(rebuilt[covered]))
    with pytest.raises(ValueError, match="8 channels but the arm has 4 joints"):
        wide = EigenMovementPCA(3).fit([np.hstack([c, c]) for c in clips])
        controller.simulate(codes[:1], segments[:1], eigenmovements=wide, arm=arm, frame_rate=30)
