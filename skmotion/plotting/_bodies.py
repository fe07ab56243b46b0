"""Stick figures of a body: one pose, a clip as poses over time, and an animation file."""

import os
from pathlib import Path

import numpy as np

from ._body_data import _AXES, body_frames
from ._pyplot import _pyplot

__all__ = ["animate_clip", "plot_clip", "plot_pose"]


def _view_axes(up):
    """Data axes drawn as matplotlib's (x, y, z): two horizontal axes (right-handed), then up."""
    return ((up + 1) % 3, (up + 2) % 3, up)


def _new_axes(plt, dims, figsize):
    figure = plt.figure(figsize=figsize)
    ax = figure.add_subplot(projection="3d" if dims == 3 else None)
    return figure, ax


def _label_axes(ax, body):
    unit = f" ({body.unit})" if body.unit else ""
    if body.up is None:
        ax.set_xlabel(f"x{unit}")
        ax.set_ylabel(f"y{unit}")
        ax.set_aspect("equal", adjustable="datalim")
        return
    a, b, up = _view_axes(body.up)
    ax.set_xlabel(f"{_AXES[a]}{unit}")
    ax.set_ylabel(f"{_AXES[b]}{unit}")
    ax.set_zlabel(f"{_AXES[up]}{unit}, up")


def _set_limits(ax, points, up):
    """Equal scale on every axis, around all the points drawn."""
    low, high = points.min(axis=0), points.max(axis=0)
    largest = max(float((high - low).max()), 1e-9)
    # Every axis spans at least 40% of the largest (a pose is tall and thin), plus a margin.
    half = np.maximum((high - low) / 2, 0.2 * largest) + 0.05 * largest
    low, high = (low + high) / 2 - half, (low + high) / 2 + half
    if up is None:
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        return
    order = _view_axes(up)
    for setter, axis in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), order):
        setter(low[axis], high[axis])
    # The box takes the data's proportions, so a metre is as long on every axis.
    sizes = [float(high[a] - low[a]) for a in order]
    ax.set_box_aspect(sizes)
    for axis, size in zip((ax.xaxis, ax.yaxis, ax.zaxis), sizes):
        if size < 0.6 * max(sizes):  # a short axis: few ticks, or their labels overlap
            axis.set_major_locator(_pyplot().MaxNLocator(3))


def _draw(ax, pose, body, color, **line):
    """One pose's bones as lines; returns the lines."""
    lines = []
    for a, b in body.bones:
        ends = pose[[a, b]]
        if body.up is None:
            lines += ax.plot(ends[:, 0], ends[:, 1], "-", color=color, **line)
        else:
            x, y, z = (ends[:, k] for k in _view_axes(body.up))
            lines += ax.plot(x, y, z, "-", color=color, **line)
    return lines


def _scatter(ax, points, body, **kwargs):
    if body.up is None:
        return ax.scatter(points[:, 0], points[:, 1], **kwargs)
    x, y, z = (points[:, k] for k in _view_axes(body.up))
    return ax.scatter(x, y, z, **kwargs)


def plot_pose(pose, body=None, *, bones=None, up_axis=None, ax=None, title=None):
    """A stick figure of one pose, in 3-D or 2-D.

    Parameters
    ----------
    pose : array-like
        One frame: joint angles of shape ``(n_channels,)`` for a Skeleton, else joint
        positions ``(n_joints, 2 or 3)`` or flat ``(n_joints * d,)``.
    body : Skeleton or layout, default=None
        A :class:`~skmotion.kinematics.Skeleton` (positions by forward kinematics),
        or any object with joint names (``joints``/``joint_names``/``names``) and
        ``parents`` or ``bones``; None when ``bones`` is given.
    bones : array-like, default=None
        Pairs of joints (names or indices), or one parent index per joint (-1 for a root).
    up_axis : {"x", "y", "z"}, default=None
        Which data axis points up in 3-D (drawn vertically); by default the body's
        ``up_axis``, else "z".
    ax : matplotlib Axes, default=None
        Where to draw (3-D axes for 3-D positions); a new figure by default.
    title : str, default=None

    Returns
    -------
    figure : matplotlib.figure.Figure

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from skmotion.plotting import plot_pose
    >>> pose = np.array([[0, 0, 1.0], [0, 0, 1.5], [0.2, 0, 0.5], [-0.2, 0, 0.5]])
    >>> figure = plot_pose(pose, bones=[-1, 0, 0, 0])  # a parent index per joint
    >>> len(figure.axes[0].get_lines())  # three bones
    3
    """
    body = body_frames(pose, body, bones=bones, up_axis=up_axis)
    if len(body.positions) != 1:
        raise ValueError(
            f"plot_pose draws one pose; got {len(body.positions)} frames (use plot_clip)."
        )
    plt = _pyplot()
    figure, ax = (
        _new_axes(plt, body.positions.shape[2], (4.5, 4.5)) if ax is None else (ax.figure, ax)
    )
    pose = body.positions[0]
    lines = _draw(ax, pose, body, "tab:blue", linewidth=2)
    if lines:
        lines[0].set_label("bones")
    _scatter(ax, pose, body, color="k", s=10, label="joints", zorder=3)
    root = int(body.bones[0, 0]) if len(body.bones) else 0
    _scatter(
        ax,
        pose[[root]],
        body,
        color="tab:red",
        s=40,
        marker="s",
        label=f"root ({body.names[root]})",
    )
    _label_axes(ax, body)
    _set_limits(ax, pose, body.up)
    ax.set_title(title or f"pose: {len(pose)} joints, {len(body.bones)} bones")
    ax.legend(loc="upper left", fontsize="small")
    return figure


def _travel_direction(root, body, size):
    """Unit horizontal direction (drawn axes) from the first root to the last; the first
    drawn axis for a motion that travels less than half the body's size (a squat's drift
    says nothing)."""
    axes = [0, 1] if body.up is None else list(_view_axes(body.up)[:2])
    step = root[-1, axes] - root[0, axes]
    length = float(np.hypot(*step))
    return axes, (step / length if length > 0.5 * size else np.array([1.0, 0.0]))


def _offsets(positions, body, spread):
    """Per drawn pose, an offset along the travel direction so that no two poses overlap.

    The root's own travel sets poses apart where it is long enough; where it is not (a
    motion in place, or a slow step), each pose is pushed along the direction of travel
    until it starts a small gap after the previous one ends. ``spread`` instead sets a
    fixed distance between successive poses. Returns the offsets (n_poses, dims), the
    extra distance added per pose (for the root path between poses), and the direction.
    """
    root = positions[:, int(body.bones[0, 0]) if len(body.bones) else 0]
    axes, direction = _travel_direction(root, body, float(np.ptp(positions[0], axis=0).max()))
    along = positions[:, :, axes] @ direction  # (n_poses, n_joints): position along travel
    extra = np.zeros(len(positions))
    if spread is not None:
        extra = float(spread) * np.arange(len(positions))
    else:
        width = float(np.ptp(along, axis=1).max())
        gap = 0.15 * max(width, float(np.ptp(positions[0], axis=0).max()))
        for k in range(1, len(positions)):
            start = along[k].min() + extra[k - 1]
            end = along[k - 1].max() + extra[k - 1]
            extra[k] = extra[k - 1] + max(0.0, end + gap - start)
    shift = np.zeros((len(positions), positions.shape[2]))
    shift[:, axes] = extra[:, None] * direction
    return shift, extra, direction


def plot_clip(
    clip, body=None, *, bones=None, frame_rate=None, n_poses=8, spread=None, up_axis=None, ax=None
):
    """Poses of a clip over time as stick figures coloured by time, with the root's path.

    Parameters
    ----------
    clip : array-like
        Joint angles ``(n_frames, n_channels)`` for a Skeleton, else joint positions
        ``(n_frames, n_joints, 2 or 3)`` or flat ``(n_frames, n_joints * d)``.
    body : Skeleton or layout, default=None
        As in :func:`plot_pose`.
    bones : array-like, default=None
        As in :func:`plot_pose`.
    frame_rate : float, default=None
        With it the colour bar is in seconds, else in frames.
    n_poses : int, default=8
        How many poses, evenly spaced in time.
    spread : float, default=None
        Extra distance between successive poses along the direction of travel (in
        the positions' unit). By default each pose is moved on just enough not to
        overlap the previous one (a motion in place would be drawn on top of
        itself); the root path follows the moved poses, and the title says how
        far they were set apart. The view looks across the direction of travel.
    up_axis : {"x", "y", "z"}, default=None
        As in :func:`plot_pose`.
    ax : matplotlib Axes, default=None

    Returns
    -------
    figure : matplotlib.figure.Figure

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.plotting import plot_clip
    >>> data = make_motions(n_clips_per_class=1, classes=["walk"], random_state=0)
    >>> figure = plot_clip(data.clips[0], data.skeletons[0], frame_rate=data.frame_rate)
    >>> figure.axes[1].get_ylabel()  # the colour bar
    'time (s)'
    """
    body = body_frames(clip, body, bones=bones, up_axis=up_axis)
    n_frames = len(body.positions)
    if not 1 <= int(n_poses):
        raise ValueError(f"n_poses must be at least 1; got {n_poses}.")
    frames = np.unique(
        np.linspace(0, n_frames - 1, min(int(n_poses), n_frames)).round().astype(int)
    )
    plt = _pyplot()
    dims = body.positions.shape[2]
    figure, ax = _new_axes(plt, dims, (6.5, 4.5)) if ax is None else (ax.figure, ax)
    shift, extra, direction = _offsets(body.positions[frames], body, spread)
    times = frames / frame_rate if frame_rate else frames.astype(float)
    cmap = plt.get_cmap("viridis")
    norm = plt.Normalize(times.min(), max(times.max(), times.min() + 1e-9))
    for k, f in enumerate(frames):
        _draw(ax, body.positions[f] + shift[k], body, cmap(norm(times[k])), linewidth=1.5)
    root = int(body.bones[0, 0]) if len(body.bones) else 0
    # The root's path through the drawn poses: between two poses, the offset grows with time.
    offset = np.interp(np.arange(n_frames), frames, extra)
    axes = [0, 1] if body.up is None else list(_view_axes(body.up)[:2])
    path = body.positions[:, root].copy()
    path[:, axes] += offset[:, None] * direction
    coords = path.T if body.up is None else [path[:, k] for k in _view_axes(body.up)]
    ax.plot(*coords, "-", color="tab:red", linewidth=2.0, label=f"root path ({body.names[root]})")
    ax.legend(loc="upper left", fontsize="small")
    mappable = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    label = "time (s)" if frame_rate else "frame"
    figure.colorbar(mappable, ax=ax, shrink=0.7, pad=0.12, label=label)
    if body.up is not None:
        # Look across the row of poses: the direction of travel runs left to right on screen.
        ax.view_init(elev=12, azim=float(np.degrees(np.arctan2(direction[1], direction[0]))) - 90)
    _label_axes(ax, body)
    drawn = (body.positions[frames] + shift[:, None, :]).reshape(-1, dims)
    _set_limits(ax, np.vstack([drawn, path]), body.up)
    added = extra[-1] if len(extra) > 1 else 0.0
    apart = f", set apart by {added / max(len(frames) - 1, 1):.2g} more per pose" if added else ""
    ax.set_title(f"{len(frames)} poses of {n_frames} frames{apart}")
    return figure


def animate_clip(
    clip, body=None, path="clip.gif", *, bones=None, frame_rate=30.0, step=1, up_axis=None, dpi=80
):
    """Write a clip as an animated stick figure: GIF (Pillow) or MP4 (ffmpeg).

    The file is written under a temporary name in the same folder and renamed, so an
    interrupted write never leaves a partial file under ``path``.

    Parameters
    ----------
    clip : array-like
        As in :func:`plot_clip`.
    body : Skeleton or layout, default=None
        As in :func:`plot_pose`.
    path : str or path-like, default="clip.gif"
        ``.gif`` (matplotlib's Pillow writer) or ``.mp4`` (needs the ``ffmpeg`` program).
    bones : array-like, default=None
    frame_rate : float, default=30.0
        The clip's frame rate; the animation plays in real time.
    step : int, default=1
        Draw every ``step``-th frame (smaller files).
    up_axis : {"x", "y", "z"}, default=None
    dpi : int, default=80

    Returns
    -------
    path : Path
        The file written.

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> import tempfile, pathlib
    >>> import numpy as np
    >>> from skmotion.plotting import animate_clip
    >>> t = np.linspace(0, 1, 10)[:, None]
    >>> clip = np.stack([np.hstack([0 * t, 0 * t]), np.hstack([np.cos(t), np.sin(t)])], axis=1)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     written = animate_clip(clip, bones=[(0, 1)], path=pathlib.Path(folder) / "arm.gif")
    ...     written.read_bytes()[:6]
    b'GIF89a'
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"animate_clip writes .gif or .mp4 files; got {path.name!r}.")
    if not (isinstance(step, (int, np.integer)) and step >= 1):
        raise ValueError(f"step must be a positive integer; got {step!r}.")
    if not frame_rate > 0:
        raise ValueError(f"frame_rate must be positive; got {frame_rate!r}.")
    body = body_frames(clip, body, bones=bones, up_axis=up_axis)
    plt = _pyplot()
    from matplotlib import animation

    if suffix == ".mp4" and not animation.FFMpegWriter.isAvailable():
        raise RuntimeError(
            f"writing {path.name} needs the ffmpeg program on the PATH; write a .gif instead."
        )
    frames = np.arange(0, len(body.positions), step)
    fps = frame_rate / step
    dims = body.positions.shape[2]
    figure, ax = _new_axes(plt, dims, (4.5, 4.5))
    lines = _draw(ax, body.positions[0], body, "tab:blue", linewidth=2)
    if lines:
        lines[0].set_label("bones")
    _label_axes(ax, body)
    _set_limits(ax, body.positions.reshape(-1, dims), body.up)
    ax.legend(loc="upper left", fontsize="small")

    def update(k):
        pose = body.positions[frames[k]]
        for line, (a, b) in zip(lines, body.bones):
            ends = pose[[a, b]]
            if body.up is None:
                line.set_data(ends[:, 0], ends[:, 1])
            else:
                line.set_data_3d(*(ends[:, j] for j in _view_axes(body.up)))
        ax.set_title(f"t = {frames[k] / frame_rate:.2f} s")
        return lines

    movie = animation.FuncAnimation(figure, update, frames=len(frames), blit=False)
    writer = (
        animation.PillowWriter(fps=fps) if suffix == ".gif" else animation.FFMpegWriter(fps=fps)
    )
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.part{suffix}")
    try:
        movie.save(temporary, writer=writer, dpi=dpi)
        os.replace(temporary, path)
    finally:
        plt.close(figure)
        temporary.unlink(missing_ok=True)
    return path
