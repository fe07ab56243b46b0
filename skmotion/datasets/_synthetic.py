"""Synthetic labelled motion clips on the built-in humanoid (``make_motions``)."""

from numbers import Integral, Real

import numpy as np
from sklearn.utils import Bunch, check_random_state

from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.datasets._motion_generators import (
    _GENERATORS,
    _TWO_PI,
    _check_duration,
    _check_names,
    _other,
    _Pose,
)
from skmotion.kinematics import forward_kinematics
from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = ["MOTION_CLASSES", "make_motions"]

#: The motion classes :func:`make_motions` can generate, in label order.
MOTION_CLASSES = ("walk", "jog", "jump", "kick", "wave", "punch", "squat")
_LOCOMOTION = frozenset({"walk", "jog"})


# -- assembling a clip ------------------------------------------------------------


def _root_channels(skeleton, pose, t, p, speed, flight, pitch):
    """Root yaw, pitch, travel on the floor and height with the feet on the floor."""
    frame_time = t[1] - t[0] if len(t) > 1 else 1.0
    yaw = p["heading"] + p["turn"] * t
    yaw_rad = np.deg2rad(yaw)
    step = speed * frame_time
    x = p["start"][0] + np.cumsum(step * np.sin(yaw_rad)) - step[0] * np.sin(yaw_rad[0])
    z = p["start"][1] + np.cumsum(step * np.cos(yaw_rad)) - step[0] * np.cos(yaw_rad[0])
    channels = np.deg2rad(pose.deg)
    cols = {c: skeleton.channel_index("Hips", c) for c in skeleton.channels[0]}
    channels[:, cols["Yrotation"]] = yaw_rad
    channels[:, cols["Xrotation"]] = np.deg2rad(pitch)
    channels[:, cols["Xposition"]] = x
    channels[:, cols["Zposition"]] = z
    channels[:, cols["Yposition"]] = 0.0
    # Put the lowest point of the feet on the floor, then add any flight.
    fk = forward_kinematics(skeleton, channels)
    idx = [
        skeleton.joint_index(j) for j in ("LeftFoot", "RightFoot", "LeftToe_end", "RightToe_end")
    ]
    heights = fk.positions[:, idx, 1]
    heights[:, :2] -= 0.08 * p["scale"]  # the sole lies below the ankle joint
    channels[:, cols["Yposition"]] = -heights.min(axis=1) + flight
    return channels


def _subject_style(rng):
    return {
        "scale": rng.uniform(0.88, 1.12),
        "tempo": float(np.clip(rng.normal(1.0, 0.07), 0.85, 1.15)),
        "amp": float(np.clip(rng.normal(1.0, 0.10), 0.75, 1.25)),
        "lean": rng.normal(0.0, 3.0),
        "carry": rng.normal(8.0, 3.0),
        "left_handed": rng.uniform() < 0.25,
        "class_amp": {
            name: float(np.clip(rng.normal(1.0, 0.08), 0.8, 1.2)) for name in MOTION_CLASSES
        },
    }


def _clip_params(name, subject, rng):
    dominant = "Left" if subject["left_handed"] else "Right"
    side = dominant if rng.uniform() < 0.8 else _other(dominant)
    locomotion = name in _LOCOMOTION
    return {
        "scale": subject["scale"],
        "tempo": subject["tempo"] * float(np.clip(rng.normal(1.0, 0.08), 0.8, 1.2)),
        "amp": subject["amp"]
        * subject["class_amp"][name]
        * float(np.clip(rng.normal(1.0, 0.10), 0.75, 1.25)),
        "lean": subject["lean"],
        "carry": subject["carry"],
        "side": side,
        "phase": rng.uniform(0.0, _TWO_PI),
        "heading": rng.uniform(0.0, 360.0),
        "turn": rng.normal(0.0, 20.0 if locomotion else 3.0),
        "start": rng.uniform(-2.0, 2.0, size=2),
        "hop": rng.uniform(0.0, 0.3),
        "onset": rng.uniform(-0.6, 0.4),
    }


def _make_clip(name, skeleton, n_frames, frame_rate, params, noise, rng):
    t = np.arange(n_frames) / frame_rate
    pose = _Pose(skeleton, n_frames)
    speed, flight, pitch = _GENERATORS[name](pose, t, params)
    channels = _root_channels(skeleton, pose, t, params, speed, flight, pitch)
    if noise:
        is_pos = np.array([c.endswith("position") for c in skeleton.channel_names])
        sigma = np.where(is_pos, 0.003, np.deg2rad(0.5)) * noise
        channels += rng.normal(size=channels.shape) * sigma
    return channels


@validate_params(
    {
        "n_clips_per_class": [Interval(Integral, 1, None, closed="left")],
        "n_subjects": [Interval(Integral, 1, None, closed="left")],
        "classes": [list, tuple, None],
        "frame_rate": [Interval(Real, 0, None, closed="neither")],
        "duration": [tuple, list],
        "noise": [Interval(Real, 0, None, closed="left")],
        "return_X_y": ["boolean"],
        "random_state": ["random_state"],
    },
    prefer_skip_nested_validation=True,
)
def make_motions(
    n_clips_per_class=12,
    *,
    n_subjects=4,
    classes=None,
    frame_rate=30.0,
    duration=(2.0, 4.0),
    noise=1.0,
    return_X_y=False,
    random_state=None,
):
    """Generate labelled joint-angle clips of a humanoid performing motions.

    Seven classes share the same joints in different ways (legs in walk, jog,
    jump, kick and squat; arms in wave, punch and jog; the root's height in jump
    and squat), so they are distinguishable but not trivially. Each subject has
    a body size (bone lengths scaled by 0.88-1.12), a tempo, an amplitude, a
    posture (trunk lean, arm carry) and a dominant side for kick, wave and punch;
    each clip varies its speed, amplitude, duration, start phase, start position
    and heading. Walks and jogs travel and turn. The root height keeps the
    lowest point of the feet on the floor (plus flight in jumps and jogs).
    Sensor noise is added to every channel.

    Parameters
    ----------
    n_clips_per_class : int, default=12
        Clips of each class; they are shared round-robin among the subjects, so
        with ``n_clips_per_class >= n_subjects`` every subject performs every class.
    n_subjects : int, default=4
        Number of subjects (the ``groups``).
    classes : sequence of str, default=None
        Classes to generate, from :data:`MOTION_CLASSES`; all seven by default.
    frame_rate : float, default=30.0
        Frames per second.
    duration : tuple of (float, float), default=(2.0, 4.0)
        Range of clip durations in seconds.
    noise : float, default=1.0
        Scale of the sensor noise: 1.0 adds Gaussian noise of 0.5 degrees to
        angles and 3 mm to positions; 0 gives noise-free clips.
    return_X_y : bool, default=False
        Return ``(clips, target)`` instead of a Bunch.
    random_state : int, RandomState instance or None, default=None
        Seed of all random draws; the same seed gives the same clips.

    Returns
    -------
    data : Bunch
        clips : list of ndarray of shape (n_frames_i, 66)
            Joint-angle clips: the root position (metres) and rotation, then
            three rotations per joint (radians), in ``skeleton.channel_names`` order.
        target : ndarray of shape (n_clips,)
            Class index of each clip.
        target_names : ndarray of str
            Class names, indexed by ``target``.
        groups : ndarray of shape (n_clips,)
            Subject id of each clip, for ``GroupKFold``.
        skeleton : Skeleton
            The humanoid at scale 1 (a 1.75 m adult).
        skeletons : list of Skeleton
            Each clip's subject-sized skeleton; a clip's root positions are in
            its subject's size, so ``skeletons[i]`` reproduces it exactly.
        subject_scale : ndarray of shape (n_subjects,)
            Bone length scale of each subject.
        frame_rate : float
            Frames per second.
        feature_names : list of str
            The channel names.
        DESCR : str
            This description.
    (clips, target) : tuple
        With ``return_X_y=True``.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> data = make_motions(n_clips_per_class=4, random_state=0)
    >>> len(data.clips), data.clips[0].shape[1], data.target_names[:3].tolist()
    (28, 66, ['walk', 'jog', 'jump'])
    >>> sorted(set(data.groups.tolist()))
    [0, 1, 2, 3]
    """
    names = MOTION_CLASSES if classes is None else tuple(classes)
    _check_names("classes", names, MOTION_CLASSES)
    _check_duration(duration)
    rng = check_random_state(random_state)
    subjects = [_subject_style(rng) for _ in range(n_subjects)]
    reference = humanoid_skeleton()
    sized = [humanoid_skeleton(s["scale"]) for s in subjects]
    min_frames = 4
    clips, target, groups, skeletons = [], [], [], []
    for label, name in enumerate(names):
        for k in range(n_clips_per_class):
            subject = k % n_subjects
            params = _clip_params(name, subjects[subject], rng)
            n_frames = max(min_frames, int(round(rng.uniform(*duration) * frame_rate)))
            clips.append(_make_clip(name, sized[subject], n_frames, frame_rate, params, noise, rng))
            target.append(label)
            groups.append(subject)
            skeletons.append(sized[subject])
    target = np.asarray(target)
    if return_X_y:
        return clips, target
    return Bunch(
        clips=clips,
        target=target,
        target_names=np.asarray(names),
        groups=np.asarray(groups),
        skeleton=reference,
        skeletons=skeletons,
        subject_scale=np.array([s["scale"] for s in subjects]),
        frame_rate=float(frame_rate),
        feature_names=list(reference.channel_names),
        DESCR=make_motions.__doc__.split("Parameters")[0].strip(),
    )
