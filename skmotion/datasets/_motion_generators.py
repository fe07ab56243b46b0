"""The motion classes of the synthetic data: joint-angle generators on the humanoid.

Each generator fills a :class:`_Pose` (degrees, by anatomical names) for one
clip and returns the root's forward speed, extra height and pitch per frame;
:mod:`skmotion.datasets._synthetic` assembles clips from them.
"""

import numpy as np
from scipy.interpolate import CubicSpline

_TWO_PI = 2.0 * np.pi


def _check_names(what, names, allowed):
    """Refuse ``names`` unless they are distinct, at least one, and all in ``allowed``."""
    unknown = [n for n in names if n not in allowed]
    if unknown or not names or len(set(names)) != len(names):
        raise ValueError(f"{what} must be distinct names from {list(allowed)}; got {list(names)}.")


def _check_duration(duration):
    """Refuse a ``duration`` that is not ``(min, max)`` seconds with ``0 < min <= max``."""
    if len(duration) != 2 or not 0 < duration[0] <= duration[1]:
        raise ValueError(
            f"duration must be (min, max) seconds with 0 < min <= max; got {duration!r}."
        )


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
