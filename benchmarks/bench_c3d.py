"""C3D reading: ``skmotion.io.read_c3d`` against the ``c3d`` package's frame reader and ``ezc3d``.

Two tables. ``bench_c3d``: a float32 C3D file of ``--frames`` frames and
``--markers`` markers (with gaps, and ``--analog`` analog channels at 10 samples
per frame) is written by the ``c3d`` package into a temporary folder, then read,
in alternation, by ``read_c3d`` (header and parameters parsed from the bytes,
points and analog channels decoded with NumPy), by the package's own
``Reader.read_frames`` (one Python step per frame) and, when installed, by
``ezc3d`` (C++). All stop when the positions (and analog samples) are in memory.
``bench_c3d_real``: the four real files of the shared data (``c3d/``), each read
by the three readers: whether it reads, the time, and the largest difference of
the points from read_c3d's (NaN where either marks the point invalid).
Run: ``pip install -e ".[c3d,bench]" && python benchmarks/bench_c3d.py [--frames 100000]``.
"""

import argparse
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, interleaved, write_results  # noqa: E402

from skmotion.io import read_c3d  # noqa: E402


def write_file(path, n_frames, n_markers, seed=0, n_analog=0):
    import c3d

    rng = np.random.default_rng(seed)
    writer = c3d.Writer(point_rate=100.0, analog_rate=1000.0 if n_analog else 0.0, point_scale=-0.1)
    writer.set_point_labels([f"M{k:02d}" for k in range(n_markers)])
    if n_analog:
        writer.set_analog_labels([f"A{k:02d}" for k in range(n_analog)])
        # ezc3d 1.7.2 crashes (segmentation fault) on the empty SCALE and OFFSET the
        # writer leaves by default.
        writer.set_analog_scales(np.ones(n_analog))
        writer.set_analog_offsets(np.zeros(n_analog, np.int16))
    analog = rng.normal(size=(n_analog, 10)).astype(np.float32) if n_analog else np.zeros((0, 0))
    base = rng.normal(scale=500.0, size=(n_markers, 3)).astype(np.float32)
    frames = []
    for f in range(n_frames):
        points = np.zeros((n_markers, 5), np.float32)
        points[:, :3] = base + f * 0.5
        points[:, 3] = 0.5
        points[f % n_markers, 3] = -1.0  # one marker unseen in every frame
        frames.append((points, analog))
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


def _package_points(path):
    """The c3d package's points (n_frames, n_points, 3), NaN where invalid."""
    import c3d

    with open(path, "rb") as handle, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        frames = np.array([p.copy() for _, p, _ in c3d.Reader(handle).read_frames(copy=False)])
    xyz = frames[:, :, :3].astype(float)
    xyz[frames[:, :, 3] < 0] = np.nan
    return xyz


def _ezc3d_xyz(path):
    return ezc3d_points(path)[:3].transpose(2, 1, 0)


def _difference(ours, theirs):
    if ours.shape != theirs.shape:
        return f"shape {theirs.shape[:2]}"
    both = ~np.isnan(ours) & ~np.isnan(theirs)
    agree = np.isnan(ours) == np.isnan(theirs)
    return float(np.abs(ours[both] - theirs[both]).max()) if agree.all() else "validity differs"


def real_files(rounds):
    """One row per real file and reader: reads or not, median seconds, points vs read_c3d."""
    folder = SHARED_DATA / "c3d"
    if not folder.is_dir():
        print(f"no real C3D files at {folder}: bench_c3d_real is left out")
        return
    readers = {"skmotion read_c3d": lambda p: read_c3d(p, units=None), "c3d": _package_points}
    try:
        import ezc3d  # noqa: F401

        readers["ezc3d"] = _ezc3d_xyz
    except ImportError:
        pass
    rows = []
    for path in sorted(folder.iterdir()):
        ours = read_c3d(path, units=None)
        ours_xyz = ours.channels.reshape(ours.n_frames, -1, 3)
        for name, reader in readers.items():
            try:
                got = reader(path)
            except Exception as exc:  # a peer refusing the file is a result
                rows.append(
                    {
                        "file": path.name,
                        "reader": name,
                        "reads": f"no: {exc}"[:60],
                        "seconds": float("nan"),
                        "max |points - read_c3d| (file unit)": "",
                    }
                )
                continue
            (t,) = interleaved([lambda r=reader: r(path)], rounds)
            got = got.channels.reshape(ours_xyz.shape) if hasattr(got, "channels") else got
            rows.append(
                {
                    "file": path.name,
                    "reader": name,
                    "reads": "yes",
                    "seconds": t,
                    "max |points - read_c3d| (file unit)": _difference(ours_xyz, got),
                }
            )
    write_results("bench_c3d_real", rows, notes=f"median of {rounds} reads per file and reader")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=5000)
    parser.add_argument("--markers", type=int, default=40)
    parser.add_argument("--analog", type=int, default=16, help="analog channels (10 per frame)")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bench.c3d")
        write_file(path, args.frames, args.markers, n_analog=args.analog)
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
        notes=f"{args.frames} frames x {args.markers} markers and {args.analog} analog channels "
        f"(10 samples per frame), float32, {size_mb:.1f} MB; median of {args.rounds} interleaved "
        "rounds; read_c3d decodes the analog channels too",
    )
    real_files(args.rounds)


if __name__ == "__main__":
    main()
