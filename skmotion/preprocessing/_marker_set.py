"""Virtual marker sets: labelled points fixed on the links of a skeleton."""

from collections import namedtuple

import numpy as np

from skmotion.kinematics import forward_kinematics
from skmotion.kinematics._forward_loops import marker_pass

__all__ = ["Marker", "MarkerSet"]

Marker = namedtuple("Marker", ["name", "joint", "offset"])
Marker.__doc__ = """One virtual marker: a labelled point fixed on a joint's link.

Attributes
----------
name : str
    The marker's label; markers of the same name on different skeletons
    land in the same feature space.
joint : str
    The joint whose link carries the marker (it moves with the joint's world
    rotation).
offset : tuple of float
    The marker's position in the joint's frame, in the skeleton's length unit.
"""


class MarkerSet:
    """An ordered set of virtual markers ``(name, joint, offset)`` for one skeleton.

    A marker ``(name, joint, offset)`` sits at ``p_joint + R_joint @ offset``,
    with ``p_joint`` and ``R_joint`` the joint's world position and rotation from
    forward kinematics. The set knows nothing of any estimator: it validates
    itself against a skeleton and computes marker positions.

    Parameters
    ----------
    markers : iterable of Marker or of (name, joint, offset) tuples
        The markers, in output order; names must be unique.

    Attributes
    ----------
    names : tuple of str
        Marker names, in order.
    joints : tuple of str
        The joint carrying each marker.
    offsets : ndarray of shape (n_markers, 3)
        Each marker's offset in its joint's frame (read-only).

    See Also
    --------
    skmotion.preprocessing.marker_preset : the built-in sets for common skeletons.
    skmotion.preprocessing.VirtualMarkerTransform : markers as features.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.kinematics import Skeleton
    >>> from skmotion.preprocessing import MarkerSet
    >>> arm = Skeleton(["shoulder", "elbow", "hand"], [-1, 0, 1],
    ...                [[0, 0, 0], [1, 0, 0], [1, 0, 0]], [["Zrotation"], ["Zrotation"], []])
    >>> markers = MarkerSet([("elbow", "elbow", (0, 0, 0)), ("mid_forearm", "elbow", (0.5, 0, 0))])
    >>> markers.positions(arm, [[np.pi / 2, 0.0]]).round(6) + 0.0
    array([[[0. , 1. , 0. ],
            [0. , 1.5, 0. ]]])
    """

    def __init__(self, markers):
        rows = [Marker(*m) for m in markers]
        if not rows:
            raise ValueError("A MarkerSet needs at least one marker.")
        names = tuple(str(m.name) for m in rows)
        if len(set(names)) != len(names):
            seen = set()
            dup = next(n for n in names if n in seen or seen.add(n))
            raise ValueError(f"Marker names must be unique; {dup!r} appears twice.")
        offsets = np.array([np.asarray(m.offset, dtype=float) for m in rows])
        if offsets.shape != (len(rows), 3) or not np.isfinite(offsets).all():
            raise ValueError(
                "Each marker offset must be 3 finite numbers; got an array of shape "
                f"{offsets.shape}."
            )
        offsets.setflags(write=False)
        self.names = names
        self.joints = tuple(str(m.joint) for m in rows)
        self.offsets = offsets

    def __len__(self):
        return len(self.names)

    def __iter__(self):
        return (
            Marker(n, j, tuple(o))
            for n, j, o in zip(self.names, self.joints, self.offsets.tolist())
        )

    def __eq__(self, other):
        if not isinstance(other, MarkerSet):
            return NotImplemented
        return (self.names, self.joints) == (other.names, other.joints) and np.array_equal(
            self.offsets, other.offsets
        )

    def __hash__(self):
        return hash((self.names, self.joints, self.offsets.tobytes()))

    def __reduce__(self):
        return (MarkerSet, (list(self),))

    def __repr__(self):
        shown = ", ".join(self.names[:4]) + (", ..." if len(self) > 4 else "")
        return f"MarkerSet(n_markers={len(self)}: {shown})"

    def joint_indices(self, skeleton):
        """Index of each marker's joint in ``skeleton``; a clear error for unknown joints.

        Parameters
        ----------
        skeleton : Skeleton

        Returns
        -------
        indices : ndarray of int of shape (n_markers,)
        """
        index = {name: j for j, name in enumerate(skeleton.joints)}
        missing = [(m, j) for m, j in zip(self.names, self.joints) if j not in index]
        if missing:
            marker, joint = missing[0]
            raise ValueError(
                f"Marker {marker!r} is on joint {joint!r}, which the skeleton "
                f"(root {skeleton.joints[0]!r}, {skeleton.n_joints} joints) does not have"
                + (
                    f"; {len(missing) - 1} more markers have unknown joints."
                    if len(missing) > 1
                    else "."
                )
            )
        return np.array([index[j] for j in self.joints], dtype=np.intp)

    def positions(self, skeleton, channels):
        """World positions of the markers in every frame.

        Parameters
        ----------
        skeleton : Skeleton
        channels : array-like of shape (n_frames, n_channels)
            One clip of the skeleton's channels.

        Returns
        -------
        positions : ndarray of shape (n_frames, n_markers, 3)
        """
        joints = self.joint_indices(skeleton)
        fk = forward_kinematics(skeleton, channels)
        # p + R @ offset in one compiled pass (no gathered copies of the joints' poses)
        out = np.empty((len(fk.positions), len(joints), 3))
        marker_pass(fk.positions, fk.rotations, joints, self.offsets, out)
        return out
