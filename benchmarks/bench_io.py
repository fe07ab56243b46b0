"""Reading speed: skmotion's BVH and ASF/AMC readers against PyPI readers, in the same run.

BVH: the largest BVH files in ``../shared/data``, read by ``skmotion.io.read_bvh``,
by ``bvh`` (``Bvh(text)`` and its frames as a float array) and by ``bvhio``
(``readAsBvh``), all to the point where the channel values are numbers in memory.
AMC: the largest CMU AMC files, read by ``skmotion.io.read_amc`` and by a plain
line-by-line parser (a dict of bone values per frame, as the common Python AMC
readers do). Run: ``python benchmarks/bench_io.py`` (needs ``pip install -e ".[bench]"``).
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, interleaved, write_results  # noqa: E402

from skmotion.io import read_amc, read_asf, read_bvh  # noqa: E402


def peer_bvh(path):
    import bvh

    with open(path) as fh:
        mocap = bvh.Bvh(fh.read())
    return np.asarray(mocap.frames, dtype=float)


def peer_bvhio(path):
    import bvhio

    return bvhio.readAsBvh(str(path))


def line_by_line_amc(path):
    """One dict of bone values per frame, parsed line by line."""
    frames = []
    with open(path) as fh:
        for line in fh:
            words = line.split()
            if not words or words[0].startswith((":", "#")):
                continue
            if words[0].isdigit():
                frames.append({})
            else:
                frames[-1][words[0]] = [float(w) for w in words[1:]]
    return frames


def bench_bvh(files, repeats):
    rows = []
    for path in files:
        megabytes = path.stat().st_size / 1e6
        ours = read_bvh(path)
        degrees = np.where(
            [c.endswith("rotation") for c in ours.channel_names],
            np.rad2deg(ours.channels),
            ours.channels,
        )
        np.testing.assert_allclose(degrees, peer_bvh(path), atol=1e-9)  # the same numbers
        fast, bvh_time, bvhio_time = interleaved(
            [lambda: read_bvh(path), lambda: peer_bvh(path), lambda: peer_bvhio(path)], repeats
        )
        rows.append(
            {
                "file": f"{path.parent.name}/{path.name}",
                "MB": megabytes,
                "frames": ours.n_frames,
                "channels": ours.n_channels,
                "skmotion_MB_s": megabytes / fast,
                "bvh_MB_s": megabytes / bvh_time,
                "bvhio_MB_s": megabytes / bvhio_time,
                "speedup_vs_fastest_peer": min(bvh_time, bvhio_time) / fast,
            }
        )
    return rows


def bench_amc(files, repeats):
    rows = []
    for path in files:
        megabytes = path.stat().st_size / 1e6
        skeleton = read_asf(path.with_name(f"{path.stem.split('_')[0]}.asf"))
        motion = read_amc(path, skeleton)
        assert len(line_by_line_amc(path)) == motion.n_frames
        fast, slow = interleaved(
            [lambda: read_amc(path, skeleton), lambda: line_by_line_amc(path)], repeats
        )
        rows.append(
            {
                "file": f"{path.parent.name}/{path.name}",
                "MB": megabytes,
                "frames": motion.n_frames,
                "skmotion_MB_s": megabytes / fast,
                "line_by_line_MB_s": megabytes / slow,
                "speedup": slow / fast,
            }
        )
    return rows


def main(n_files=4, repeats=5):
    if not SHARED_DATA.is_dir():
        sys.exit(f"The real data is not at {SHARED_DATA}.")
    by_size = lambda paths: sorted(paths, key=lambda p: p.stat().st_size, reverse=True)[:n_files]  # noqa: E731
    bvh_rows = bench_bvh(by_size(SHARED_DATA.glob("**/*.bvh")), repeats)
    write_results(
        "io_bvh",
        bvh_rows,
        notes="MB/s of reading a BVH file to channel values in memory (median of 5 interleaved "
        "rounds); speedup = time of the fastest of bvh and bvhio / time of skmotion.read_bvh "
        "(target >= 5).",
    )
    amc_rows = bench_amc(by_size(SHARED_DATA.glob("cmu-asfamc/*/*.amc")), repeats)
    write_results(
        "io_amc",
        amc_rows,
        notes="MB/s of reading a CMU AMC file (skeleton already read) against a line-by-line "
        "Python parser.",
    )


if __name__ == "__main__":
    main()
