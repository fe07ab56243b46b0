"""Synthetic motions each performed several times in a row (``make_repeated_motions``)."""

from numbers import Integral, Real

import numpy as np
from sklearn.utils import Bunch, check_random_state

from skmotion.datasets._motion_generators import _check_duration
from skmotion.datasets._synthetic import make_motions
from skmotion.kinematics import forward_kinematics
from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = ["make_repeated_motions"]

_ROOT_CHANNELS = 6  # the humanoid's root: 3 positions, then yaw, pitch, roll


def _pelvis_relative_positions(skeleton, channels):
    """Joint positions with the root at the origin, unrotated: (n_frames, 3 * (n_joints - 1))."""
    posture = channels.copy()
    posture[:, :_ROOT_CHANNELS] = 0.0
    positions = forward_kinematics(skeleton, posture).positions[:, 1:, :]
    return positions.reshape(len(channels), -1)


@validate_params(
    {
        "n_motions_per_class": [Interval(Integral, 1, None, closed="left")],
        "n_repeats": [Interval(Integral, 1, None, closed="left")],
        "n_subjects": [Interval(Integral, 1, None, closed="left")],
        "classes": [list, tuple, None],
        "frame_rate": [Interval(Real, 0, None, closed="neither")],
        "duration": [tuple, list],
        "noise": [Interval(Real, 0, None, closed="left")],
        "output": [StrOptions({"positions", "angles"})],
        "random_state": ["random_state"],
    },
    prefer_skip_nested_validation=True,
)
def make_repeated_motions(
    n_motions_per_class=9,
    n_repeats=5,
    *,
    n_subjects=4,
    classes=None,
    frame_rate=30.0,
    duration=(2.0, 4.0),
    noise=1.0,
    output="positions",
    random_state=None,
):
    """Generate motions that are each repeated by several clips.

    The set-up of Li & Prabhakaran's experiments: a database in which every
    motion is performed several times (their 62 body motions, 5 times each).
    Each motion is one long :func:`make_motions` clip (one subject, one tempo,
    amplitude and side); it is cut into ``n_repeats`` consecutive clips of random
    durations, which are its repetitions. Clips of one motion are similar;
    ``target`` tells them apart, ``motion_class`` gives the kind of motion.

    Parameters
    ----------
    n_motions_per_class : int, default=9
        Motions of each class (7 classes give 63 motions).
    n_repeats : int, default=5
        Clips per motion.
    n_subjects : int, default=4
        Number of subjects (the ``groups``).
    classes : sequence of str, default=None
        Classes, from :data:`MOTION_CLASSES`; all seven by default.
    frame_rate : float, default=30.0
        Frames per second.
    duration : tuple of (float, float), default=(2.0, 4.0)
        Range of each clip's duration in seconds.
    noise : float, default=1.0
        Sensor noise scale, as in :func:`make_motions`.
    output : {"positions", "angles"}, default="positions"
        ``"positions"``: 3-D positions (metres) of the 25 non-root joints
        relative to the pelvis, in the pelvis frame (the root's position and
        rotation set to zero before forward kinematics), 75 channels, the
        representation of the paper's experiments. ``"angles"``: the 60
        joint-angle channels without the root's six. Either way, where the
        subject stands and which way it faces play no part.
    random_state : int, RandomState instance or None, default=None
        Seed of all random draws.

    Returns
    -------
    data : Bunch
        clips : list of ndarray of shape (n_frames_i, 75) or (n_frames_i, 60)
            Joint positions per frame.
        target : ndarray of shape (n_clips,)
            Motion id of each clip (``n_repeats`` clips per id).
        motion_class : ndarray of shape (n_clips,)
            Class index of each clip.
        class_names : ndarray of str
            Class names, indexed by ``motion_class``.
        groups : ndarray of shape (n_clips,)
            Subject id of each clip.
        feature_names : list of str
            Channel names.
        frame_rate : float
            Frames per second.

    Examples
    --------
    >>> from skmotion.datasets import make_repeated_motions
    >>> data = make_repeated_motions(n_motions_per_class=2, n_repeats=3, random_state=0)
    >>> len(data.clips), data.clips[0].shape[1], data.target[:6].tolist()
    (42, 75, [0, 0, 0, 1, 1, 1])
    >>> data.class_names[data.motion_class[:6]].tolist()
    ['walk', 'walk', 'walk', 'walk', 'walk', 'walk']
    """
    _check_duration(duration)
    rng = check_random_state(random_state)
    total = n_repeats * float(duration[1])
    source = make_motions(
        n_motions_per_class,
        n_subjects=n_subjects,
        classes=classes,
        frame_rate=frame_rate,
        duration=(total, total),
        noise=noise,
        random_state=rng,
    )
    skeleton = source.skeleton
    if output == "positions":
        names = [f"{j}_{a}" for j in skeleton.joints[1:] for a in "xyz"]
    else:
        names = list(source.feature_names[_ROOT_CHANNELS:])
    clips, target, motion_class, groups = [], [], [], []
    for motion, channels in enumerate(source.clips):
        if output == "positions":
            channels = _pelvis_relative_positions(source.skeletons[motion], channels)
        else:
            channels = channels[:, _ROOT_CHANNELS:]
        lengths = np.maximum(
            1, np.round(rng.uniform(*duration, size=n_repeats) * frame_rate).astype(int)
        )
        starts = np.r_[0, np.cumsum(lengths)[:-1]]
        clips += [np.ascontiguousarray(channels[s : s + n]) for s, n in zip(starts, lengths)]
        target += [motion] * n_repeats
        motion_class += [source.target[motion]] * n_repeats
        groups += [source.groups[motion]] * n_repeats
    return Bunch(
        clips=clips,
        target=np.asarray(target),
        motion_class=np.asarray(motion_class),
        class_names=source.target_names,
        groups=np.asarray(groups),
        feature_names=names,
        frame_rate=float(frame_rate),
        DESCR=make_repeated_motions.__doc__.split("Parameters")[0].strip(),
    )
