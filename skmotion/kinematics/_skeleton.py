"""The Skeleton: an immutable description of a joint hierarchy and its channels."""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from skmotion.kinematics._rotations import check_rotation_order

__all__ = ["CHANNEL_KINDS", "Skeleton"]

#: The channel names a joint may carry (BVH spelling). Positions are in the
#: skeleton's length unit, rotations in radians.
CHANNEL_KINDS = (
    "Xposition",
    "Yposition",
    "Zposition",
    "Xrotation",
    "Yrotation",
    "Zrotation",
)
_UP_AXES = ("x", "y", "z")


def _readonly(array):
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False, repr=False)
class Skeleton:
    """A joint hierarchy with per-joint channels, immutable and picklable.

    Joints are listed parents first. Each joint sits at ``offsets[j]`` in its
    parent's frame; its local rotation, built from its rotation channels in
    ``rotation_orders[j]`` (intrinsic, BVH semantics), turns its children. A
    joint's position channels, when present, replace the matching components of
    its offset (so a root's position channels are its absolute position, as in
    BVH and AMC files). A joint with a bone ``axes[j]`` (the ASF ``axis``, a
    rotation matrix ``C``) rotates by ``C @ M @ C.T`` where ``M`` is built from
    its channels. Joints without channels and children are end sites.

    Parameters
    ----------
    joints : sequence of str
        Joint names, unique; parents come before children.
    parents : sequence of int
        Index of each joint's parent, ``-1`` for the root (exactly one root).
    offsets : array-like of shape (n_joints, 3)
        Rest offset of each joint from its parent, in the parent's frame.
    channels : sequence of sequence of str
        Per joint, its channels in data order, from :data:`CHANNEL_KINDS`.
    rotation_orders : sequence of str, default=None
        Per joint, the intrinsic Euler order of its rotation, a permutation of
        ``"XYZ"``. By default the order in which its rotation channels appear
        (with missing axes appended in X, Y, Z order).
    axes : array-like of shape (n_joints, 3, 3), default=None
        Per joint, the bone axis frame ``C`` (ASF); ``None`` means identity.
    units : str, default="unknown"
        Name of the length unit of offsets and position channels.
    meters_per_unit : float, default=None
        Metres per length unit, when known.
    up_axis : {"x", "y", "z"}, default="y"
        The vertical axis of the world frame.

    Attributes
    ----------
    n_joints : int
        Number of joints, end sites included.
    n_channels : int
        Number of channels of a clip of this skeleton.
    channel_names : list of str
        ``"<joint>_<channel>"`` for every channel, in data order.

    See Also
    --------
    skmotion.kinematics.forward_kinematics : world poses from channels.

    Examples
    --------
    >>> from skmotion.kinematics import Skeleton
    >>> arm = Skeleton(
    ...     joints=["shoulder", "elbow", "hand"],
    ...     parents=[-1, 0, 1],
    ...     offsets=[[0, 0, 0], [0.3, 0, 0], [0.25, 0, 0]],
    ...     channels=[["Zrotation"], ["Zrotation"], []],
    ...     units="m", meters_per_unit=1.0,
    ... )
    >>> arm.n_channels, arm.channel_names
    (2, ['shoulder_Zrotation', 'elbow_Zrotation'])
    """

    joints: tuple
    parents: tuple
    offsets: np.ndarray
    channels: tuple
    rotation_orders: tuple = None
    axes: np.ndarray = None
    units: str = "unknown"
    meters_per_unit: float = None
    up_axis: str = "y"

    def __post_init__(self):
        set_ = object.__setattr__
        joints = tuple(str(j) for j in self.joints)
        n = len(joints)
        if n == 0:
            raise ValueError("A Skeleton needs at least one joint.")
        if len(set(joints)) != n:
            seen = set()
            dup = next(j for j in joints if j in seen or seen.add(j))
            raise ValueError(f"Joint names must be unique; {dup!r} appears twice.")
        parents = tuple(int(p) for p in self.parents)
        if len(parents) != n:
            raise ValueError(f"parents has {len(parents)} entries for {n} joints.")
        roots = [j for j, p in enumerate(parents) if p < 0]
        if roots != [0]:
            raise ValueError(
                f"The first joint must be the only root (parent -1); roots found at {roots}."
            )
        for j, p in enumerate(parents[1:], start=1):
            if not 0 <= p < j:
                raise ValueError(
                    f"Joint {joints[j]!r} (index {j}) has parent index {p}; parents "
                    "must be listed before their children."
                )
        offsets = np.asarray(self.offsets, dtype=float)
        if offsets.shape != (n, 3) or not np.isfinite(offsets).all():
            raise ValueError(
                f"offsets must be a finite array of shape ({n}, 3); got shape {offsets.shape}."
            )
        channels = tuple(tuple(str(c) for c in chans) for chans in self.channels)
        if len(channels) != n:
            raise ValueError(f"channels has {len(channels)} entries for {n} joints.")
        for joint, chans in zip(joints, channels):
            unknown = [c for c in chans if c not in CHANNEL_KINDS]
            if unknown:
                raise ValueError(
                    f"Joint {joint!r} has unknown channel(s) {unknown}; expected names "
                    f"from {list(CHANNEL_KINDS)}."
                )
            if len(set(chans)) != len(chans):
                raise ValueError(f"Joint {joint!r} lists a channel twice: {list(chans)}.")
        if self.rotation_orders is None:
            orders = tuple(_default_order(chans) for chans in channels)
        else:
            orders = tuple(self.rotation_orders)
            if len(orders) != n:
                raise ValueError(f"rotation_orders has {len(orders)} entries for {n} joints.")
            orders = tuple(
                check_rotation_order(o, where=f"rotation order of joint {joints[j]!r}")
                for j, o in enumerate(orders)
            )
        axes = None
        if self.axes is not None:
            axes = np.asarray(self.axes, dtype=float)
            if axes.shape != (n, 3, 3):
                raise ValueError(f"axes must have shape ({n}, 3, 3); got {axes.shape}.")
            gram = np.einsum("jik,jil->jkl", axes, axes)
            bad = np.flatnonzero(np.abs(gram - np.eye(3)).max(axis=(1, 2)) > 1e-6)
            if bad.size or (np.linalg.det(axes) < 0).any():
                which = joints[bad[0]] if bad.size else joints[int(np.argmin(np.linalg.det(axes)))]
                raise ValueError(f"axes of joint {which!r} is not a rotation matrix.")
            axes = _readonly(axes)
        up_axis = str(self.up_axis).lower()
        if up_axis not in _UP_AXES:
            raise ValueError(f"up_axis must be one of {_UP_AXES}, got {self.up_axis!r}.")
        if self.meters_per_unit is not None and not self.meters_per_unit > 0:
            raise ValueError(f"meters_per_unit must be positive, got {self.meters_per_unit!r}.")
        set_(self, "joints", joints)
        set_(self, "parents", parents)
        set_(self, "offsets", _readonly(offsets))
        set_(self, "channels", channels)
        set_(self, "rotation_orders", orders)
        set_(self, "axes", axes)
        set_(self, "up_axis", up_axis)
        set_(self, "units", str(self.units))
        set_(
            self,
            "meters_per_unit",
            None if self.meters_per_unit is None else float(self.meters_per_unit),
        )

    # -- identity -------------------------------------------------------------
    @cached_property
    def _key(self):
        return (
            self.joints,
            self.parents,
            self.offsets.tobytes(),
            self.channels,
            self.rotation_orders,
            None if self.axes is None else self.axes.tobytes(),
            self.units,
            self.meters_per_unit,
            self.up_axis,
        )

    def __eq__(self, other):
        if not isinstance(other, Skeleton):
            return NotImplemented
        return self._key == other._key

    def __hash__(self):
        return hash(self._key)

    def __reduce__(self):
        return (
            Skeleton,
            (
                self.joints,
                self.parents,
                np.array(self.offsets),
                self.channels,
                self.rotation_orders,
                None if self.axes is None else np.array(self.axes),
                self.units,
                self.meters_per_unit,
                self.up_axis,
            ),
        )

    def __repr__(self):
        return (
            f"Skeleton(n_joints={self.n_joints}, n_channels={self.n_channels}, "
            f"root={self.joints[0]!r}, up_axis={self.up_axis!r}, units={self.units!r})"
        )

    # -- structure ------------------------------------------------------------
    @property
    def n_joints(self):
        return len(self.joints)

    @cached_property
    def n_channels(self):
        return sum(len(c) for c in self.channels)

    @cached_property
    def channel_names(self):
        return [f"{j}_{c}" for j, chans in zip(self.joints, self.channels) for c in chans]

    @cached_property
    def _children(self):
        children = [[] for _ in self.joints]
        for j, p in enumerate(self.parents):
            if p >= 0:
                children[p].append(j)
        return tuple(tuple(c) for c in children)

    def children(self, joint):
        """Indices of the children of ``joint`` (a name or an index)."""
        return self._children[self.joint_index(joint)]

    @cached_property
    def end_sites(self):
        """Indices of joints with neither channels nor children."""
        return tuple(
            j for j in range(self.n_joints) if not self.channels[j] and not self._children[j]
        )

    @cached_property
    def depths(self):
        """Depth of each joint in the tree (the root has depth 0), as an int array."""
        depths = np.zeros(self.n_joints, dtype=np.intp)
        for j, p in enumerate(self.parents[1:], start=1):
            depths[j] = depths[p] + 1
        depths.setflags(write=False)
        return depths

    def joint_index(self, joint):
        """Index of a joint given by name or index; a clear error if unknown."""
        if isinstance(joint, (int, np.integer)):
            if not -self.n_joints <= joint < self.n_joints:
                raise IndexError(f"Joint index {joint} out of range for {self.n_joints} joints.")
            return int(joint) % self.n_joints
        try:
            return self.joints.index(joint)
        except ValueError:
            raise KeyError(
                f"Unknown joint {joint!r}; this skeleton has {list(self.joints)}."
            ) from None

    def channel_index(self, joint, channel):
        """Column of ``channel`` (e.g. ``"Xrotation"``) of ``joint`` in a clip."""
        j = self.joint_index(joint)
        if channel not in self.channels[j]:
            raise KeyError(
                f"Joint {self.joints[j]!r} has no channel {channel!r}; "
                f"it has {list(self.channels[j])}."
            )
        start = sum(len(c) for c in self.channels[:j])
        return start + self.channels[j].index(channel)

    # -- geometry ---------------------------------------------------------------
    def rest_positions(self):
        """World positions of all joints at zero channels, shape ``(n_joints, 3)``.

        Position channels at zero would put the root at the origin; the rest pose
        instead keeps every offset, the root's included.
        """
        positions = np.zeros((self.n_joints, 3))
        for j, p in enumerate(self.parents):
            positions[j] = self.offsets[j] + (positions[p] if p >= 0 else 0.0)
        return positions

    def height(self):
        """Extent of the rest pose along the up axis: the standing height."""
        up = _UP_AXES.index(self.up_axis)
        rest = self.rest_positions()[:, up]
        return float(rest.max() - rest.min())

    def scaled(self, factor):
        """A copy with all lengths multiplied by ``factor`` (a bigger or smaller subject).

        Position channels of clips must be scaled by the same factor.
        """
        if not factor > 0:
            raise ValueError(f"factor must be positive, got {factor!r}.")
        return Skeleton(
            self.joints,
            self.parents,
            np.asarray(self.offsets) * factor,
            self.channels,
            self.rotation_orders,
            self.axes,
            self.units,
            self.meters_per_unit,
            self.up_axis,
        )

    def forward_kinematics(self, channels):
        """World positions and rotations of every joint for every frame.

        See :func:`skmotion.kinematics.forward_kinematics`.
        """
        from skmotion.kinematics._forward import forward_kinematics

        return forward_kinematics(self, channels)


def _default_order(channels):
    axes = [c[0] for c in channels if c.endswith("rotation")]
    return "".join(axes + [a for a in "XYZ" if a not in axes])
