"""Tracking joint trajectories with PD servos on a simulated arm (MuJoCo)."""

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

__all__ = ["ArmSimulation", "simulate_arm"]


def _import_mujoco():
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - exercised only without the extra
        raise ImportError(
            'Simulating the arm needs MuJoCo, an optional dependency: pip install "skmotion[sim]"'
        ) from exc
    return mujoco


@dataclass(frozen=True)
class ArmSimulation:
    """What the simulated arm did, frame by frame.

    Attributes
    ----------
    times : ndarray of shape (n_frames,)
        Seconds from the start.
    desired : ndarray of shape (n_frames, n_dof)
        The target joint angles (radians).
    angles : ndarray of shape (n_frames, n_dof)
        The simulated joint angles (radians).
    velocities : ndarray of shape (n_frames, n_dof)
        The simulated joint velocities (rad/s).
    torques : ndarray of shape (n_frames, n_dof)
        The servo torques at each frame (N m).
    tip : ndarray of shape (n_frames, 3)
        World position of the arm's end (metres from the base).

    Frames the target does not cover are NaN in every array.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.control import ArmSimulation
    >>> desired = np.zeros((3, 1))
    >>> sim = ArmSimulation(np.arange(3) / 30, desired, np.array([[0.0], [0.03], [0.04]]),
    ...                     np.zeros((3, 1)), np.zeros((3, 1)), np.zeros((3, 3)))
    >>> round(sim.rms_error, 4)
    0.0289
    """

    times: np.ndarray
    desired: np.ndarray
    angles: np.ndarray
    velocities: np.ndarray
    torques: np.ndarray
    tip: np.ndarray

    @property
    def rms_error(self):
        """RMS tracking error over every joint and covered frame, radians."""
        err = self.angles - self.desired
        return float(np.sqrt(np.nanmean(err**2)))

    @property
    def rms_error_per_dof(self):
        """RMS tracking error of each joint, radians."""
        err = self.angles - self.desired
        return np.sqrt(np.nanmean(err**2, axis=0))


def _gains(value, n_dof, name):
    gains = np.asarray(value, dtype=float)
    if gains.ndim > 1 or (gains.ndim == 1 and len(gains) != n_dof):
        raise ValueError(
            f"{name} must be a number or one number per joint ({n_dof}); got shape {gains.shape}."
        )
    if not (np.isfinite(gains).all() and (gains >= 0).all()):
        raise ValueError(f"{name} must be finite and non-negative; got {gains.tolist()}.")
    return np.broadcast_to(gains, (n_dof,))


def simulate_arm(trajectory, *, arm, frame_rate, kp=200.0, kd=20.0, timestep=0.001):
    """Track a joint trajectory with joint-space PD servos on a simulated arm.

    The arm (an :class:`ArmModel`) is simulated by MuJoCo under gravity. Every
    physics step each joint gets the torque
    ``tau = kp (q_d - q) + kd (qd_d - qd)``, where ``q_d`` and ``qd_d`` come
    from a cubic spline through the target frames. The arm starts on the
    target (angle and velocity). There is no gravity compensation and no torque
    limit, so the error left is what PD servos of these gains leave.

    Parameters
    ----------
    trajectory : ndarray of shape (n_frames, n_dof)
        Target joint angles in radians, at ``frame_rate``, in the order of
        ``arm.dof_names``; at least two frames, all finite.
    arm : ArmModel
        The arm.
    frame_rate : float
        Frames per second of the trajectory.
    kp : float or array-like of shape (n_dof,), default=200.0
        Stiffness, N m per radian.
    kd : float or array-like of shape (n_dof,), default=20.0
        Damping, N m s per radian.
    timestep : float, default=0.001
        Largest physics step in seconds; it is shortened so that a whole number
        of steps makes one frame.

    Returns
    -------
    simulation : ArmSimulation
        The simulated motion at the trajectory's frames.

    Raises
    ------
    ImportError
        Without MuJoCo (``pip install "skmotion[sim]"``).

    Examples
    --------
    >>> import numpy as np
    >>> import pytest; _ = pytest.importorskip("mujoco")  # pip install "skmotion[sim]"
    >>> from skmotion.control import ArmModel, simulate_arm
    >>> from skmotion.datasets import humanoid_skeleton
    >>> arm = ArmModel.from_skeleton(humanoid_skeleton(), ["RightArm", "RightForeArm"],
    ...                              dofs=["ZXY", "X"], end="RightHand_end")
    >>> t = np.arange(60) / 30  # raise the arm forward and bend the elbow, 2 s
    >>> target = np.c_[0 * t, -np.sin(np.pi * t / 2), 0 * t, -0.5 * np.sin(np.pi * t / 2)]
    >>> soft = simulate_arm(target, arm=arm, frame_rate=30, kp=50, kd=5)
    >>> stiff = simulate_arm(target, arm=arm, frame_rate=30, kp=800, kd=80)
    >>> bool(stiff.rms_error < soft.rms_error / 5), stiff.angles.shape
    (True, (60, 4))
    """
    mujoco = _import_mujoco()
    q_target = np.asarray(trajectory, dtype=float)
    if q_target.ndim != 2 or q_target.shape[1] != arm.n_dof or len(q_target) < 2:
        raise ValueError(
            f"trajectory must have shape (n_frames >= 2, {arm.n_dof}) for this arm; "
            f"got {q_target.shape}."
        )
    if not np.isfinite(q_target).all():
        frame, dof = np.argwhere(~np.isfinite(q_target))[0]
        raise ValueError(
            f"trajectory is not finite at frame {frame}, joint {arm.dof_names[dof]!r}."
        )
    if not frame_rate > 0 or not timestep > 0:
        raise ValueError(
            f"frame_rate and timestep must be positive; got {frame_rate!r}, {timestep!r}."
        )
    kp, kd = _gains(kp, arm.n_dof, "kp"), _gains(kd, arm.n_dof, "kd")

    steps_per_frame = max(1, int(np.ceil(1.0 / (frame_rate * timestep) - 1e-9)))
    dt = 1.0 / (frame_rate * steps_per_frame)
    n_frames = len(q_target)
    reference = CubicSpline(np.arange(n_frames) / frame_rate, q_target, axis=0)
    step_times = np.arange((n_frames - 1) * steps_per_frame) * dt
    controls = np.hstack([reference(step_times), reference(step_times, 1)])

    model = mujoco.MjModel.from_xml_string(arm.to_mjcf(kp=kp, kd=kd, timestep=dt))
    data = mujoco.MjData(model)
    data.qpos[:] = q_target[0]
    data.qvel[:] = reference(0.0, 1)
    mujoco.mj_forward(model, data)
    angles = np.empty((n_frames, arm.n_dof))
    velocities = np.empty_like(angles)
    tip = np.empty((n_frames, 3))
    angles[0], velocities[0], tip[0] = data.qpos, data.qvel, data.site_xpos[0]
    # Physics is sequential: one mj_step per physics step, recording every frame.
    for k, control in enumerate(controls, start=1):
        data.ctrl[:] = control
        mujoco.mj_step(model, data)
        if k % steps_per_frame == 0:
            f = k // steps_per_frame
            mujoco.mj_kinematics(model, data)  # site positions of the new state, not the last
            angles[f], velocities[f], tip[f] = data.qpos, data.qvel, data.site_xpos[0]
    times = np.arange(n_frames) / frame_rate
    desired_velocity = reference(times, 1)
    torques = kp * (q_target - angles) + kd * (desired_velocity - velocities)
    return ArmSimulation(times, q_target, angles, velocities, torques, tip)
