"""ArmModel: a serial arm of rigid cylinders, and its MuJoCo (MJCF) description."""

from dataclasses import dataclass

import numpy as np

from skmotion.kinematics import forward_kinematics

__all__ = ["ArmModel"]

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_UP = {"x": 0, "y": 1, "z": 2}


def _readonly(array):
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _fmt(values):
    return " ".join(f"{v:.9g}" for v in np.ravel(values))


@dataclass(frozen=True, eq=False)
class ArmModel:
    """A serial arm of rigid cylinders on a fixed base, in metres, hanging at rest.

    Link ``i`` is a solid cylinder from its joint to the next joint (the last to
    the arm's end); its joint is a chain of hinges applied in order, each turning
    about its axis in the frame left by the hinges before it (intrinsic Euler
    angles, as in :mod:`skmotion.kinematics`). Masses and inertias follow from
    the cylinders' geometry and a uniform density. The base is fixed in the
    world with the rest orientation of the skeleton it came from, and gravity
    points down the up axis.

    Parameters
    ----------
    links : array-like of shape (n_links, 3)
        Each link's vector from its joint to the next joint, in the rest pose
        (world frame, metres).
    hinges : sequence of sequence of array-like of shape (3,)
        Per link, the unit axes of its hinges in order, in the rest frame.
    radii : array-like of shape (n_links,)
        Radius of each link's cylinder, metres.
    density : float, default=1050.0
        kg per cubic metre (human soft tissue is about 1050).
    up_axis : {"x", "y", "z"}, default="y"
        The world's vertical axis; gravity is ``-9.81`` m/s^2 along it.
    dof_names : sequence of str, default=None
        A name per hinge (e.g. the skeleton channel it follows).

    Attributes
    ----------
    n_dof : int
        Number of hinges.
    lengths : ndarray of shape (n_links,)
        Link lengths, metres.
    masses : ndarray of shape (n_links,)
        Link masses, kg.

    Examples
    --------
    >>> from skmotion.control import ArmModel
    >>> from skmotion.datasets import humanoid_skeleton
    >>> arm = ArmModel.from_skeleton(humanoid_skeleton(), ["RightArm", "RightForeArm"],
    ...                              dofs=["ZXY", "X"], end="RightHand_end")
    >>> arm.n_dof, arm.lengths.round(2).tolist(), arm.dof_names
    (4, [0.29, 0.44], ('RightArm_Zrotation', 'RightArm_Xrotation', 'RightArm_Yrotation',
                       'RightForeArm_Xrotation'))
    """

    links: np.ndarray
    hinges: tuple
    radii: np.ndarray
    density: float = 1050.0
    up_axis: str = "y"
    dof_names: tuple = None

    def __post_init__(self):
        links = np.asarray(self.links, dtype=float)
        if (
            links.ndim != 2
            or links.shape[1] != 3
            or len(links) == 0
            or not np.isfinite(links).all()
        ):
            raise ValueError(
                f"links must be a finite array of shape (n_links, 3); got {links.shape}."
            )
        if (np.linalg.norm(links, axis=1) <= 0).any():
            raise ValueError("Every link must have a positive length.")
        hinges = tuple(tuple(_readonly(a) for a in h) for h in self.hinges)
        if len(hinges) != len(links):
            raise ValueError(f"hinges has {len(hinges)} entries for {len(links)} links.")
        for i, h in enumerate(hinges):
            for a in h:
                if a.shape != (3,) or abs(np.linalg.norm(a) - 1) > 1e-9:
                    raise ValueError(
                        f"hinge axes of link {i} must be unit 3-vectors; got {a.tolist()}."
                    )
        radii = np.broadcast_to(np.asarray(self.radii, dtype=float), (len(links),))
        if not (radii > 0).all():
            raise ValueError(f"radii must be positive; got {radii.tolist()}.")
        if not self.density > 0:
            raise ValueError(f"density must be positive; got {self.density!r}.")
        up = str(self.up_axis).lower()
        if up not in _UP:
            raise ValueError(f"up_axis must be one of {sorted(_UP)}; got {self.up_axis!r}.")
        n_dof = sum(len(h) for h in hinges)
        names = (
            tuple(f"q{k}" for k in range(n_dof))
            if self.dof_names is None
            else tuple(self.dof_names)
        )
        if len(names) != n_dof:
            raise ValueError(f"dof_names has {len(names)} names for {n_dof} hinges.")
        object.__setattr__(self, "links", _readonly(links))
        object.__setattr__(self, "hinges", hinges)
        object.__setattr__(self, "radii", _readonly(radii))
        object.__setattr__(self, "density", float(self.density))
        object.__setattr__(self, "up_axis", up)
        object.__setattr__(self, "dof_names", names)

    @classmethod
    def from_skeleton(cls, skeleton, joints, *, dofs, end, radii=(0.045, 0.035), density=1050.0):
        """The arm of a skeleton: a link per listed joint, hinges on its rotation axes.

        Link ``i`` runs from ``joints[i]`` to ``joints[i + 1]`` (the last to
        ``end``) in the skeleton's rest pose, so an arm's joint angles are the
        skeleton's channels: hinge angles equal to the channels
        ``dof_names`` give the pose forward kinematics gives (with the
        joints above the arm at rest). Each joint's hinges follow its
        rotation order, about its bone axes (ASF ``axis``) when it has them.

        Parameters
        ----------
        skeleton : Skeleton
            With ``meters_per_unit`` set (lengths are converted to metres).
        joints : sequence of str
            The arm's joints, from the base outward along one chain.
        dofs : sequence of str
            Per joint, the rotation axes to actuate, e.g. ``"ZXY"`` or ``"X"``.
        end : str
            The joint (or end site) where the last link ends.
        radii : float or sequence of float, default=(0.045, 0.035)
            Link radii, metres.
        density : float, default=1050.0
            kg per cubic metre.

        Returns
        -------
        arm : ArmModel
        """
        if skeleton.meters_per_unit is None:
            raise ValueError(
                "The skeleton's meters_per_unit is unknown; set it to build an arm in metres."
            )
        if len(dofs) != len(joints):
            raise ValueError(f"dofs has {len(dofs)} entries for {len(joints)} joints.")
        rest = forward_kinematics(skeleton, np.zeros((1, skeleton.n_channels))).positions[0]
        chain = [skeleton.joint_index(j) for j in [*joints, end]]
        links = (rest[chain[1:]] - rest[chain[:-1]]) * skeleton.meters_per_unit
        hinges, names = [], []
        for joint, j, wanted in zip(joints, chain, dofs):
            wanted = str(wanted).upper()
            order = skeleton.rotation_orders[j]
            unknown = [
                a for a in wanted if a not in order or f"{a}rotation" not in skeleton.channels[j]
            ]
            if unknown:
                raise ValueError(f"Joint {joint!r} has no rotation channel about {unknown}.")
            frame = np.eye(3) if skeleton.axes is None else skeleton.axes[j]
            used = [a for a in order if a in wanted]
            hinges.append([frame @ np.array(_AXES[a]) for a in used])
            names += [f"{joint}_{a}rotation" for a in used]
        return cls(links, hinges, radii, density=density, up_axis=skeleton.up_axis, dof_names=names)

    @property
    def n_dof(self):
        """Number of hinges."""
        return sum(len(h) for h in self.hinges)

    @property
    def lengths(self):
        """Link lengths, metres."""
        return np.linalg.norm(self.links, axis=1)

    @property
    def masses(self):
        """Link masses, kg (solid cylinders of the arm's density)."""
        return self.density * np.pi * self.radii**2 * self.lengths

    def to_mjcf(self, *, kp, kd, timestep=0.001):
        """The MuJoCo model: bodies, hinges and a PD servo on every hinge.

        Each hinge carries a position servo (force ``kp * (ctrl - q)``) and a
        velocity servo (force ``kd * (ctrl - qdot)``); with the desired angle and
        velocity as their controls they sum to the PD law
        ``tau = kp (q_d - q) + kd (qd_d - qd)``. The ``implicitfast`` integrator
        treats the damping implicitly, which keeps stiff servos stable.

        Parameters
        ----------
        kp, kd : array-like of shape (n_dof,)
            Stiffness (N m/rad) and damping (N m s/rad) per hinge.
        timestep : float, default=0.001
            Physics step in seconds.

        Returns
        -------
        xml : str
        """
        gravity = np.zeros(3)
        gravity[_UP[self.up_axis]] = -9.81
        lines = [
            '<mujoco model="skmotion_arm">',
            f'  <option timestep="{timestep:.9g}" gravity="{_fmt(gravity)}"'
            ' integrator="implicitfast"/>',
            "  <worldbody>",
        ]
        k, indent, opened = 0, "    ", 0
        for i, (link, hinges, radius) in enumerate(zip(self.links, self.hinges, self.radii)):
            pos = np.zeros(3) if i == 0 else self.links[i - 1]
            lines.append(f'{indent}<body name="link{i}" pos="{_fmt(pos)}">')
            for axis in hinges:
                lines.append(f'{indent}  <joint name="q{k}" type="hinge" axis="{_fmt(axis)}"/>')
                k += 1
            lines.append(
                f'{indent}  <geom type="cylinder" fromto="0 0 0 {_fmt(link)}" size="{radius:.9g}" '
                f'density="{self.density:.9g}" contype="0" conaffinity="0"/>'
            )
            indent += "  "
            opened += 1
        lines.append(f'{indent}<site name="tip" pos="{_fmt(self.links[-1])}"/>')
        for _ in range(opened):
            indent = indent[:-2]
            lines.append(f"{indent}</body>")
        lines += ["  </worldbody>", "  <actuator>"]
        kp, kd = np.broadcast_to(kp, (k,)), np.broadcast_to(kd, (k,))
        lines += [f'    <position joint="q{d}" kp="{kp[d]:.9g}"/>' for d in range(k)]
        lines += [f'    <velocity joint="q{d}" kv="{kd[d]:.9g}"/>' for d in range(k)]
        lines += ["  </actuator>", "</mujoco>"]
        return "\n".join(lines)
