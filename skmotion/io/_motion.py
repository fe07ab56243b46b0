"""The Motion: one clip read from a file, with the skeleton it belongs to."""

from numbers import Real

import numpy as np

from skmotion.kinematics import Skeleton, forward_kinematics

__all__ = ["Motion", "as_motions"]


class Motion:
    """One motion clip with its skeleton: what the file readers return.

    A ``Motion`` converts to its channel array (``np.asarray(motion)``), so a
    list of motions is itself a valid clip collection for every skmotion
    estimator; :class:`~skmotion.preprocessing.VirtualMarkerTransform` also
    uses each motion's own skeleton and frame rate.

    Parameters
    ----------
    skeleton : Skeleton
        The joint hierarchy the channels drive.
    channels : array-like of shape (n_frames, n_channels)
        Channel values in ``skeleton.channel_names`` order: angles in radians,
        positions in the skeleton's length unit.
    frame_rate : float
        Frames per second.
    source : str, default=None
        Where the motion came from (a file path), for messages and reports.

    Attributes
    ----------
    channel_names : list of str
        ``"<joint>_<channel>"`` per column (the skeleton's channel names).
    n_frames : int
        Number of frames.
    duration : float
        ``n_frames / frame_rate`` seconds.

    See Also
    --------
    skmotion.io.read_bvh, skmotion.io.read_amc : readers returning a Motion.
    as_motions : wrap arrays and skeletons (e.g. ``make_motions`` output).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import humanoid_skeleton
    >>> from skmotion.io import Motion
    >>> sk = humanoid_skeleton()
    >>> motion = Motion(sk, np.zeros((60, sk.n_channels)), frame_rate=30.0)
    >>> motion
    Motion(n_frames=60, n_channels=66, frame_rate=30.0, source=None)
    >>> np.asarray(motion).shape, motion.duration
    ((60, 66), 2.0)
    """

    def __init__(self, skeleton, channels, *, frame_rate, source=None):
        if not isinstance(skeleton, Skeleton):
            raise TypeError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}.")
        channels = np.array(channels, dtype=float, order="C")
        if channels.ndim != 2 or channels.shape[1] != skeleton.n_channels:
            raise ValueError(
                f"channels must have shape (n_frames, {skeleton.n_channels}) for this skeleton; "
                f"got {channels.shape}."
            )
        if not isinstance(frame_rate, Real) or isinstance(frame_rate, bool):
            # A string or None is not parsed or guessed: say what was given.
            raise TypeError(
                f"frame_rate must be a number of Hz, got {type(frame_rate).__name__} {frame_rate!r}."
            )
        frame_rate = float(frame_rate)
        if not frame_rate > 0 or not np.isfinite(frame_rate):
            raise ValueError(f"frame_rate must be a positive number of Hz, got {frame_rate!r}.")
        self.skeleton = skeleton
        self.channels = channels
        self.frame_rate = frame_rate
        self.source = None if source is None else str(source)

    @property
    def channel_names(self):
        return list(self.skeleton.channel_names)

    @property
    def n_frames(self):
        return self.channels.shape[0]

    @property
    def n_channels(self):
        return self.channels.shape[1]

    @property
    def duration(self):
        return self.n_frames / self.frame_rate

    def __array__(self, dtype=None, copy=None):
        if copy:
            return np.array(self.channels, dtype=dtype)
        return self.channels if dtype is None else self.channels.astype(dtype, copy=False)

    def forward_kinematics(self):
        """World positions and rotations of every joint in every frame.

        Returns
        -------
        result : FKResult
            See :func:`skmotion.kinematics.forward_kinematics`.
        """
        return forward_kinematics(self.skeleton, self.channels)

    def __repr__(self):
        return (
            f"Motion(n_frames={self.n_frames}, n_channels={self.n_channels}, "
            f"frame_rate={self.frame_rate!r}, source={self.source!r})"
        )


def as_motions(clips, skeletons, frame_rate, *, sources=None):
    """Wrap joint-angle clips and their skeletons as a list of :class:`Motion`.

    This turns a ``make_motions`` Bunch (whose ``skeletons`` hold each clip's
    subject-sized skeleton) into motions that carry their own skeleton, e.g.
    for :class:`~skmotion.preprocessing.VirtualMarkerTransform`.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        The channel arrays.
    skeletons : Skeleton or list of Skeleton
        One skeleton for all clips, or one per clip.
    frame_rate : float
        Frames per second of every clip.
    sources : list of str, default=None
        A source name per clip.

    Returns
    -------
    motions : list of Motion

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import as_motions
    >>> data = make_motions(n_clips_per_class=1, classes=["walk", "wave"], random_state=0)
    >>> motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    >>> len(motions), motions[0].skeleton is data.skeletons[0]
    (2, True)
    """
    clips = list(clips)
    if isinstance(skeletons, Skeleton):
        skeletons = [skeletons] * len(clips)
    skeletons = list(skeletons)
    if len(skeletons) != len(clips):
        raise ValueError(
            f"{len(skeletons)} skeletons for {len(clips)} clips; give one per clip or one for all."
        )
    sources = [None] * len(clips) if sources is None else list(sources)
    if len(sources) != len(clips):
        raise ValueError(f"{len(sources)} sources for {len(clips)} clips.")
    motions = []
    for i, (clip, skeleton, source) in enumerate(zip(clips, skeletons, sources)):
        try:
            motions.append(Motion(skeleton, clip, frame_rate=frame_rate, source=source))
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"clip {i}: {exc}") from None
    return motions
