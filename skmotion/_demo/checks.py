"""Demo section: bad input is rejected with a message naming what and where."""

import tempfile
from pathlib import Path

import numpy as np

from skmotion.decomposition import SVDFeatureExtractor
from skmotion.io import Motion, as_motions, file_format, read_bvh, write_bvh
from skmotion.preprocessing import ResampleClips
from skmotion.tree import MotionTreeHMM

TITLE = "Bad input: what skmotion checks"


def _message(call):
    try:
        call()
    except (ValueError, TypeError) as error:  # NotFittedError and MotionFileError are ValueErrors
        return f"{type(error).__name__}: {str(error).splitlines()[0]}"
    raise AssertionError("the bad input was accepted")


def _truncated_bvh(motion, folder):
    """The first 40 frames of a motion written as BVH, then cut in the middle of frame line 20."""
    path = Path(folder) / "walk.bvh"
    write_bvh(
        Motion(motion.skeleton, motion.channels[:40], frame_rate=motion.frame_rate),
        path,
        precision=4,
    )
    lines = path.read_text().splitlines(keepends=True)
    first = next(k for k, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    cut = first + min(19, len(lines) - first - 1)  # a short clip is cut in its last line
    path.write_text("".join(lines[:cut]) + lines[cut][: len(lines[cut]) // 2])
    return path


def _truncated_copy(filename, folder):
    """The first half of a file's bytes, under its own name, and the reader of its format."""
    source = Path(filename)
    path = Path(folder) / source.name
    data = source.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    return path, file_format(source).reader


def run(context):
    data = context.data
    if data.get("kind") == "series":
        return ["not run on labelled time series: the checks garble a motion file and its clips"]
    # The data's own clips (synthetic, or --data FOLDER's), made bad in each way.
    on_folder = data.get("motions") is not None
    motion = (
        data.get("motions") or as_motions(data.clips[:1], data.skeletons[:1], data.frame_rate)
    )[0]
    clip = data.clips[0]
    with_nan = [c.copy() for c in data.clips[:4]]
    bad = len(with_nan) - 1
    with_nan[bad][min(17, len(with_nan[bad]) - 1), min(8, clip.shape[1] - 1)] = np.nan
    source = (
        f"the folder's first {len(with_nan)} clip(s) (from {Path(data.filenames[0]).name}, ...)"
        if on_folder
        else f"the first {len(with_nan)} synthetic clips"
    )
    tried = [
        ("NaN in a clip", lambda: MotionTreeHMM().fit(with_nan, [0, 1, 0, 1][: len(with_nan)])),
        ("channels differ", lambda: SVDFeatureExtractor().fit([clip, clip[:, :-2]])),
        ("predict before fit", lambda: MotionTreeHMM().predict([clip])),
        ("frame_rate 0", lambda: ResampleClips(frame_rate=0, target_frame_rate=30).fit([clip])),
        ("one clip, not a list", lambda: ResampleClips(n_frames=8).fit(clip)),
    ]
    with tempfile.TemporaryDirectory() as folder:
        if motion.skeleton is None:  # positions: the folder's own first file, cut in half
            path, read = _truncated_copy(data.filenames[0], folder)
            tried.append((f"truncated {path.suffix[1:].upper()}", lambda: read(path)))
        else:
            path = _truncated_bvh(motion, folder)
            tried.append(("truncated BVH", lambda: read_bvh(path)))
        lines = [
            f"{what:>20}: {_message(call).replace(str(path), path.name)}" for what, call in tried
        ]
    return (
        [f"bad inputs made from {source}; the file from the first clip's motion:"]
        + lines
        + ["(every estimator and reader, with many more cases: tests/bad_input/, docs/errors.md)"]
    )
