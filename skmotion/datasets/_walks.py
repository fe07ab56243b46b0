"""Synthetic walks in several directions with their true root velocity (``make_walks``)."""

from numbers import Integral, Real

import numpy as np
from sklearn.utils import Bunch, check_random_state

from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.datasets._motion_generators import (
    _TWO_PI,
    _WALK,
    _bump,
    _check_duration,
    _check_names,
    _gait,
    _Pose,
)
from skmotion.kinematics import forward_kinematics
from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = ["WALK_DIRECTIONS", "make_walks"]

#: Directions of travel relative to the facing, in radians counter-clockwise
#: seen from above (left is positive).
WALK_DIRECTIONS = {"forward": 0.0, "left": np.pi / 2, "backward": np.pi, "right": -np.pi / 2}


def _sideways_gait(pose, phi, sign, amp):
    """Side steps: the leading leg abducts, lifts and lands, the other follows."""
    for side, shift in (("Left", 0.0), ("Right", np.pi)):
        ph = phi + shift
        lead = 1.0 if (side == "Left") == (sign > 0) else 0.6
        pose.hip(
            side,
            6.0 + 10.0 * amp * _bump(ph, 1.2, 0.6),
            abduct=2.0 + 9.0 * lead * amp * (1 + np.sin(ph)) / 2,
        )
        pose.knee(side, 6.0 + 30.0 * amp * _bump(ph, 1.2, 0.6))
        pose.ankle(side, 4.0 * np.sin(ph))
        pose.shoulder(side, 0.0, abduct=8.0 + 4.0 * np.sin(ph))
        pose.elbow(side, 15.0)
    pose.spine(3.0, bend=3.0 * amp * np.sin(phi))
    pose.head(-1.5)


def _walk_clip(skeleton, direction, n_frames, frame_rate, p):
    t = np.arange(n_frames) / frame_rate
    pose = _Pose(skeleton, n_frames)
    angle = WALK_DIRECTIONS[direction]
    if direction in ("left", "right"):
        phi = _TWO_PI * 0.8 * p["tempo"] * t + p["phase"]
        _sideways_gait(pose, phi, np.sign(angle), p["amp"])
        speed = 0.55 * p["scale"] * p["amp"] * p["tempo"] * (1 + 0.1 * np.cos(2 * phi))
    else:
        # A backward walk is a forward gait played in reverse.
        f = 0.9 * p["tempo"] * (1.0 if direction == "forward" else -1.0)
        phi = _TWO_PI * f * t + p["phase"]
        gait = {"amp": p["amp"], "lean": 0.0, "carry": 8.0}
        _gait(pose, phi, gait, **_WALK)
        speed = (
            (1.3 if direction == "forward" else 0.8)
            * p["scale"]
            * p["amp"]
            * p["tempo"]
            * (1 + 0.05 * np.cos(2 * phi))
        )
    yaw = p["heading"] + p["turn"] * t
    # Integrate the travel exactly on the frame grid: frame k moves by speed * dt.
    step = speed / frame_rate
    travel = yaw + angle
    # The humanoid faces +Z with its left at +X: heading yaw faces (sin yaw, cos yaw) in (X, Z).
    x = np.concatenate([[0.0], np.cumsum((step * np.sin(travel))[:-1])]) + p["start"][0]
    z = np.concatenate([[0.0], np.cumsum((step * np.cos(travel))[:-1])]) + p["start"][1]
    channels = np.deg2rad(pose.deg)
    col = {c: skeleton.channel_index("Hips", c) for c in skeleton.channels[0]}
    channels[:, col["Yrotation"]] = yaw
    channels[:, col["Xrotation"]] = np.deg2rad(2.0)
    channels[:, col["Xposition"]] = x
    channels[:, col["Zposition"]] = z
    fk = forward_kinematics(skeleton, channels)
    feet = [
        skeleton.joint_index(j) for j in ("LeftFoot", "RightFoot", "LeftToe_end", "RightToe_end")
    ]
    heights = fk.positions[:, feet, 1]
    heights[:, :2] -= 0.08 * p["scale"]
    channels[:, col["Yposition"]] = -heights.min(axis=1)
    # The true planar velocity of the hips in the facing frame (forward, left), and the yaw rate.
    velocity = np.column_stack(
        [speed * np.cos(angle), speed * np.sin(angle), np.full(n_frames, p["turn"])]
    )
    return channels, velocity


@validate_params(
    {
        "n_clips_per_direction": [Interval(Integral, 1, None, closed="left")],
        "directions": [list, tuple, None],
        "turn": [Interval(Real, 0, None, closed="left")],
        "frame_rate": [Interval(Real, 0, None, closed="neither")],
        "duration": [tuple, list],
        "random_state": ["random_state"],
    },
    prefer_skip_nested_validation=True,
)
def make_walks(
    n_clips_per_direction=3,
    *,
    directions=None,
    turn=0.0,
    frame_rate=30.0,
    duration=(3.0, 4.0),
    random_state=None,
):
    """Generate noise-free walks forward, backward and sideways, with their true root velocity.

    Each clip walks in one direction relative to the subject's facing (side
    steps for ``"left"`` and ``"right"``, a reversed gait for ``"backward"``)
    at a speed that varies within the gait cycle, optionally turning at a
    constant rate. ``root_velocity`` gives the truth a root-motion estimate
    can be tested against: the planar velocity of the hips in the facing
    frame and the yaw rate. :func:`make_motions` is left as it is.

    Parameters
    ----------
    n_clips_per_direction : int, default=3
        Clips per direction.
    directions : sequence of str, default=None
        From :data:`WALK_DIRECTIONS` (``"forward"``, ``"left"``,
        ``"backward"``, ``"right"``); all four by default.
    turn : float, default=0.0
        Largest turning rate in radians per second: each clip turns at a rate
        drawn uniformly from ``[-turn, turn]``.
    frame_rate : float, default=30.0
        Frames per second.
    duration : tuple of (float, float), default=(3.0, 4.0)
        Range of clip durations in seconds.
    random_state : int, RandomState instance or None, default=None
        Seed of all random draws.

    Returns
    -------
    data : Bunch
        clips : list of ndarray of shape (n_frames_i, 66)
            Joint-angle clips of the humanoid (root position in metres, angles in radians).
        target : ndarray of shape (n_clips,)
            Direction index of each clip, into ``target_names``.
        target_names : ndarray of str
            The walking directions.
        root_velocity : list of ndarray of shape (n_frames_i, 3)
            Per frame, the hips' forward and leftward speed (m/s) in the
            facing frame and the yaw rate (rad/s, counter-clockwise from above).
        skeletons : list of Skeleton
            Each clip's skeleton (bone lengths scaled by 0.95-1.05).
        skeleton : Skeleton
            The humanoid at scale 1.
        frame_rate : float
            Frames per second.

    Examples
    --------
    >>> from skmotion.datasets import make_walks
    >>> data = make_walks(1, directions=["forward", "left"], random_state=0)
    >>> data.target_names.tolist(), data.clips[0].shape[1]
    (['forward', 'left'], 66)
    >>> forward, left = data.root_velocity[0], data.root_velocity[1]
    >>> bool(forward[:, 0].mean() > 1.0), bool(abs(left[:, 1].mean() - 0.55) < 0.1)
    (True, True)
    """
    names = tuple(WALK_DIRECTIONS) if directions is None else tuple(directions)
    _check_names("directions", names, WALK_DIRECTIONS)
    _check_duration(duration)
    rng = check_random_state(random_state)
    clips, target, velocity, skeletons = [], [], [], []
    for label, direction in enumerate(names):
        for _ in range(n_clips_per_direction):
            p = {
                "scale": rng.uniform(0.95, 1.05),
                "tempo": rng.uniform(0.9, 1.1),
                "amp": rng.uniform(0.9, 1.1),
                "phase": rng.uniform(0.0, _TWO_PI),
                "heading": rng.uniform(-np.pi, np.pi),
                "turn": rng.uniform(-turn, turn),
                "start": rng.uniform(-2.0, 2.0, size=2),
            }
            skeleton = humanoid_skeleton(p["scale"])
            n_frames = max(4, int(round(rng.uniform(*duration) * frame_rate)))
            channels, truth = _walk_clip(skeleton, direction, n_frames, float(frame_rate), p)
            clips.append(channels)
            velocity.append(truth)
            target.append(label)
            skeletons.append(skeleton)
    return Bunch(
        clips=clips,
        target=np.asarray(target),
        target_names=np.asarray(names),
        root_velocity=velocity,
        skeletons=skeletons,
        skeleton=humanoid_skeleton(),
        frame_rate=float(frame_rate),
    )
