"""Demo section: bad input is rejected with a message naming what and where."""

import tempfile
from pathlib import Path

import numpy as np

from skmotion.decomposition import SVDFeatureExtractor
from skmotion.io import Motion, as_motions, read_bvh, write_bvh
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
    """The first 40 frames of a motion written as BVH, then cut in the middle of the 20th frame line."""
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


def run(context):
    data = context.data
    # One clip of the data (synthetic, or the first file of --data FOLDER) made bad in each way.
    motion = (
        data.get("motions") or as_motions(data.clips[:1], data.skeletons[:1], data.frame_rate)
    )[0]
    clip = motion.channels
    with_nan = [clip.copy() for _ in range(4)]
    with_nan[3][min(17, len(clip) - 1), min(8, clip.shape[1] - 1)] = np.nan
    tried = [
        ("NaN in a clip", lambda: MotionTreeHMM().fit(with_nan, [0, 1, 0, 1])),
        ("channels differ", lambda: SVDFeatureExtractor().fit([clip, clip[:, :-2]])),
        ("predict before fit", lambda: MotionTreeHMM().predict([clip])),
        ("frame_rate 0", lambda: ResampleClips(frame_rate=0, target_frame_rate=30).fit([clip])),
        ("one clip, not a list", lambda: ResampleClips(n_frames=8).fit(clip)),
    ]
    with tempfile.TemporaryDirectory() as folder:
        path = _truncated_bvh(motion, folder)
        tried.append(("truncated BVH", lambda: read_bvh(path)))
        lines = [
            f"{what:>20}: {_message(call).replace(str(path), path.name)}" for what, call in tried
        ]
    return lines + [
        "(every estimator and reader, with many more cases: tests/bad_input/, docs/errors.md)"
    ]
