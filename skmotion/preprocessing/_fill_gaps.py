"""FillGaps: fill the gaps of position clips (occluded markers, lost tracking)."""

from numbers import Integral, Real

import numpy as np
import pandas as pd
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipTransformerMixin, MotionTags
from skmotion.kinematics._layouts import Layout
from skmotion.kinematics._named_layouts import LAYOUTS, get_layout
from skmotion.preprocessing._gaps import fill_points, missing_points
from skmotion.utils._clips import check_clips
from skmotion.utils._parallel import parallel_map
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["FillGaps"]

_REPORT = ("n_missing", "n_gaps", "longest_gap", "n_rigid", "n_interpolated", "n_unfilled")


class FillGaps(ClipTransformerMixin, BaseEstimator):
    """Fill gaps in position clips: rigid-body fill, then interpolation.

    A clip holds ``dim`` coordinates per point (joint or marker), joint-major,
    optionally followed per point by a confidence value. A point is missing in
    a frame when a coordinate is NaN, when its confidence is below
    ``confidence_threshold``, or (``zeros``) when the tracker wrote zeros.
    Each gap (a run of frames in which one point is missing) of at most
    ``max_gap`` frames is filled:

    1. **rigid-body fill** (as Vicon Nexus's): when the point belongs to a
       rigid group of the layout (``layout.groups``, or ``groups``) and at
       least 3 other members are visible throughout the gap and in the frame
       before (or after) it, the point follows the least-squares rigid motion
       (Kabsch) of those donors from that reference frame; with references on
       both sides the two fits are blended linearly, so the fill joins both
       ends. It also fills gaps at the clip's start or end;
    2. **interpolation** through the point's visible frames (``"linear"``, or
       a ``"cubic"`` spline) for gaps with visible frames on both sides.

    Longer gaps, and gaps neither way reaches, stay NaN or raise
    (``unfilled``). Nothing is learned: ``fit`` only checks the parameters and
    the channel count.

    Parameters
    ----------
    max_gap : int or float, default=10
        The longest gap filled, in ``max_gap_unit``.
    max_gap_unit : {"frames", "seconds"}, default="frames"
        Seconds need ``frame_rate``.
    method : {"linear", "cubic"}, default="cubic"
        The interpolation.
    layout : str or Layout, default=None
        Gives ``dim`` and the rigid groups, and names the output channels.
    dim : {2, 3}, default=None
        Coordinates per point; None takes the layout's (3 without a layout).
    groups : sequence of sequence of (int or str), default=None
        Rigid groups (point indices, or joint names with a layout); None takes
        the layout's groups; ``[]`` turns rigid filling off.
    zeros : {"keep", "frame", "point"}, default="keep"
        ``"frame"``: an all-zero frame is missing (a tracker that lost the
        body); ``"point"``: an all-zero point is missing (OpenPose's way).
    confidence_threshold : float, default=None
        When given, each point has a confidence channel after its coordinates
        (``dim + 1`` channels per point); values below it are missing and the
        output drops the confidence channels.
    unfilled : {"nan", "raise"}, default="nan"
        What to do with gaps that cannot be filled.
    frame_rate : float, default=None
        Frames per second, for ``max_gap_unit="seconds"``.
    n_jobs : int, default=None
        Clips processed in parallel (joblib threads).

    Attributes
    ----------
    n_features_in_ : int
        Number of input channels.
    feature_names_in_ : ndarray of str
        Input channel names, when fit saw a DataFrame with string columns.
    n_points_ : int
        Points per frame.
    max_gap_frames_ : int
        ``max_gap`` in frames.

    See Also
    --------
    VirtualMarkerTransform : features from the filled positions.

    Notes
    -----
    The per-clip report of what was filled is a method, :meth:`fill_report`,
    not an attribute set by ``transform``: a transformer's ``transform`` does
    not change its state (sklearn's contract; a fitted pipeline may transform
    many batches, in parallel), so the report is computed on demand for the
    clips you pass.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import make_position_motions
    >>> from skmotion.preprocessing import FillGaps
    >>> data = make_position_motions("kinect_v2", n_clips_per_class=1, classes=["walk"],
    ...                              random_state=0)
    >>> clip = data.clips[0].copy()
    >>> clip[10:14, 21:24] = np.nan  # HandTipLeft occluded for 4 frames
    >>> fill = FillGaps(layout="kinect_v2").fit([clip])
    >>> filled = fill.transform([clip])[0]
    >>> float(np.abs(filled - data.clips[0]).max()) < 1e-9  # exact: the hand is a rigid group
    True
    >>> fill.fill_report([clip])[["n_gaps", "n_rigid", "n_unfilled"]].iloc[0].tolist()
    [1, 4, 0]
    """

    _parameter_constraints = {
        "max_gap": [Interval(Real, 0, None, closed="left")],
        "max_gap_unit": [StrOptions({"frames", "seconds"})],
        "method": [StrOptions({"linear", "cubic"})],
        "layout": [StrOptions(set(LAYOUTS)), Layout, None],
        "dim": [Interval(Integral, 2, 3, closed="both"), None],
        "groups": [list, tuple, None],
        "zeros": [StrOptions({"keep", "frame", "point"})],
        "confidence_threshold": [Real, None],
        "unfilled": [StrOptions({"nan", "raise"})],
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "n_jobs": [Integral, None],
    }
    _motion_tags = MotionTags(output_kind="clips")

    def __init__(
        self,
        *,
        max_gap=10,
        max_gap_unit="frames",
        method="cubic",
        layout=None,
        dim=None,
        groups=None,
        zeros="keep",
        confidence_threshold=None,
        unfilled="nan",
        frame_rate=None,
        n_jobs=None,
    ):
        self.max_gap = max_gap
        self.max_gap_unit = max_gap_unit
        self.method = method
        self.layout = layout
        self.dim = dim
        self.groups = groups
        self.zeros = zeros
        self.confidence_threshold = confidence_threshold
        self.unfilled = unfilled
        self.frame_rate = frame_rate
        self.n_jobs = n_jobs

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        return tags

    def _resolved(self):
        """(layout or None, dim, per-point channels, rigid groups as index tuples)."""
        layout = None if self.layout is None else get_layout(self.layout)
        dim = int(self.dim) if self.dim is not None else (layout.dim if layout else 3)
        if layout is not None and dim != layout.dim:
            raise ValueError(f"dim={dim} disagrees with layout {layout.name!r} (dim {layout.dim}).")
        groups = self.groups
        if groups is None:
            groups = layout.groups if layout is not None else ()
        resolved = []
        for group in groups:
            ids = [layout.index(g) if isinstance(g, str) and layout else g for g in group]
            if not all(isinstance(i, (Integral, np.integer)) for i in ids) or len(ids) < 4:
                raise ValueError(
                    f"groups: {list(group)!r} must be 4 or more point indices (or joint names "
                    "with a layout)."
                )
            resolved.append(tuple(int(i) for i in ids))
        per_point = dim + (self.confidence_threshold is not None)
        return layout, dim, per_point, tuple(resolved)

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Check the parameters and the channel count; nothing is learned.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray or DataFrame
            Position clips; NaN marks missing values.
        y : None
            Ignored.

        Returns
        -------
        self : FillGaps
            The fitted transformer.
        """
        clips = check_clips(X, estimator=self, reset=True, allow_nan=True)
        layout, _, per_point, groups = self._resolved()
        if clips.n_channels % per_point:
            raise ValueError(
                f"X has {clips.n_channels} channels, not a multiple of {per_point} channels per "
                "point (dim, plus 1 with confidence_threshold)."
            )
        self.n_points_ = clips.n_channels // per_point
        if layout is not None and self.n_points_ != layout.n_joints:
            raise ValueError(
                f"X has {self.n_points_} points, but layout {layout.name!r} has "
                f"{layout.n_joints} joints."
            )
        bad = [i for g in groups for i in g if not 0 <= i < self.n_points_]
        if bad:
            raise ValueError(f"groups: point {bad[0]} is out of range for {self.n_points_} points.")
        if self.max_gap_unit == "seconds":
            if self.frame_rate is None:
                raise ValueError("max_gap_unit='seconds' needs frame_rate= (Hz).")
            self.max_gap_frames_ = int(np.floor(self.max_gap * self.frame_rate + 1e-9))
        else:
            if self.max_gap != int(self.max_gap):
                raise ValueError(f"max_gap={self.max_gap!r} frames must be a whole number.")
            self.max_gap_frames_ = int(self.max_gap)
        return self

    def _fill(self, clip, i):
        """(filled clip, report) of one clip."""
        _, dim, per_point, groups = self._resolved()
        data = clip.reshape(len(clip), self.n_points_, per_point)
        points = np.array(data[..., :dim], dtype=float)
        confidence = data[..., dim] if per_point > dim else None
        missing = missing_points(
            points, zeros=self.zeros, confidence=confidence, threshold=self.confidence_threshold
        )
        report = fill_points(
            points, missing, max_gap=self.max_gap_frames_, method=self.method, groups=groups
        )
        if self.unfilled == "raise" and report["n_unfilled"]:
            point, start, stop = (int(a[0]) for a in report["unfilled"])
            if stop - start > self.max_gap_frames_:
                why = f"it is longer than max_gap={self.max_gap_frames_} frames"
            elif start == 0 or stop == len(clip):
                why = "it touches the clip's start or end and no rigid group fills it"
            else:
                why = "the point has fewer than 2 visible frames"
            raise ValueError(
                f"X: clip {i}, point {self._point_name(point)}: frames {start}-{stop - 1} "
                f"({stop - start} frames) cannot be filled: {why}; {report['n_unfilled']} "
                "missing values stay in this clip."
            )
        return points.reshape(len(clip), -1), report

    def _point_name(self, point):
        layout = self._resolved()[0]
        return repr(layout.joints[point]) if layout is not None else str(point)

    def transform(self, X):
        """The clips with their gaps filled.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray or DataFrame
            Position clips like those seen in fit.

        Returns
        -------
        X_new : list of ndarray of shape (n_frames_i, dim * n_points_)
            Filled clips (confidence channels dropped), in the container kind
            of ``X``; unfilled values are NaN.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self, allow_nan=True)
        out = parallel_map(
            lambda i: self._fill(clips[i], i)[0], range(len(clips)), n_jobs=self.n_jobs
        )
        return self._wrap_clips(out, clips)

    def fill_report(self, X):
        """What :meth:`transform` fills in each clip, without changing the transformer.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), ndarray or DataFrame
            Position clips like those seen in fit.

        Returns
        -------
        report : DataFrame
            One row per clip: ``n_missing`` (missing point-frames),
            ``n_gaps``, ``longest_gap`` (frames), ``n_rigid`` and
            ``n_interpolated`` (point-frames filled each way) and
            ``n_unfilled`` (point-frames left NaN).
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self, allow_nan=True)
        reports = parallel_map(
            lambda i: self._fill(clips[i], i)[1], range(len(clips)), n_jobs=self.n_jobs
        )
        return pd.DataFrame([[r[k] for k in _REPORT] for r in reports], columns=list(_REPORT))

    def get_feature_names_out(self, input_features=None):
        """Output channel names: the layout's, the input's coordinates, or ``p<k>_<x|y|z>``.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Input channel names; by default ``feature_names_in_`` when fit saw
            them.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        layout, dim, per_point, _ = self._resolved()
        if layout is not None:
            return np.asarray(layout.feature_names(), dtype=object)
        names = input_features
        if names is None:
            names = getattr(self, "feature_names_in_", None)
        if names is None:
            return np.asarray(
                [f"p{k}_{c}" for k in range(self.n_points_) for c in "xyz"[:dim]], dtype=object
            )
        names = np.asarray(names, dtype=object).reshape(self.n_points_, per_point)
        return names[:, :dim].ravel()
