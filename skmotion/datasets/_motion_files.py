"""Loading folders of motion files: the formats of ``skmotion.io.FORMATS`` that folders hold."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.utils import Bunch

from skmotion.io import FORMATS, file_format, folder_suffixes
from skmotion.utils import progress

__all__ = ["load_bvh_folder", "load_cmu_asfamc", "load_motion_folder", "read_cmu_index"]

_TRIAL = re.compile(r"^(\d+)_(\d+)$")
_INDEX_COLUMNS = ("Subject", "Trial #", "Motion Description")


def read_cmu_index(path):
    """Read the CMU database index (subject, trial, description, frame rate).

    Parameters
    ----------
    path : str or path-like
        A CSV file with the columns ``Subject``, ``Trial #``, ``Motion
        Description`` and optionally ``framerate``.

    Returns
    -------
    index : DataFrame
        Indexed by trial id ``"NN_TT"`` (``"02_01"``), with columns
        ``subject``, ``trial``, ``description`` and ``frame_rate`` (NaN when
        the file has no rates).

    Examples
    --------
    >>> import tempfile, os
    >>> from skmotion.datasets import read_cmu_index
    >>> text = 'Subject,Trial #,Motion Description,framerate\\n2,1,walk,120\\n2,3,"run/jog",120\\n'
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "index.csv")
    ...     _ = open(path, "w").write(text)
    ...     index = read_cmu_index(path)
    >>> index.loc["02_03", "description"]
    'run/jog'
    """
    table = pd.read_csv(path)
    missing = [c for c in _INDEX_COLUMNS if c not in table.columns]
    if missing:
        raise ValueError(f"{path} is not a CMU index: it lacks the columns {missing}.")
    rates = table["framerate"].astype(float) if "framerate" in table.columns else np.nan
    index = pd.DataFrame(
        {
            "subject": table["Subject"].astype(int),
            "trial": table["Trial #"].astype(int),
            "description": table["Motion Description"].fillna("").astype(str),
            "frame_rate": rates,
        }
    )
    index.index = [f"{s:02d}_{t:02d}" for s, t in zip(index["subject"], index["trial"])]
    return index


def _find_index(folder):
    """A CMU index CSV at the top of ``folder``, if there is one."""
    for path in sorted(Path(folder).glob("*.csv")):
        header = path.open(errors="replace").readline()
        if all(c in header for c in _INDEX_COLUMNS):
            return path
    return None


def _as_index(index):
    if index is None or isinstance(index, pd.DataFrame):
        return index
    return read_cmu_index(index)


def _trial_id(stem):
    """``"02_01"`` for a CMU trial file name, else None."""
    match = _TRIAL.match(stem)
    return f"{int(match.group(1)):02d}_{int(match.group(2)):02d}" if match else None


def _short_label(description):
    """A class label from a CMU description: its text up to the first comma or dash."""
    return re.split(r",| - |;", description.strip().lower(), maxsplit=1)[0].strip()


def _skeleton_for(path, suffix):
    """The skeleton file of a motion stored apart: ``NN<suffix>``, or the folder's only one."""
    folder = path.parent
    subject = path.stem.split("_")[0]
    candidate = folder / f"{subject}{suffix}"
    if candidate.is_file():
        return candidate
    candidates = sorted(folder.glob(f"*{suffix}"))
    if len(candidates) != 1:
        raise FileNotFoundError(
            f"No skeleton for {path}: expected {candidate.name} or a single {suffix} file in "
            f"{folder}."
        )
    return candidates[0]


def _find_files(folder, suffixes):
    """(format row, path) of every file below ``folder`` with one of ``suffixes``, table order."""
    order = {row.suffix: k for k, row in enumerate(FORMATS)}
    paths = [p for p in folder.rglob("*") if p.suffix.lower() in suffixes and p.is_file()]
    paths.sort(key=lambda p: (order[p.suffix.lower()], p))
    return [(file_format(p), p) for p in paths]


def _read_files(files, index, options, verbose):
    """Every (motion, path) of ``files``; a skeleton file is read once for all its motions."""
    skeletons = {}
    out = []
    for row, path in progress(files, verbose=verbose, desc="reading motion files"):
        if row.skeleton_suffix is None:
            out.append((row.reader(path, **options.get(row.suffix, {})), path))
            continue
        skeleton_path = _skeleton_for(path, row.skeleton_suffix)
        if skeleton_path not in skeletons:
            skeletons[skeleton_path] = file_format(skeleton_path).reader(skeleton_path)
        trial = _trial_id(path.stem)
        rate = 120.0  # CMU's rate; AMC files do not record theirs
        if (
            index is not None
            and trial in index.index
            and np.isfinite(index.loc[trial, "frame_rate"])
        ):
            rate = float(index.loc[trial, "frame_rate"])
        out.append((row.reader(path, skeletons[skeleton_path], frame_rate=rate), path))
    return out


def _check_layouts(entries, folder, channel_layouts):
    """Per clip, the index of its channel layout; refuses mixed layouts unless allowed."""
    names = [tuple(m.channel_names) for m, _ in entries]
    layouts = list(dict.fromkeys(names))
    layout = np.array([layouts.index(n) for n in names], dtype=int)
    if len(layouts) > 1 and channel_layouts == "same":
        groups = []
        for k, channels in enumerate(layouts):
            paths = [p.name for (_, p), j in zip(entries, layout) if j == k]
            shown = ", ".join(paths[:3]) + (
                f", ... ({len(paths) - 3} more)" if len(paths) > 3 else ""
            )
            groups.append(
                f"{len(channels)} channels ({channels[0]}, ...) in {len(paths)} files: {shown}"
            )
        raise ValueError(
            f"The files under {folder} have {len(layouts)} different channel layouts, whose clips "
            "do not share features:\n  " + "\n  ".join(groups) + "\nLoad them separately, or "
            "pass channel_layouts='any' (each motion keeps its own skeleton; "
            "VirtualMarkerTransform maps different skeletons onto shared markers)."
        )
    return layout, layouts


def _bunch(entries, root, index, descr, channel_layouts="any"):
    """The Bunch of a list of (motion, path)."""
    layout, layouts = _check_layouts(entries, root, channel_layouts)
    motions = [m for m, _ in entries]
    paths = [p for _, p in entries]
    trials = [_trial_id(p.stem) for p in paths]
    folders = [
        p.parent.relative_to(root).as_posix() if p.parent != root else root.name for p in paths
    ]
    known = [index is not None and t in index.index for t in trials]
    descriptions = [index.loc[t, "description"] if k else "" for t, k in zip(trials, known)]
    labels = [_short_label(d) if k and d else f for d, k, f in zip(descriptions, known, folders)]
    subjects = [t.split("_")[0] if t else f for t, f in zip(trials, folders)]
    target_names, target = np.unique(np.asarray(labels, dtype=object), return_inverse=True)
    subject_names, groups = np.unique(np.asarray(subjects, dtype=object), return_inverse=True)
    rates = {m.frame_rate for m in motions}
    return Bunch(
        motions=motions,
        clips=[m.channels for m in motions],
        skeletons=[m.skeleton for m in motions],
        target=target,
        target_names=target_names,
        groups=groups,
        subject_names=subject_names,
        trials=np.asarray([t or "" for t in trials], dtype=object),
        description=np.asarray(descriptions, dtype=object),
        filenames=np.asarray([str(p) for p in paths], dtype=object),
        frame_rate=rates.pop() if len(rates) == 1 else None,
        layout=layout,
        layout_channels=tuple(layouts),
        DESCR=descr,
    )


def _check_choice(channel_layouts):
    if channel_layouts not in ("same", "any"):
        raise ValueError(f"channel_layouts must be 'same' or 'any'; got {channel_layouts!r}.")


def _check_folder(folder):
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"No folder at {folder}.")
    return folder


_BUNCH_DOC = """
        motions : list of Motion
            Each trial with its own skeleton and frame rate.
        clips : list of ndarray of shape (n_frames_i, n_channels_i)
            The channel arrays (radians, the file's length unit).
        skeletons : list of Skeleton
            Each clip's skeleton.
        target : ndarray of int
            Label index per clip: the CMU description up to its first comma
            or dash when the index knows the trial, else the clip's subfolder.
        target_names : ndarray of str
        groups : ndarray of int
            Subject per clip (the ``NN`` of a CMU ``NN_TT`` file name, else the
            subfolder), for ``GroupKFold``; names in ``subject_names``.
        trials, description, filenames : ndarray of str
            CMU trial id (or ""), description from the index (or ""), file.
        frame_rate : float or None
            The clips' frame rate when they share one, else None.
        layout : ndarray of int
            Per clip, its channel layout: an index into ``layout_channels``,
            the distinct tuples of channel names (one when every clip has the
            same channels)."""


def load_cmu_asfamc(folder, index=None, *, subjects=None, verbose=0):
    """Load CMU-style Acclaim data: one folder per subject with ``NN.asf`` and ``NN_TT.amc``.

    Parameters
    ----------
    folder : str or path-like
        Holds one subfolder per subject (``01/01.asf``, ``01/01_01.amc``, ...),
        as ``../shared/data/cmu-asfamc`` or the cache of :func:`fetch_cmu_mocap`.
    index : str, path-like or DataFrame, default=None
        The CMU index CSV (:func:`read_cmu_index`) for descriptions and frame
        rates; without it every trial is taken at 120 Hz.
    subjects : list of int, default=None
        Only these subjects.
    verbose : int, default=0
        Report progress over the files on standard error when >= 1.

    Returns
    -------
    data : Bunch
        %(bunch)s

    Examples
    --------
    >>> from skmotion.datasets import load_cmu_asfamc
    >>> shared = "../shared/data/"
    >>> data = load_cmu_asfamc(shared + "cmu-asfamc", shared + "cmu-index.csv")  # doctest: +SKIP
    >>> data.description[data.trials == "02_03"]  # doctest: +SKIP
    array(['run/jog'], dtype=object)
    """
    folder = _check_folder(folder)
    index = _as_index(index)
    wanted = None if subjects is None else {int(s) for s in np.atleast_1d(subjects)}
    files = []
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):
        if wanted is None or (sub.name.isdigit() and int(sub.name) in wanted):
            files += _find_files(sub, (".amc",))
    entries = _read_files(files, index, {}, verbose)
    if not entries:
        raise FileNotFoundError(f"No .amc trials under {folder} (expected one folder per subject).")
    return _bunch(
        entries, folder, index, "CMU Graphics Lab Motion Capture Database, Acclaim ASF/AMC."
    )


def load_bvh_folder(folder, *, up_axis=None, channel_layouts="same", verbose=0):
    """Load every ``.bvh`` file under a folder (recursively), labelled by subfolder.

    Parameters
    ----------
    folder : str or path-like
        The folder; ``folder/walk/a.bvh`` gets the label ``"walk"``.
    up_axis : {"x", "y", "z"}, default=None
        Passed to :func:`skmotion.io.read_bvh` (None: detected per file).
    channel_layouts : {"same", "any"}, default="same"
        ``"same"`` refuses files whose channels differ (say 306 and 303
        channels), naming the files of each layout; ``"any"`` loads them all
        (``layout`` tells each clip's).
    verbose : int, default=0
        Report progress over the files on standard error when >= 1.

    Returns
    -------
    data : Bunch
        %(bunch)s

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> from skmotion.datasets import load_bvh_folder, make_motions
    >>> from skmotion.io import as_motions, write_bvh
    >>> data = make_motions(n_clips_per_class=2, classes=["walk", "wave"], random_state=0)
    >>> with tempfile.TemporaryDirectory() as home:
    ...     for k, motion in enumerate(as_motions(data.clips, data.skeletons, data.frame_rate)):
    ...         label = data.target_names[data.target[k]]
    ...         (pathlib.Path(home) / label).mkdir(exist_ok=True)
    ...         write_bvh(motion, pathlib.Path(home) / label / f"{k}.bvh")
    ...     loaded = load_bvh_folder(home)
    >>> loaded.target_names.tolist(), loaded.target.tolist(), loaded.frame_rate
    (['walk', 'wave'], [0, 0, 1, 1], 30.0)
    """
    folder = _check_folder(folder)
    _check_choice(channel_layouts)
    files = _find_files(folder, (".bvh",))
    if not files:
        raise FileNotFoundError(f"No .bvh files under {folder}.")
    entries = _read_files(files, None, {".bvh": {"up_axis": up_axis}}, verbose)
    return _bunch(entries, folder, None, f"BVH files under {folder}.", channel_layouts)


def load_motion_folder(folder, index=None, *, channel_layouts="any", verbose=0):
    """Load every motion file under a folder: BVH, ASF/AMC subject folders and C3D files.

    The formats are the rows of :data:`skmotion.io.FORMATS` marked
    ``in_folders`` (:func:`skmotion.io.folder_suffixes`); suffixes match in
    any case.

    Parameters
    ----------
    folder : str or path-like
        Searched recursively; a folder holding ``.amc`` files must hold their
        ``.asf`` (``NN.asf``, or a single ``.asf``).
    index : str, path-like or DataFrame, default=None
        A CMU index CSV; by default one at the top of ``folder`` is used when
        present. Trials it knows are labelled by their description.
    channel_layouts : {"any", "same"}, default="any"
        ``"any"`` loads files of different skeletons and formats together
        (``layout`` tells each clip's channel layout; map them onto shared
        virtual markers with VirtualMarkerTransform); ``"same"`` refuses
        them, naming the files of each layout.
    verbose : int, default=0
        Report progress over the files on standard error when >= 1.

    Returns
    -------
    data : Bunch
        %(bunch)s

    Examples
    --------
    >>> from skmotion.datasets import load_motion_folder
    >>> data = load_motion_folder("../shared/data")  # doctest: +SKIP
    >>> data.target_names  # doctest: +SKIP
    """
    folder = _check_folder(folder)
    if index is None:
        index = _find_index(folder)
    index = _as_index(index)
    _check_choice(channel_layouts)
    suffixes = folder_suffixes()
    files = _find_files(folder, suffixes)
    if not files:
        raise FileNotFoundError(f"No motion files ({', '.join(suffixes)}) under {folder}.")
    entries = _read_files(files, index, {}, verbose)
    return _bunch(entries, folder, index, f"Motion files under {folder}.", channel_layouts)


for _func in (load_cmu_asfamc, load_bvh_folder, load_motion_folder):
    _func.__doc__ = _func.__doc__ % {"bunch": _BUNCH_DOC.strip()}
