"""Does a layout's joint order fit the data? Four checks a body passes whatever it does.

A tracker's joints read in another tracker's order run silently and may still score
well; only a picture shows a head below the hips. A body recorded in the right order
has bones of constant length, left and right limbs of equal length, the head above
the pelvis, and hips and shoulders that face the same way. Each failed check names
the joints it concerns.
"""

import warnings

import numpy as np

from skmotion.kinematics._named_layouts import get_layout

__all__ = ["check_layout"]

# Thresholds, chosen between the values of real and of shuffled orders: on MSRC-12's 593
# Kinect v1 recordings (30 people) the bones' median within-clip coefficient of variation
# is at most 0.21 (wrist-hand), left/right bone ratios at most 1.023, the head is above
# the pelvis in 99.998% of frames and hips and shoulders face alike in 99.97%.
MAX_BONE_VARIATION = 0.25
MAX_SIDE_RATIO = 1.5
MIN_HEAD_UP = 0.75
MIN_SAME_FACING = 0.75
_HEADS = ("head_top", "head", "nose", "neck")


def _frames(clips, layout):
    """Every clip as (n_frames, n_joints, dim), with a clear error on a wrong width."""
    out = []
    for k, clip in enumerate(clips):
        clip = np.asarray(clip, dtype=float)
        if clip.ndim != 2 or clip.shape[1] != layout.n_joints * layout.dim:
            raise ValueError(
                f"clip {k}: shape {clip.shape}, expected (n_frames, "
                f"{layout.n_joints * layout.dim}) "
                f"for the {layout.n_joints} {layout.dim}-D joints of layout {layout.name!r}."
            )
        if len(clip) >= 2:
            out.append(clip.reshape(len(clip), layout.n_joints, layout.dim))
    if not out:
        raise ValueError("check_layout needs at least one clip of 2 or more frames.")
    return out


def _bone_lengths(points, bones, index):
    a = [index[p] for p, _ in bones]
    b = [index[c] for _, c in bones]
    return np.linalg.norm(points[:, a] - points[:, b], axis=2)  # (n_frames, n_bones)


def _bone_problems(clips, layout, index):
    bones = layout.bones
    variation, typical = [], []
    with warnings.catch_warnings(), np.errstate(invalid="ignore", divide="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)  # a joint never seen: all-NaN lengths
        for points in clips:
            lengths = _bone_lengths(points, bones, index)
            mean = np.nanmean(lengths, axis=0)
            variation.append(np.nanstd(lengths, axis=0) / mean)
            typical.append(mean)
        variation = np.nanmedian(np.array(variation), axis=0)
        typical = np.nanmedian(np.array(typical), axis=0)
    problems = [
        f"bone {p}-{c} changes length by {v:.0%} within a clip"
        for (p, c), v in zip(bones, variation)
        if v > MAX_BONE_VARIATION
    ]
    length = {bone: t for bone, t in zip(bones, typical)}
    mark = dict(layout.landmarks)
    joint = {m: j for j, m in layout.landmarks}
    for (p, c), t in length.items():
        mp, mc = mark.get(p, ""), mark.get(c, "")
        if not (mp.startswith("left_") or mc.startswith("left_")):
            continue
        mirror = tuple(joint.get(m.replace("left_", "right_"), j) for m, j in ((mp, p), (mc, c)))
        other = length.get(mirror)
        if other is not None and max(t, other) > MAX_SIDE_RATIO * min(t, other):
            problems.append(
                f"left bone {p}-{c} is {t / other:.2f} times as long as right bone "
                f"{mirror[0]}-{mirror[1]}"
            )
    return problems


def _up(points, up):
    axis = "xyz".index(up[-1])
    return -points[..., axis] if up.startswith("-") else points[..., axis]


def _posture_problems(points, layout):
    """Head above pelvis; hips and shoulders facing the same way (3-D only)."""
    joint = {m: j for j, m in layout.landmarks}
    idx = layout.index
    hips = [idx(layout.left_hip), idx(layout.right_hip)]
    pelvis_name = joint.get("pelvis", f"the middle of {layout.left_hip} and {layout.right_hip}")
    pelvis = points[:, idx(joint["pelvis"])] if "pelvis" in joint else points[:, hips].mean(axis=1)
    problems = []
    head = next((joint[m] for m in _HEADS if m in joint), None)
    if head is not None:
        above = _up(points[:, idx(head)], layout.up) > _up(pelvis, layout.up)
        if np.mean(above) < MIN_HEAD_UP:
            problems.append(
                f"head {head} is above pelvis {pelvis_name} in only {np.mean(above):.0%} of frames"
            )
    if layout.dim == 3:
        axis = "xyz".index(layout.up[-1])
        across_hips = points[:, hips[0]] - points[:, hips[1]]
        shoulders = [idx(layout.left_shoulder), idx(layout.right_shoulder)]
        across_shoulders = points[:, shoulders[0]] - points[:, shoulders[1]]
        across_hips[:, axis] = across_shoulders[:, axis] = 0.0  # horizontal directions
        same = np.sum(across_hips * across_shoulders, axis=1) > 0
        if np.mean(same) < MIN_SAME_FACING:
            problems.append(
                f"hips {layout.left_hip}->{layout.right_hip} and shoulders "
                f"{layout.left_shoulder}->{layout.right_shoulder} face the same way in only "
                f"{np.mean(same):.0%} of frames (the facing direction is not stable)"
            )
    return problems


def check_layout(clips, layout):
    """What in the data does not fit a layout's joint order; empty when it fits.

    Four checks, over all frames of all clips: each bone of the layout's stick
    figure (:attr:`Layout.bones`) keeps its length within a clip (median
    coefficient of variation over clips at most 25%); a left bone and its
    right mirror have about the same length (ratio at most 1.5); the head (or
    nose, or neck) is above the pelvis in at least 75% of frames; the
    left-to-right directions of the hips and of the shoulders agree
    (positive dot product of their horizontal parts) in at least 75% of
    frames. A joint order that is not the tracker's fails several of them.

    Parameters
    ----------
    clips : list of array-like of shape (n_frames_i, n_joints * dim)
        Joint positions, joint-major, in the layout's up axis.
    layout : str or Layout
        The layout the clips are said to be in.

    Returns
    -------
    problems : list of str
        One sentence per failed check, naming the joints.

    See Also
    --------
    skmotion.datasets.load_motion_folder : warns with these problems when loading with ``layout=``.

    Examples
    --------
    >>> from skmotion.datasets import make_position_motions
    >>> from skmotion.kinematics import Layout, check_layout, get_layout
    >>> data = make_position_motions("kinect_v1", n_clips_per_class=1, random_state=0)
    >>> check_layout(data.clips, "kinect_v1")
    []
    >>> v1 = get_layout("kinect_v1")
    >>> swapped = list(v1.joints)
    >>> swapped[3], swapped[14] = swapped[14], swapped[3]  # Head and AnkleLeft trade places
    >>> wrong = Layout("wrong", swapped, root=v1.root, left_hip="HipLeft", right_hip="HipRight",
    ...                left_shoulder="ShoulderLeft", right_shoulder="ShoulderRight",
    ...                size_chain=v1.size_chain, landmarks=v1.landmarks)
    >>> for problem in check_layout(data.clips, wrong)[-2:]:
    ...     print(problem)
    left bone AnkleLeft-FootLeft is 11.95 times as long as right bone AnkleRight-FootRight
    head Head is above pelvis HipCenter in only 0% of frames
    """
    layout = get_layout(layout)
    clips = _frames(clips, layout)
    index = {j: k for k, j in enumerate(layout.joints)}
    problems = _bone_problems(clips, layout, index)
    return problems + _posture_problems(np.concatenate(clips), layout)
