"""What ``skmotion info FILE`` prints: a motion file's skeleton, channels, rate and duration."""

from collections import Counter
from pathlib import Path

from skmotion.io._amc import read_amc
from skmotion.io._asf import read_asf
from skmotion.io._bvh import read_bvh

__all__ = ["describe_file"]


def _skeleton_lines(skeleton):
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
        f"skeleton: {skeleton.n_joints} joints ({skeleton.n_joints - end_sites} with channels or children, "
        f"{end_sites} end sites), root {skeleton.joints[0]!r}, {skeleton.up_axis}-up, length unit {unit}",
        f"rest-pose height: {skeleton.height():.4g} units",
        "rotation orders (intrinsic): " + ", ".join(f"{o} x{n}" for o, n in orders.most_common()),
    ]
    try:
        from skmotion.preprocessing import detect_marker_preset

        lines.append(f"marker preset: {detect_marker_preset(skeleton)}")
    except ValueError:
        lines.append("marker preset: none fits (define a MarkerSet)")
    return lines


def _find_asf(amc):
    subject = amc.stem.split("_")[0]
    candidates = [amc.with_name(f"{subject}.asf")] + sorted(amc.parent.glob("*.asf"))
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise FileNotFoundError(
        f"No skeleton for {amc}: give --asf (no {subject}.asf or other .asf beside it)."
    )


def describe_file(path, *, asf=None):
    """The lines ``skmotion info`` prints for a ``.bvh``, ``.amc`` or ``.asf`` file.

    Parameters
    ----------
    path : str or path-like
        The file.
    asf : str or path-like, default=None
        The skeleton of an ``.amc`` file; by default ``NN.asf`` (or the only
        ``.asf``) beside it.

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
    suffix = path.suffix.lower()
    if suffix == ".asf":
        skeleton = read_asf(path)
        return [
            f"file: {path}",
            "format: Acclaim skeleton (ASF)",
            *_skeleton_lines(skeleton),
            f"channels: {skeleton.n_channels} (an AMC frame of this skeleton)",
        ]
    if suffix == ".amc":
        asf = Path(asf) if asf is not None else _find_asf(path)
        motion = read_amc(path, read_asf(asf))
        kind = f"Acclaim motion (AMC), skeleton {asf}; frame rate not recorded in AMC files: CMU's 120 Hz"
    elif suffix == ".bvh":
        motion = read_bvh(path)
        kind = "BVH"
    else:
        raise ValueError(
            f"{path}: unknown motion file type {suffix!r} (expected .bvh, .amc or .asf)"
        )
    names = motion.channel_names
    shown = ", ".join(names[:6]) + (f", ... ({len(names) - 6} more)" if len(names) > 6 else "")
    return [
        f"file: {path}",
        f"format: {kind}",
        *_skeleton_lines(motion.skeleton),
        f"channels: {motion.n_channels}: {shown}",
        f"frames: {motion.n_frames} at {motion.frame_rate:g} Hz, duration {motion.duration:.2f} s",
    ]
