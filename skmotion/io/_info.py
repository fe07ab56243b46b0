"""What ``skmotion info FILE`` prints: skeleton or markers, channels, rate and duration."""

from collections import Counter
from pathlib import Path

import numpy as np

from skmotion.io._formats import FORMATS, file_format

__all__ = ["describe_file"]


def _skeleton_lines(skeleton, skeleton_notes):
    end_sites = len(skeleton.end_sites)
    unit = (
        skeleton.units
        if skeleton.meters_per_unit is None
        else (f"{skeleton.units} ({skeleton.meters_per_unit:.6g} m)")
    )
    orders = Counter(
        o for o, c in zip(skeleton.rotation_orders, skeleton.channels) if any("rot" in x for x in c)
    )
    lines = [
        f"skeleton: {skeleton.n_joints} joints ({skeleton.n_joints - end_sites} with channels or "
        f"children, {end_sites} end sites), root {skeleton.joints[0]!r}, {skeleton.up_axis}-up, "
        f"length unit {unit}",
        f"rest-pose height: {skeleton.height():.4g} units",
        "rotation orders (intrinsic): " + ", ".join(f"{o} x{n}" for o, n in orders.most_common()),
    ]
    # What the skeleton means elsewhere (the CLI adds its marker preset): io knows no presets.
    if skeleton_notes is not None:
        lines += list(skeleton_notes(skeleton))
    return lines


def _shown(names, n=6):
    return ", ".join(names[:n]) + (f", ... ({len(names) - n} more)" if len(names) > n else "")


def _position_lines(motion, rate_known):
    positions = motion.channels.reshape(motion.n_frames, len(motion.marker_names), -1)
    missing = np.isnan(positions).any(axis=2)
    lines = [
        f"markers: {len(motion.marker_names)} ({motion.n_dims}-D, length unit {motion.units}): "
        + _shown(list(motion.marker_names)),
        f"missing: {missing.mean():.1%} of marker positions; "
        f"{int(missing.all(axis=0).sum())} markers never seen",
    ]
    lines += [f"extras: {', '.join(motion.extras)}"] if motion.extras else []
    if motion.analog is not None:
        analog = motion.analog
        lines.append(
            f"analog: {len(analog.labels)} channels at {analog.rate:g} Hz: "
            + _shown(list(analog.labels))
        )
    if motion.events:
        counts = Counter(f"{e.context} {e.label}".strip() for e in motion.events)
        lines.append(
            f"events: {len(motion.events)} ("
            + ", ".join(f"{k} x{n}" for k, n in sorted(counts.items()))
            + ")"
        )
    if rate_known:
        return lines + [_frames_line(motion)]
    return lines + [f"frames: {motion.n_frames} (no frame rate in the file; give --frame-rate)"]


def _frames_line(motion):
    rate, duration = f"{motion.frame_rate:g}", f"{motion.duration:.2f}"
    return f"frames: {motion.n_frames} at {rate} Hz, duration {duration} s"


def _series_lines(row, path):
    clips, labels = row.reader(path)
    lengths = [len(c) for c in clips]
    lines = [
        f"series: {len(clips)}, {clips[0].shape[1]} dimensions, "
        f"length {min(lengths)}-{max(lengths)}"
        if clips
        else "series: none",
    ]
    if labels is not None:
        counts = Counter(labels.tolist())
        lines.append("labels: " + ", ".join(f"{k} {n}" for k, n in sorted(counts.items())))
    return lines


def _find_skeleton(amc, suffix):
    subject = amc.stem.split("_")[0]
    candidates = [amc.with_name(f"{subject}{suffix}")] + sorted(amc.parent.glob(f"*{suffix}"))
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise FileNotFoundError(
        f"No skeleton for {amc}: give --asf (no {subject}{suffix} or other {suffix} beside it)."
    )


def describe_file(path, *, asf=None, frame_rate=None, skeleton_notes=None, units="m"):
    """The lines ``skmotion info`` prints for a motion file of any format in :data:`FORMATS`.

    Parameters
    ----------
    path : str or path-like
        The file; its suffix picks the reader (:func:`file_format`).
    asf : str or path-like, default=None
        The skeleton of an ``.amc`` file; by default ``NN.asf`` (or the only
        ``.asf``) beside it.
    frame_rate : float, default=None
        Frames per second of a file that does not record it (keypoints).
    skeleton_notes : callable, default=None
        ``skeleton_notes(skeleton)`` gives further lines about a skeleton
        (the command adds its marker preset).
    units : {"m", "cm", "mm", "in", "ft"} or None, default="m"
        Length unit a C3D file's positions are converted to; None keeps the
        file's numbers (a file whose ``POINT:UNITS`` is empty).

    Returns
    -------
    lines : list of str

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import Motion, write_bvh
    >>> from skmotion.io._info import describe_file
    >>> data = make_motions(n_clips_per_class=1, classes=["wave"], random_state=0)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "wave.bvh")
    ...     write_bvh(Motion(data.skeletons[0], data.clips[0], frame_rate=30), path)
    ...     lines = describe_file(path)
    >>> print(lines[1])
    format: BVH
    >>> print(lines[-1])
    frames: 88 at 30 Hz, duration 2.93 s
    """
    path = Path(path)
    row = file_format(path)
    head = [f"file: {path}", f"format: {row.name}"]
    if row.kind == "series":
        return head + _series_lines(row, path)
    if row.kind == "skeleton":
        skeleton = row.reader(path)
        return [
            *head,
            *_skeleton_lines(skeleton, skeleton_notes),
            f"channels: {skeleton.n_channels} (an AMC frame of this skeleton)",
        ]
    if row.skeleton_suffix is not None:
        asf = Path(asf) if asf is not None else _find_skeleton(path, row.skeleton_suffix)
        motion = row.reader(path, file_format(asf).reader(asf))
        head[1] += f", skeleton {asf}; frame rate not recorded in AMC files: CMU's 120 Hz"
    elif row.needs_frame_rate:
        motion = row.reader(path, frame_rate=frame_rate or 1.0)
    elif row.kind == "positions":
        motion = row.reader(path, units=units)
    else:
        motion = row.reader(path)
    if motion.kind == "positions":
        return head + _position_lines(motion, frame_rate is not None or not row.needs_frame_rate)
    return [
        *head,
        *_skeleton_lines(motion.skeleton, skeleton_notes),
        f"channels: {motion.n_channels}: {_shown(motion.channel_names)}",
        _frames_line(motion),
    ]


def formats_help():
    """One line per format of :data:`FORMATS`, for help texts.

    Returns
    -------
    text : str

    Examples
    --------
    >>> from skmotion.io._info import formats_help
    >>> print(formats_help().splitlines()[0])
    .bvh  BVH: skeleton and joint angles
    """
    return "\n".join(
        f"{row.suffix:<5} {row.name}: {row.description}"
        + (f" (extra '{row.extra}')" if row.extra else "")
        for row in FORMATS
    )
