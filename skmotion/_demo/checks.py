"""Demo section: bad input is rejected with a message naming what and where."""

import tempfile
from pathlib import Path

import numpy as np

from skmotion.decomposition import SVDFeatureExtractor
from skmotion.io import Motion, read_bvh, write_bvh
from skmotion.preprocessing import ResampleClips
from skmotion.tree import MotionTreeHMM

TITLE = "Bad input: what skmotion checks"


def _message(call):
    try:
        call()
    except (ValueError, TypeError) as error:  # NotFittedError and MotionFileError are ValueErrors
        return f"{type(error).__name__}: {str(error).splitlines()[0]}"
    raise AssertionError("the bad input was accepted")


def _truncated_bvh(data, folder):
    """A clip written as BVH, then cut in the middle of its 20th frame line."""
    path = Path(folder) / "walk.bvh"
    write_bvh(Motion(data.skeleton, data.clips[0][:40], frame_rate=data.frame_rate), path, precision=4)
    lines = path.read_text().splitlines(keepends=True)
    first = next(k for k, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    cut = first + 19
    path.write_text("".join(lines[:cut]) + lines[cut][: len(lines[cut]) // 2])
    return path


def run(context):
    data = context.data
    clips = [c.copy() for c in data.clips[:6]]
    clips[3][17, 8] = np.nan
    ragged = [clips[0], clips[1][:, :-2]]
    tried = [
        ("NaN in a clip", lambda: MotionTreeHMM().fit(clips, data.target[:6])),
        ("channels differ", lambda: SVDFeatureExtractor().fit(ragged)),
        ("predict before fit", lambda: MotionTreeHMM().predict(data.clips[:2])),
        ("frame_rate 0", lambda: ResampleClips(frame_rate=0, target_frame_rate=30).fit(data.clips[:2])),
        ("one clip, not a list", lambda: ResampleClips(n_frames=8).fit(data.clips[0])),
    ]
    with tempfile.TemporaryDirectory() as folder:
        path = _truncated_bvh(data, folder)
        tried.append(("truncated BVH", lambda: read_bvh(path)))
        lines = [f"{what:>20}: {_message(call).replace(str(path), path.name)}" for what, call in tried]
    return lines + ["(every estimator and reader, with many more cases: tests/bad_input/, docs/errors.md)"]
