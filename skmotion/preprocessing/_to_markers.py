"""to_markers: virtual-marker clips of motions from several skeleton families at once."""

from sklearn.base import clone

from skmotion.io._motion import Motion
from skmotion.preprocessing._virtual_markers import VirtualMarkerTransform

__all__ = ["to_markers"]


def to_markers(motions, transformer=None):
    """Virtual-marker clips of motions from any mix of skeletons, in input order.

    One :class:`VirtualMarkerTransform` call takes clips that share their
    channels. Motions of different skeleton families (a CMU ASF subject and
    a Character Creator BVH, say) have different channels, but the same
    marker names: this groups the motions by channel layout, fits a clone of
    ``transformer`` on each group and returns every clip's markers, which all
    share one feature space.

    Parameters
    ----------
    motions : list of Motion
        The motions, each with its own skeleton and frame rate.
    transformer : VirtualMarkerTransform, default=None
        Its parameters are used for every group (default: all defaults).

    Returns
    -------
    clips : list of ndarray of shape (n_frames_i, 6 * n_markers)
        One per motion, in input order.
    names : ndarray of str
        The output channel names, shared by every clip.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.io import Motion, as_motions
    >>> from skmotion.kinematics import Skeleton
    >>> from skmotion.preprocessing import VirtualMarkerTransform, to_markers
    >>> data = make_motions(n_clips_per_class=1, classes=["walk", "wave"], random_state=0)
    >>> motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    >>> # A second skeleton family: the humanoid without toes has 6 channels fewer.
    >>> sk = motions[1].skeleton
    >>> keep = [j for j, name in enumerate(sk.joints) if "Toe" not in name]
    >>> parents = [keep.index(sk.parents[j]) if j else -1 for j in keep]
    >>> bare = Skeleton([sk.joints[j] for j in keep], parents,
    ...                 sk.offsets[keep], [sk.channels[j] for j in keep], up_axis="y")
    >>> columns = [c for c, name in enumerate(sk.channel_names) if "Toe" not in name]
    >>> motions[1] = Motion(bare, motions[1].channels[:, columns], frame_rate=30.0)
    >>> motions[0].n_channels, motions[1].n_channels
    (66, 60)
    >>> clips, names = to_markers(motions, VirtualMarkerTransform(markers=[
    ...     ("pelvis", "Hips", (0, 0, 0)), ("left_hip", "LeftUpLeg", (0, 0, 0)),
    ...     ("right_hip", "RightUpLeg", (0, 0, 0)), ("head", "Head", (0, 0, 0))],
    ...     size_markers=None))
    >>> [c.shape[1] for c in clips], names[0]
    ([24, 24], 'pelvis_px')
    """
    transformer = VirtualMarkerTransform() if transformer is None else transformer
    motions = list(motions)
    bad = [i for i, m in enumerate(motions) if not isinstance(m, Motion)]
    if bad:
        raise TypeError(
            f"motions: item {bad[0]} is a {type(motions[bad[0]]).__name__}, not a Motion."
        )
    groups = {}
    for i, motion in enumerate(motions):
        groups.setdefault(tuple(motion.channel_names), []).append(i)
    clips, names = [None] * len(motions), None
    for rows in groups.values():
        fitted = clone(transformer).fit([motions[i] for i in rows])
        group_names = fitted.get_feature_names_out()
        if names is not None and list(group_names) != list(names):
            raise ValueError("motions: the skeletons' marker sets have different marker names.")
        names = group_names
        for i, clip in zip(rows, fitted.transform([motions[i] for i in rows])):
            clips[i] = clip
    return clips, names
