"""The Motion: one clip read from a file, with the skeleton it belongs to."""

from numbers import Real

import numpy as np

from skmotion.io._recording import AnalogChannels
from skmotion.kinematics import Skeleton, forward_kinematics

__all__ = ["Motion", "as_motions"]

#: Metres per unit of the length units position files state (C3D ``POINT:UNITS``).
METERS_PER_UNIT = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}
_AXES = ("x", "y", "z")


class Motion:
    """One motion clip with its skeleton: what the file readers return.

    A ``Motion`` converts to its channel array (``np.asarray(motion)``), so a
    list of motions is itself a valid clip collection for every skmotion
    estimator; :class:`~skmotion.preprocessing.VirtualMarkerTransform` also
    uses each motion's own skeleton and frame rate.

    A motion of **positions** (markers from a C3D file, keypoints of a
    tracker) has no skeleton: ``skeleton=None`` and ``marker_names`` name its
    points; its channels are ``x, y[, z]`` per point, named
    ``"<marker>_x"``, ``"<marker>_y"``, ``"<marker>_z"``, NaN where a point is
    missing. ``VirtualMarkerTransform`` treats it as marker-position input.

    Parameters
    ----------
    skeleton : Skeleton or None
        The joint hierarchy the channels drive; None for positions.
    channels : array-like of shape (n_frames, n_channels)
        Channel values in ``skeleton.channel_names`` order: angles in radians,
        positions in the skeleton's length unit. For positions, 2 or 3
        columns per marker, marker after marker.
    frame_rate : float
        Frames per second.
    source : str, default=None
        Where the motion came from (a file path), for messages and reports.
    marker_names : sequence of str, default=None
        The points of a position motion (required when ``skeleton`` is None).
    units : str, default=None
        Length unit of a position motion (``"m"``, ``"mm"``, ``"px"``, ...);
        None is ``"unknown"``. A skeleton motion's unit is its skeleton's.
    extras : dict of str to ndarray, default=None
        Further per-frame data kept from the file, each array with
        ``n_frames`` rows: a C3D file's ``"residuals"``, a keypoint file's
        ``"confidence"`` (one column per marker).
    analog : AnalogChannels, default=None
        Analog channels recorded with the motion (a C3D file's force plates
        and EMG), at their own rate.
    events : sequence of MotionEvent, default=()
        Labelled instants (a C3D file's foot strikes and toe-offs), in time
        order.

    Attributes
    ----------
    channel_names : list of str
        ``"<joint>_<channel>"`` per column (the skeleton's channel names).
    n_frames : int
        Number of frames.
    duration : float
        ``n_frames / frame_rate`` seconds.
    kind : {"angles", "positions"}
        ``"positions"`` when there is no skeleton.
    n_dims : int or None
        2 or 3 coordinates per marker of a position motion; None for angles.
    meters_per_unit : float or None
        Metres per length unit, when the unit is known.

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

    Two markers tracked in millimetres:

    >>> points = Motion(None, np.zeros((4, 6)), frame_rate=100, marker_names=["LASI", "RASI"],
    ...                 units="mm")
    >>> points.channel_names[:4], points.kind, points.meters_per_unit
    (['LASI_x', 'LASI_y', 'LASI_z', 'RASI_x'], 'positions', 0.001)
    """

    def __init__(
        self,
        skeleton,
        channels,
        *,
        frame_rate,
        source=None,
        marker_names=None,
        units=None,
        extras=None,
        analog=None,
        events=(),
    ):
        channels = np.array(channels, dtype=float, order="C")
        if skeleton is None:
            marker_names = _check_markers(marker_names, channels)
        elif not isinstance(skeleton, Skeleton):
            raise TypeError(f"skeleton must be a Skeleton or None, got {type(skeleton).__name__}.")
        elif marker_names is not None or units is not None:
            raise ValueError("marker_names and units are for position motions (skeleton=None).")
        elif channels.ndim != 2 or channels.shape[1] != skeleton.n_channels:
            raise ValueError(
                f"channels must have shape (n_frames, {skeleton.n_channels}) for this skeleton; "
                f"got {channels.shape}."
            )
        if not isinstance(frame_rate, Real) or isinstance(frame_rate, bool):
            # A string or None is not parsed or guessed: say what was given.
            raise TypeError(
                f"frame_rate must be a number of Hz, got {type(frame_rate).__name__} "
                f"{frame_rate!r}."
            )
        frame_rate = float(frame_rate)
        if not frame_rate > 0 or not np.isfinite(frame_rate):
            raise ValueError(f"frame_rate must be a positive number of Hz, got {frame_rate!r}.")
        self.skeleton = skeleton
        self.channels = channels
        self.frame_rate = frame_rate
        self.source = None if source is None else str(source)
        self.marker_names = marker_names
        self.units = (skeleton.units if skeleton is not None else None) or units or "unknown"
        self.extras = _check_extras(extras, len(channels))
        if analog is not None and not isinstance(analog, AnalogChannels):
            raise TypeError(f"analog must be AnalogChannels or None, got {type(analog).__name__}.")
        self.analog = analog
        self.events = tuple(sorted(events, key=lambda e: e.time))

    @property
    def channel_names(self):
        if self.skeleton is None:
            return [f"{m}_{a}" for m in self.marker_names for a in _AXES[: self.n_dims]]
        return list(self.skeleton.channel_names)

    @property
    def kind(self):
        return "positions" if self.skeleton is None else "angles"

    @property
    def n_dims(self):
        if self.skeleton is None:
            return self.channels.shape[1] // len(self.marker_names)
        return None

    @property
    def meters_per_unit(self):
        if self.skeleton is not None:
            return self.skeleton.meters_per_unit
        return METERS_PER_UNIT.get(self.units)

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
        if self.skeleton is None:
            raise ValueError(
                f"{self.source or 'this motion'} holds positions of {len(self.marker_names)} "
                "markers, not joint angles: it has no skeleton to pose."
            )
        return forward_kinematics(self.skeleton, self.channels)

    def __repr__(self):
        return (
            f"Motion(n_frames={self.n_frames}, n_channels={self.n_channels}, "
            f"frame_rate={self.frame_rate!r}, source={self.source!r})"
        )


def _check_markers(marker_names, channels):
    """The marker names of a position motion, checked against its channel array."""
    if marker_names is None:
        raise ValueError("A position motion (skeleton=None) needs marker_names.")
    names = tuple(str(m) for m in marker_names)
    if not names or len(set(names)) != len(names):
        raise ValueError(f"marker_names must be unique and not empty; got {list(names)[:8]}.")
    n = len(names)
    if channels.ndim != 2 or channels.shape[1] not in (2 * n, 3 * n):
        raise ValueError(
            f"channels must have shape (n_frames, {3 * n}) (x, y, z per marker) or (n_frames, "
            f"{2 * n}) (x, y) for {n} markers; got {channels.shape}."
        )
    return names


def _check_extras(extras, n_frames):
    extras = dict(extras or {})
    for key, value in extras.items():
        value = np.asarray(value)
        if value.ndim < 1 or len(value) != n_frames:
            raise ValueError(f"extras[{key!r}] must have {n_frames} rows (one per frame).")
        extras[key] = value
    return extras


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
