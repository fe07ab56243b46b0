"""Synthetic labelled motion clips on the built-in humanoid (``make_motions``)."""

from numbers import Integral, Real

import numpy as np
from scipy.interpolate import CubicSpline
from sklearn.utils import Bunch, check_random_state

from skmotion.datasets._humanoid import humanoid_skeleton
from skmotion.kinematics import forward_kinematics
from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = ["MOTION_CLASSES", "make_motions"]

#: The motion classes :func:`make_motions` can generate, in label order.
MOTION_CLASSES = ("walk", "jog", "jump", "kick", "wave", "punch", "squat")
_LOCOMOTION = frozenset({"walk", "jog"})
_TWO_PI = 2.0 * np.pi


class _Pose:
    """Joint angles (degrees) of one clip, filled by anatomical names.

    Sign conventions of the humanoid (Y up, facing +Z, left is +X): flexion of
    hip and shoulder is a negative X rotation, knee flexion a positive one;
    abduction is +Z on the left and -Z on the right.
    """

    def __init__(self, skeleton, n_frames):
        self.skeleton = skeleton
        self.deg = np.zeros((n_frames, skeleton.n_channels))

    def _add(self, joint, axis, values):
        self.deg[:, self.skeleton.channel_index(joint, f"{axis}rotation")] += values

    def hip(self, side, flex, abduct=0.0):
        self._add(f"{side}UpLeg", "X", -flex)
        self._add(f"{side}UpLeg", "Z", _sign(side) * abduct)

    def knee(self, side, flex):
        self._add(f"{side}Leg", "X", flex)

    def ankle(self, side, dorsiflex):
        self._add(f"{side}Foot", "X", -dorsiflex)

    def shoulder(self, side, flex, abduct=0.0):
        self._add(f"{side}Arm", "X", -flex)
        self._add(f"{side}Arm", "Z", _sign(side) * abduct)

    def elbow(self, side, flex, sideways=0.0):
        self._add(f"{side}ForeArm", "X", -flex)
        self._add(f"{side}ForeArm", "Z", _sign(side) * sideways)

    def spine(self, flex, twist=0.0, bend=0.0):
        for joint in ("Spine", "Chest"):
            self._add(joint, "X", flex / 2)
            self._add(joint, "Y", twist / 2)
            self._add(joint, "Z", bend / 2)

    def head(self, flex, turn=0.0):
        self._add("Neck", "X", flex / 2)
        self._add("Head", "X", flex / 2)
        self._add("Head", "Y", turn)


def _sign(side):
    return 1.0 if side == "Left" else -1.0


def _other(side):
    return "Right" if side == "Left" else "Left"


def _bump(phase, center, width):
    """A smooth periodic bump of height 1 at ``center`` (radians)."""
    d = np.angle(np.exp(1j * (phase - center)))
    return np.exp(-0.5 * (d / width) ** 2)


def _keyframes(u, points):
    """Periodic cubic spline through ``(u, value)`` keyframes, u in [0, 1)."""
    knots, values = np.asarray(points, dtype=float).T
    knots = np.r_[knots, 1.0]
    values = np.r_[values, values[0]]
    return CubicSpline(knots, values, bc_type="periodic")(np.mod(u, 1.0))


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


# -- the motion classes ---------------------------------------------------------
# Each generator fills the pose and returns (forward speed in m/s per frame,
# extra root height in m per frame, root pitch in degrees per frame).


# The walk's and the run's parameters of _gait (angles in degrees); a backward walk reuses _WALK.
_WALK = dict(hip=(4, 22), knee=(5, 55, -0.35), stance=12, ankle=8, arm=16, elbow=(12, 10), lean=2)
_RUN = dict(hip=(8, 32), knee=(15, 85, -0.5), stance=20, ankle=15, arm=28, elbow=(80, 15), lean=8)


def _gait(pose, phi, p, *, hip, knee, stance, ankle, arm, elbow, lean):
    amp = p["amp"]
    for side, shift in (("Left", 0.0), ("Right", np.pi)):
        ph = phi + shift
        pose.hip(side, hip[0] + hip[1] * amp * np.sin(ph), abduct=2.0)
        pose.knee(
            side, knee[0] + knee[1] * amp * _bump(ph, knee[2], 0.75) + stance * _bump(ph, 1.9, 0.4)
        )
        pose.ankle(side, ankle * np.sin(ph - 0.8))
        pose.shoulder(side, -arm * amp * np.sin(ph), abduct=p["carry"])
        pose.elbow(side, elbow[0] + elbow[1] * (1 - np.sin(ph)) / 2)
    pose.spine(lean + p["lean"], twist=5.0 * amp * np.sin(phi))
    pose.head(-lean / 2)


def _walk(pose, t, p):
    f = 0.95 * p["tempo"]
    phi = _TWO_PI * f * t + p["phase"]
    _gait(pose, phi, p, **_WALK)
    speed = 1.4 * p["scale"] * np.sqrt(p["amp"]) * f * (1 + 0.05 * np.cos(2 * phi))
    return speed, np.zeros_like(t), np.full_like(t, 2.0)


def _jog(pose, t, p):
    f = 1.4 * p["tempo"]
    phi = _TWO_PI * f * t + p["phase"]
    _gait(pose, phi, p, **_RUN)
    speed = 1.9 * p["scale"] * np.sqrt(p["amp"]) * f * (1 + 0.08 * np.cos(2 * phi))
    flight = 0.05 * p["scale"] * p["amp"] * _bump(2 * phi, np.pi / 2, 0.6)
    return speed, flight, np.full_like(t, 5.0)


def _jump(pose, t, p):
    f = p["tempo"] / 1.3
    u = f * t + p["phase"] / _TWO_PI
    depth = p["amp"] * _keyframes(
        u,
        [
            (0, 0),
            (0.12, 0.25),
            (0.30, 1.0),
            (0.40, 0.0),
            (0.52, 0.12),
            (0.64, 0.0),
            (0.72, 0.7),
            (0.86, 0.2),
        ],
    )
    arms = p["amp"] * _keyframes(
        u, [(0, 0), (0.30, -45), (0.40, 120), (0.55, 150), (0.64, 90), (0.75, 10)]
    )
    for side in ("Left", "Right"):
        pose.hip(side, 75 * depth)
        pose.knee(side, 105 * depth)
        pose.ankle(side, 28 * depth)
        pose.shoulder(side, arms, abduct=p["carry"])
        pose.elbow(side, 15 + 10 * depth)
    pose.spine(28 * depth + p["lean"])
    pose.head(-10 * depth)
    s = np.mod(u, 1.0)
    in_air = (s >= 0.40) & (s < 0.64)
    w = (s - 0.40) / 0.24
    flight = np.where(in_air, 4 * 0.3 * p["scale"] * p["amp"] * w * (1 - w), 0.0)
    speed = np.where(in_air, p["hop"] * f / 0.24, 0.0)
    return speed, flight, 10 * depth


def _kick(pose, t, p):
    f = p["tempo"] / 1.6
    u = f * t + p["phase"] / _TWO_PI
    kick, support = p["side"], _other(p["side"])
    amp = p["amp"]
    pose.hip(
        kick,
        amp * _keyframes(u, [(0, 0), (0.25, 5), (0.38, 60), (0.48, 80), (0.60, 30), (0.75, 0)]),
    )
    pose.knee(
        kick, _keyframes(u, [(0, 5), (0.25, 10), (0.38, 95), (0.48, 10), (0.60, 50), (0.75, 10)])
    )
    pose.ankle(kick, _keyframes(u, [(0, 0), (0.38, 5), (0.48, -20), (0.60, 0)]))
    strike = _keyframes(u, [(0, 0), (0.25, 0.1), (0.45, 1.0), (0.60, 0.5), (0.75, 0.0)])
    pose.hip(support, 8 + 4 * strike)
    pose.knee(support, 12 + 10 * strike)
    pose.shoulder(support, 35 * amp * strike, abduct=p["carry"] + 20 * strike)
    pose.shoulder(kick, -25 * amp * strike, abduct=p["carry"] + 20 * strike)
    for side in ("Left", "Right"):
        pose.elbow(side, 20 + 30 * strike)
    pose.spine(p["lean"] - 12 * strike, twist=_sign(kick) * 8 * strike)
    pose.head(8 * strike)
    return np.zeros_like(t), np.zeros_like(t), -4 * strike


def _wave(pose, t, p):
    omega = _TWO_PI * 2.0 * p["tempo"]
    raised = _smoothstep((t - p["onset"]) / 0.6)
    arm, rest = p["side"], _other(p["side"])
    swing = np.sin(omega * t + p["phase"])
    pose.shoulder(
        arm, 20 * raised, abduct=raised * (100 + 10 * p["amp"] * swing) + (1 - raised) * p["carry"]
    )
    pose.elbow(
        arm,
        10 * raised,
        sideways=raised * (55 + 30 * p["amp"] * np.sin(omega * t + p["phase"] + 0.3)),
    )
    pose.shoulder(rest, 0.0, abduct=p["carry"])
    pose.elbow(rest, 10.0)
    sway = np.sin(0.5 * omega * t)
    for side in ("Left", "Right"):
        pose.hip(side, 3.0, abduct=2 * _sign(side) * sway)
        pose.knee(side, 5.0)
    pose.spine(p["lean"], bend=-_sign(arm) * 4 * raised)
    pose.head(0.0, turn=_sign(arm) * 15 * raised)
    return np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)


def _punch(pose, t, p):
    f = 1.1 * p["tempo"]
    phi = _TWO_PI * f * t + p["phase"]
    amp = p["amp"]
    lead = p["side"]
    hits = {"Left": _bump(phi, 0.0, 0.35), "Right": _bump(phi, np.pi, 0.35)}
    for side, hit in hits.items():
        pose.shoulder(side, 45 + 45 * amp * hit, abduct=15 - 10 * hit)
        pose.elbow(side, np.maximum(115 - 110 * amp * hit, 0.0))
        pose.hip(side, 12 + (15 if side == lead else -10))
        pose.knee(side, 15.0 + 4.0 * np.sin(2 * phi))  # bouncing in the stance
    pose.spine(p["lean"] + 5, twist=-18 * amp * (hits["Left"] - hits["Right"]))
    pose.head(-5.0)
    return np.zeros_like(t), np.zeros_like(t), np.full_like(t, 3.0)


def _squat(pose, t, p):
    f = p["tempo"] / 2.6
    u = f * t + p["phase"] / _TWO_PI
    depth = p["amp"] * ((1 - np.cos(_TWO_PI * u)) / 2) ** 1.2
    for side in ("Left", "Right"):
        pose.hip(side, 95 * depth, abduct=8 * depth)
        pose.knee(side, 120 * depth)
        pose.ankle(side, 30 * depth)
        pose.shoulder(side, 85 * depth, abduct=p["carry"])
        pose.elbow(side, 10.0)
    pose.spine(35 * depth + p["lean"])
    pose.head(-20 * depth)
    return np.zeros_like(t), np.zeros_like(t), 10 * depth


_GENERATORS = {
    "walk": _walk,
    "jog": _jog,
    "jump": _jump,
    "kick": _kick,
    "wave": _wave,
    "punch": _punch,
    "squat": _squat,
}


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
    unknown = [c for c in names if c not in MOTION_CLASSES]
    if unknown or not names or len(set(names)) != len(names):
        raise ValueError(
            f"classes must be distinct names from {list(MOTION_CLASSES)}; got {list(names)}."
        )
    if len(duration) != 2 or not 0 < duration[0] <= duration[1]:
        raise ValueError(
            f"duration must be (min, max) seconds with 0 < min <= max; got {duration!r}."
        )
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
