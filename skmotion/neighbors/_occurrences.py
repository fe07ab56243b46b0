"""Where does this motion occur in long takes: ranked occurrences of a query clip.

Two distances between the query and a stretch of a take:

- ``"znorm"``: the z-normalised Euclidean distance of every window of the
  query's length (Mueen et al., MASS, 2017), per channel, averaged over the
  channels, as stumpy's ``match`` defines it for several dimensions. The
  sliding dot products are FFT correlations computed block by block
  (overlap-save: many short transforms instead of one of the take's length);
  the take is searched a stretch of blocks at a time, every channel at once,
  so that the copy, the FFTs and the distances work in cache; the windows'
  means and spreads come from a compiled sliding pass
  (``_occurrence_loops.pyx``) that is exact for constant windows. The chosen
  occurrences' distances are recomputed by z-normalising their windows;
- ``"dtw"``: subsequence dynamic time warping (Mueller 2007): the whole query
  is warped onto a stretch of the take that may start and end anywhere, with
  the squared Euclidean cost between frames; the distance is the square root
  of the accumulated cost, as tslearn's ``dtw_subsequence_path`` gives it.

Occurrences are chosen greedily: the smallest distance first, then, as
stumpy's ``match`` does, no window starting within ``exclusion`` frames of a
chosen one in the same take (``"znorm"``), or no path overlapping a chosen
one (``"dtw"``), and so on.
"""

from concurrent.futures import ThreadPoolExecutor
from numbers import Integral, Real

import numpy as np
import pandas as pd
from joblib import effective_n_jobs
from numpy.lib.stride_tricks import as_strided

from skmotion.neighbors import _occurrence_loops as _loops
from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = ["find_occurrences"]

#: Shortest FFT block of the sliding dot products: long enough that the hop
#: (the block less the query) wastes little, short enough to stay in cache.
MIN_BLOCK = 2048

#: FFT blocks per unit of work of the z-normalised search: every channel of
#: that stretch of the take goes through the FFTs and the compiled pass while
#: it is still in cache (a few hundred kilobytes), instead of one whole-take
#: array per stage.
CHUNK_BLOCKS = 16


def _as_frames(values, what):
    """A float64 C-contiguous ``(n_frames, n_channels)`` array; NaN or inf is an error."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2:
        raise ValueError(f"{what} must be (n_frames, n_channels); got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        frame, channel = np.argwhere(bad)[0]
        raise ValueError(f"{what} has a non-finite value at frame {frame}, channel {channel}")
    return np.ascontiguousarray(array)


def _block_length(m):
    """The FFT length for a query of ``m`` frames: a power of two, at least ``2 m``."""
    return 1 << int(np.ceil(np.log2(max(MIN_BLOCK, 32 * m))))


def _padded(series, m, block):
    """``series`` (``(..., n)``) in zeros of ``n_blocks * hop + m - 1`` frames; ``hop``."""
    hop = block - m + 1
    n = series.shape[-1]
    n_blocks = -(-(n - m + 1) // hop)
    padded = np.zeros((*series.shape[:-1], n_blocks * hop + m - 1))
    padded[..., :n] = series
    return padded, hop


def _block_dots(q_spectrum, padded, hop, block, spectrum=None, out=None):
    """The FFT blocks' correlations, ``(..., n_blocks, block)``: of block ``b``, the first ``hop``.

    Block ``b`` holds frames ``b * hop ... b * hop + block - 1`` of ``padded``
    (``(..., n_blocks * hop + m - 1)``); its first ``hop`` circular
    correlations with the query do not wrap around. ``q_spectrum``: the
    conjugate spectrum of the query, ``(..., 1, block // 2 + 1)``. numpy's
    FFTs, which write into ``spectrum`` and ``out`` when given (a search
    reuses them from stretch to stretch; numpy's transforms measured twice as
    fast as scipy's on these blocks).
    """
    n_blocks = (padded.shape[-1] - block) // hop + 1
    blocks = as_strided(
        padded,
        (*padded.shape[:-1], n_blocks, block),
        (*padded.strides[:-1], hop * padded.itemsize, padded.itemsize),
        writeable=False,
    )
    spectrum = np.fft.rfft(blocks, axis=-1, out=spectrum)
    spectrum *= q_spectrum
    return np.fft.irfft(spectrum, block, axis=-1, out=out)


def sliding_dots(query, series, block=None):
    """``out[..., i] = sum_j query[..., j] * series[..., i + j]`` for every window, by block FFTs.

    Parameters
    ----------
    query : ndarray of shape (..., m)
    series : ndarray of shape (..., n), ``n >= m``
        Its leading dimensions are the query's (one query per series).
    block : int, default=None
        FFT length (a power of two at least ``2 m``); by default
        ``max(MIN_BLOCK, 32 m)`` rounded up to a power of two.

    Returns
    -------
    dots : ndarray of shape (..., n - m + 1)
    """
    m, n = query.shape[-1], series.shape[-1]
    block = _block_length(m) if block is None else block
    padded, hop = _padded(series, m, block)
    q_spectrum = np.conj(np.fft.rfft(query, block, axis=-1))[..., None, :]
    dots = _block_dots(q_spectrum, padded, hop, block)[..., :hop]
    return dots.reshape(*series.shape[:-1], -1)[..., : n - m + 1]


def _znorm_profile(query, take, n_threads):
    """Mean over channels of the z-normalised distance of each window to the query.

    The take is searched a stretch of ``CHUNK_BLOCKS`` FFT blocks at a time,
    every channel at once; with several threads, each takes whole stretches
    (the FFTs and the compiled pass release the GIL, and each stretch writes
    its own windows of the result). The compiled pass reads the dot products
    where the inverse FFT wrote them.
    """
    m, n_channels = query.shape
    n_windows = len(take) - m + 1
    block = _block_length(m)
    constant = (query == query[:1]).all(axis=0)
    # A constant query channel is never correlated (the compiled pass ignores its dots).
    q_hat = (query - query.mean(axis=0)) / np.where(constant, 1.0, query.std(axis=0))
    q_spectrum = np.conj(np.fft.rfft(q_hat.T, block, axis=-1))[:, None, :]
    hop = block - m + 1
    # A short take is one stretch of only the blocks it fills.
    per_stretch = min(CHUNK_BLOCKS, -(-n_windows // hop))
    span = hop * per_stretch
    total = np.zeros(n_windows)
    stretches = range(0, n_windows, span)
    n_threads = max(1, min(n_threads, len(stretches)))

    def add_stretches(thread):
        # This thread's buffers, reused for each of its stretches.
        padded = np.empty((n_channels, span + m - 1))
        spectrum = np.empty((n_channels, per_stretch, block // 2 + 1), dtype=complex)
        dots = np.empty((n_channels, per_stretch, block))
        for first in stretches[thread::n_threads]:
            last = min(first + span, n_windows)
            frames = take[first : last + m - 1]
            n_blocks = -(-(last - first) // hop)
            # Channel-major, each channel shifted to mean 0: shifting changes no
            # z-normalised distance (nor a dot product with a query of mean 0) but
            # shrinks the FFT's rounding, which grows with the values' size.
            np.subtract(frames.T, frames.mean(axis=0)[:, None], out=padded[:, : len(frames)])
            padded[:, len(frames) :] = 0.0
            found = _block_dots(
                q_spectrum,
                padded[:, : n_blocks * hop + m - 1],
                hop,
                block,
                spectrum[:, :n_blocks],
                dots[:, :n_blocks],
            )
            for c in range(n_channels):
                _loops.add_znorm_distance(
                    padded[c, : len(frames)], found[c], hop, m, bool(constant[c]), total[first:last]
                )

    if n_threads == 1:
        add_stretches(0)
    else:
        with ThreadPoolExecutor(n_threads) as pool:
            list(pool.map(add_stretches, range(n_threads)))
    return total / n_channels


def _dtw_profile(query, take):
    """Subsequence DTW distance of the best path ending at each take frame, and its start."""
    cost, start = _loops.subsequence_dtw(query, take)
    return np.sqrt(cost), start


def _profiles(query, takes, metric, max_distance, n_threads):
    """Each take's distance profile, and the start of each entry's window (None: its index).

    An entry farther than ``max_distance`` is set to inf: never chosen, and never
    excluding another.
    """
    m = len(query)
    profiles, starts = [], []
    for take in takes:
        if metric == "znorm":
            profile = _znorm_profile(query, take, n_threads) if len(take) >= m else np.empty(0)
            start = None  # a window starts at its own index
        else:
            profile, start = _dtw_profile(query, take)
        if max_distance < np.inf:
            profile[~(profile <= max_distance)] = np.inf
        profiles.append(profile)
        starts.append(start)
    return profiles, starts


def _greedy(profiles, starts, n_occurrences, exclusion):
    """``(index, distance)`` into the concatenated profiles, smallest first, each
    excluding its neighbours; and the profiles' bounds.

    With ``exclusion`` (z-normalised windows), the indices within ``exclusion``
    of a chosen one in the same take; without (DTW), every path that overlaps
    the chosen one (those ending at or after its start and starting at or
    before its end). The profiles are the caller's own: excluded entries are set
    to inf in them (one take's profile is not copied).
    """
    bounds = np.concatenate([[0], np.cumsum([len(p) for p in profiles])]).astype(np.intp)
    distance = profiles[0] if len(profiles) == 1 else np.concatenate(profiles or [np.empty(0)])
    chosen = []
    limit = len(distance) if n_occurrences is None else n_occurrences
    while len(chosen) < limit and len(distance):
        i = int(np.argmin(distance))
        if not np.isfinite(distance[i]):
            break
        chosen.append((i, float(distance[i])))
        t = int(np.searchsorted(bounds, i, side="right")) - 1
        if exclusion is not None:
            distance[max(bounds[t], i - exclusion) : min(bounds[t + 1], i + exclusion + 1)] = np.inf
        else:
            first = bounds[t] + starts[t][i - bounds[t]]
            later = distance[first : bounds[t + 1]]
            later[starts[t][first - bounds[t] :] <= i - bounds[t]] = np.inf
    return chosen, bounds


@validate_params(
    {
        "query": ["array-like"],
        "takes": [list, tuple],
        "metric": [StrOptions({"znorm", "dtw"})],
        "n_occurrences": [Interval(Integral, 1, None, closed="left"), None],
        "exclusion": [Interval(Integral, 0, None, closed="left"), None],
        "max_distance": [Interval(Real, 0, None, closed="both")],
        "n_jobs": [Integral, None],
    },
    prefer_skip_nested_validation=True,
)
def find_occurrences(
    query,
    takes,
    *,
    metric="znorm",
    n_occurrences=10,
    exclusion=None,
    max_distance=np.inf,
    n_jobs=None,
):
    """Ranked occurrences of a query clip in long takes: ``(take, start, end, distance)``.

    Parameters
    ----------
    query : array-like of shape (m, n_channels)
        The motion to look for: per frame, the same features as the takes
        (marker positions in the body frame, say, from
        :class:`~skmotion.preprocessing.VirtualMarkerTransform`).
    takes : list of array-like of shape (n_frames_i, n_channels)
        The recordings to search. A take shorter than the query (for
        ``"znorm"``) holds no window and contributes no occurrence.
    metric : {"znorm", "dtw"}, default="znorm"
        ``"znorm"``: windows of ``m`` frames, each channel z-normalised, the
        distances averaged over the channels (stumpy's ``match``; a constant
        channel is at 0 from a constant window and ``sqrt(m)`` from any
        other). ``"dtw"``: subsequence DTW on the raw features, any length.
    n_occurrences : int or None, default=10
        How many occurrences to return (None: all that ``max_distance`` lets through).
    exclusion : int, default=None
        ``"znorm"``: frames around a chosen occurrence's start where no other
        starts; by default ``ceil(m / 4)``, as stumpy. Not used by ``"dtw"``,
        whose occurrences never overlap.
    max_distance : float, default=inf
        Occurrences farther than this are not returned.
    n_jobs : int, default=None
        Threads (``"znorm"``), each handling whole stretches of a take; None
        is one, -1 all cores.

    Returns
    -------
    occurrences : pandas.DataFrame
        Columns ``take``, ``start``, ``end`` (the frames ``start:end`` of
        that take) and ``distance``, smallest distance first. Read the first
        column as ``occurrences["take"]``: ``occurrences.take`` is pandas'
        own method.

    Raises
    ------
    ValueError
        When the query or a take holds NaN or inf (the message names the take,
        frame and channel) or the channels differ.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors import find_occurrences
    >>> t = np.linspace(0, 20 * np.pi, 2000)
    >>> take = np.column_stack([np.sin(t), np.cos(2 * t)])
    >>> query = 3.0 * take[500:560] + 1.0         # z-normalisation ignores scale and offset
    >>> found = find_occurrences(query, [take], n_occurrences=3)
    >>> found.loc[0, ["take", "start", "end"]].tolist(), bool(found.distance[0] < 1e-6)
    ([0, 500, 560], True)
    >>> find_occurrences(take[500:560], [take], metric="dtw", n_occurrences=1).end.tolist()
    [560]
    """
    query = _as_frames(query, "the query")
    m, n_channels = query.shape
    if m < 2 and metric == "znorm":
        raise ValueError("a z-normalised query needs 2 frames or more")
    arrays = []
    for i, take in enumerate(takes):
        array = _as_frames(take, f"take {i}")
        if array.shape[1] != n_channels:
            raise ValueError(f"take {i} has {array.shape[1]} channels and the query {n_channels}")
        arrays.append(array)
    if metric == "znorm":
        exclusion = int(np.ceil(m / 4)) if exclusion is None else exclusion
    else:
        exclusion = None
    profiles, starts = _profiles(query, arrays, metric, max_distance, effective_n_jobs(n_jobs))
    chosen, bounds = _greedy(profiles, starts, n_occurrences, exclusion)
    rows = []
    for index, distance in chosen:
        t = int(np.searchsorted(bounds, index, side="right")) - 1
        local = index - int(bounds[t])
        start = local if starts[t] is None else int(starts[t][local])
        end = start + m if metric == "znorm" else local + 1
        rows.append((t, start, end, distance))
    found = pd.DataFrame(rows, columns=["take", "start", "end", "distance"]).astype(
        {"take": np.intp, "start": np.intp, "end": np.intp, "distance": float}
    )
    if metric == "znorm" and len(found):
        windows = np.stack([arrays[t][s : s + m] for t, s in zip(found["take"], found.start)])
        found["distance"] = _window_distances(query, windows)
    return found


def _window_distances(query, windows):
    """The z-normalised distance of each window, each window z-normalised explicitly.

    What is reported for the chosen occurrences: the FFT's dot products round
    to about ``1e-16`` of the values' size, which the square root of a distance
    near 0 turns into ``1e-8``-``1e-7``; here an exact match is at 0 (to
    ``1e-15``). ``windows`` is ``(k, m, n_channels)``.
    """
    m = query.shape[0]
    q_constant = (query == query[:1]).all(axis=0)
    w_constant = (windows == windows[:, :1]).all(axis=1)
    q_hat = (query - query.mean(axis=0)) / np.where(q_constant, 1.0, query.std(axis=0))
    spread = np.where(w_constant, 1.0, windows.std(axis=1))
    w_hat = (windows - windows.mean(axis=1, keepdims=True)) / spread[:, None]
    per_channel = np.sqrt(((w_hat - q_hat) ** 2).sum(axis=1))
    per_channel = np.where(w_constant & q_constant, 0.0, per_channel)
    per_channel = np.where(w_constant ^ q_constant, np.sqrt(m), per_channel)
    return per_channel.mean(axis=1)
