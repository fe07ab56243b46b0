"""The table of motion file formats: suffix -> reader, what the file holds, the extra it needs.

``skmotion info``, the folder loaders of :mod:`skmotion.datasets` and the
command line read this table; adding a format is adding one row.
"""

import importlib
from dataclasses import dataclass
from pathlib import Path

__all__ = ["FORMATS", "FileFormat", "file_format", "folder_suffixes", "formats_help"]

KINDS = ("angles", "positions", "skeleton", "series")


@dataclass(frozen=True)
class FileFormat:
    """One row of the table of file formats.

    Parameters
    ----------
    suffix : str
        The file name's ending, lower case with its dot (``".bvh"``).
    name : str
        The format's name as ``skmotion info`` prints it.
    kind : {"angles", "positions", "skeleton", "series"}
        What a file holds: joint angles with a skeleton (a :class:`Motion`),
        point positions (a position :class:`Motion`), a skeleton only, or
        labelled time series.
    reader_name : str
        Where the public reader lives, ``"module:function"``; the
        :attr:`reader` property imports it on first use, so that reading the
        table (``skmotion --help``) imports no reader and no numpy.
    description : str
        One line for tables and help texts.
    extra : str, default=None
        The optional extra the reader needs (``pip install 'skmotion[c3d]'``).
    skeleton_suffix : str, default=None
        For motions stored apart from their skeleton (AMC): the skeleton
        file's suffix; ``reader(path, skeleton)`` then takes it.
    needs_frame_rate : bool, default=False
        The file does not record its frame rate: ``reader(path,
        frame_rate=...)``.
    in_folders : bool, default=False
        The folder loaders read every such file below a folder (formats
        whose suffix is unambiguous and whose file is one clip).
    """

    suffix: str
    name: str
    kind: str
    reader_name: str
    description: str
    extra: str = None
    skeleton_suffix: str = None
    needs_frame_rate: bool = False
    in_folders: bool = False

    @property
    def reader(self):
        """The public reader, ``reader(path, ...)``."""
        module, name = self.reader_name.split(":")
        return getattr(importlib.import_module(module), name)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"{self.suffix}: kind must be one of {KINDS}; got {self.kind!r}.")
        if not self.suffix.startswith(".") or self.suffix != self.suffix.lower():
            raise ValueError(
                f"suffix must be lower case and start with a dot; got {self.suffix!r}."
            )


#: Every format skmotion reads, in the order tables list them.
FORMATS = (
    FileFormat(
        ".bvh",
        "BVH",
        "angles",
        "skmotion.io._bvh:read_bvh",
        "skeleton and joint angles",
        in_folders=True,
    ),
    FileFormat(
        ".amc",
        "Acclaim motion (AMC)",
        "angles",
        "skmotion.io._amc:read_amc",
        "joint angles of an ASF skeleton (the CMU database)",
        skeleton_suffix=".asf",
        in_folders=True,
    ),
    FileFormat(
        ".asf",
        "Acclaim skeleton (ASF)",
        "skeleton",
        "skmotion.io._asf:read_asf",
        "the skeleton of AMC files",
    ),
    FileFormat(
        ".c3d",
        "C3D",
        "positions",
        "skmotion.io._c3d:read_c3d",
        "optical marker positions with residuals, analog channels, events",
        in_folders=True,
    ),
    FileFormat(
        ".npy",
        "keypoint array",
        "positions",
        "skmotion.io._keypoints:read_keypoints",
        "joint positions per frame",
        needs_frame_rate=True,
    ),
    FileFormat(
        ".npz",
        "keypoint arrays",
        "positions",
        "skmotion.io._keypoints:read_keypoints",
        "joint positions per frame, confidences, joint names",
        needs_frame_rate=True,
    ),
    FileFormat(
        ".csv",
        "keypoint table",
        "positions",
        "skmotion.io._keypoints:read_keypoints",
        "one frame per row, joint after joint",
        needs_frame_rate=True,
    ),
    FileFormat(
        ".txt",
        "keypoint text",
        "positions",
        "skmotion.io._keypoints:read_keypoints",
        "x y z [confidence] per joint or per frame (Kinect recorders)",
        needs_frame_rate=True,
    ),
    FileFormat(
        ".ts",
        "UEA/sktime time series (.ts)",
        "series",
        "skmotion.io._ts:read_ts",
        "labelled time series",
    ),
)


def file_format(path):
    """The row of :data:`FORMATS` for a file, by its suffix.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    row : FileFormat

    Raises
    ------
    ValueError
        An unknown suffix; the message lists the known ones.

    Examples
    --------
    >>> from skmotion.io import file_format
    >>> row = file_format("walk.BVH")
    >>> row.name, row.kind, row.reader.__name__
    ('BVH', 'angles', 'read_bvh')
    """
    suffix = Path(path).suffix.lower()
    for row in FORMATS:
        if row.suffix == suffix:
            return row
    known = ", ".join(row.suffix for row in FORMATS)
    raise ValueError(f"{path}: unknown motion file type {suffix!r} (skmotion reads {known}).")


def folder_suffixes():
    """The suffixes the folder loaders read, in table order.

    Returns
    -------
    suffixes : tuple of str

    Examples
    --------
    >>> from skmotion.io import folder_suffixes
    >>> folder_suffixes()
    ('.bvh', '.amc', '.c3d')
    """
    return tuple(row.suffix for row in FORMATS if row.in_folders)


def formats_help():
    """One line per format of :data:`FORMATS`, for help texts.

    Returns
    -------
    text : str

    Examples
    --------
    >>> from skmotion.io._formats import formats_help
    >>> print(formats_help().splitlines()[0])
    .bvh  BVH: skeleton and joint angles
    """
    return "\n".join(
        f"{row.suffix:<5} {row.name}: {row.description}"
        + (f" (extra '{row.extra}')" if row.extra else "")
        for row in FORMATS
    )
