"""Reading keypoint files: joint positions per frame from trackers and pose estimators.

The joint names come from a *layout*: a :class:`~skmotion.kinematics.Layout`, any
object with a ``joints`` or ``joint_names`` sequence, or a layout name that
:func:`skmotion.kinematics.get_layout` resolves.
"""

import io
import re
import zipfile
from pathlib import Path

import numpy as np

from skmotion.io._errors import MotionFileError
from skmotion.io._motion import Motion
from skmotion.io._text import NUMBER, decode_text, read_text
from skmotion.kinematics._named_layouts import get_layout

__all__ = ["read_keypoints"]

# Values per joint by default: 2 -> x, y; 3 -> x, y, z; 4 -> x, y, z and a confidence.
_DEFAULT_COLUMNS = {2: "xy", 3: "xyz", 4: "xyzc"}
_COLUMNS = ("xy", "xyz", "xyc", "xyzc")
_BLANKS = re.compile(r"[ \t]+")
_NOT_NUMERIC = re.compile(r"[^0-9+\-.eEnNaA, \t\n]")


def _joint_names(layout):
    """The joint names of ``layout`` (None, a layout name or an object with ``joint_names``)."""
    if layout is None:
        return None
    if isinstance(layout, str):
        layout = get_layout(layout)
    # a skmotion Layout names its joints `joints`; other layout objects may say `joint_names`
    names = getattr(layout, "joints", None) or getattr(layout, "joint_names", None)
    if names is None:
        raise TypeError(
            f"layout must be None, a layout name or an object with joints (or joint_names); got "
            f"{type(layout).__name__}."
        )
    return [str(n) for n in names]


def _is_number(word):
    """Whether ``word`` is a finite ASCII number or NaN (no ``1_000``, no infinity)."""
    return bool(NUMBER.fullmatch(word)) or word.lower().lstrip("+-") == "nan"


def _values_of(text, delimiter):
    """The words of a line's text without its comment: split at commas, or at spaces and
    tabs (not at other Unicode blanks: a no-break space inside a number is an error)."""
    text = text.split("#", 1)[0].strip(" \t")
    if not text:
        return []
    return [w.strip(" \t") for w in (text.split(",") if delimiter else _BLANKS.split(text))]


def _find_bad_line(path, lines, delimiter, first, n_values):
    """The MotionFileError naming the first line of ``lines[first:]`` that does not parse."""
    for number, line in enumerate(lines[first:], start=first + 1):
        words = _values_of(line, delimiter)
        if not words:
            continue
        if n_values is not None and len(words) != n_values:
            return MotionFileError(path, number, f"{len(words)} values, expected {n_values}")
        bad = next((w for w in words if not _is_number(w)), None)
        if bad is not None:
            return MotionFileError(path, number, f"not a finite number: {bad!r}")
    return MotionFileError(path, None, "cannot be read as a table of numbers")


def _read_text(path):
    """(values of shape (n_rows, n_values), (header names, line) or None) of a text table.

    The one text rule of every reader (``skmotion.io._text``): a UTF-8 byte-order mark
    is dropped, LF, CRLF and CR end a line, another control byte is an error naming
    its line, and numbers are ASCII.
    """
    lines = decode_text(read_text(path)).split("\n")
    data_lines = [k for k, line in enumerate(lines) if _values_of(line, None)]
    if not data_lines:
        raise MotionFileError(path, None, "no data lines")
    first = data_lines[0]
    delimiter = "," if "," in lines[first].split("#", 1)[0] else None
    words = _values_of(lines[first], delimiter)
    header = None
    if not any(_is_number(w) for w in words):  # a header names every column
        header, first = (words, first + 1), first + 1
    n_values = len(words)  # every line has as many values as the first
    body = "\n".join(line.split("#", 1)[0] for line in lines[first:])
    if not body.strip(" \t\n"):
        raise MotionFileError(path, None, "no data lines (a header only)")
    if _NOT_NUMERIC.search(body):  # what numpy would read loosely (Unicode blanks, digits)
        raise _find_bad_line(path, lines, delimiter, first, n_values)
    try:
        values = np.loadtxt(io.StringIO(body), delimiter=delimiter, ndmin=2, dtype=float)
    except ValueError:
        raise _find_bad_line(path, lines, delimiter, first, n_values) from None
    if values.size == 0:
        raise MotionFileError(path, None, "no data lines")
    if values.shape[1] != n_values or np.isinf(values).any():
        raise _find_bad_line(path, lines, delimiter, first, n_values)
    return values, header


def _array_header(path, handle, available, where):
    """(shape, fortran order, dtype) of the ``.npy`` stream ``handle``, checked against
    the ``available`` bytes before anything is allocated."""
    start = handle.tell()
    version = np.lib.format.read_magic(handle)
    read_header = {
        (1, 0): np.lib.format.read_array_header_1_0,
        (2, 0): np.lib.format.read_array_header_2_0,
    }.get(version)
    if read_header is None:
        raise MotionFileError(path, None, f"{where}: .npy format version {version} is not read")
    shape, fortran, dtype = read_header(handle, max_header_size=10000)
    if dtype.hasobject or dtype.names is not None or dtype.kind not in "fiubUS":
        raise MotionFileError(path, None, f"{where}: holds {dtype} values, not numbers")
    needed = int(np.prod(shape, dtype=object)) * dtype.itemsize
    have = available - (handle.tell() - start)
    if needed > have:
        raise MotionFileError(
            path,
            None,
            f"{where}: the header announces {shape} {dtype} ({needed} bytes); "
            f"the file holds {have}",
        )
    return shape, fortran, dtype


def _load_array(path, handle, available, where):
    shape, fortran, dtype = _array_header(path, handle, available, where)
    count = int(np.prod(shape, dtype=np.int64))
    data = handle.read(count * dtype.itemsize)
    if len(data) != count * dtype.itemsize:
        raise MotionFileError(path, None, f"{where}: the data is cut short")
    order = "F" if fortran else "C"
    return np.frombuffer(data, dtype=dtype, count=count).reshape(shape, order=order)


def _npz_members(path, archive):
    """The arrays of an ``.npz`` archive, each checked before it is read."""
    arrays = {}
    for info in archive.infolist():
        name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
        # Deflate cannot expand more than about 1032:1: a larger claim is a forged size.
        if (
            info.compress_type != zipfile.ZIP_STORED
            and info.file_size > 1100 * info.compress_size + 1024
        ):
            raise MotionFileError(path, None, f"array {name!r}: implausible uncompressed size")
        with archive.open(info) as member:
            arrays[name] = _load_array(path, member, info.file_size, f"array {name!r}")
    return arrays


def _read_array(path):
    """(values, joint names or None, confidence or None) of a ``.npy`` or ``.npz`` file.

    The arrays are read without pickles, and every header is checked against
    the bytes the file holds before any allocation. Whatever goes wrong in the
    bytes (a damaged zip, a garbled header) is a :class:`MotionFileError`.
    """
    size = Path(path).stat().st_size  # a missing file: the OSError names it
    try:
        with open(path, "rb") as handle:
            if handle.read(2) == b"PK":
                with zipfile.ZipFile(handle) as archive:
                    arrays = _npz_members(path, archive)
            else:
                handle.seek(0)
                return _load_array(path, handle, size, "array"), None, None
    except MotionFileError:
        raise
    except Exception as exc:  # BadZipFile, zlib.error, a header's SyntaxError/TokenError ...
        raise MotionFileError(
            path, None, f"not a readable NumPy array file ({type(exc).__name__}: {exc})"
        ) from None
    main = [k for k in ("keypoints", "positions") if k in arrays]
    if not main:
        main = sorted(set(arrays) - {"confidence", "joint_names"})
    if len(main) != 1:
        raise MotionFileError(
            path, None, f"expected an array 'keypoints' (or one array); found {sorted(arrays)}"
        )
    names = arrays.get("joint_names")
    if names is not None:
        if names.ndim != 1 or names.dtype.kind not in "U":
            raise MotionFileError(
                path, None, f"joint_names is {names.dtype} {names.shape}, not text"
            )
        names = names.tolist()
    return arrays[main[0]], names, arrays.get("confidence")


def _joints_from_header(path, header, line, columns):
    """Joint names from column names ``<joint>_<x|y|z|c...>``, checked group by group.

    A column named for an axis must be that axis (``hip_y`` where ``columns`` puts x
    would swap the axes silently); a confidence column may be named anything.
    """
    if len(header) % len(columns):
        raise MotionFileError(path, line, f"{len(header)} columns, not {len(columns)} per joint")
    groups = np.asarray(header, dtype=object).reshape(-1, len(columns))
    names = []
    for group in groups:
        stems = {str(c).rsplit("_", 1)[0] for c in group}
        if len(stems) != 1:
            raise MotionFileError(
                path,
                line,
                f"columns {list(group)} do not name one joint (<joint>_x, <joint>_y, ...)",
            )
        for column, axis in zip(group, columns):
            suffix = column.rsplit("_", 1)[-1].lower()
            if axis in "xyz" and suffix in ("x", "y", "z") and suffix != axis:
                raise MotionFileError(path, line, f"column {column!r} where {axis} belongs")
        names.append(stems.pop())
    return names


def _as_frames(path, values, names, columns, per_line):
    """Values reshaped to (n_frames, n_joints, n_values)."""
    if values.dtype.kind not in "fiu" or values.ndim not in (2, 3):
        raise MotionFileError(
            path,
            None,
            f"expected numbers of shape (n_frames, n_joints, n_values) or (n_frames, n_columns); "
            f"got {values.dtype} of shape {values.shape}",
        )
    if 0 in values.shape:
        raise MotionFileError(path, None, f"no values: an array of shape {values.shape}")
    with np.errstate(invalid="ignore"):  # float32 signalling NaNs are NaN (missing) too
        values = values.astype(float)
    if values.ndim == 3:
        return values
    n_joints = len(names) if names is not None else None
    n_values = len(columns) if columns is not None else None
    if per_line is None:
        per_line = "joint" if n_joints and n_joints > 1 and values.shape[1] <= 4 else "frame"
    if per_line == "joint":
        if n_joints is None:
            raise ValueError(f"{path}: one joint per line needs layout= to know the joint count.")
        if len(values) % n_joints:
            raise MotionFileError(
                path, None, f"{len(values)} joint lines are not whole frames of {n_joints} joints"
            )
        return values.reshape(-1, n_joints, values.shape[1])
    if n_joints is None and n_values is None:
        raise ValueError(
            f"{path}: {values.shape[1]} values per frame; give layout= (the joints) or columns= "
            "(the values per joint) to split them."
        )
    n_values = n_values or values.shape[1] // n_joints
    if values.shape[1] % n_values or (n_joints and values.shape[1] != n_joints * n_values):
        raise MotionFileError(
            path, None, f"{values.shape[1]} values per frame do not split into the joints"
        )
    return values.reshape(len(values), -1, n_values)


def read_keypoints(
    path,
    layout=None,
    *,
    frame_rate,
    columns=None,
    min_confidence=None,
    units=None,
    per_line=None,
):
    """Read joint positions per frame (a tracker's or pose estimator's output) as a :class:`Motion`.

    Four kinds of file:

    - ``.npy``: an array ``(n_frames, n_joints, n_values)`` or
      ``(n_frames, n_joints * n_values)``;
    - ``.npz``: the array ``keypoints`` (or the file's only array), and
      optionally ``confidence`` ``(n_frames, n_joints)`` and ``joint_names``;
    - ``.csv``: one frame per row, joint after joint; an optional header
      row names the columns ``<joint>_x, <joint>_y, ...``;
    - ``.txt`` (and any other text): numbers separated by spaces or commas,
      one frame per line, or one joint per line (``x y z [confidence]``, the
      frames one after another, as Kinect recorders write them). ``#``
      starts a comment; a missing value is written ``nan``.

    Parameters
    ----------
    path : str or path-like
        The file.
    layout : None, str, Layout or object with ``joints``/``joint_names``, default=None
        The joints in file order: a layout name (resolved by
        :func:`skmotion.kinematics.get_layout`), or any object with a
        ``joint_names`` sequence. None takes the names from the file
        (``.npz`` ``joint_names``, a CSV header), else ``joint0, joint1, ...``.
    frame_rate : float
        Frames per second (keypoint files do not record it).
    columns : {"xy", "xyz", "xyc", "xyzc"}, default=None
        The values of each joint; ``c`` is a confidence. None: 2 values are
        ``xy``, 3 ``xyz`` and 4 ``xyzc`` (give ``"xyc"`` for 2-D keypoints
        with a confidence, as COCO and OpenPose write them).
    min_confidence : float, default=None
        Positions whose confidence is below this become NaN (missing); the
        confidences themselves are kept unchanged in
        ``motion.extras["confidence"]``. None keeps every position.
    units : str, default=None
        The length unit of the positions (``"m"``, ``"mm"``, ``"px"`` ...),
        recorded on the motion; None is ``"unknown"``. Nothing is converted.
    per_line : {"frame", "joint"}, default=None
        What one line (or row) of a text or 2-D array holds; None: one joint
        when a line has at most 4 values and the layout has several joints,
        else one frame.

    Returns
    -------
    motion : Motion
        A position motion (``skeleton=None``) whose ``marker_names`` are the
        joints and whose channels are ``<joint>_x``, ``_y`` [, ``_z``];
        ``motion.extras["confidence"]`` when the file has confidences.

    Raises
    ------
    MotionFileError
        A value that is not a number, a line with the wrong number of
        values, joint lines that are not whole frames, a header that
        disagrees with the layout; the message names the file and line.

    Examples
    --------
    A Kinect-style text file, one joint per line (``x y z confidence``),
    two frames of a three-joint layout:

    >>> import os, tempfile
    >>> from types import SimpleNamespace
    >>> from skmotion.io import read_keypoints
    >>> layout = SimpleNamespace(joint_names=["hip", "knee", "ankle"])
    >>> text = "0 1 2 1\\n0 0.5 2 1\\n0 0 2 0.2\\n0.1 1 2 1\\n0.1 0.5 2 1\\n0.1 0 2 1\\n"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "take.txt")
    ...     _ = open(path, "w").write(text)
    ...     motion = read_keypoints(path, layout, frame_rate=30, min_confidence=0.5, units="m")
    >>> motion.channel_names[:4]
    ['hip_x', 'hip_y', 'hip_z', 'knee_x']
    >>> motion.channels[:, 6:9]  # the ankle, below the threshold in the first frame
    array([[nan, nan, nan],
           [0.1, 0. , 2. ]])
    >>> motion.extras["confidence"][:, 2]
    array([0.2, 1. ])
    """
    path = Path(path)
    if columns is not None and columns not in _COLUMNS:
        raise ValueError(f"columns must be None or one of {_COLUMNS}; got {columns!r}.")
    if per_line not in (None, "frame", "joint"):
        raise ValueError(f"per_line must be None, 'frame' or 'joint'; got {per_line!r}.")
    names = _joint_names(layout)
    confidence = header = None
    if path.suffix.lower() in (".npy", ".npz"):
        values, file_names, confidence = _read_array(path)
    else:
        values, header = _read_text(path)
        file_names = None
        if header is not None:
            header, line = header
            header_columns = columns
            if header_columns is None and names:
                per_joint = max(len(header) // len(names), 1)
                header_columns = _DEFAULT_COLUMNS.get(per_joint, "?" * per_joint)
            if header_columns is None:
                raise ValueError(f"{path}: give layout= or columns= to split the header.")
            file_names = _joints_from_header(path, header, line, header_columns)
    if names is not None and file_names is not None and list(file_names) != names:
        raise MotionFileError(
            path, line if header else None, f"joints {list(file_names)[:6]}... are not the layout's"
        )
    frames = _as_frames(path, values, names or file_names, columns, per_line)
    n_frames, n_joints, n_values = frames.shape
    columns = columns or _DEFAULT_COLUMNS.get(n_values)
    if columns is None or len(columns) != n_values:
        raise MotionFileError(
            path, None, f"{n_values} values per joint; columns={columns!r} does not describe them"
        )
    names = names or file_names or [f"joint{k}" for k in range(n_joints)]
    if len(names) != n_joints:
        raise MotionFileError(path, None, f"{n_joints} joints, but the layout names {len(names)}")
    positions = frames[:, :, [k for k, c in enumerate(columns) if c != "c"]]
    if "c" in columns:
        confidence = frames[:, :, columns.index("c")]
    if confidence is not None:
        confidence = np.asarray(confidence, dtype=float)
        if confidence.shape != (n_frames, n_joints):
            raise MotionFileError(
                path, None, f"confidence of shape {confidence.shape}, not {(n_frames, n_joints)}"
            )
        if min_confidence is not None:
            positions = np.where((confidence < min_confidence)[:, :, None], np.nan, positions)
    elif min_confidence is not None:
        raise ValueError(f"{path}: min_confidence is given but the file has no confidences.")
    return Motion(
        None,
        positions.reshape(n_frames, -1),
        frame_rate=frame_rate,
        source=str(path),
        marker_names=names,
        units=units,
        extras={} if confidence is None else {"confidence": confidence},
    )
