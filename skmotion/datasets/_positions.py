"""Joint-position clips in any layout, from forward kinematics of joint-angle clips."""

from numbers import Integral, Real

import numpy as np
from sklearn.utils import Bunch

from skmotion.datasets._synthetic import make_motions
from skmotion.kinematics import forward_kinematics
from skmotion.kinematics._layouts import Layout
from skmotion.kinematics._named_layouts import LAYOUTS, get_layout
from skmotion.preprocessing._marker_presets import MARKER_NAMES, marker_preset
from skmotion.preprocessing._marker_set import MarkerSet
from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = ["EXTRA_LANDMARKS", "layout_markers", "layout_positions", "make_position_motions"]

_HEIGHT = 1.75  # the offsets below are for a 1.75 m adult and scale with the skeleton's height


def _both(table):
    """Left entries as given; right entries mirrored (left offset negated)."""
    out = {}
    for name, (base, ref, t, (left, up, forward)) in table.items():
        for side, sign in (("left", 1.0), ("right", -1.0)):
            rename = name.format(side=side)
            out[rename] = (base.format(side=side), ref and ref.format(side=side), t)
            out[rename] += ((sign * left, up, forward),)
    return out


#: Body landmarks beyond the 32 :data:`MARKER_NAMES`, rigidly attached to the link of
#: a base marker: ``(base, ref, t, (left, up, forward) metres)`` places the landmark at
#: ``base + t * (base - ref)`` plus the offset, in the rest pose.
EXTRA_LANDMARKS = {
    "nose": ("head", None, 0.0, (0.0, -0.03, 0.10)),
    "spine_mid": ("spine", "chest", -0.5, (0.0, 0.0, 0.0)),
    **_both(
        {
            "{side}_eye": ("head", None, 0.0, (0.032, 0.01, 0.085)),
            "{side}_eye_inner": ("head", None, 0.0, (0.015, 0.01, 0.09)),
            "{side}_eye_outer": ("head", None, 0.0, (0.05, 0.01, 0.075)),
            "{side}_ear": ("head", None, 0.0, (0.075, -0.005, 0.0)),
            "mouth_{side}": ("head", None, 0.0, (0.025, -0.065, 0.085)),
            "{side}_hand_tip": ("{side}_hand", "{side}_wrist", 1.0, (0.0, 0.0, 0.0)),
            "{side}_thumb": ("{side}_hand", "{side}_wrist", 0.0, (0.0, 0.0, 0.04)),
            "{side}_index": ("{side}_hand", "{side}_wrist", 0.2, (0.0, 0.0, 0.02)),
            "{side}_pinky": ("{side}_hand", "{side}_wrist", 0.2, (0.0, 0.0, -0.02)),
            "{side}_heel": ("{side}_ankle", None, 0.0, (0.0, -0.06, -0.06)),
            "{side}_big_toe": ("{side}_ankle", None, 0.0, (-0.02, -0.08, 0.18)),
            "{side}_small_toe": ("{side}_ankle", None, 0.0, (0.03, -0.08, 0.14)),
            "{side}_foot_index": ("{side}_ankle", None, 0.0, (0.0, -0.08, 0.18)),
        }
    ),
}


def _rest_axes(skeleton, preset):
    """World (left, up, forward) unit vectors of the skeleton's rest pose."""
    rest = preset.positions(skeleton, np.zeros((1, skeleton.n_channels)))[0]
    up = np.zeros(3)
    up["xyz".index(skeleton.up_axis)] = 1.0
    left = rest[preset.names.index("left_hip")] - rest[preset.names.index("right_hip")]
    left -= (left @ up) * up
    left /= np.linalg.norm(left)
    return np.stack([left, up, np.cross(left, up)]), rest


def layout_markers(skeleton, layout):
    """A :class:`MarkerSet` placing every joint of a layout on a skeleton.

    Each joint sits on its landmark (:attr:`Layout.landmarks`): one of the 32
    :data:`MARKER_NAMES` of the skeleton's marker preset, or one of
    :data:`EXTRA_LANDMARKS`, fixed on the link of its base marker.

    Parameters
    ----------
    skeleton : Skeleton
        A skeleton with a marker preset (the humanoid, CMU ASF, ...).
    layout : str or Layout

    Returns
    -------
    markers : MarkerSet
        Named by the layout's joints, in the layout's order.

    Examples
    --------
    >>> from skmotion.datasets import humanoid_skeleton, layout_markers
    >>> markers = layout_markers(humanoid_skeleton(), "coco17")
    >>> len(markers), markers.names[:2], markers.joints[:2]
    (17, ('nose', 'left_eye'), ('Head', 'Head'))
    """
    layout = get_layout(layout)
    preset = marker_preset(skeleton)
    spots = dict(zip(preset.names, zip(preset.joints, preset.offsets)))
    unplaced = [j for j in layout.joints if layout.landmark(j) is None]
    unknown = [
        (j, layout.landmark(j))
        for j in layout.joints
        if layout.landmark(j) not in (*MARKER_NAMES, *EXTRA_LANDMARKS, None)
    ]
    if unplaced or unknown:
        bad = unplaced[0] if unplaced else f"{unknown[0][0]} (landmark {unknown[0][1]!r})"
        raise ValueError(
            f"Layout {layout.name!r}: joint {bad} has no known landmark; give landmarks= from "
            "MARKER_NAMES or EXTRA_LANDMARKS to place it on a skeleton."
        )
    axes, rest = _rest_axes(skeleton, preset)
    fk = forward_kinematics(skeleton, np.zeros((1, skeleton.n_channels)))
    scale = skeleton.height() / _HEIGHT
    rows = []
    for joint in layout.joints:
        landmark = layout.landmark(joint)
        if landmark in spots:
            rows.append((joint, *spots[landmark]))
            continue
        base, ref, t, offset = EXTRA_LANDMARKS[landmark]
        base_joint, base_offset = spots[base]
        world = np.asarray(offset) @ axes * scale
        if ref is not None:
            names = preset.names
            world = world + t * (rest[names.index(base)] - rest[names.index(ref)])
        rotation = fk.rotations[0, skeleton.joint_index(base_joint)]
        rows.append((joint, base_joint, base_offset + rotation.T @ world))
    return MarkerSet(rows)


def layout_positions(skeleton, channels, layout):
    """Joint positions of a layout computed from one joint-angle clip.

    Parameters
    ----------
    skeleton : Skeleton
    channels : array-like of shape (n_frames, n_channels)
    layout : str or Layout
        A 3-D layout (project 3-D positions yourself for image keypoints, or
        use :func:`make_position_motions`).

    Returns
    -------
    clip : ndarray of shape (n_frames, 3 * n_joints)
        In the skeleton's length unit and world axes (its ``up_axis`` up).

    Examples
    --------
    >>> from skmotion.datasets import make_motions, layout_positions
    >>> data = make_motions(n_clips_per_class=1, classes=["walk"], random_state=0)
    >>> layout_positions(data.skeletons[0], data.clips[0], "kinect_v2").shape
    (88, 75)
    """
    markers = layout_markers(skeleton, layout)
    channels = np.asarray(channels, dtype=float)
    return markers.positions(skeleton, channels).reshape(len(channels), -1)


def _project(points, up_axis):
    """Pinhole image of world points (metres): a camera 6 m away, 1.2 m high, 1000 px focal."""
    up = "xyz".index(up_axis)
    h1, h2 = (up + 1) % 3, (up + 2) % 3
    # The camera stands at -6 m along h2 and looks along +h2; (h1, h2, up) is right-handed,
    # so the image's right is +h1 and its down is -up.
    depth = points[..., h2] + 6.0
    u = 640.0 + 1000.0 * points[..., h1] / depth
    v = 360.0 - 1000.0 * (points[..., up] - 1.2) / depth
    return np.stack([u, v], axis=-1)


@validate_params(
    {
        "layout": [StrOptions(set(LAYOUTS)), Layout],
        "n_clips_per_class": [Interval(Integral, 1, None, closed="left")],
        "frame_rate": [Interval(Real, 0, None, closed="neither")],
        "random_state": ["random_state"],
    },
    prefer_skip_nested_validation=True,
)
def make_position_motions(
    layout, n_clips_per_class=12, *, frame_rate=30.0, random_state=None, **kw
):
    """Labelled joint-position clips of the synthetic humanoid, in a tracker's layout.

    The joint-angle clips of :func:`make_motions` (same classes, subjects and
    random draws for the same arguments) go through forward kinematics; each
    layout joint sits on its landmark (:func:`layout_markers`). 3-D layouts
    are in metres with the layout's own up axis (``"-y"`` layouts have ``y``
    pointing down). 2-D layouts are pinhole images (pixels, ``y`` down) from a
    camera 6 m in front of the start area, 1.2 m high, focal length 1000 px.

    Parameters
    ----------
    layout : str or Layout
        A name from :data:`~skmotion.preprocessing.LAYOUTS` or a Layout whose
        joints all have landmarks.
    n_clips_per_class : int, default=12
        As in :func:`make_motions`.
    frame_rate : float, default=30.0
        Frames per second.
    random_state : int, RandomState instance or None, default=None
        Seed; the same seed gives the motions of :func:`make_motions`.
    **kw
        Other :func:`make_motions` arguments (``n_subjects``, ``classes``,
        ``duration``, ``noise``).

    Returns
    -------
    data : Bunch
        clips : list of ndarray of shape (n_frames_i, dim * n_joints)
            Joint positions, joint-major.
        target, target_names, groups, frame_rate
            As in :func:`make_motions`.
        layout : Layout
            The layout of the clips.
        angles : list of ndarray
            The joint-angle clips the positions come from.
        skeletons : list of Skeleton
            Each clip's skeleton.
        feature_names : list of str
            ``"<joint>_<x|y|z>"``.

    Examples
    --------
    >>> from skmotion.datasets import make_position_motions
    >>> data = make_position_motions("coco17", n_clips_per_class=2, random_state=0)
    >>> len(data.clips), data.clips[0].shape, data.feature_names[:2]
    (14, (88, 34), ['nose_x', 'nose_y'])
    """
    layout = get_layout(layout)
    data = make_motions(n_clips_per_class, frame_rate=frame_rate, random_state=random_state, **kw)
    placed = {}
    clips = []
    for channels, skeleton in zip(data.clips, data.skeletons):
        if skeleton not in placed:
            placed[skeleton] = layout_markers(skeleton, get_layout(layout, dim=3))
        points = placed[skeleton].positions(skeleton, channels)  # Y up, metres
        if layout.dim == 2:
            points = _project(points, skeleton.up_axis)
        else:
            points = _to_up(points, skeleton.up_axis, layout.up)
        clips.append(points.reshape(len(channels), -1))
    return Bunch(
        clips=clips,
        target=data.target,
        target_names=data.target_names,
        groups=data.groups,
        frame_rate=data.frame_rate,
        layout=layout,
        angles=data.clips,
        skeletons=data.skeletons,
        feature_names=layout.feature_names(),
        DESCR=make_position_motions.__doc__.split("Parameters")[0].strip(),
    )


def _to_up(points, source, target):
    """World points with ``source`` up, turned so that ``target`` (maybe ``"-y"``) is up."""
    if target == source:
        return points
    s, t = "xyz".index(source), "xyz".index(target[-1])
    out = points.copy()
    if s != t:  # a cyclic permutation of the axes keeps the frame right-handed
        shift = (t - s) % 3
        out = np.roll(out, shift, axis=-1)
    if target.startswith("-"):  # a half turn about the next axis keeps handedness
        out[..., t] *= -1
        out[..., (t + 2) % 3] *= -1
    return out
