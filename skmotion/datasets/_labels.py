"""Labels of motion files: a labels file the user writes; a check of labels taken from folders.

A folder of recordings is most often laid out by person (``S01/trial1.bvh``). Labels
taken from folder names are then the people, and a classifier that tells them apart
scores well while recognising no motion. :func:`subject_confound` names that case,
so that the loaders warn and the demo refuses to call such a score recognition.
"""

import csv
import re
from collections import defaultdict
from pathlib import Path

__all__ = ["match_labels", "read_labels", "subject_confound", "subject_level"]

_KEY_COLUMNS = ("path", "file", "filename", "stem", "name")
# Folder names that look like people: "S01", "sub-02", "subject_3", "P4", "actor05", "07".
_SUBJECT_NAME = re.compile(
    r"^(s|sub|subj|subject|p|participant|person|actor|user|performer)?[-_ ]?\d+$", re.I
)


def read_labels(path):
    """Read a labels file: which file holds which motion, and optionally who performs it.

    The file is a CSV with a header. One column names the file (``path``,
    ``file``, ``filename``, ``stem`` or ``name``: a path relative to the data
    folder, a file name, or a name without its suffix), one holds the
    ``label``, and an optional ``subject`` column the person.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    table : dict of str to (str, str or None)
        File key -> (label, subject or None).

    Raises
    ------
    ValueError
        A missing column, an empty label or a file named twice, with its line.

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.datasets import read_labels
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "labels.csv")
    ...     _ = open(path, "w").write("path,label,subject\\nS01/t1.bvh,walk,S01\\nt2,run,S02\\n")
    ...     table = read_labels(path)
    >>> table["S01/t1.bvh"], table["t2"]
    (('walk', 'S01'), ('run', 'S02'))
    """
    with open(path, newline="", encoding="utf-8-sig") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise ValueError(f"{path}: empty labels file (expected a header: path,label[,subject]).")
    header = [h.strip().lower() for h in rows[0]]
    key = next((c for c in _KEY_COLUMNS if c in header), None)
    if key is None or "label" not in header:
        raise ValueError(
            f"{path}, line 1: the header {rows[0]} lacks "
            + ("a file column (path, file, stem or name)" if key is None else "a 'label' column")
            + "; expected for example: path,label,subject"
        )
    k, j = header.index(key), header.index("label")
    s = header.index("subject") if "subject" in header else None
    table = {}
    for number, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) < len(header):
            raise ValueError(f"{path}, line {number}: {len(row)} values, expected {len(header)}.")
        name, label = row[k].strip().replace("\\", "/"), row[j].strip()
        if not name or not label:
            raise ValueError(f"{path}, line {number}: an empty {'file' if not name else 'label'}.")
        if name in table:
            raise ValueError(f"{path}, line {number}: {name!r} is labelled twice.")
        table[name] = (label, (row[s].strip() or None) if s is not None else None)
    return table


def _keys(path, root):
    """The names a labels file may give a file: relative path (with, without suffix), name, stem."""
    relative = Path(path).relative_to(root).as_posix()
    return (relative, relative.rsplit(".", 1)[0], Path(path).name, Path(path).stem)


def match_labels(paths, root, table, *, where="the labels file"):
    """Each file's (label, subject or None) from a labels table; every file must be there.

    Parameters
    ----------
    paths : list of path-like
        Files under ``root``.
    root : path-like
    table : dict
        From :func:`read_labels`.
    where : str
        How the error names the table.

    Returns
    -------
    labels, subjects : lists
        Per file; a subject is None where the table gives none.

    Raises
    ------
    ValueError
        Files the table does not name (all of them listed, up to ten).
    """
    root = Path(root)
    found = [next((table[k] for k in _keys(p, root) if k in table), None) for p in paths]
    missing = [Path(p).relative_to(root).as_posix() for p, f in zip(paths, found) if f is None]
    if missing:
        shown = ", ".join(missing[:10]) + (
            f", ... ({len(missing) - 10} more)" * (len(missing) > 10)
        )
        raise ValueError(
            f"{where} does not label {len(missing)} of {len(paths)} files: {shown}. Add a line "
            "per file (path relative to the folder, file name, or name without suffix)."
        )
    return [f[0] for f in found], [f[1] for f in found]


def subject_level(paths, root):
    """The folder level (0 is the top) whose names all look like people (``S01``, ``07``), or None.

    Parameters
    ----------
    paths : list of path-like
    root : path-like

    Returns
    -------
    level : int or None

    Examples
    --------
    >>> from skmotion.datasets._labels import subject_level
    >>> subject_level(["d/S01/walk/a.bvh", "d/S02/run/b.bvh"], "d")
    0
    >>> subject_level(["d/walk/a.bvh", "d/run/b.bvh"], "d") is None
    True
    """
    folders = [Path(p).relative_to(root).parts[:-1] for p in paths]
    for level in range(min((len(f) for f in folders), default=0)):
        names = {f[level] for f in folders}
        if len(names) >= 2 and all(_SUBJECT_NAME.match(n) for n in names):
            return level
    return None


def subject_confound(labels, sources, subjects, subjects_known, stems):
    """Why labels taken from folder names may be the people rather than the motions, or None.

    Parameters
    ----------
    labels, sources, subjects, stems : sequences of str
        Per clip: its label, where the label comes from (``"folder name"`` is
        the case checked), its subject, its file name without suffix.
    subjects_known : bool
        Whether the subjects come from elsewhere than the labels' folders (CMU
        trial names, a labels file, a folder level of person-like names).

    Returns
    -------
    reason : str or None
        One clause, None when nothing points to subjects.

    Examples
    --------
    >>> from skmotion.datasets._labels import subject_confound
    >>> subject_confound(["S01", "S02"], ["folder name"] * 2, ["S01", "S02"], False, ["t1", "t1"])
    'the folder names look like people (S01, S02)'
    >>> subject_confound(["walk", "run"], ["folder name"] * 2, ["walk", "run"], False, ["a", "b"])
    """
    folder = [k for k, s in enumerate(sources) if s == "folder name"]
    names = sorted({labels[k] for k in folder})
    if len(names) < 2:
        return None
    if all(_SUBJECT_NAME.match(n) for n in names):
        shown = ", ".join(names[:4]) + (", ..." if len(names) > 4 else "")
        return f"the folder names look like people ({shown})"
    # Same file names in every folder (walk/take1, run/take1) are as common for motion
    # folders as for subject folders, so they are not taken as a sign (``stems`` unused).
    people = defaultdict(set)
    for k in folder:
        people[labels[k]].add(subjects[k])
    if subjects_known and all(len(p) == 1 for p in people.values()):
        pairs = ", ".join(f"{n} = {next(iter(people[n]))}" for n in names[:3])
        return f"each of these labels holds a single subject ({pairs}, ...)"
    return None
