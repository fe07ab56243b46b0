"""Loading datasets of the UEA multivariate time-series archive from ``.ts`` files."""

from pathlib import Path

import numpy as np
from sklearn.utils import Bunch

from skmotion.datasets._home import get_data_home
from skmotion.io import read_ts

__all__ = ["load_uea"]

_SUBSETS = ("train", "test", "all")


def load_uea(name_or_path, *, subset="all", data_home=None):
    r"""Load a UEA/UCR dataset (BasicMotions, JapaneseVowels, ...) from ``.ts`` files.

    Nothing is downloaded: the files ``<name>_TRAIN.ts`` and ``<name>_TEST.ts``
    must be in ``data_home`` (or its ``uea`` subfolder), or a single ``.ts``
    file is given by path.

    Parameters
    ----------
    name_or_path : str or path-like
        A dataset name, or the path of one ``.ts`` file.
    subset : {"train", "test", "all"}, default="all"
        Which split to return; ``"all"`` is train then test, with ``subset``
        telling them apart. Ignored for a single file.
    data_home : str or path-like, default=None
        Folder holding the files; see :func:`get_data_home`.

    Returns
    -------
    data : Bunch
        clips : list of ndarray of shape (n_frames_i, n_dimensions)
            One clip per series.
        target : ndarray of str
            The class label of each clip.
        target_names : ndarray of str
            The sorted distinct labels.
        subset : ndarray of str
            ``"train"`` or ``"test"`` per clip.
        name : str
            The data set's name.
        frame_rate : None
            The archive does not record sampling rates.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from skmotion.datasets import load_uea
    >>> header = "@problemName Toy\n@dimensions 1\n@classLabel true up down\n@data\n"
    >>> with tempfile.TemporaryDirectory() as home:
    ...     for split, rows in [("TRAIN", "1,2,3:up\n3,2,1:down\n"), ("TEST", "1,2:up\n")]:
    ...         _ = (pathlib.Path(home) / f"Toy_{split}.ts").write_text(header + rows)
    ...     data = load_uea("Toy", data_home=home)
    >>> len(data.clips), data.target.tolist(), data.subset.tolist()
    (3, ['up', 'down', 'up'], ['train', 'train', 'test'])
    """
    if subset not in _SUBSETS:
        raise ValueError(f"subset must be one of {_SUBSETS}, got {subset!r}.")
    path = Path(name_or_path)
    if path.suffix == ".ts":
        if not path.is_file():
            raise FileNotFoundError(f"No .ts file at {path}.")
        files = {"file": path}
        name = path.stem
    else:
        name = str(name_or_path)
        home = get_data_home(data_home)
        folder = next((f for f in (home, home / "uea") if (f / f"{name}_TRAIN.ts").is_file()), None)
        if folder is None:
            raise FileNotFoundError(
                f"Dataset {name!r} not found: expected {name}_TRAIN.ts and {name}_TEST.ts in "
                f"{home} or {home / 'uea'} (skmotion does not download UEA data)."
            )
        wanted = ("train", "test") if subset == "all" else (subset,)
        files = {s: folder / f"{name}_{s.upper()}.ts" for s in wanted}
    clips, target, parts = [], [], []
    for part, file in files.items():
        part_clips, labels = read_ts(file)
        if labels is None:
            raise ValueError(
                f"{file} has no class labels; load_uea needs a classification dataset."
            )
        clips += part_clips
        target.append(labels)
        parts += [part] * len(part_clips)
    target = np.concatenate(target)
    return Bunch(
        clips=clips,
        target=target,
        target_names=np.unique(target),
        subset=np.asarray(parts),
        name=name,
        frame_rate=None,
    )
