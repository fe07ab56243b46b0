"""Downloading CMU motion capture subjects into a local cache."""

import os
import shutil
import urllib.error
import urllib.request

import numpy as np

from skmotion.datasets._home import get_data_home
from skmotion.datasets._motion_files import _as_index, load_cmu_asfamc

__all__ = ["fetch_cmu_mocap"]

CMU_URL = "http://mocap.cs.cmu.edu/subjects"
_COMPLETE = ".complete"  # written once every trial of a probed subject is in the cache
_MAX_TRIALS = 200


def _urlopen(url, timeout):
    """The one place that touches the network (tests replace it)."""
    return urllib.request.urlopen(url, timeout=timeout)


def _download(url, target, timeout):
    """Fetch ``url`` into ``target`` atomically; False when the server says 404."""
    partial = target.with_name(target.name + ".part")
    try:
        with _urlopen(url, timeout) as response, open(partial, "wb") as fh:
            shutil.copyfileobj(response, fh)
    except urllib.error.HTTPError as exc:
        partial.unlink(missing_ok=True)
        if exc.code == 404:
            return False
        raise ConnectionError(f"Could not download {url}: HTTP {exc.code} {exc.reason}.") from None
    except (urllib.error.URLError, OSError) as exc:
        partial.unlink(missing_ok=True)
        reason = getattr(exc, "reason", exc)
        raise ConnectionError(
            f"Could not download {url} ({reason}): skmotion needs the network to fetch CMU data the first "
            f"time. Offline, place the files in {target.parent} yourself (NN.asf and NN_TT.amc)."
        ) from None
    os.replace(partial, target)
    return True


def _subject_trials(subject, trials, index):
    if trials is not None:
        return sorted({int(t) for t in np.atleast_1d(trials)})
    if index is not None:
        return sorted(index.loc[index["subject"] == subject, "trial"].astype(int))
    return None  # probe 01, 02, ... until the server has no more


def fetch_cmu_mocap(subjects, *, trials=None, data_home=None, index=None, timeout=30.0):
    """Download CMU subjects' ASF/AMC files into a cache and load them.

    Files come from ``http://mocap.cs.cmu.edu/subjects/NN/NN.asf`` and
    ``.../NN/NN_TT.amc`` into ``<data_home>/cmu-asfamc/NN/``, the layout
    :func:`load_cmu_asfamc` reads. Files already in the cache are never
    downloaded again; a subject whose trials were all fetched once (or whose
    requested trials are cached) needs no network at all.

    Parameters
    ----------
    subjects : int or list of int
        CMU subject numbers.
    trials : int or list of int, default=None
        Trial numbers to fetch for every subject. By default the trials the
        ``index`` lists, or, without an index, trials 1, 2, ... until the
        server has no more.
    data_home : str or path-like, default=None
        The cache root; see :func:`get_data_home` (``~/skmotion_data``).
    index : str, path-like or DataFrame, default=None
        The CMU index CSV, for the trial list, descriptions and frame rates.
    timeout : float, default=30.0
        Seconds to wait for the server.

    Returns
    -------
    data : Bunch
        As :func:`load_cmu_asfamc`, for the requested subjects.

    Raises
    ------
    ConnectionError
        When a file is not cached and cannot be downloaded (offline); the
        message names the file and the cache folder.

    Examples
    --------
    >>> from skmotion.datasets import fetch_cmu_mocap
    >>> data = fetch_cmu_mocap([2], trials=[1, 3])  # doctest: +SKIP
    >>> data.trials.tolist()  # doctest: +SKIP
    ['02_01', '02_03']
    """
    index = _as_index(index)
    subjects = [int(s) for s in np.atleast_1d(subjects)]
    root = get_data_home(data_home) / "cmu-asfamc"
    for subject in subjects:
        name = f"{subject:02d}"
        folder = root / name
        folder.mkdir(parents=True, exist_ok=True)
        asf = folder / f"{name}.asf"
        if not asf.is_file() and not _download(f"{CMU_URL}/{name}/{name}.asf", asf, timeout):
            raise ValueError(
                f"CMU has no subject {subject} ({CMU_URL}/{name}/{name}.asf not found)."
            )
        wanted = _subject_trials(subject, trials, index)
        if wanted is None:
            if (folder / _COMPLETE).is_file():
                continue
            for trial in range(1, _MAX_TRIALS + 1):
                amc = folder / f"{name}_{trial:02d}.amc"
                if not amc.is_file() and not _download(
                    f"{CMU_URL}/{name}/{amc.name}", amc, timeout
                ):
                    break
            (folder / _COMPLETE).write_text("every trial of this subject is cached\n")
            continue
        for trial in wanted:
            amc = folder / f"{name}_{trial:02d}.amc"
            if not amc.is_file() and not _download(f"{CMU_URL}/{name}/{amc.name}", amc, timeout):
                raise ValueError(
                    f"CMU has no trial {name}_{trial:02d} ({CMU_URL}/{name}/{amc.name} not found)."
                )
    data = load_cmu_asfamc(root, index, subjects=subjects)
    if trials is not None:
        keep = np.isin(
            [int(t.split("_")[1]) for t in data.trials], np.atleast_1d(trials).astype(int)
        )
        data = _select(data, np.flatnonzero(keep))
    return data


def _select(data, rows):
    """The Bunch restricted to some clips."""
    picked = {}
    for key, value in data.items():
        if isinstance(value, list):
            picked[key] = [value[i] for i in rows]
        elif isinstance(value, np.ndarray) and key not in ("target_names", "subject_names"):
            picked[key] = value[rows]
        else:
            picked[key] = value
    data.update(picked)
    return data
