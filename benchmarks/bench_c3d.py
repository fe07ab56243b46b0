"""C3D reading: ``skmotion.io.read_c3d`` against the ``c3d`` package's frame reader and ``ezc3d``.

A float32 C3D file of ``--frames`` frames and ``--markers`` markers (with gaps) is
written by the ``c3d`` package into a temporary folder, then read, in alternation,
by ``read_c3d`` (the package parses the header and parameters, NumPy decodes the
points), by the package's own ``Reader.read_frames`` (one Python step per frame)
and, when installed, by ``ezc3d`` (C++). All stop when the positions are in memory.
Run: ``pip install -e ".[c3d]" ezc3d && python benchmarks/bench_c3d.py [--frames 100000]``.
"""

import argparse
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import interleaved, write_results  # noqa: E402

from skmotion.io import read_c3d  # noqa: E402


def write_file(path, n_frames, n_markers, seed=0):
    import c3d

    rng = np.random.default_rng(seed)
    writer = c3d.Writer(point_rate=100.0, point_scale=-0.1)
    writer.set_point_labels([f"M{k:02d}" for k in range(n_markers)])
    base = rng.normal(scale=500.0, size=(n_markers, 3)).astype(np.float32)
    frames = []
    for f in range(n_frames):
        points = np.zeros((n_markers, 5), np.float32)
        points[:, :3] = base + f * 0.5
        points[:, 3] = 0.5
        points[f % n_markers, 3] = -1.0  # one marker unseen in every frame
        frames.append((points, np.zeros((0, 0))))
    writer.add_frames(frames)
    with warnings.catch_warnings(), open(path, "wb") as handle:
        warnings.simplefilter("ignore")
        writer.write(handle)


def package_frames(path):
    import c3d

    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reader = c3d.Reader(handle)
        out = np.empty((reader.frame_count, int(reader.point_used), 3))
        for k, (_, points, _) in enumerate(reader.read_frames(copy=False)):
            out[k] = points[:, :3]
    return out


def ezc3d_points(path):
    import ezc3d

    return ezc3d.c3d(str(path))["data"]["points"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5000)
    parser.add_argument("--markers", type=int, default=40)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bench.c3d")
        write_file(path, args.frames, args.markers)
        size_mb = os.path.getsize(path) / 1e6
        readers = {"skmotion read_c3d": read_c3d, "c3d Reader.read_frames": package_frames}
        try:
            import ezc3d  # noqa: F401

            readers["ezc3d"] = ezc3d_points
        except ImportError:
            print("ezc3d is not installed: its row is left out")
        ours = read_c3d(path, units=None)
        reference = package_frames(path)
        seen = ~np.isnan(ours.channels.reshape(reference.shape))
        assert np.array_equal(ours.channels.reshape(reference.shape)[seen], reference[seen])
        funcs = [lambda f=f: f(path) for f in readers.values()]
        times = interleaved(funcs, args.rounds)
    rows = [
        {
            "reader": name,
            "seconds": t,
            "MB/s": size_mb / t,
            "frames/s": args.frames / t,
            "time / read_c3d": t / times[0],
        }
        for name, t in zip(readers, times)
    ]
    write_results(
        "bench_c3d",
        rows,
        notes=f"{args.frames} frames x {args.markers} markers, float32, {size_mb:.1f} MB; "
        f"median of {args.rounds} interleaved rounds",
    )


if __name__ == "__main__":
    main()
