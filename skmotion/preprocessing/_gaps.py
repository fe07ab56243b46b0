"""Gaps in point trajectories: finding them, interpolating them, rigid-body filling them.

Array functions on one clip of points ``(n_frames, n_points, dim)``, no
estimator: :class:`FillGaps` wraps them. A *gap* is a run of consecutive frames
in which one point is missing (NaN). Work is vectorised over frames: loops run
over points or over gap runs, never over frames.
"""

import numpy as np
from scipy.interpolate import CubicSpline

__all__ = ["fill_points", "gap_runs", "kabsch_fill", "missing_points"]

#: The fewest visible group members that fix a missing one (as in Vicon Nexus's
#: rigid body fill: three non-collinear points determine a rigid motion).
MIN_DONORS = 3


def missing_points(points, *, zeros="keep", confidence=None, threshold=None):
    """Which points are missing in which frames.

    Parameters
    ----------
    points : ndarray of shape (n_frames, n_points, dim)
    zeros : {"keep", "frame", "point"}, default="keep"
        ``"frame"``: a frame whose coordinates are all exactly 0 is missing (a
        tracker that lost the body); ``"point"``: a point whose coordinates
        are all 0 is missing (OpenPose writes undetected keypoints so).
    confidence : ndarray of shape (n_frames, n_points), default=None
        Per point confidence; below ``threshold`` (or NaN) means missing.
    threshold : float, default=None

    Returns
    -------
    missing : ndarray of bool of shape (n_frames, n_points)
        True where any coordinate is NaN or a rule above says missing.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing._gaps import missing_points
    >>> p = np.array([[[1.0, 2.0], [0.0, 0.0]], [[np.nan, 1.0], [3.0, 4.0]]])
    >>> missing_points(p, zeros="point").tolist()
    [[False, True], [True, False]]
    """
    missing = np.isnan(points).any(axis=2)
    if zeros == "point":
        missing |= (points == 0).all(axis=2)
    elif zeros == "frame":
        missing |= (points == 0).all(axis=(1, 2))[:, None]
    if confidence is not None:
        missing |= ~(confidence >= threshold)
    return missing


def gap_runs(missing):
    """Every gap as ``(point, start, stop)``: frames ``start..stop-1`` of ``point`` are missing.

    Parameters
    ----------
    missing : ndarray of bool of shape (n_frames, n_points)

    Returns
    -------
    point, start, stop : ndarray of int
        One entry per gap, ordered by point then start.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing._gaps import gap_runs
    >>> missing = np.array([[0, 1], [1, 1], [1, 0], [0, 1]], dtype=bool)
    >>> [a.tolist() for a in gap_runs(missing)]
    [[0, 1, 1], [1, 0, 3], [3, 2, 4]]
    """
    n_points = missing.shape[1]
    edge = np.zeros((1, n_points), dtype=np.int8)
    step = np.diff(np.concatenate([edge, missing.astype(np.int8), edge]), axis=0).T
    point, start = np.nonzero(step == 1)
    _, stop = np.nonzero(step == -1)
    return point, start, stop


def _mask_of(runs, shape):
    """Boolean (n_frames, n_points) mask of the frames covered by ``runs``."""
    point, start, stop = runs
    mark = np.zeros((shape[0] + 1, shape[1]), dtype=np.intp)
    np.add.at(mark, (start, point), 1)
    np.add.at(mark, (stop, point), -1)
    return np.cumsum(mark, axis=0)[:-1] > 0


def _interpolate(points, missing, fill, method):
    """Fill the frames ``fill`` of each point from its visible frames (in place)."""
    frames = np.arange(len(points))
    for j in np.flatnonzero(fill.any(axis=0)):
        seen = ~missing[:, j]
        at = frames[fill[:, j]]
        if method == "linear" or seen.sum() < 3:
            for c in range(points.shape[2]):
                points[at, j, c] = np.interp(at, frames[seen], points[seen, j, c])
        else:
            points[at, j] = CubicSpline(frames[seen], points[seen, j], axis=0)(at)


def kabsch_fill(reference, donors_ref, donors):
    """Where a point moves with its rigid group: the best rigid motion of the donors (Kabsch).

    Parameters
    ----------
    reference : ndarray of shape (dim,)
        The point in the reference frame.
    donors_ref : ndarray of shape (n_donors, dim)
        The donors in the reference frame.
    donors : ndarray of shape (n_frames, n_donors, dim)
        The donors in the frames to fill.

    Returns
    -------
    filled : ndarray of shape (n_frames, dim)
        The point carried along by the least-squares rotation and translation
        that takes ``donors_ref`` to ``donors`` in each frame (reflections
        excluded).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing._gaps import kabsch_fill
    >>> square = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> turned = square @ np.array([[0.0, 1, 0], [-1, 0, 0], [0, 0, 1]]) + 5  # 90 deg about z
    >>> kabsch_fill(np.array([1.0, 1, 0]), square, turned[None]).round(6) + 0.0
    array([[4., 6., 5.]])
    """
    centre_ref = donors_ref.mean(axis=0)
    centre = donors.mean(axis=1)
    h = np.einsum("ki,fkj->fij", donors_ref - centre_ref, donors - centre[:, None])
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(np.einsum("fij,fjk->fik", u, vt)))
    vt[:, -1] *= d[:, None]  # the closest rotation, never a reflection
    rotation = np.einsum("fji,fkj->fik", vt, u)  # R = V U^T
    return np.einsum("fij,j->fi", rotation, reference - centre_ref) + centre


def _rigid(points, missing, runs, groups):
    """Fill gaps of group members from 3+ donors visible throughout (in place); frames filled."""
    n_frames = len(points)
    filled = np.zeros(missing.shape, dtype=bool)
    member = {}
    for group in groups:
        for j in group:
            member.setdefault(j, []).append(group)
    for j, start, stop in zip(*runs):
        for group in member.get(int(j), ()):
            span = missing[start:stop]
            refs = [r for r in (start - 1, stop) if 0 <= r < n_frames]
            donors = [k for k in group if k != j and not span[:, k].any()]
            donors = [k for k in donors if not missing[refs, k].any()]
            if len(donors) < MIN_DONORS or not refs:
                continue
            moved = points[start:stop][:, donors]
            guesses = [kabsch_fill(points[r, j], points[r, donors], moved) for r in refs]
            if len(guesses) == 2:  # blend the fits from both ends: no jump at either end
                w = ((np.arange(start, stop) - start + 1) / (stop - start + 1))[:, None]
                guesses = [(1 - w) * guesses[0] + w * guesses[1]]
            points[start:stop, j] = guesses[0]
            filled[start:stop, j] = True
            break
    return filled


def fill_points(points, missing, *, max_gap, method="cubic", groups=()):
    """Fill the gaps of one clip of points; gaps it cannot fill stay NaN.

    Gaps of at most ``max_gap`` frames are filled: first rigidly from their
    group (``groups``; any gap, at the clip's ends too), then by interpolation
    through the point's visible frames (gaps with visible frames on both
    sides). Longer gaps, and gaps that neither way reaches, stay NaN.

    Parameters
    ----------
    points : ndarray of shape (n_frames, n_points, dim)
        Modified in place.
    missing : ndarray of bool of shape (n_frames, n_points)
    max_gap : int
        The longest gap to fill, in frames.
    method : {"linear", "cubic"}, default="cubic"
    groups : sequence of sequence of int, default=()
        Rigid groups of point indices.

    Returns
    -------
    report : dict
        ``n_missing`` (point-frames), ``n_gaps``, ``longest_gap`` (frames),
        ``n_rigid``, ``n_interpolated``, ``n_unfilled`` (point-frames), and
        ``unfilled``: the gaps left, as ``(point, start, stop)`` arrays.
    """
    runs = gap_runs(missing)
    lengths = runs[2] - runs[1]
    short = lengths <= max_gap
    report = {
        "n_missing": int(missing.sum()),
        "n_gaps": len(lengths),
        "longest_gap": int(lengths.max(initial=0)),
    }
    rigid = _rigid(points, missing, tuple(r[short] for r in runs), groups)
    missing = missing & ~rigid
    runs = gap_runs(missing)
    inside = (runs[1] > 0) & (runs[2] < len(points)) & (runs[2] - runs[1] <= max_gap)
    seen = (~missing).sum(axis=0)[runs[0]] >= 2
    fill = _mask_of(tuple(r[inside & seen] for r in runs), missing.shape)
    _interpolate(points, missing, fill, method)
    left = missing & ~fill
    points[left] = np.nan
    report.update(
        n_rigid=int(rigid.sum()),
        n_interpolated=int(fill.sum()),
        n_unfilled=int(left.sum()),
        unfilled=tuple(r[~(inside & seen)] for r in runs),
    )
    return report
