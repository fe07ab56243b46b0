"""What ``skmotion info FILE`` prints: skeleton or markers, channels, rate and duration."""

from collections import Counter
from pathlib import Path

import numpy as np

from skmotion.io._formats import FORMATS, file_format, formats_help

__all__ = ["describe_file", "describe_folder", "formats_help"]


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


def describe_file(
    path,
    *,
    asf=None,
    frame_rate=None,
    layout=None,
    skeleton_notes=None,
    position_notes=None,
    units="m",
):
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
    layout : str or Layout, default=None
        The joint order of a keypoint file (:func:`read_keypoints`).
    skeleton_notes : callable, default=None
        ``skeleton_notes(skeleton)`` gives further lines about a skeleton
        (the command adds its marker preset).
    position_notes : callable, default=None
        ``position_notes(motion)`` gives further lines about a position
        motion (the command adds its check of ``layout``).
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
        motion = row.reader(path, layout, frame_rate=frame_rate or 1.0)
    elif row.kind == "positions":
        motion = row.reader(path, units=units)
    else:
        motion = row.reader(path)
    if motion.kind == "positions":
        lines = _position_lines(motion, frame_rate is not None or not row.needs_frame_rate)
        notes = list(position_notes(motion)) if position_notes is not None else []
        return head + lines + notes
    return [
        *head,
        *_skeleton_lines(motion.skeleton, skeleton_notes),
        f"channels: {motion.n_channels}: {_shown(motion.channel_names)}",
        _frames_line(motion),
    ]


def _summary(path, row, layout, frame_rate):
    """(clips, frames, seconds or None, description of the channels) of one file."""
    if row.kind == "series":
        clips, _ = row.reader(path)
        return len(clips), sum(len(c) for c in clips), None, f"{clips[0].shape[1]} dimensions"
    if row.skeleton_suffix is not None:
        asf = _find_skeleton(path, row.skeleton_suffix)
        motion = row.reader(path, file_format(asf).reader(asf))
    elif row.needs_frame_rate:
        motion = row.reader(path, layout, frame_rate=frame_rate or 1.0)
    else:
        motion = row.reader(path)
    seconds = motion.duration if frame_rate or not row.needs_frame_rate else None
    what = f"{motion.n_channels} channels"
    if motion.skeleton is not None:
        what += f" ({motion.skeleton.n_joints}-joint skeleton)"
    return 1, motion.n_frames, seconds, what


def describe_folder(folder, *, layout=None, frame_rate=None):
    """The lines ``skmotion info FOLDER`` prints: what the motion files under a folder hold.

    Every file of a format in :data:`FORMATS` is read (keypoint files only
    with ``layout``: a ``.csv`` may be an index or a labels file); files that
    cannot be read are listed with the reason.

    Parameters
    ----------
    folder : str or path-like
    layout : str or Layout, default=None
        The joint order of the keypoint files; None leaves them unread.
    frame_rate : float, default=None
        Frames per second of the keypoint files.

    Returns
    -------
    lines : list of str

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import Motion, write_bvh
    >>> from skmotion.io._info import describe_folder
    >>> data = make_motions(n_clips_per_class=2, classes=["wave"], random_state=0)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k, clip in enumerate(data.clips):
    ...         os.makedirs(os.path.join(folder, f"S0{k}"))
    ...         write_bvh(Motion(data.skeletons[k], clip, frame_rate=30),
    ...                   os.path.join(folder, f"S0{k}", "wave.bvh"))
    ...     lines = describe_folder(folder)
    >>> print("\\n".join(lines[1:]))
    files: 2 (2 BVH) in 2 subfolders (S00, S01)
    clips: 2, 178 frames, 5.93 s (clip length 2.93-3.00 s)
    channels: 66 channels (26-joint skeleton) x2
    """
    folder = Path(folder)
    keypoints = {row.suffix for row in FORMATS if row.needs_frame_rate}
    files, unread = [], Counter()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        suffix = path.suffix.lower()
        known = any(row.suffix == suffix for row in FORMATS)
        if known and suffix in keypoints and layout is None:
            unread[suffix] += 1
        elif known and file_format(path).kind != "skeleton":
            files.append((file_format(path), path))
    lines = [f"folder: {folder}"]
    if not files:
        return lines + ["files: no motion files" + _unread_text(unread)]
    formats = Counter(row.name for row, _ in files)
    subfolders = sorted({p.parent.relative_to(folder).as_posix() for _, p in files} - {"."})
    where = f" in {len(subfolders)} subfolders ({_shown(subfolders, 4)})" if subfolders else ""
    lines.append(
        f"files: {len(files)} ("
        + ", ".join(f"{n} {name}" for name, n in formats.items())
        + f"){where}"
        + _unread_text(unread)
    )
    clips = frames = 0
    seconds, kinds, errors = [], Counter(), []
    for row, path in files:
        try:
            n, m, s, what = _summary(path, row, layout, frame_rate)
        except (OSError, ValueError, ImportError) as exc:
            reason = " ".join(str(exc).split()).removeprefix(f"{path}: ")
            errors.append(f"  {path.relative_to(folder)}: {reason}")
            continue
        clips, frames = clips + n, frames + m
        seconds += [s] if s is not None else []
        kinds[what] += 1
    timing = (
        f", {sum(seconds):.2f} s (clip length {min(seconds):.2f}-{max(seconds):.2f} s)"
        if seconds
        else ""
    )
    lines.append(f"clips: {clips}, {frames:,} frames{timing}")
    if kinds:
        lines.append("channels: " + "; ".join(f"{what} x{n}" for what, n in kinds.most_common()))
    if errors:
        lines += [f"unreadable: {len(errors)} files"] + errors
    return lines


def _unread_text(unread):
    if not unread:
        return ""
    shown = ", ".join(f"{n} {suffix}" for suffix, n in sorted(unread.items()))
    return f"; not read: {shown} (keypoint files: give --layout and --frame-rate)"
