"""VirtualMarkerTransform: joint-angle clips to body-frame virtual-marker clips.

The transformer, whole: where each clip gets its skeleton, markers and frame
rate (a Motion's own or the parameters; markers placed on a skeleton, named by
marker-position input, or given roles by a layout), and the features. The
body frame of point trajectories is computed by
:func:`~skmotion.preprocessing._position_frame.position_frame_features`.
"""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipTransformerMixin, MotionTags
from skmotion.io._motion import Motion
from skmotion.kinematics import Skeleton
from skmotion.kinematics._layouts import Layout, layout_plan
from skmotion.kinematics._named_layouts import LAYOUTS, get_layout
from skmotion.preprocessing._marker_presets import MARKER_NAMES, MARKER_PRESETS, marker_preset
from skmotion.preprocessing._marker_set import MarkerSet
from skmotion.preprocessing._position_frame import CHUNK, position_frame_features
from skmotion.utils._clips import check_clips
from skmotion.utils._parallel import parallel_map
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["SIZE_CHAIN", "VirtualMarkerTransform"]

#: The default chain of :func:`body_size`: ankle to head top along the body.
SIZE_CHAIN = ("left_ankle", "left_knee", "left_hip", "pelvis", "spine", "chest", "neck", "head_top")
_COMPONENTS = {3: ("px", "py", "pz", "vx", "vy", "vz"), 2: ("py", "pz", "vy", "vz")}


class VirtualMarkerTransform(ClipTransformerMixin, BaseEstimator):
    """Joint-angle clips to virtual-marker clips in a body-centred frame.

    Each output frame holds, for every virtual marker, its position and
    velocity ``(px, py, pz, vx, vy, vz)`` (Yamane et al. 2011, section III-A):

    1. forward kinematics gives each marker's world position (a marker is a
       point fixed on a joint's link, see :class:`MarkerSet`); its velocity
       is the time derivative (central differences, ``frame_rate`` aware);
    2. both are expressed in a frame with its origin on the floor below the
       root marker, ``z`` up and ``x`` the subject's facing on the floor
       (from a left and a right marker), ``y`` to the subject's left: this
       removes horizontal travel and turning;
    3. lengths are divided by the subject's size (:func:`body_size` along
       ``size_markers``), so subjects of different size match.

    Where the skeleton comes from:

    - **a list of** :class:`~skmotion.io.Motion`: each clip uses its own
      skeleton and frame rate (several subjects, several skeleton families);
    - **plain arrays with** ``skeleton``: every clip uses that skeleton;
    - **plain arrays with** ``skeleton=None``: the clips already hold 3-D
      marker positions, ``3 * n_markers`` channels, named by ``markers``; only
      steps 2-3 run;
    - **plain arrays with** ``layout``: joint positions of a tracker or pose
      estimator (:func:`get_layout`: Kinect, Azure Kinect, COCO, OpenPose,
      MediaPipe, Human3.6M, SMPL, or your own :class:`Layout`), ``dim`` channels
      per joint; the layout gives the root (the mid-hip), the facing (hips and
      shoulders), the size chain (ankle, knee, hip, shoulder) and the up axis.
      2-D layouts stay in the image plane: outputs ``(py, pz[, vy, vz])`` per
      marker, ``z`` the image's up and ``y`` horizontal, signed so that the
      subject's left is positive over the clip (depth, ``x``, is unknown).

    With ``markers="auto"`` each skeleton gets its family's preset
    (:func:`marker_preset`), so clips of different skeletons share the same
    32 output markers.

    Parameters
    ----------
    skeleton : Skeleton, default=None
        The skeleton of plain-array clips; None for marker-position input (or
        when every clip is a Motion).
    markers : "auto", "all", str, MarkerSet or list, default="auto"
        With a skeleton: ``"auto"`` (the preset detected from the joint
        names), a preset name from :data:`MARKER_PRESETS`, a
        :class:`MarkerSet` or a list of ``(name, joint, offset)``. For marker
        positions: the input markers' names, in channel order (``"auto"``
        means :data:`MARKER_NAMES`). With a layout: ``"auto"`` outputs the
        joints on the shared :data:`MARKER_NAMES` (named by the marker, so
        clips of different systems share features), ``"all"`` every joint
        under its own name, a list those joints.
    layout : str or Layout, default=None
        The joint layout of position clips (a name from :data:`LAYOUTS` or a
        :class:`Layout`); its roles replace ``root_marker``,
        ``facing_markers`` and a list of ``size_markers``, which must keep
        their defaults.
    root_marker : str or int, default="pelvis"
        The marker the origin lies below.
    facing_markers : tuple of (str or int), default=("left_hip", "right_hip")
        A marker on the subject's left and one on the right; forward is
        perpendicular to the line between them, on the floor.
    size_markers : "auto", sequence of (str or int) or None, default="auto"
        The chain whose length is the subject's size (``"auto"``:
        :data:`SIZE_CHAIN`); None keeps the input's length unit.
    floor : "lowest" or float, default="lowest"
        The floor height in the world: the lowest marker over each clip, or a
        given height (in the input's length unit).
    up_axis : {"x", "y", "z", "-x", "-y", "-z"}, default=None
        The world's vertical axis (``"-y"``: ``y`` points down); None takes
        each skeleton's ``up_axis``, the layout's ``up``, or ``"y"`` for marker
        positions.
    velocities : bool, default=True
        Append each marker's velocity; without them ``frame_rate`` is not
        needed and the output has half the channels.
    frame_rate : float, default=None
        Frames per second of plain-array clips (for velocities). Motions use
        their own rate; if given, it must agree with theirs.
    n_jobs : int, default=None
        Clips transformed in parallel (joblib threads); None is serial.

    Attributes
    ----------
    n_features_in_ : int
        Number of input channels.
    feature_names_in_ : ndarray of str
        Input channel names, when fit saw a DataFrame with string columns.
    marker_names_ : ndarray of str
        The output markers, in order.
    n_markers_ : int
        Number of markers; the output has ``6 * n_markers_`` channels (3-D with
        velocities; 3 without, 4 or 2 in 2-D).
    layout_ : Layout or None
        The resolved layout.
    root_index_ : int or tuple of int
        Index in ``marker_names_`` of ``root_marker``; with a layout, the input
        joints whose mean is the root.
    facing_indices_ : tuple of int
        Indices of the left and right ``facing_markers``; with a layout,
        ``((left_hip, left_shoulder), (right_hip, right_shoulder))`` joint
        indices.
    size_indices_ : list of int or None
        Indices of the ``size_markers`` chain (input joints with a layout);
        None without size normalisation.

    See Also
    --------
    MarkerSet : define your own markers.
    marker_preset : the standard markers on a known skeleton.
    skmotion.io.as_motions : give each clip of a dataset its own skeleton.

    References
    ----------
    K. Yamane, Y. Yamaguchi and Y. Nakamura, "Human motion database with a
    binary tree and node transition graphs", Autonomous Robots 30(1), 2011.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import as_motions
    >>> from skmotion.preprocessing import VirtualMarkerTransform
    >>> data = make_motions(n_clips_per_class=2, classes=["walk", "wave"], random_state=0)
    >>> motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    >>> markers = VirtualMarkerTransform().fit(motions)
    >>> out = markers.transform(motions)
    >>> out[0].shape, markers.get_feature_names_out()[:3].tolist()
    ((88, 192), ['head_top_px', 'head_top_py', 'head_top_pz'])

    Joint positions of a tracker:

    >>> from skmotion.datasets import make_position_motions
    >>> kinect = make_position_motions("kinect_v2", n_clips_per_class=1, random_state=0)
    >>> vmt = VirtualMarkerTransform(layout="kinect_v2", frame_rate=kinect.frame_rate)
    >>> vmt.fit_transform(kinect.clips)[0].shape, vmt.marker_names_[:3].tolist()
    ((88, 126), ['head', 'neck', 'chest'])
    """

    _parameter_constraints = {
        "skeleton": [Skeleton, None],
        "markers": [StrOptions({"auto", "all", *MARKER_PRESETS}), MarkerSet, list, tuple],
        "layout": [StrOptions(set(LAYOUTS)), Layout, None],
        "root_marker": [str, Integral],
        "facing_markers": [tuple, list],
        "size_markers": [StrOptions({"auto"}), tuple, list, None],
        "floor": [StrOptions({"lowest"}), Real],
        "up_axis": [StrOptions({"x", "y", "z", "-x", "-y", "-z"}), None],
        "velocities": ["boolean"],
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "n_jobs": [Integral, None],
    }
    _motion_tags = MotionTags(output_kind="clips", min_frames=2)

    def __init__(
        self,
        skeleton=None,
        *,
        markers="auto",
        layout=None,
        root_marker="pelvis",
        facing_markers=("left_hip", "right_hip"),
        size_markers="auto",
        floor="lowest",
        up_axis=None,
        velocities=True,
        frame_rate=None,
        n_jobs=None,
    ):
        self.skeleton = skeleton
        self.markers = markers
        self.layout = layout
        self.root_marker = root_marker
        self.facing_markers = facing_markers
        self.size_markers = size_markers
        self.floor = floor
        self.up_axis = up_axis
        self.velocities = velocities
        self.frame_rate = frame_rate
        self.n_jobs = n_jobs

    # -- the markers and their roles ----------------------------------------------------
    def marker_set(self, skeleton):
        """The markers this transformer places on ``skeleton``.

        Parameters
        ----------
        skeleton : Skeleton

        Returns
        -------
        markers : MarkerSet
            ``markers`` itself when it is a MarkerSet or a list of markers;
            otherwise the preset for ``skeleton``.

        Examples
        --------
        >>> from skmotion.datasets import humanoid_skeleton
        >>> from skmotion.preprocessing import VirtualMarkerTransform
        >>> len(VirtualMarkerTransform().marker_set(humanoid_skeleton()))
        32
        """
        if isinstance(self.markers, MarkerSet):
            return self.markers
        if isinstance(self.markers, (list, tuple)):
            return MarkerSet(self.markers)
        return marker_preset(skeleton, None if self.markers == "auto" else self.markers)

    def _indices(self, names):
        root = self._index(names, self.root_marker, "root_marker")
        if len(self.facing_markers) != 2:
            raise ValueError(
                f"facing_markers must be a (left, right) pair, got {self.facing_markers!r}."
            )
        left, right = (self._index(names, m, "facing marker") for m in self.facing_markers)
        if self.size_markers is None:
            chain = None
        else:
            wanted = SIZE_CHAIN if isinstance(self.size_markers, str) else self.size_markers
            chain = [self._index(names, m, "size marker") for m in wanted]
            if len(chain) < 2:
                raise ValueError("size_markers needs at least two markers.")
        return root, left, right, chain

    # -- the estimator API ------------------------------------------------------------------
    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Check the clips and resolve the marker set(s).

        Parameters
        ----------
        X : list of Motion or of ndarray of shape (n_frames_i, n_channels), ndarray or DataFrame
            Joint-angle clips (Motions, or arrays of ``skeleton``), or marker
            positions when ``skeleton=None``; at least two frames per clip.
        y : None
            Ignored.

        Returns
        -------
        self : VirtualMarkerTransform
            The fitted transformer.
        """
        clips = check_clips(X, estimator=self, reset=True)
        if self.layout is not None:
            return self._fit_layout(X, clips)
        _, names = self._plans(X, clips)
        self.root_index_, left, right, self.size_indices_ = self._indices(names)
        self.facing_indices_ = (left, right)
        self.marker_names_ = np.asarray(names, dtype=object)
        self.n_markers_ = len(names)
        self.layout_ = None
        return self

    # -- where each clip's skeleton, markers and frame rate come from ---------------------

    def _clip_sources(self, X, n_clips):
        """Per clip: (skeleton or None, frame rate)."""
        items = list(X) if isinstance(X, (list, tuple)) else [None] * n_clips
        is_motion = [isinstance(item, Motion) for item in items]
        if any(is_motion) and not all(is_motion) and self.skeleton is None:
            plain = is_motion.index(False)
            raise ValueError(
                f"X: clip {plain} is a plain array while other clips are Motions; give "
                "skeleton= for plain arrays, or make every clip a Motion."
            )
        sources = []
        for i, (item, motion) in enumerate(zip(items, is_motion)):
            if motion:
                if self.frame_rate is not None and not np.isclose(item.frame_rate, self.frame_rate):
                    raise ValueError(
                        f"X: clip {i} is a Motion at {item.frame_rate:g} Hz, but "
                        f"frame_rate={self.frame_rate:g}."
                    )
                sources.append((item.skeleton, item.frame_rate))
            else:
                if self.frame_rate is None and self.velocities:
                    raise ValueError(
                        f"X: clip {i} is a plain array; give frame_rate= (Hz) for velocities, "
                        "or pass Motions."
                    )
                rate = None if self.frame_rate is None else float(self.frame_rate)
                sources.append((self.skeleton, rate))
        return sources

    def _input_marker_names(self, n_channels):
        """Names of the markers of marker-position input (``skeleton=None``)."""
        if n_channels % 3:
            raise ValueError(
                f"X has {n_channels} channels; marker positions (skeleton=None) need 3 per "
                "marker. Give skeleton= for joint-angle clips."
            )
        if isinstance(self.markers, MarkerSet):
            names = self.markers.names
        elif isinstance(self.markers, str):
            names = MARKER_NAMES
        else:
            names = tuple(str(m) for m in self.markers)
        if len(names) != n_channels // 3:
            raise ValueError(
                f"X has {n_channels // 3} markers (3 channels each), but markers names "
                f"{len(names)}; give the input markers' names in channel order."
            )
        return tuple(names)

    def _index(self, names, marker, what):
        if isinstance(marker, (Integral, np.integer)):
            if not 0 <= marker < len(names):
                raise ValueError(f"{what} index {marker} is out of range for {len(names)} markers.")
            return int(marker)
        if marker not in names:
            raise ValueError(f"{what} {marker!r} is not a marker; the markers are {list(names)}.")
        return names.index(marker)

    def _plans(self, X, clips):
        """Per clip: (skeleton, MarkerSet or None, frame rate); and the marker names."""
        sources = self._clip_sources(X, len(clips))
        resolved = {}
        plans, names = [], None
        for i, (skeleton, frame_rate) in enumerate(sources):
            if skeleton is None:
                markers, clip_names = None, self._input_marker_names(clips.n_channels)
            else:
                if skeleton.n_channels != clips.n_channels:
                    raise ValueError(
                        f"X: clip {i} has {clips.n_channels} channels, but its skeleton has "
                        f"{skeleton.n_channels}."
                    )
                if skeleton not in resolved:
                    markers = self.marker_set(skeleton)
                    markers.joint_indices(skeleton)  # every marker's joint exists
                    resolved[skeleton] = markers
                markers = resolved[skeleton]
                clip_names = markers.names
            if names is None:
                names = clip_names
            elif clip_names != names:
                raise ValueError(
                    f"X: clip {i} gets markers {list(clip_names)[:5]}..., other clips "
                    f"{list(names)[:5]}..."
                )
            plans.append((skeleton, markers, frame_rate))
        return plans, names

    def _fit_layout(self, X, clips):
        """Fit for joint positions of a layout: the roles come from the layout."""
        layout = get_layout(self.layout)
        if self.skeleton is not None or any(isinstance(c, Motion) for c in _items(X)):
            raise ValueError(
                "layout= is for joint-position clips (plain arrays); joint-angle clips take "
                "skeleton= or Motions, without layout=."
            )
        custom = [
            f"{name}={value!r}"
            for name, value, default in (
                ("root_marker", self.root_marker, "pelvis"),
                ("facing_markers", tuple(self.facing_markers), ("left_hip", "right_hip")),
            )
            if value != default
        ]
        if not (self.size_markers is None or isinstance(self.size_markers, str)):
            custom.append(f"size_markers={self.size_markers!r}")
        if custom:
            raise ValueError(
                f"With layout={layout.name!r} the root, facing and size joints come from the "
                f"layout; {', '.join(custom)} would be ignored. Define a Layout with those roles "
                "instead."
            )
        if isinstance(self.markers, MarkerSet) or self.markers in MARKER_PRESETS:
            raise ValueError(
                f"markers={self.markers!r} places markers on a skeleton; with a layout use 'auto', "
                "'all' or a list of joint names."
            )
        expected = layout.dim * layout.n_joints
        if clips.n_channels != expected:
            raise ValueError(
                f"X has {clips.n_channels} channels, but layout {layout.name!r} has "
                f"{layout.n_joints} joints x {layout.dim} coordinates = {expected} channels."
            )
        if self.velocities and self.frame_rate is None:
            raise ValueError("give frame_rate= (Hz) for velocities, or velocities=False.")
        plan = layout_plan(layout, self.markers)
        self.layout_ = layout
        self.root_index_ = plan["root"]
        self.facing_indices_ = (plan["lefts"], plan["rights"])
        self.size_indices_ = None if self.size_markers is None else list(plan["size_chain"])
        self.marker_names_ = np.asarray(plan["names"], dtype=object)
        self.n_markers_ = len(plan["names"])
        self._outputs = plan["outputs"]
        return self

    # -- the features ------------------------------------------------------------------

    def transform(self, X):
        """Virtual-marker positions and velocities of every clip.

        Parameters
        ----------
        X : list of Motion or of ndarray of shape (n_frames_i, n_channels), ndarray or DataFrame
            Clips like those seen in fit.

        Returns
        -------
        X_new : list of ndarray of shape (n_frames_i, n_features_out)
            ``6 * n_markers_`` channels (3-D with velocities), in the container
            kind of ``X`` (a DataFrame after ``set_output(transform="pandas")``).
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        if self.layout_ is not None:
            plans = [(None, None, self.frame_rate)] * len(clips)
        else:
            plans, names = self._plans(X, clips)
            if list(names) != list(self.marker_names_):
                raise ValueError("X: the clips' markers differ from those seen in fit.")
        out = parallel_map(
            lambda i: self._one(clips[i], plans[i], i), range(len(clips)), n_jobs=self.n_jobs
        )
        return self._wrap_clips(out, clips)

    def _one(self, clip, plan, i):
        """The features of one clip (``plan``: skeleton, markers, frame rate)."""
        skeleton, markers, frame_rate = plan
        outputs, lefts, rights = None, self.facing_indices_[:1], self.facing_indices_[1:]
        root = (self.root_index_,)
        if self.layout_ is not None:
            layout = self.layout_
            positions = clip.reshape(len(clip), layout.n_joints, layout.dim)
            up, outputs = self.up_axis or layout.up, self._outputs
            root, (lefts, rights) = self.root_index_, self.facing_indices_
        elif markers is None:
            positions = clip.reshape(len(clip), -1, 3)
            up = self.up_axis or "y"
        else:
            positions = _marker_positions(markers, skeleton, clip)
            up = self.up_axis or skeleton.up_axis
        try:
            return position_frame_features(
                positions,
                root=root,
                lefts=lefts,
                rights=rights,
                size_chain=self.size_indices_,
                up=up,
                floor=self.floor,
                frame_rate=frame_rate,
                velocities=self.velocities,
                outputs=outputs,
            )
        except ValueError as exc:
            raise ValueError(f"X: clip {i}: {exc}") from None

    def get_feature_names_out(self, input_features=None):
        """Output channel names, ``"<marker>_<px|py|pz|vx|vy|vz>"``.

        In 2-D (a 2-D layout) the components are ``py, pz, vy, vz``; without
        velocities only the positions.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Ignored (the output names come from the markers).

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        dim = 3 if self.layout_ is None else self.layout_.dim
        components = _COMPONENTS[dim][: dim * (2 if self.velocities else 1)]
        return np.asarray(
            [f"{m}_{c}" for m in self.marker_names_ for c in components], dtype=object
        )


def _marker_positions(markers, skeleton, clip):
    """Marker world positions, forward kinematics chunk by chunk (bounded memory)."""
    positions = np.empty((len(clip), len(markers), 3))
    for start in range(0, len(clip), CHUNK):
        positions[start : start + CHUNK] = markers.positions(skeleton, clip[start : start + CHUNK])
    return positions


def _items(X):
    return list(X) if isinstance(X, (list, tuple)) else []
