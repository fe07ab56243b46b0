"""Where a VirtualMarkerTransform's clips get their skeleton, markers and frame rate.

:class:`VirtualMarkerPlanMixin` holds the parts of
:class:`~skmotion.preprocessing.VirtualMarkerTransform` that resolve, per clip, the
skeleton and frame rate (a Motion's own or the parameters), the markers placed on
that skeleton or named by marker-position input, and, for joint positions of a
layout, the roles the layout gives; the transformer itself computes the features.
"""

from numbers import Integral

import numpy as np

from skmotion.io._motion import Motion
from skmotion.kinematics._layouts import layout_plan
from skmotion.kinematics._named_layouts import get_layout
from skmotion.preprocessing._marker_presets import MARKER_NAMES, MARKER_PRESETS
from skmotion.preprocessing._marker_set import MarkerSet


class VirtualMarkerPlanMixin:
    """Per-clip skeletons, markers and frame rates of a VirtualMarkerTransform.

    Reads the transformer's parameters (``skeleton``, ``markers``, ``frame_rate``,
    ``velocities``, ...) and its :meth:`marker_set`; sets the fitted roles in
    :meth:`_fit_layout`.
    """

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


def _items(X):
    return list(X) if isinstance(X, (list, tuple)) else []
