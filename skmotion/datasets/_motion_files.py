"""Loading folders of motion files: the formats of ``skmotion.io.FORMATS`` that folders hold."""

import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.utils import Bunch

from skmotion.datasets._labels import match_labels, read_labels, subject_confound, subject_level
from skmotion.io import FORMATS, file_format, folder_suffixes
from skmotion.utils import progress

__all__ = ["load_bvh_folder", "load_cmu_asfamc", "load_motion_folder", "read_cmu_index"]

#: Keypoint files (joint positions per frame), read from folders with ``layout=``.
KEYPOINT_SUFFIXES = (".npy", ".npz", ".csv", ".txt")
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


def _read_one(row, path, index, options, skeletons):
    """The motion of one file; a skeleton file is read once for all its motions."""
    if row.skeleton_suffix is None:
        return row.reader(path, **options.get(row.suffix, {}))
    skeleton_path = _skeleton_for(path, row.skeleton_suffix)
    if skeleton_path not in skeletons:
        skeletons[skeleton_path] = file_format(skeleton_path).reader(skeleton_path)
    trial = _trial_id(path.stem)
    rate = 120.0  # CMU's rate; AMC files do not record theirs
    if index is not None and trial in index.index and np.isfinite(index.loc[trial, "frame_rate"]):
        rate = float(index.loc[trial, "frame_rate"])
    return row.reader(path, skeletons[skeleton_path], frame_rate=rate)


# What a damaged or unreadable file raises (MotionFileError is a ValueError; a missing
# skeleton an OSError; a missing optional reader an ImportError).
_FILE_ERRORS = (OSError, ValueError, ImportError, EOFError)


def _read_files(files, index, options, verbose, errors="skip"):
    """Every (motion, path) of ``files`` that reads, and (path, reason) of those that do not."""
    skeletons = {}
    out, skipped = [], []
    for row, path in progress(files, verbose=verbose, desc="reading motion files"):
        try:
            out.append((_read_one(row, path, index, options, skeletons), path))
        except _FILE_ERRORS as exc:
            if errors == "raise" or len(files) == 1:
                raise
            skipped.append((str(path), " ".join(str(exc).split()) or type(exc).__name__))
    return out, skipped


def _report_skipped(entries, skipped, folder):
    """A warning naming every skipped file; an error when no file at all could be read."""
    if not skipped:
        return
    listed = "\n  ".join(f"{path}: {reason}" for path, reason in skipped)
    if not entries:
        raise ValueError(
            f"None of the {len(skipped)} motion files under {folder} could be read:\n  {listed}"
        )
    warnings.warn(
        f"Skipped {len(skipped)} of {len(skipped) + len(entries)} motion files under {folder} "
        f"that could not be read (the others are loaded):\n  {listed}",
        UserWarning,
        stacklevel=3,
    )


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


def _folder_of(path, root, level):
    """A file's folder below ``root`` as a label, without the folder level that names people."""
    parts = list(path.parent.relative_to(root).parts)
    if level is not None and len(parts) > 1:
        del parts[level]
    return "/".join(parts) or root.name


def _labels(paths, root, index, table):
    """Per file: label, its source, subject, and whether the subjects come from elsewhere."""
    trials = [_trial_id(p.stem) for p in paths]
    level = subject_level(paths, root)
    known = [index is not None and t in index.index for t in trials]
    descriptions = [index.loc[t, "description"] if k else "" for t, k in zip(trials, known)]
    given = [None] * len(paths)
    if table is not None:
        labels, given = match_labels(paths, root, table)
        sources = ["labels file"] * len(paths)
    else:
        labels = [
            _short_label(d) if d else _folder_of(p, root, level)
            for d, p in zip(descriptions, paths)
        ]
        sources = ["CMU index" if d else "folder name" for d in descriptions]
    subjects, subjects_known = [], level is not None
    for path, trial, subject in zip(paths, trials, given):
        parts = path.parent.relative_to(root).parts
        subjects_known |= subject is not None or trial is not None
        if subject is None and trial is None and level is None:
            subject = parts[0] if parts else root.name  # unknown: the top folder stands in
        subjects.append(subject or (trial.split("_")[0] if trial else parts[level]))
    return labels, sources, subjects, subjects_known, descriptions, trials


def confound_warning(folder, labels, sources, subjects, subjects_known, paths):
    """The loud sentence when folder-name labels look like the subjects, or None."""
    reason = subject_confound(
        labels, sources, subjects, subjects_known, [Path(p).stem for p in paths]
    )
    if reason is None:
        return None
    return (
        f"{folder}: the labels come from folder names, and {reason}. The classes are then "
        "probably the people, and a classifier's score measures telling subjects apart, not "
        "recognising motions. Give the labels in a CSV file (columns path,label[,subject]): "
        "labels= here, --labels on the command line."
    )


def _bunch(entries, root, index, descr, channel_layouts="any", table=None, skipped=()):
    """The Bunch of a list of (motion, path)."""
    layout, layouts = _check_layouts(entries, root, channel_layouts)
    motions = [m for m, _ in entries]
    paths = [p for _, p in entries]
    labels, sources, subjects, subjects_known, descriptions, trials = _labels(
        paths, root, index, table
    )
    warning = confound_warning(root, labels, sources, subjects, subjects_known, paths)
    if warning is not None:
        warnings.warn(warning, UserWarning, stacklevel=3)
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
        label_source=np.asarray(sources, dtype=object),
        label_warning=warning,
        skipped=list(skipped),
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
            The distinct labels, sorted.
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
            same channels).
        label_source : ndarray of str
            Per clip: ``"labels file"``, ``"CMU index"`` or ``"folder name"``.
        label_warning : str or None
            Why the folder-name labels may be the subjects (also warned).
        skipped : list of (str, str)
            The files that could not be read, and why."""


def load_cmu_asfamc(folder, index=None, *, subjects=None, errors="skip", verbose=0):
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
    errors : {"skip", "raise"}, default="skip"
        Skip a file that cannot be read (with a warning naming it), or raise.
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
    if not files:
        raise FileNotFoundError(f"No .amc trials under {folder} (expected one folder per subject).")
    entries, skipped = _read_files(files, index, {}, verbose, errors)
    _report_skipped(entries, skipped, folder)
    descr = "CMU Graphics Lab Motion Capture Database, Acclaim ASF/AMC."
    return _bunch(entries, folder, index, descr, skipped=skipped)


def load_bvh_folder(folder, *, labels=None, up_axis=None, channel_layouts="same", verbose=0):
    """Load every ``.bvh`` file under a folder (recursively), labelled by subfolder.

    Parameters
    ----------
    folder : str or path-like
        The folder; ``folder/walk/a.bvh`` gets the label ``"walk"``. A file
        that cannot be read is skipped with a warning naming it.
    labels : str, path-like or dict, default=None
        A labels file (:func:`read_labels`) instead of the folder names; the
        loader warns when folder names look like subjects (see
        :func:`load_motion_folder`).
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
    table = read_labels(labels) if isinstance(labels, (str, Path)) else labels
    entries, skipped = _read_files(files, None, {".bvh": {"up_axis": up_axis}}, verbose)
    _report_skipped(entries, skipped, folder)
    descr = f"BVH files under {folder}."
    return _bunch(entries, folder, None, descr, channel_layouts, table, skipped)


def load_motion_folder(
    folder,
    index=None,
    *,
    labels=None,
    layout=None,
    frame_rate=None,
    channel_layouts="any",
    errors="skip",
    verbose=0,
):
    """Load every motion file under a folder: BVH, ASF/AMC subject folders, C3D, keypoint files.

    The formats are the rows of :data:`skmotion.io.FORMATS` marked
    ``in_folders`` (:func:`skmotion.io.folder_suffixes`); suffixes match in
    any case. With
    ``layout=``, keypoint files (``.npy``, ``.npz``, ``.csv``, ``.txt``:
    joint positions per frame, see :func:`skmotion.io.read_keypoints`) are
    read too, in that layout's joint order, and the order is checked against
    the data (:func:`skmotion.kinematics.check_layout`): a warning names the
    joints that do not fit.

    A file that cannot be read is skipped with a warning naming it and the
    reason; the others load. Labels come from a labels file when given, else
    from the CMU index for CMU trials, else from the folder names; when those
    folder names look like the subjects, a warning says so (see Notes).

    Parameters
    ----------
    folder : str or path-like
        Searched recursively; a folder holding ``.amc`` files must hold their
        ``.asf`` (``NN.asf``, or a single ``.asf``).
    index : str, path-like or DataFrame, default=None
        A CMU index CSV; by default one at the top of ``folder`` is used when
        present. Trials it knows are labelled by their description.
    labels : str, path-like or dict, default=None
        A labels file (:func:`read_labels`: CSV columns ``path``, ``label``
        and optionally ``subject``) or its table; every file must be in it.
    layout : str or Layout, default=None
        The joint order of the folder's keypoint files (a name of
        :data:`skmotion.kinematics.LAYOUTS` or a Layout). None reads no
        keypoint files.
    frame_rate : float, default=None
        Frames per second of the keypoint files (they do not record it);
        needed with ``layout``.
    channel_layouts : {"any", "same"}, default="any"
        ``"any"`` loads files of different skeletons and formats together
        (``layout`` tells each clip's channel layout; map them onto shared
        virtual markers with VirtualMarkerTransform); ``"same"`` refuses
        them, naming the files of each layout.
    errors : {"skip", "raise"}, default="skip"
        ``"skip"`` leaves out a file that cannot be read (listed in
        ``skipped`` and in a warning); ``"raise"`` stops at it. A folder
        where no file reads is an error either way.
    verbose : int, default=0
        Report progress over the files on standard error when >= 1.

    Returns
    -------
    data : Bunch
        %(bunch)s

    Notes
    -----
    Recordings are most often filed by person (``S01/trial1.bvh``). Labels
    taken from such folders are the people, and a classifier scores well by
    telling them apart. The loader warns when the folder-name labels look
    like people (``S01``, ``sub-2``, ``07``), when the subjects are known
    (CMU trial names, a folder level of person-like names) and each label
    holds one of them. A folder level of person-like names (``S01/walk/a.bvh``) gives
    the subjects, and the label is the rest of the path (``walk``).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from skmotion.datasets import load_motion_folder, make_position_motions
    >>> data = make_position_motions("kinect_v1", n_clips_per_class=2, classes=["walk", "wave"],
    ...                              random_state=0)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     with open(os.path.join(folder, "labels.csv"), "w") as handle:
    ...         _ = handle.write("file,label\\n")
    ...         for k, clip in enumerate(data.clips):
    ...             np.save(os.path.join(folder, f"take{k}.npy"), clip)
    ...             _ = handle.write(f"take{k},{data.target_names[data.target[k]]}\\n")
    ...     loaded = load_motion_folder(folder, labels=os.path.join(folder, "labels.csv"),
    ...                                 layout="kinect_v1", frame_rate=30)
    >>> loaded.target_names.tolist(), loaded.target.tolist(), loaded.clips[0].shape
    (['walk', 'wave'], [0, 0, 1, 1], (88, 60))
    """
    folder = _check_folder(folder)
    if index is None:
        index = _find_index(folder)
    not_data = {Path(p).resolve() for p in (index, labels) if isinstance(p, (str, Path))}
    index = _as_index(index)
    table = read_labels(labels) if isinstance(labels, (str, Path)) else labels
    _check_choice(channel_layouts)
    if errors not in ("skip", "raise"):
        raise ValueError(f"errors must be 'skip' or 'raise'; got {errors!r}.")
    suffixes = folder_suffixes()
    options = {}
    if layout is not None:
        if frame_rate is None:
            raise ValueError("Keypoint files do not record their frame rate: pass frame_rate=.")
        suffixes += KEYPOINT_SUFFIXES
        options = {s: {"layout": layout, "frame_rate": frame_rate} for s in KEYPOINT_SUFFIXES}
    files = [(r, p) for r, p in _find_files(folder, suffixes) if p.resolve() not in not_data]
    if not files:
        raise FileNotFoundError(f"No motion files ({', '.join(suffixes)}) under {folder}.")
    entries, skipped = _read_files(files, index, options, verbose, errors)
    _report_skipped(entries, skipped, folder)
    data = _bunch(
        entries, folder, index, f"Motion files under {folder}.", channel_layouts, table, skipped
    )
    if layout is not None:
        _warn_layout(data, layout, folder)
    return data


def _warn_layout(data, layout, folder):
    """A warning naming the joints when the keypoint clips do not fit ``layout``'s order."""
    from skmotion.kinematics import check_layout, get_layout

    layout = get_layout(layout)
    width = layout.n_joints * layout.dim
    clips = [m.channels for m in data.motions if m.skeleton is None and m.n_channels == width]
    problems = check_layout(clips, layout) if clips else []
    if problems:
        warnings.warn(
            f"{folder}: the data do not fit the joint order of layout {layout.name!r}: "
            + "; ".join(problems)
            + ". Is the order the one your tracker writes its joints in?",
            UserWarning,
            stacklevel=3,
        )


for _func in (load_cmu_asfamc, load_bvh_folder, load_motion_folder):
    _func.__doc__ = _func.__doc__ % {"bunch": _BUNCH_DOC.strip()}
