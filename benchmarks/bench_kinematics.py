"""Forward kinematics: skmotion's batched FK against a per-frame loop.

The per-frame loop is how PyMO and most BVH tools compute positions (one pose at a
time, joint by joint). Run: ``python benchmarks/bench_kinematics.py``.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import time_call, write_results  # noqa: E402

from skmotion.datasets import humanoid_skeleton  # noqa: E402
from skmotion.kinematics import euler_to_matrix, forward_kinematics  # noqa: E402


def per_frame_fk(skeleton, channels):
    """Reference: frame by frame, joint by joint."""
    out = np.zeros((len(channels), skeleton.n_joints, 3))
    starts = np.cumsum([0] + [len(c) for c in skeleton.channels])
    for f, frame in enumerate(channels):
        rotations = [None] * skeleton.n_joints
        for j, chans in enumerate(skeleton.channels):
            values = dict(zip(chans, frame[starts[j] : starts[j + 1]]))
            order = skeleton.rotation_orders[j]
            local = euler_to_matrix([values.get(f"{a}rotation", 0.0) for a in order], order)
            offset = np.array(skeleton.offsets[j])
            for k, a in enumerate("XYZ"):
                offset[k] = values.get(f"{a}position", offset[k])
            p = skeleton.parents[j]
            if p < 0:
                rotations[j], out[f, j] = local, offset
            else:
                rotations[j] = rotations[p] @ local
                out[f, j] = out[f, p] + rotations[p] @ offset
    return out


def main():
    rng = np.random.default_rng(0)
    skeleton = humanoid_skeleton()
    rows = []
    for n_frames in (100, 1_000, 10_000):
        channels = rng.uniform(-1, 1, size=(n_frames, skeleton.n_channels))
        np.testing.assert_allclose(
            forward_kinematics(skeleton, channels[:50]).positions,
            per_frame_fk(skeleton, channels[:50]),
            atol=1e-10,
        )
        fast, _ = time_call(lambda: forward_kinematics(skeleton, channels), repeats=5)
        loop_frames = min(n_frames, 1_000)
        slow, _ = time_call(
            lambda: per_frame_fk(skeleton, channels[:loop_frames]), repeats=1, warmup=0
        )
        slow *= n_frames / loop_frames
        rows.append(
            {
                "frames": n_frames,
                "joints": skeleton.n_joints,
                "skmotion_ms": 1e3 * fast,
                "per_frame_loop_ms": 1e3 * slow,
                "speedup": slow / fast,
                "skmotion_frames_per_s": n_frames / fast,
            }
        )
    write_results(
        "kinematics",
        rows,
        notes="Forward kinematics of the 26-joint humanoid; the per-frame loop's time beyond "
        "1,000 frames is extrapolated linearly from 1,000 frames.",
    )


if __name__ == "__main__":
    main()
