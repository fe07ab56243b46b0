"""Joint layouts of trackers and pose estimators: names, roles and shared markers.

A :class:`Layout` says what the channels of a position clip are: the joint
names in the system's own order (``dim`` channels per joint, joint-major), which
joints give the root, the facing direction and the body size, where each joint
sits on the body (a landmark name; those among the 32 :data:`MARKER_NAMES` put
clips of different systems into one feature space) and which joints move as
one rigid segment (for gap filling). The named layouts follow each system's
documentation (:mod:`skmotion.kinematics._named_layouts`); the sources are
listed in ``docs/positions.md``.
"""

from dataclasses import dataclass

import numpy as np

from skmotion.kinematics._marker_names import MARKER_NAMES

# The shared markers along which a layout's stick figure is drawn (see Layout.bones).
_TRUNK = ("pelvis", "spine", "chest", "neck", "head", "head_top")  # from the root up
_ARM = ("clavicle", "shoulder", "upper_arm", "elbow", "forearm", "wrist", "hand")
_LEG = ("hip", "thigh", "knee", "shin", "ankle", "toe")

__all__ = ["Layout", "layout_plan"]

_UP = ("x", "y", "z", "-x", "-y", "-z")


def _names(value, what):
    names = (value,) if isinstance(value, str) else tuple(value)
    if not names or not all(isinstance(n, str) for n in names):
        raise ValueError(f"Layout {what} must be a joint name or a non-empty sequence of them.")
    return names


@dataclass(frozen=True)
class Layout:
    """The joints of a position-clip system and their roles.

    Parameters
    ----------
    name : str
        The layout's name.
    joints : sequence of str
        Joint names in the system's own order; a clip has ``dim`` channels per
        joint, joint-major (``x, y[, z]`` of joint 0, then of joint 1, ...).
    root : str or sequence of str
        The joint (or joints, averaged) the body frame's origin lies below.
    left_hip, right_hip, left_shoulder, right_shoulder : str
        The joints on the subject's left and right that give the facing
        direction: forward is perpendicular to the sum of the two left-minus-
        right vectors, on the floor.
    size_chain : sequence of str
        Joints along the body whose summed median distances are the body size.
    dim : {2, 3}, default=3
        Coordinates per joint: 3 for trackers and 3-D estimators, 2 for image
        keypoints.
    up : {"x", "y", "z", "-x", "-y", "-z"}, default="y"
        The vertical axis of the system's coordinates (``"-y"``: ``y`` points
        down, as in image and camera coordinates).
    landmarks : sequence of (str, str) or dict, default=()
        For some or all joints, the body landmark it sits on: a name from
        :data:`MARKER_NAMES` (shared with the marker presets) or one of the
        extra landmarks of :func:`skmotion.datasets.make_position_motions`.
    groups : sequence of sequence of str, default=()
        Joints that move as one rigid segment, at least 4 per group (3 visible
        donors fix a missing one, see :class:`FillGaps`).
    source : str, default=""
        Where the joint order comes from.

    Attributes
    ----------
    n_joints : int
        Number of joints.
    shared_markers : tuple of (str, str)
        ``(joint, marker)`` for the joints whose landmark is one of the 32
        shared :data:`MARKER_NAMES`, in the order of ``MARKER_NAMES``.

    See Also
    --------
    get_layout : the named layouts.
    VirtualMarkerTransform : ``layout=`` turns position clips into features.

    Examples
    --------
    >>> from skmotion.preprocessing import Layout
    >>> mine = Layout("lab", ["pelvis", "lhip", "rhip", "lsho", "rsho", "lknee", "lankle", "head"],
    ...               root="pelvis", left_hip="lhip", right_hip="rhip", left_shoulder="lsho",
    ...               right_shoulder="rsho", size_chain=["lankle", "lknee", "lhip", "lsho"],
    ...               landmarks={"pelvis": "pelvis", "lhip": "left_hip", "lknee": "left_knee"})
    >>> mine.n_joints, mine.shared_markers[0]
    (8, ('pelvis', 'pelvis'))
    """

    name: str
    joints: tuple
    root: tuple
    left_hip: str
    right_hip: str
    left_shoulder: str
    right_shoulder: str
    size_chain: tuple
    dim: int = 3
    up: str = "y"
    landmarks: tuple = ()
    groups: tuple = ()
    source: str = ""

    def __post_init__(self):
        set_ = object.__setattr__
        joints = _names(self.joints, "joints")
        if len(set(joints)) != len(joints):
            dup = next(j for j in joints if joints.count(j) > 1)
            raise ValueError(f"Layout {self.name!r}: joint {dup!r} appears twice.")
        set_(self, "joints", joints)
        set_(self, "root", _names(self.root, "root"))
        set_(self, "size_chain", _names(self.size_chain, "size_chain"))
        landmarks = self.landmarks.items() if isinstance(self.landmarks, dict) else self.landmarks
        set_(self, "landmarks", tuple((str(j), str(m)) for j, m in landmarks))
        set_(self, "groups", tuple(_names(g, "group") for g in self.groups))
        if self.dim not in (2, 3):
            raise ValueError(f"Layout {self.name!r}: dim must be 2 or 3, got {self.dim!r}.")
        if self.up not in _UP:
            raise ValueError(f"Layout {self.name!r}: up must be one of {_UP}, got {self.up!r}.")
        used = [*self.root, self.left_hip, self.right_hip, self.left_shoulder]
        used += [self.right_shoulder, *self.size_chain, *(j for j, _ in self.landmarks)]
        used += [j for g in self.groups for j in g]
        unknown = [j for j in used if j not in joints]
        if unknown:
            raise ValueError(
                f"Layout {self.name!r}: {unknown[0]!r} is not one of its joints {list(joints)}."
            )
        if len(self.size_chain) < 2:
            raise ValueError(f"Layout {self.name!r}: size_chain needs at least two joints.")
        small = [g for g in self.groups if len(g) < 4]
        if small:
            raise ValueError(
                f"Layout {self.name!r}: rigid group {list(small[0])} has fewer than 4 joints; a "
                "missing joint is fitted from 3 visible ones."
            )
        shared = [m for _, m in self.landmarks if m in MARKER_NAMES]
        if len(set(shared)) != len(shared):
            dup = next(m for m in shared if shared.count(m) > 1)
            raise ValueError(f"Layout {self.name!r}: two joints sit on marker {dup!r}.")

    @property
    def n_joints(self):
        """Number of joints."""
        return len(self.joints)

    @property
    def shared_markers(self):
        """``(joint, marker)`` pairs on the shared markers, in :data:`MARKER_NAMES` order."""
        on = {m: j for j, m in self.landmarks if m in MARKER_NAMES}
        return tuple((on[m], m) for m in MARKER_NAMES if m in on)

    @property
    def bones(self):
        """Pairs of joints to draw as a stick figure, from the joints' places on the body.

        The layouts list no bones of their own; joints on the shared markers are
        joined along the trunk (pelvis to head top, so the first bone starts at the
        root), each arm (from the neck, or the
        chest or spine where the layout has no neck, to the hand) and each leg (from
        the pelvis, or the spine, to the toe), skipping the markers the layout lacks;
        a layout with no trunk joint gets a torso of shoulders and hips. Joints on
        other landmarks (eyes, ears, fingers) stay unjoined.

        Returns
        -------
        bones : tuple of (str, str)
            ``(parent joint, child joint)`` pairs.

        Examples
        --------
        >>> from skmotion.kinematics import get_layout
        >>> get_layout("kinect_v2").bones[:2]
        (('SpineBase', 'SpineMid'), ('SpineMid', 'SpineShoulder'))
        """
        on = {m: j for j, m in self.landmarks if m in MARKER_NAMES}
        chains = [[on[m] for m in _TRUNK if m in on]]
        for side in ("left", "right"):
            for anchors, parts in ((("neck", "chest", "spine"), _ARM), (("pelvis", "spine"), _LEG)):
                start = [next((on[a] for a in anchors if a in on), None)]
                limb = [on[f"{side}_{p}"] for p in parts if f"{side}_{p}" in on]
                chains.append([j for j in start if j is not None] + limb if limb else [])
        bones = [pair for chain in chains for pair in zip(chain[:-1], chain[1:])]
        if not chains[0]:  # no trunk (COCO, MediaPipe): a torso from the limbs' first joints,
            # hips first, so that the first bone starts at the root as in the other layouts
            la, ll, ra, rl = (chain[0] if chain else None for chain in chains[1:])
            torso = ((ll, rl), (ll, la), (rl, ra), (la, ra))
            bones = [(a, b) for a, b in torso if a and b] + bones
        return tuple(bones)

    def landmark(self, joint):
        """The landmark a joint sits on, or None.

        Parameters
        ----------
        joint : str

        Returns
        -------
        landmark : str or None
        """
        return dict(self.landmarks).get(joint)

    def index(self, joint):
        """Position of ``joint`` in :attr:`joints`, with a clear error.

        Parameters
        ----------
        joint : str

        Returns
        -------
        index : int
        """
        if joint not in self.joints:
            raise ValueError(
                f"{joint!r} is not a joint of layout {self.name!r}; joints: {list(self.joints)}."
            )
        return self.joints.index(joint)

    def feature_names(self):
        """Channel names of a clip in this layout, ``"<joint>_<x|y|z>"``.

        Returns
        -------
        names : list of str
        """
        return [f"{j}_{c}" for j in self.joints for c in "xyz"[: self.dim]]


def layout_plan(layout, markers="auto"):
    """Joint indices of a layout's roles and of the points to output.

    Parameters
    ----------
    layout : Layout
    markers : "auto", "all" or sequence of str, default="auto"
        ``"auto"``: the joints on shared markers, named by the marker, in
        :data:`MARKER_NAMES` order; ``"all"``: every joint under its own name; a
        list: those joints (layout or shared-marker names), in that order.

    Returns
    -------
    plan : dict
        ``outputs`` (joint indices), ``names`` (output names), ``root``,
        ``lefts``, ``rights``, ``size_chain`` (joint indices).

    Examples
    --------
    >>> from skmotion.preprocessing import get_layout
    >>> from skmotion.kinematics._layouts import layout_plan
    >>> plan = layout_plan(get_layout("coco17"))
    >>> plan["names"][:3], plan["root"]
    (('left_shoulder', 'left_elbow', 'left_wrist'), (11, 12))
    """
    index = layout.index
    if isinstance(markers, str) and markers == "auto":
        pairs = layout.shared_markers
        if not pairs:
            raise ValueError(
                f"Layout {layout.name!r} maps no joint onto the shared markers; use markers='all'."
            )
    elif isinstance(markers, str) and markers == "all":
        pairs = tuple((j, j) for j in layout.joints)
    elif isinstance(markers, str):
        raise ValueError(f"markers={markers!r}: with a layout, use 'auto', 'all' or joint names.")
    else:
        on = {m: j for j, m in layout.shared_markers}
        pairs = tuple((on.get(str(n), str(n)), str(n)) for n in markers)
    return {
        "outputs": np.array([index(j) for j, _ in pairs], dtype=np.intp),
        "names": tuple(n for _, n in pairs),
        "root": tuple(index(j) for j in layout.root),
        "lefts": (index(layout.left_hip), index(layout.left_shoulder)),
        "rights": (index(layout.right_hip), index(layout.right_shoulder)),
        "size_chain": tuple(index(j) for j in layout.size_chain),
    }
