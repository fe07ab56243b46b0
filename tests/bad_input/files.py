"""Small motion files for the file tables: written by the tests, or cut from the real data.

Each source returns ``(name, text bytes, read)``, where ``read(path)`` reads a file
of that format (the AMC reader with its skeleton).
"""

import re
from pathlib import Path

import numpy as np

from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.io import Motion, read_amc, read_asf, read_bvh, read_ts, write_bvh
from tests.io.test_asf_amc import ASF, _amc, _frames


def written_bvh(folder, n_frames=8):
    """A make_motions clip written by write_bvh (a 26-joint humanoid)."""
    clip = make_motions(n_clips_per_class=1, classes=["walk"], n_subjects=1, random_state=0).clips[
        0
    ][:n_frames]
    path = Path(folder) / "written.bvh"
    write_bvh(Motion(humanoid_skeleton(), clip, frame_rate=30.0), path, precision=4)
    return path.read_bytes()


def written_asf():
    return ASF.encode()


def written_amc(n_frames=4):
    return _amc(_frames(np.random.default_rng(0), n_frames)).replace("\r\n", "\n").encode()


def written_ts():
    text = "#toy\n@problemName toy\n@univariate false\n@dimensions 2\n@equalLength false\n"
    text += "@classLabel true walk run\n@data\n1.5,2,3:4,5,6:walk\n7,8:9,10:run\n"
    text += "0.25,-1,2,3:1,1,1,1:walk\n"
    return text.encode()


def real_bvh(shared_data, n_frames=6):
    """The header and the first frames of a real BVH file (Frames: set to match)."""
    text = (shared_data / "cmu-bvh" / "07" / "07_01.bvh").read_bytes()
    head, body = text.split(b"Frame Time:", 1)
    frame_time, *frames = body.split(b"\n")[: n_frames + 1]
    head = re.sub(rb"Frames:\s*\d+", b"Frames: %d" % n_frames, head)
    return head + b"Frame Time:" + frame_time + b"\n" + b"\n".join(frames) + b"\n"


def real_asf(shared_data):
    return (shared_data / "cmu-asfamc" / "01" / "01.asf").read_bytes()


def real_amc(shared_data, n_frames=3):
    """The header and the first frames of a real AMC file."""
    lines = (shared_data / "cmu-asfamc" / "01" / "01_01.amc").read_bytes().split(b"\n")
    frame_lines = [k for k, line in enumerate(lines) if line.strip().isdigit()]
    return b"\n".join(lines[: frame_lines[n_frames]]) + b"\n"


def real_ts(shared_data, n_series=3):
    lines = (shared_data / "uea" / "BasicMotions_TRAIN.ts").read_bytes().split(b"\n")
    data = next(k for k, line in enumerate(lines) if line.strip().lower() == b"@data")
    return b"\n".join(lines[: data + 1 + n_series]) + b"\n"


def reader_for(kind, folder, asf_bytes=None):
    """The reader of one kind of file; AMC files are read with the skeleton of ``asf_bytes``."""
    if kind == "bvh":
        return read_bvh
    if kind == "asf":
        return read_asf
    if kind == "ts":
        return read_ts
    asf = Path(folder) / "skeleton.asf"
    asf.write_bytes(asf_bytes)
    skeleton = read_asf(asf)
    return lambda path: read_amc(path, skeleton)
