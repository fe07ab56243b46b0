"""Downloading CMU motion capture subjects into a local cache.

A file enters the cache only whole and readable: it is downloaded to a unique
temporary name in the cache folder (``.part``, with the process id, so that a later
fetch removes what a killed one left), within a whole-transfer deadline, its size is
checked against the server's ``Content-Length`` (without one, a second download must
give the same bytes), it is refused when it is an HTML page, and it is parsed with
:func:`read_asf` / :func:`read_amc` (every frame complete) before :func:`os.replace`
gives it its name.
Transient failures (a cut connection, a timeout, a 5xx answer, a truncated or
unreadable body) are retried with exponential back-off, then reported as one
``ConnectionError`` naming the URL, the last reason and the cache folder.
"""

import http.client
import os
import tempfile
import time
import urllib.error
import urllib.request
from numbers import Integral

import numpy as np

from skmotion.datasets._home import get_data_home
from skmotion.datasets._motion_files import _as_index, load_cmu_asfamc
from skmotion.io import MotionFileError, read_amc, read_asf
from skmotion.utils import progress, say

__all__ = ["fetch_cmu_mocap"]

CMU_URL = "https://mocap.cs.cmu.edu/subjects"
_COMPLETE = ".complete"  # written once every trial of a probed subject is in the cache
_MAX_TRIALS = 200
_ATTEMPTS = 3  # tries per file
_BACKOFF = 0.5  # seconds before the second try; doubled before each further one
_TRANSIENT_HTTP = frozenset({408, 425, 429, 500, 502, 503, 504})
_HTML_STARTS = (b"<!doctype", b"<html", b"<head", b"<body", b"<?xml")


def _urlopen(url, timeout):
    """The one place that touches the network (tests replace it)."""
    return urllib.request.urlopen(url, timeout=timeout)


class _Retry(Exception):
    """A transient failure of one attempt: the reason is kept for the final message."""


def _content_length(response):
    headers = getattr(response, "headers", None)
    value = headers.get("Content-Length") if headers is not None else None
    return int(value) if value is not None and value.strip().isdigit() else None


def _looks_like_html(path):
    """An error page served with status 200 (judged by content: some servers label
    plain-text motion files ``text/html``, so the Content-Type header is not used)."""
    with open(path, "rb") as fh:
        head = fh.read(1024).lstrip().lower()
    return head.startswith(_HTML_STARTS)


def _copy(response, fh, deadline):
    """Copy the body, giving up at ``deadline`` (a trickling server never trips the
    per-read timeout: each read returns a few bytes in time)."""
    read = getattr(response, "read1", None) or response.read
    while True:
        if time.monotonic() > deadline:
            raise _Retry("the transfer did not finish within transfer_timeout")
        chunk = read(1 << 16)
        if not chunk:
            return
        fh.write(chunk)


def _part_name(target):
    # The process id in the name lets a later fetch remove what a killed one left.
    return f".{target.name}.{os.getpid()}."


def _remove_orphans(folder):
    """Remove ``.part`` files of downloads whose process is gone (killed mid-transfer)."""
    for part in folder.glob(".*.part"):
        pid = part.name[: -len(".part")].split(".")[-2]
        if pid.isdigit() and (int(pid) == os.getpid() or _process_alive(int(pid))):
            continue  # a download running now, in this process or another
        part.unlink(missing_ok=True)


def _process_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's process
    return True


def _attempt(url, target, timeout, check, transfer_timeout):
    """Download once into a unique temporary file in the cache folder.

    Returns the temporary path and whether the server stated the body's length.
    """
    deadline = time.monotonic() + transfer_timeout
    with _urlopen(url, timeout) as response:
        expected = _content_length(response)
        fd, temporary = tempfile.mkstemp(
            dir=target.parent, prefix=_part_name(target), suffix=".part"
        )
        try:
            with os.fdopen(fd, "wb") as fh:
                _copy(response, fh, deadline)
            size = os.path.getsize(temporary)
            if expected is not None and size != expected:
                raise _Retry(f"received {size} of {expected} bytes")
            if _looks_like_html(temporary):
                raise _Retry("the server sent an HTML page, not a motion file")
            try:
                check(temporary)
            except MotionFileError as exc:
                where = "" if exc.line is None else f" (line {exc.line})"
                raise _Retry(
                    f"the download does not read as a motion file{where}: {exc.message}"
                ) from None
        except BaseException:
            os.unlink(temporary)
            raise
    return temporary, expected is not None


def _same_bytes(a, b):
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


def _download(url, target, timeout, check, verbose=0, transfer_timeout=600.0):
    """Fetch ``url`` into ``target`` whole and checked; False when the server says 404.

    A body whose length the server does not state (no ``Content-Length``) is
    kept only when a second download gives the same bytes: a connection that
    drops between two frames leaves a file that parses, and only a second copy
    (or a frame count ``check`` knows) can tell.
    """
    reason, unconfirmed = None, None
    for attempt in range(_ATTEMPTS + 1):
        if attempt:
            time.sleep(_BACKOFF * 2 ** (attempt - 1))
        try:
            temporary, stated = _attempt(url, target, timeout, check, transfer_timeout)
            if not stated:
                if unconfirmed is None or not _same_bytes(unconfirmed, temporary):
                    if unconfirmed is not None:
                        os.unlink(unconfirmed)
                    unconfirmed = temporary
                    raise _Retry("no Content-Length: a second copy must confirm the length")
                os.unlink(unconfirmed)
                unconfirmed = None
        except urllib.error.HTTPError as exc:
            if exc.code == 404:
                return False
            reason = f"HTTP {exc.code} {exc.reason}"
            if exc.code not in _TRANSIENT_HTTP:
                raise ConnectionError(f"Could not download {url}: {reason}.") from None
        except _Retry as exc:
            reason = str(exc)
        except (urllib.error.URLError, http.client.HTTPException, OSError) as exc:
            # URLError (no network, DNS), IncompleteRead, RemoteDisconnected, timeouts, resets.
            reason = str(getattr(exc, "reason", "") or exc) or type(exc).__name__
        except BaseException:
            if unconfirmed is not None:
                os.unlink(unconfirmed)
            raise
        else:
            os.replace(temporary, target)
            say(verbose, f"downloaded {url}")
            return True
        say(verbose, f"{url}: attempt {attempt + 1} of {_ATTEMPTS} failed ({reason})")
        if attempt + 1 >= _ATTEMPTS and unconfirmed is None:
            break
    if unconfirmed is not None:
        os.unlink(unconfirmed)
    raise ConnectionError(
        f"Could not download {url} ({reason}) after {_ATTEMPTS} attempts. skmotion needs the "
        f"network to fetch CMU data the first time; offline, place the files in {target.parent} "
        "yourself (NN.asf and NN_TT.amc)."
    )


def _whole_numbers(values, what):
    """A list of positive ints from an int or a list of ints (NumPy ints too; not bool, not 2.7)."""
    items = list(values) if isinstance(values, (list, tuple, np.ndarray, range)) else [values]
    out = []
    for value in items:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Integral):
            raise TypeError(
                f"{what} must be whole numbers (int), got {value!r} of type {type(value).__name__}."
            )
        if value < 1:
            raise ValueError(f"{what} must be positive, got {int(value)}.")
        out.append(int(value))
    if not out:
        raise ValueError(f"{what} is empty: give at least one number.")
    return out


def _subject_trials(subject, trials, index):
    if trials is not None:
        return sorted(set(trials))
    if index is not None:
        return sorted(index.loc[index["subject"] == subject, "trial"].astype(int))
    return None  # probe 01, 02, ... until the server has no more


def _verify(folder, skeleton_file, verbose):
    """Re-read every cached file of a subject folder; remove those that do not read."""
    removed = []
    skeleton = None
    if skeleton_file.is_file():
        try:
            skeleton = read_asf(skeleton_file)
        except MotionFileError as exc:
            say(verbose, f"removing {skeleton_file}: {exc}")
            removed.append(skeleton_file)
    for amc in sorted(folder.glob("*.amc")):
        try:
            if skeleton is None:
                raise MotionFileError(amc, None, "its skeleton file is missing or broken")
            read_amc(amc, skeleton)
        except MotionFileError as exc:
            say(verbose, f"removing {amc}: {exc}")
            removed.append(amc)
    for path in removed:
        path.unlink(missing_ok=True)
    if removed:
        (folder / _COMPLETE).unlink(missing_ok=True)
    return removed


def fetch_cmu_mocap(
    subjects,
    *,
    trials=None,
    data_home=None,
    index=None,
    timeout=30.0,
    transfer_timeout=600.0,
    verify=False,
    verbose=0,
):
    """Download CMU subjects' ASF/AMC files into a cache and load them.

    Files come from ``https://mocap.cs.cmu.edu/subjects/NN/NN.asf`` and
    ``.../NN/NN_TT.amc`` into ``<data_home>/cmu-asfamc/NN/``, the layout
    :func:`load_cmu_asfamc` reads. A file enters the cache only whole and
    readable: it is downloaded to a unique temporary name, checked against the
    server's ``Content-Length``, refused when it is an HTML page, and read with
    :func:`~skmotion.io.read_asf` / :func:`~skmotion.io.read_amc` before an
    atomic rename gives it its name (concurrent fetches of one file are safe).
    Transient failures are retried with back-off. Files already in the cache
    are never downloaded again; a subject whose trials were all fetched once
    (or whose requested trials are cached) needs no network at all.

    Parameters
    ----------
    subjects : int or list of int
        CMU subject numbers (NumPy integers too; not floats or bools).
    trials : int or list of int, default=None
        Trial numbers to fetch for every subject. By default the trials the
        ``index`` lists, or, without an index, trials 1, 2, ... until the
        server has no more.
    data_home : str or path-like, default=None
        The cache root; see :func:`get_data_home` (``~/skmotion_data``).
    index : str, path-like or DataFrame, default=None
        The CMU index CSV, for the trial list, descriptions and frame rates.
    timeout : float, default=30.0
        Seconds to wait for the server (to connect, and for each read).
    transfer_timeout : float, default=600.0
        Seconds one whole file may take to arrive; a server that trickles a
        few bytes at a time never trips ``timeout``, and is given up on (and
        retried) after this.
    verify : bool, default=False
        Re-read every cached file of the requested subjects first; files that
        do not read (cut, or cached by an older version) are removed and
        downloaded again.
    verbose : int, default=0
        1 or more reports each subject, download and retry on standard error.

    Returns
    -------
    data : Bunch
        As :func:`load_cmu_asfamc`, for the requested subjects.

    Raises
    ------
    ConnectionError
        When a file is not cached and cannot be downloaded after the retries;
        the message names the URL, the last reason and the cache folder.
    ValueError
        When CMU has no such subject or trial (the server answers 404).
    TypeError
        When a subject or trial number is not a whole number (``2.7``, ``True``).

    Examples
    --------
    >>> from skmotion.datasets import fetch_cmu_mocap
    >>> data = fetch_cmu_mocap([2], trials=[1, 3])  # doctest: +SKIP
    >>> data.trials.tolist()  # doctest: +SKIP
    ['02_01', '02_03']
    """
    subjects = _whole_numbers(subjects, "subjects")
    trials = None if trials is None else _whole_numbers(trials, "trials")
    index = _as_index(index)
    root = get_data_home(data_home) / "cmu-asfamc"
    for subject in progress(subjects, verbose=verbose, desc="CMU subjects"):
        _fetch_subject(root, subject, trials, index, (timeout, transfer_timeout), verify, verbose)
    data = load_cmu_asfamc(
        root, index, subjects=subjects, errors="raise"
    )  # a bad cache is an error
    if trials is not None:
        keep = np.isin([int(t.split("_")[1]) for t in data.trials], trials)
        data = _select(data, np.flatnonzero(keep))
    return data


def _fetch_subject(root, subject, trials, index, timeouts, verify, verbose):
    name = f"{subject:02d}"
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    _remove_orphans(folder)
    timeout, transfer_timeout = timeouts
    asf = folder / f"{name}.asf"
    if verify:
        _verify(folder, asf, verbose)
    if not asf.is_file() and not _download(
        f"{CMU_URL}/{name}/{name}.asf", asf, timeout, read_asf, verbose, transfer_timeout
    ):
        raise ValueError(f"CMU has no subject {subject} ({CMU_URL}/{name}/{name}.asf not found).")
    try:
        skeleton = read_asf(asf)
    except MotionFileError as exc:
        raise MotionFileError(
            exc.path, exc.line, f"{exc.message} (fetch_cmu_mocap(..., verify=True) replaces it)"
        ) from None

    def fetch(amc):
        if amc.is_file():
            return True
        url = f"{CMU_URL}/{name}/{amc.name}"
        check = lambda path: read_amc(path, skeleton)  # noqa: E731
        return _download(url, amc, timeout, check, verbose, transfer_timeout)

    wanted = _subject_trials(subject, trials, index)
    if wanted is None:
        if (folder / _COMPLETE).is_file():
            return
        trial = 1
        while trial <= _MAX_TRIALS and fetch(folder / f"{name}_{trial:02d}.amc"):
            trial += 1
        (folder / _COMPLETE).write_text("every trial of this subject is cached\n")
        return
    for trial in wanted:
        if not fetch(folder / f"{name}_{trial:02d}.amc"):
            raise ValueError(
                f"CMU has no trial {name}_{trial:02d} ({CMU_URL}/{name}/{name}_{trial:02d}.amc "
                "not found)."
            )


def _select(data, rows):
    """The Bunch restricted to some clips."""
    picked = {}
    for key, value in data.items():
        if isinstance(value, list) and key != "skipped":  # skipped: files, not clips
            picked[key] = [value[i] for i in rows]
        elif isinstance(value, np.ndarray) and key not in ("target_names", "subject_names"):
            picked[key] = value[rows]
        else:
            picked[key] = value
    data.update(picked)
    return data
