"""A motion-matching controller: follow a root path by searching a motion database.

Every few frames the controller asks a fitted
:class:`~skmotion.neighbors.MotionMatcher` for the frame whose pose and
velocities are those playing now and whose future trajectory is the one the
path asks for (Clavet, GDC 2016), and plays on from there. Between searches the
database frames play in order; their root motion (the body frame's travel and
turn, :func:`~skmotion.neighbors.floor_frames`) moves the character.

Two things follow Holden's motion-matching demonstration (Holden, "Code vs
Data Driven Displacement", 2021; Holden et al., "Learned Motion Matching",
SIGGRAPH 2020):

- **inertialisation** (Bollo, GDC 2016): at a switch the difference between
  the frame that would have come next and the new frame (each in its own body
  frame) and the difference of their velocities decay to zero by a critically
  damped spring, so the pose and its velocity are continuous while the new
  clip plays unaltered underneath;
- **adjustment**: the character's root is pulled towards the point the path
  asks for now (and its facing towards the path's direction) by a spring with
  a half-life, the pull clamped to a fraction of the root's own motion in that
  frame, so the feet do not visibly slide.
"""

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from skmotion.io import Motion
from skmotion.planning._plan import _place

__all__ = ["MatchedPath", "follow_path", "path_distance", "path_from_velocities"]

_TWO_PI = 2.0 * np.pi


def _wrap(angle):
    return (angle + np.pi) % _TWO_PI - np.pi


def path_distance(points, path):
    """Distance of each point to a polyline, metres.

    Parameters
    ----------
    points : ndarray of shape (n, 2)
    path : ndarray of shape (n_vertices, 2)

    Returns
    -------
    distance : ndarray of shape (n,)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.planning import path_distance
    >>> path_distance(np.array([[0.5, 0.2], [2.0, 0.0]]), np.array([[0.0, 0.0], [1.0, 0.0]]))
    array([0.2, 1. ])
    """
    a, b = path[:-1], path[1:]
    ab = b - a
    t = np.einsum("psk,sk->ps", points[:, None, :] - a[None], ab) / np.einsum("sk,sk->s", ab, ab)
    closest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - closest, axis=2).min(axis=1)


def path_from_velocities(velocities, frame_rate, start=(0.0, 0.0)):
    """The floor path a velocity command per frame traces: points for :func:`follow_path`.

    Parameters
    ----------
    velocities : array-like of shape (n_frames, 2)
        Floor velocity (m/s, the planner's axes) commanded at each frame.
    frame_rate : float
        Frames per second.
    start : (float, float), default=(0, 0)

    Returns
    -------
    path : ndarray of shape (n_frames + 1, 2)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.planning import path_from_velocities
    >>> path_from_velocities(np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), 2.0)
    array([[0. , 0. ],
           [0.5, 0. ],
           [1. , 0. ],
           [1. , 0.5]])
    """
    steps = np.asarray(velocities, dtype=float) / float(frame_rate)
    if steps.ndim != 2 or steps.shape[1] != 2 or not np.isfinite(steps).all():
        raise ValueError(f"velocities must be finite, of shape (n_frames, 2); got {steps.shape}")
    return np.vstack([start, start + np.cumsum(steps, axis=0)])


def _check_path(path):
    """A float (n, 2) polyline without repeated points (consecutive repeats are dropped)."""
    points = np.asarray(path, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or not np.isfinite(points).all():
        raise ValueError(f"path must be finite floor points of shape (n, 2); got {points.shape}")
    # A zero-length leg has no direction: keep the first of repeated points (say so below).
    keep = np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 1e-9])
    points = points[keep]
    if len(points) < 2:
        raise ValueError("path needs two distinct points or more")
    return points


def _check_takes(matcher, takes):
    """The takes the matcher was fitted on, all on one skeleton."""
    if not hasattr(matcher, "origin_"):
        raise ValueError("the matcher is not fitted: fit it on the takes first")
    if len(takes) != len(matcher.origin_):
        raise ValueError(
            f"{len(takes)} takes, but the matcher was fitted on {len(matcher.origin_)}"
        )
    skeleton = getattr(takes[0], "skeleton", None)
    for i, take in enumerate(takes):
        if getattr(take, "skeleton", None) is None or take.n_channels != skeleton.n_channels:
            raise ValueError(f"take {i}: every take must be a Motion on the first take's skeleton")
        if take.n_frames != len(matcher.origin_[i]):
            raise ValueError(
                f"take {i} has {take.n_frames} frames; the matcher saw {len(matcher.origin_[i])}"
            )
    return skeleton


class _Path:
    """A polyline by arc length: position and heading at any distance along it."""

    def __init__(self, points):
        self.points = np.asarray(points, dtype=float)
        steps = np.diff(self.points, axis=0)
        self.cum = np.concatenate([[0.0], np.cumsum(np.hypot(*steps.T))])
        self.heading = np.arctan2(steps[:, 1], steps[:, 0])
        self.length = float(self.cum[-1])

    def project(self, point, near):
        """Arc length of the closest point to ``point`` within 1 m ahead of ``near``."""
        a, b = self.points[:-1], self.points[1:]
        ab = b - a
        t = np.clip(np.einsum("sk,sk->s", point - a, ab) / np.einsum("sk,sk->s", ab, ab), 0, 1)
        along = self.cum[:-1] + t * (self.cum[1:] - self.cum[:-1])
        gap = np.hypot(*(a + t[:, None] * ab - point).T)
        # Only the stretch just ahead: a zig-zag passes near its own earlier legs.
        gap[(along < near - 1e-9) | (along > near + 1.0)] = np.inf
        return float(along[np.argmin(gap)]) if np.isfinite(gap).any() else near

    def at(self, s):
        s = np.clip(s, 0.0, self.length)
        seg = np.clip(np.searchsorted(self.cum, s, side="right") - 1, 0, len(self.heading) - 1)
        t = (s - self.cum[seg]) / (self.cum[seg + 1] - self.cum[seg])
        pos = self.points[seg] + t[..., None] * (self.points[seg + 1] - self.points[seg])
        return pos, self.heading[seg]


@dataclass
class MatchedPath:
    """What :func:`follow_path` made.

    Attributes
    ----------
    motion : Motion
        The synthesised motion (write it with :func:`~skmotion.io.write_bvh`).
    root : ndarray of shape (n_frames, 3)
        The character's floor position (metres, planner axes) and facing.
    path : ndarray of shape (n_vertices, 2)
    source : ndarray of shape (n_frames, 2)
        The database take and frame played at each frame.
    switches : ndarray of int
        Output frames where a search moved to another place in the database.
    jump, jump_unblended : ndarray of shape (n_switches,)
        At each switch, the pose jump with the blend and without it: the
        body-frame joints' second difference over frames (metres, the mean
        over joints; a step in position or velocity is a spike in it), the
        larger at the frame before the switch and at the switch.
    step : float
        The median of that second difference over all frames, with the blend
        (the jumps' scale in smooth motion).
    root_error : ndarray of shape (n_frames,)
        Distance of the root from the path, metres.
    adjustment : float
        The adjustment's share of the root's travel: the summed length of
        the pulls over the summed length of the database's own root motion.
    """

    motion: Motion
    root: np.ndarray
    path: np.ndarray
    source: np.ndarray
    switches: np.ndarray
    jump: np.ndarray
    jump_unblended: np.ndarray
    step: float
    root_error: np.ndarray
    adjustment: float = 0.0


def _canonical(channels, skeleton, origin, yaw, unit):
    """Channels moved so that their body frame is at the floor's origin, facing +x."""
    c, s = np.cos(-yaw), np.sin(-yaw)
    shift = -np.column_stack(
        [c * origin[:, 0] - s * origin[:, 1], s * origin[:, 0] + c * origin[:, 1]]
    )
    root = np.column_stack([shift, -yaw])
    return _place(SimpleNamespace(skeleton=skeleton), channels, root, unit)


def _rotation_columns(skeleton):
    names = skeleton.channel_names
    return np.array([name.endswith("rotation") for name in names])


def _desired_trajectory(matcher, path, s, speed, root):
    """The trajectory columns (unscaled) the path asks for, seen from the character's root."""
    future = matcher.future_frames_ / matcher.frame_rate_
    pos, heading = path.at(s + speed * future)
    delta = pos - root[:2]
    c, si = np.cos(root[2]), np.sin(root[2])
    ahead, aside = delta[:, 0] * c + delta[:, 1] * si, -delta[:, 0] * si + delta[:, 1] * c
    turn = heading - root[2]
    return np.concatenate([ahead, aside, np.cos(turn), np.sin(turn)])


def _search(matcher, row, trajectory):
    """The best database (take, frame) for the current features with the desired trajectory."""
    query = matcher.features_[row].copy()
    cols = matcher.groups_["trajectory"]
    query[cols] = (trajectory - matcher.mean_[cols]) / matcher.scale_[cols]
    take, frame, _ = matcher.kneighbors(query[None], n_neighbors=1)
    return int(take[0, 0]), int(frame[0, 0])


def follow_path(
    matcher,
    takes,
    path,
    *,
    speed=None,
    search_every=5,
    blend_halflife=0.1,
    adjust_halflife=0.1,
    adjust_ratio=0.5,
    max_seconds=None,
):
    """Synthesise motion that follows a root path on the floor, by motion matching.

    Parameters
    ----------
    matcher : MotionMatcher
        Fitted on ``takes`` (Motions with a skeleton, all on one skeleton).
    takes : list of Motion
        The database.
    path : array-like of shape (n_vertices, 2)
        Floor points (metres, the planner's axes: :func:`plan_axes`); the
        character starts at the first, facing the second. A velocity command
        per frame becomes points by :func:`path_from_velocities`. Repeated
        consecutive points count once.
    speed : float, default=None
        Speed along the path, m/s; by default the database's median root speed.
    search_every : int, default=5
        Frames between searches.
    blend_halflife : float, default=0.1
        Seconds in which a switch's pose offset halves; 0 switches without blending.
    adjust_halflife : float, default=0.1
        Seconds in which the root's distance from the path point (and its
        facing error) would halve without the clamp; None leaves the root alone.
    adjust_ratio : float, default=0.5
        The largest adjustment per frame, as a fraction of the root's own
        travel (and turn, plus 0.5 degrees) in that frame.
    max_seconds : float, default=None
        Longest motion; by default three times the path's length at ``speed``.

    Returns
    -------
    result : MatchedPath

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import make_walks
    >>> from skmotion.io import as_motions
    >>> from skmotion.neighbors import MotionMatcher
    >>> from skmotion.planning import follow_path
    >>> data = make_walks(4, directions=["forward"], turn=0.8, random_state=0)
    >>> takes = as_motions(data.clips, data.skeleton, data.frame_rate)
    >>> matcher = MotionMatcher().fit(takes)
    >>> result = follow_path(matcher, takes, [[0.0, 0.0], [2.0, 0.0]])
    >>> bool(result.root_error.max() < 0.2), result.motion.skeleton is data.skeleton
    (True, True)
    """
    route = _Path(_check_path(path))
    skeleton = _check_takes(matcher, takes)
    if search_every < 1:
        raise ValueError(f"search_every must be 1 or more; got {search_every}")
    unit = skeleton.meters_per_unit or 1.0
    rate = matcher.frame_rate_
    dt = 1.0 / rate
    origins, yaws = matcher.origin_, matcher.yaw_
    if speed is None:
        steps = np.concatenate([np.hypot(*np.diff(o, axis=0).T) for o in origins])
        speed = float(np.median(steps)) * rate
    n_max = int(round((max_seconds or 3.0 * route.length / speed) * rate))
    canonical = [
        _canonical(np.asarray(t.channels), skeleton, o, y, unit)
        for t, o, y in zip(takes, origins, yaws)
    ]
    rot = _rotation_columns(skeleton)
    row_of = {(int(t), int(f)): i for i, (t, f) in enumerate(zip(matcher.take_, matcher.frame_))}
    root = np.array([*route.points[0], route.heading[0]])
    s = 0.0
    take, frame = _search(matcher, 0, _desired_trajectory(matcher, route, s, speed, root))
    offset = np.zeros(skeleton.n_channels)
    offset_v = np.zeros(skeleton.n_channels)
    # The spring's rate: the offset halves in about blend_halflife (Holden's damping / 2).
    y = 2.0 * np.log(2.0) / blend_halflife if blend_halflife else None
    since, left, travel, pulled = 0.0, np.inf, 0.0, 0.0
    out, raw, roots, source, switches = [], [], [], [], []
    for n in range(n_max):
        pose = canonical[take][frame]
        out.append(pose if y is None else pose + _decay(offset, offset_v, since, y))
        raw.append(pose)
        roots.append(root.copy())
        source.append((take, frame))
        to_end = float(np.hypot(*(root[:2] - route.points[-1])))
        if s >= route.length - 0.05 and (to_end < 0.05 or to_end > left):
            break  # at the end, or walking past it
        left = to_end if s >= route.length - 0.05 else np.inf
        root, move, turn = _root_motion(root, origins[take], yaws[take], frame)
        s = max(s, route.project(root[:2], s))
        travel += np.hypot(*move)
        if adjust_halflife:
            adjusted = _adjust(root, route, s, move, turn, dt, adjust_halflife, adjust_ratio)
            pulled += np.hypot(*(adjusted[:2] - root[:2]))
            root = adjusted
        frame, since = frame + 1, since + dt
        if (n + 1) % search_every == 0 or (take, frame) not in row_of:
            row = row_of.get((take, frame), row_of.get((take, frame - 1), 0))
            wanted = _desired_trajectory(matcher, route, s, speed, root)
            new_take, new_frame = _search(matcher, row, wanted)
            if new_take != take or abs(new_frame - frame) > 2:
                old, new = canonical[take], canonical[new_take]
                # The offset from the new frame to where the old clip would have gone.
                delta = old[frame] - new[new_frame]
                back = max(new_frame - 1, 0)
                velocity = (old[frame] - old[frame - 1]) - (new[new_frame] - new[back])
                delta[rot], velocity[rot] = _wrap(delta[rot]), _wrap(velocity[rot])
                if y is not None:
                    delta += _decay(offset, offset_v, since, y)
                offset, offset_v, since = delta, velocity * rate, 0.0
                take, frame = new_take, new_frame
                switches.append(n + 1)
    result = _result(skeleton, unit, rate, route, out, raw, roots, source, switches)
    result.adjustment = pulled / max(travel, 1e-12)
    return result


def _decay(offset, velocity, t, y):
    """A critically damped spring's offset after ``t`` seconds (Holden's exact decay)."""
    return (offset + (velocity + offset * y) * t) * np.exp(-y * t)


def _root_motion(root, origin, yaw, frame):
    """The root moved by the database's travel and turn from ``frame`` to the next."""
    d = origin[frame + 1] - origin[frame]
    c, s = np.cos(yaw[frame]), np.sin(yaw[frame])
    local = (d[0] * c + d[1] * s, -d[0] * s + d[1] * c)
    turn = _wrap(yaw[frame + 1] - yaw[frame])
    c, s = np.cos(root[2]), np.sin(root[2])
    move = np.array([local[0] * c - local[1] * s, local[0] * s + local[1] * c])
    return np.array([root[0] + move[0], root[1] + move[1], root[2] + turn]), move, turn


def _adjust(root, route, s, move, turn, dt, halflife, ratio):
    """Pull the root towards the path (its closest point) and direction, clamped by its motion."""
    target, heading = route.at(s)
    gain = 1.0 - np.exp(-np.log(2.0) * dt / halflife)
    pull = (target - root[:2]) * gain
    limit = ratio * np.hypot(*move)
    norm = np.hypot(*pull)
    if norm > limit:
        pull *= limit / norm
    twist = _wrap(heading - root[2]) * gain
    twist_limit = ratio * abs(turn) + np.deg2rad(0.5)
    return np.array([*(root[:2] + pull), root[2] + np.clip(twist, -twist_limit, twist_limit)])


def _body_joints(skeleton, channels):
    """Joint positions relative to the root joint, metres: the body's pose without its travel."""
    from skmotion.kinematics import forward_kinematics

    positions = forward_kinematics(skeleton, channels).positions
    return (positions - positions[:, :1]) * (skeleton.meters_per_unit or 1.0)


def _jerks(skeleton, channels):
    """Per frame, the mean over joints of the body-frame joints' second difference, metres.

    A pose jump is a spike in it: a step in position or in velocity.
    """
    joints = _body_joints(skeleton, channels)
    second = np.zeros(len(joints))
    second[1:-1] = np.linalg.norm(joints[2:] - 2.0 * joints[1:-1] + joints[:-2], axis=2).mean(
        axis=1
    )
    return second


def _result(skeleton, unit, rate, route, out, raw, roots, source, switches):
    roots = np.array(roots)
    blended = np.array(out)
    placed = _place(SimpleNamespace(skeleton=skeleton), blended, roots, unit)
    jerk, jerk_raw = _jerks(skeleton, blended), _jerks(skeleton, np.array(raw))
    switches = np.array([k for k in switches if 0 < k < len(roots) - 1], dtype=int)
    # The spike shows at the frame before the switch or at the switch (second differences).
    at = np.stack([switches - 1, switches])
    return MatchedPath(
        motion=Motion(skeleton, placed, frame_rate=rate, source="follow_path"),
        root=roots,
        path=route.points,
        source=np.array(source),
        switches=switches,
        jump=jerk[at].max(axis=0),
        jump_unblended=jerk_raw[at].max(axis=0),
        step=float(np.median(jerk)),
        root_error=path_distance(roots[:, :2], route.points),
    )
