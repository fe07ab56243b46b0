"""Demo section (``skmotion demo --data FOLDER``): real motion files instead of synthetic data.

Labels come from a labels file when one is given (``--labels``). Otherwise from the CMU
index wherever a file's name is a CMU trial (``02_01.amc``, ``07_05.bvh``, at any depth):
the trial's description mapped to a motion class by the keyword table of
:mod:`skmotion.datasets._cmu_labels`. Other files are labelled by a keyword in their own
name, and only then by their folder's name; the report counts each. Where folder-name
labels look like the subjects (:func:`skmotion.datasets._labels.subject_confound`), no
classifier is scored: its accuracy would measure telling people apart.
"""

import inspect
import re
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline
from sklearn.utils import Bunch

from skmotion._demo._split import Evaluation, choose_evaluation
from skmotion._demo.data import body_figures
from skmotion.datasets import (
    cmu_motion_class,
    load_motion_folder,
    motion_class_of_name,
    read_cmu_index,
    read_labels,
)
from skmotion.datasets._labels import match_labels, subject_confound, subject_level
from skmotion.io import file_format, folder_suffixes, read_ts
from skmotion.kinematics import LAYOUTS, get_layout
from skmotion.preprocessing import FlattenClips, ResampleClips, resample_clip, to_markers

TITLE = "Data: motion files"

_TRIAL = re.compile(r"^(\d+)_(\d+)$")
_INDEX_COLUMNS = ("Subject", "Trial #", "Motion Description")


class DemoDataError(ValueError):
    """The demo's folder cannot be used (no such folder, no motion files, a bad file)."""


def find_cmu_index(folder):
    """A CMU index CSV in ``folder`` or the nearest folder above it, or None."""
    for place in (Path(folder).resolve(), *Path(folder).resolve().parents):
        for path in sorted(place.glob("*.csv")):
            with path.open(errors="replace") as handle:
                header = handle.readline()
            if all(column in header for column in _INDEX_COLUMNS):
                return path
    return None


def label_clips(filenames, root, index, table=None):
    """Label, label source and subject of every file.

    Returns
    -------
    labels, sources, subjects : lists of str
        ``sources`` holds "labels file", "CMU index", "file name" or "folder name" per file.
    """
    level = subject_level(filenames, root)
    given_labels, given_subjects = (
        match_labels(filenames, root, table, where="--labels") if table else (None, None)
    )
    labels, sources, subjects = [], [], []
    for k, name in enumerate(filenames):
        path = Path(name)
        parts = path.parent.relative_to(root).parts
        folder = "/".join(parts) or root.name
        match = _TRIAL.match(path.stem)
        trial = f"{int(match.group(1)):02d}_{int(match.group(2)):02d}" if match else None
        subject = given_subjects[k] if table else None
        if subject is None:
            subject = (
                trial.split("_")[0] if trial else parts[level] if level is not None else folder
            )
        subjects.append(subject)
        if table:
            labels.append(given_labels[k])
            sources.append("labels file")
        elif index is not None and trial in index.index:
            labels.append(cmu_motion_class(index.loc[trial, "description"]))
            sources.append("CMU index")
        elif motion_class_of_name(path.stem):
            labels.append(motion_class_of_name(path.stem))
            sources.append("file name")
        else:
            labels.append(path.parent.name if path.parent != root else root.name)
            sources.append("folder name")
    return labels, sources, subjects


def subjects_known(filenames, root, table):
    """Whether the subjects come from elsewhere than the label folders (file, CMU name, level)."""
    if table and any(subject for _, subject in table.values()):
        return True
    if subject_level(filenames, root) is not None:
        return True
    return any(_TRIAL.match(Path(f).stem) for f in filenames)


def confound_refusal(filenames, root, labels, sources, subjects, table):
    """The sentence refusing to score folder-name labels that look like subjects, or None."""
    stems = [Path(f).stem for f in filenames]
    known = subjects_known(filenames, root, table)
    reason = subject_confound(labels, sources, subjects, known, stems)
    if reason is None:
        return None
    return (
        f"NOT EVALUATED: the labels come from folder names, and {reason}; the classes are then "
        "probably the subjects, and an accuracy would measure telling people apart, not "
        "recognising motions. Give the labels with --labels FILE (a CSV with columns "
        "path,label and optionally subject; path relative to the folder, or a file name)"
    )


def _load(folder, index_path, verbose, labels_path=None, layout=None, frame_rate=None):
    """The loader's Bunch and its warnings, with a one-line DemoDataError for what stops it."""
    folder = Path(folder)
    if not folder.exists():
        raise DemoDataError(f"no folder at {folder}")
    if not folder.is_dir():
        raise DemoDataError(f"{folder} is a file, not a folder of motion files")
    options = {"index": index_path}
    if "verbose" in inspect.signature(load_motion_folder).parameters:
        options["verbose"] = verbose  # progress of the loader, where it offers it
    if layout is not None:
        options.update(layout=layout, frame_rate=frame_rate)
    if labels_path is not None:
        options["labels"] = labels_path  # so that the loader reads no labels file as keypoints
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            data = load_motion_folder(folder, **options)
    except (OSError, ValueError) as exc:
        message = " ".join(str(exc).split())
        raise DemoDataError(f"{folder}: {message}") from None
    # The demo decides on labels itself; it reports the skipped files and the layout check.
    notes = [
        str(w.message) for w in caught if "the labels come from folder names" not in str(w.message)
    ]
    return data, notes


def to_rate(clip, frame_rate, target_rate):
    """A clip resampled from ``frame_rate`` to ``target_rate`` Hz (linear, same duration)."""
    if frame_rate == target_rate:
        return clip
    n_out = int(np.floor((len(clip) - 1) * target_rate / frame_rate + 1e-9)) + 1
    return resample_clip(clip, np.arange(n_out) * frame_rate / target_rate)


def _unwrapped(motion):
    """Channels with rotation angles unwrapped in time: interpolation never crosses a +-pi jump."""
    channels = motion.channels.copy()
    rotations = np.array([name.endswith("rotation") for name in motion.channel_names], dtype=bool)
    channels[:, rotations] = np.unwrap(channels[:, rotations], axis=0)
    return channels


def _label_lines(sources, index_path, labels_path=None):
    if labels_path is not None:
        return [f"labels: all {len(sources)} clips from the labels file {labels_path}"]
    counts = {k: sources.count(k) for k in ("CMU index", "file name", "folder name")}
    index_text = f" ({index_path})" if index_path else " (none found in or above the folder)"
    return [
        f"labels: {counts['CMU index']} clips from the CMU index{index_text}, its descriptions "
        "mapped to motion classes by keyword (skmotion.datasets.CMU_MOTION_CLASSES); "
        f"{counts['file name']} from a keyword in the file name; {counts['folder name']} from the "
        "folder name (fallback)"
    ]


def matching_layout(motion):
    """The named layout whose joints are the position motion's markers, in order, or None."""
    for name in LAYOUTS:
        layout = get_layout(name)
        if tuple(layout.joints) == tuple(motion.marker_names) and layout.dim == 3:
            return layout
    return None


def _figure_lines(context, motions, filenames, labels):
    """Stick figures of the folder's first clip, at its own frame rate and skeleton (or layout)."""
    motion = motions[0]
    what = f"{Path(filenames[0]).name} ({labels[0]})"
    body = motion.skeleton if motion.skeleton is not None else context.data.layout
    if body is None:
        return [
            "figures: skipped (position clips whose joints match no named layout: "
            "skmotion.kinematics.LAYOUTS, or a Layout of your own, says how to join them)"
        ]
    return body_figures(context, motion.channels, body, motion.frame_rate, what)


def _keep_skeleton_motions(data):
    """Leave out position files among skeleton files (no shared features), saying which."""
    kept = [k for k, m in enumerate(data.motions) if m.skeleton is not None]
    if not 0 < len(kept) < len(data.motions):
        return []
    left = [Path(f).name for k, f in enumerate(data.filenames) if k not in set(kept)]
    data.motions = [data.motions[k] for k in kept]
    data.skeletons = [data.skeletons[k] for k in kept]
    data.filenames = data.filenames[kept]
    return [
        f"left out {len(left)} files of marker or joint positions among the skeleton files (the "
        f"skeletons' virtual markers and the files' markers share no features): {', '.join(left)}"
    ]


def _series_folder(folder):
    """The ``.ts`` files under ``folder`` when it holds no motion file, else None."""
    folder = Path(folder)
    if not folder.is_dir():
        return None
    files = sorted(p for p in folder.rglob("*") if p.is_file())
    motion = set(folder_suffixes())
    if any(p.suffix.lower() in motion for p in files):
        return None
    return [p for p in files if p.suffix.lower() == ".ts"] or None


def _run_series(context, files):
    """The demo's data from UEA/sktime ``.ts`` files: labelled series, no body, no subjects."""
    clips, labels, sources = [], [], []
    for path in files:
        try:
            series, named = read_ts(path)
        except (OSError, ValueError) as exc:
            raise DemoDataError(" ".join(str(exc).split())) from None
        if named is None:
            raise DemoDataError(f"{path}: the series have no class labels (@classLabel false)")
        clips += [np.asarray(c, dtype=float) for c in series]
        labels += [str(v) for v in named]
        sources += [path.name] * len(series)
    widths = {}
    for clip, source in zip(clips, sources):
        widths.setdefault(clip.shape[1], source)
    if len(widths) > 1:
        raise DemoDataError(
            f"{context.data_folder}: the .ts files hold series of different dimensions ("
            + ", ".join(f"{w} in {name}" for w, name in widths.items())
            + "): give a folder of one data set"
        )
    target_names, target = np.unique(np.asarray(labels, dtype=object), return_inverse=True)
    # .ts files record no performer: one unknown subject, so no subject-wise split is claimed.
    groups = np.zeros(len(clips), dtype=int)
    subject_names = np.asarray(["(unknown)"], dtype=object)
    context.data = Bunch(
        clips=clips, target=target, target_names=target_names, groups=groups,
        subject_names=subject_names, frame_rate=float(getattr(context, "frame_rate", 30.0)),
        motions=None, skeletons=[None] * len(clips), skeleton=None, layout=None, kind="series",
        feature_names=[f"dim_{k}" for k in range(clips[0].shape[1])],
        filenames=np.asarray(sources, dtype=object), label_sources=["file"] * len(clips),
        DESCR=f"Labelled time series of {', '.join(p.name for p in files)}.",
    )  # fmt: skip
    evaluation = choose_evaluation(
        target_names[target], groups, subject_names, random_state=context.random_state
    )
    context.evaluation = evaluation
    lengths = np.array([len(c) for c in clips])
    lines = [
        f"{context.data_folder}: {len(clips)} labelled series in {len(files)} .ts files "
        f"({', '.join(p.name for p in files)}), the files' train/test split pooled",
        f"channels: {clips[0].shape[1]} dimensions (time series: no body, so the body figures, "
        "virtual markers and planning are not run); length "
        f"min {lengths.min()}, median {int(np.median(lengths))}, max {lengths.max()} frames",
        "classes ("
        + f"{len(target_names)}): "
        + ", ".join(f"{n} {c}" for n, c in zip(target_names, np.bincount(target))),
        "subjects: not recorded in .ts files",
        f"evaluation: {evaluation.reason}",
    ]
    if evaluation.kind is None:
        return lines
    baseline = make_pipeline(ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1))
    scores = evaluation.scores(baseline, clips, target, verbose=context.verbose)
    context.baseline_accuracy = scores.mean()
    return lines + [
        f"baseline, 1-NN on resampled clips, {evaluation.name}: "
        f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}"
    ]


def run(context):
    series = _series_folder(context.data_folder)
    if series is not None and getattr(context, "layout", None) is None:
        return _run_series(context, series)
    rate = float(getattr(context, "frame_rate", None) or 30.0)
    verbose = getattr(context, "verbose", 0)
    index_path = getattr(context, "index", None) or find_cmu_index(context.data_folder)
    labels_path, layout = getattr(context, "labels", None), getattr(context, "layout", None)
    try:
        table = read_labels(labels_path) if labels_path else None
    except (OSError, ValueError) as exc:
        raise DemoDataError(f"--labels {labels_path}: {exc}") from None
    data, notes = _load(context.data_folder, index_path, verbose, labels_path, layout, rate)
    notes += _keep_skeleton_motions(data)
    index = read_cmu_index(index_path) if index_path else None
    root = Path(context.data_folder).resolve()
    files = [Path(f).resolve() for f in data.filenames]
    try:
        labels, sources, subjects = label_clips(files, root, index, table)
    except ValueError as exc:
        raise DemoDataError(str(exc)) from None
    refusal = confound_refusal(files, root, labels, sources, subjects, table)
    target_names, target = np.unique(np.asarray(labels, dtype=object), return_inverse=True)
    subject_names, groups = np.unique(np.asarray(subjects, dtype=object), return_inverse=True)
    motions = data.motions
    layouts = {tuple(m.channel_names) for m in motions}
    position_layout = None
    if all(m.skeleton is None for m in motions):
        # Joint positions (C3D, keypoint files): no skeleton; a known layout names the body.
        position_layout = matching_layout(motions[0]) if len(layouts) == 1 else None
        kind = "joint positions" + (
            f" (the {position_layout.name} layout)" if position_layout else " (no known layout)"
        )
        clips = [to_rate(m.channels, m.frame_rate, rate) for m in motions]
        feature_names = list(motions[0].channel_names)
        skeleton = None
    elif len(layouts) == 1:
        kind = "joint angles"
        clips = [to_rate(_unwrapped(m), m.frame_rate, rate) for m in motions]
        feature_names = list(motions[0].channel_names)
        skeleton = motions[0].skeleton
    else:
        # Different skeletons share no channels: their virtual markers share one feature space.
        kind = "virtual markers (the files hold several skeletons)"
        marker_clips, names = to_markers(motions)
        clips = [to_rate(c, m.frame_rate, rate) for c, m in zip(marker_clips, motions)]
        feature_names = list(names)
        skeleton = None
    context.data = Bunch(
        clips=clips,
        target=target,
        target_names=target_names,
        groups=groups,
        subject_names=subject_names,
        frame_rate=rate,
        motions=motions,
        skeletons=data.skeletons,
        skeleton=skeleton,
        layout=position_layout,
        feature_names=feature_names,
        filenames=data.filenames,
        label_sources=sources,
        DESCR=data.DESCR,
    )
    evaluation = choose_evaluation(
        target_names[target], groups, subject_names, random_state=context.random_state
    )
    if refusal is not None:
        evaluation = Evaluation(None, None, evaluation.clips, refusal, groups, subject_names)
    context.evaluation = evaluation
    lengths = np.array([len(c) for c in clips])
    rates = sorted({m.frame_rate for m in motions})
    formats = Counter(file_format(f).name for f in data.filenames)
    rate_text = ", ".join(f"{r:g}" for r in rates)
    n_skeletons = len({m.skeleton for m in motions} - {None})
    lines = [
        f"{context.data_folder}: {len(motions)} clips ("
        + ", ".join(f"{n} {name}" for name, n in formats.items())
        + f"), {n_skeletons} skeletons, recorded at {rate_text} Hz",
        f"resampled to {rate:g} Hz: {lengths.sum():,} frames ({lengths.sum() / rate:.1f} s); "
        f"clip length min {lengths.min()}, median {int(np.median(lengths))}, max {lengths.max()}",
        f"channels: {len(feature_names)} {kind}",
        *_label_lines(sources, index_path, labels_path),
        f"classes ({len(target_names)}): "
        + ", ".join(
            f"{name} {n} ({len(np.unique(groups[target == k]))} subj.)"
            for k, (name, n) in enumerate(zip(target_names, np.bincount(target)))
        ),
        f"subjects ({len(subject_names)}): "
        + ", ".join(f"{name} {n}" for name, n in zip(subject_names, np.bincount(groups))),
        f"evaluation: {evaluation.reason}",
    ]
    lines[1:1] = [f"warning: {' '.join(note.split())}" for note in notes]
    if evaluation.kind is None:
        lines.append("baseline: not run (no split can evaluate a classifier)")
        return lines + _figure_lines(context, motions, data.filenames, target_names[target])
    baseline = make_pipeline(ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1))
    scores = evaluation.scores(baseline, clips, target, verbose=verbose, desc="baseline CV")
    context.baseline_accuracy = scores.mean()
    lines.append(
        f"baseline, 1-NN on resampled clips, {evaluation.name}: "
        f"accuracy {scores.mean():.3f} +/- {scores.std():.3f}"
    )
    return lines + _figure_lines(context, motions, data.filenames, target_names[target])
