"""Large frame collections: fit seconds and peak memory from 10^5 to 10^7 frames, against sklearn.

Every fit runs in its own fresh process (``--worker``), which makes the frames, resets
its peak resident memory to the current one (``/proc/self/clear_refs``), fits, and
reports the seconds and its peak resident memory (``VmHWM``, the frames included):

- ``MotionTree.build(copy=False)``: the tree the fits build, ``max_depth=8`` with
  median cuts (256 leaves: the vocabulary size of the peers), ``min_samples_leaf=16``,
  working in the frame array itself;
- ``MotionTree.build(copy=False, n_jobs=2)``: the same with the nodes of a layer in two
  threads (the same tree);
- ``MotionTree.build``: the same with the default ``copy=True`` (a copy of the frames);
- ``MotionTreeEncoder().fit``: the encoder with its defaults, from clips of 100 frames
  (views into the frame array); ``MotionTreeEncoder(residual_order=2).fit`` the same
  with the residuals' second order (a routing of all training frames after the build);
- sklearn's ``BisectingKMeans(256)`` and ``MiniBatchKMeans(256)`` (``random_state=0``,
  defaults otherwise), the frame vocabularies of the same size.

The frames: 60 channels, a mixture of 50 correlated Gaussian clusters (made in blocks,
so making them costs no more than the array). Sizes 10^5, 10^6, 3x10^6 and 10^7
(``--sizes`` to choose; ``--quick``: 10^4 and 10^5). ``--peers-up-to N`` leaves the
sklearn fits out above N frames (they take minutes there). ``--before SRC`` adds the
build of the skmotion source tree SRC (for example an older checkout) on the same
frames (and, with ``encoder`` or ``encoder2`` among the methods, that source's encoder
fits). The two copying builds stop at 10^6 frames (their memory figure is clear
there). The growth exponent of each method is the slope of log seconds against log
frames over the sizes it ran. ``--methods`` runs some of them (``tree_in_place``,
``tree_threads``, ``tree``, ``encoder``, ``encoder2``, ``bisecting``, ``minibatch``).
Each result row carries the load average when its fit ended. Results:
``results/<--name, default scaling_frames>.{csv,md}``.
Run: ``python benchmarks/bench_scaling_frames.py``.
"""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_results  # noqa: E402

N_CHANNELS = 60
BLOCK = 1 << 16
METHODS = {
    "MotionTree.build(copy=False)": "tree_in_place",
    "MotionTree.build(copy=False, n_jobs=2)": "tree_threads",
    "MotionTree.build (copy)": "tree",
    "MotionTreeEncoder().fit": "encoder",
    "MotionTreeEncoder(residual_order=2).fit": "encoder2",
    "BisectingKMeans(256)": "bisecting",
    "MiniBatchKMeans(256)": "minibatch",
}
PEERS = {"bisecting", "minibatch"}
ENCODERS = {"encoder", "encoder2"}


def make_frames(n):
    """``n`` frames of a 50-cluster correlated Gaussian mixture, made block by block."""
    rng = np.random.default_rng(0)
    centers = rng.normal(size=(50, N_CHANNELS)) * 2.0
    mixing = rng.normal(size=(N_CHANNELS, N_CHANNELS)) / 8.0
    frames = np.empty((n, N_CHANNELS))
    for start in range(0, n, BLOCK):
        block = frames[start : start + BLOCK]
        local = np.random.default_rng([1, start])
        noise = local.normal(size=block.shape)
        block[:] = centers[local.integers(0, 50, len(block))] + noise @ mixing
    return frames


def _status_bytes(field):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(field)


def worker(method, n):
    """One fit in this fresh process; prints a JSON line."""
    if os.environ.get("SKMOTION_SOURCE"):  # another source tree: before _common's checkout
        sys.path.insert(0, os.environ["SKMOTION_SOURCE"])
    from sklearn.cluster import BisectingKMeans, MiniBatchKMeans

    from skmotion.tree import MotionTree, MotionTreeEncoder

    frames = make_frames(n)
    build = dict(max_depth=8, split="median", min_samples_leaf=16)
    fits = {
        "tree_in_place": lambda: MotionTree.build(frames, copy=False, **build).n_nodes[-1],
        "tree_threads": lambda: MotionTree.build(frames, copy=False, n_jobs=2, **build).n_nodes[-1],
        "tree": lambda: MotionTree.build(frames, **build).n_nodes[-1],
        "before": lambda: MotionTree.build(frames, **build).n_nodes[-1],
        "encoder": lambda: (
            MotionTreeEncoder()
            .fit([frames[s : s + 100] for s in range(0, n, 100)])
            .tree_.n_nodes[-1]
        ),
        "encoder2": lambda: (
            MotionTreeEncoder(residual_order=2)
            .fit([frames[s : s + 100] for s in range(0, n, 100)])
            .tree_.n_nodes[-1]
        ),
        "bisecting": lambda: len(
            BisectingKMeans(n_clusters=256, random_state=0).fit(frames).cluster_centers_
        ),
        "minibatch": lambda: len(
            MiniBatchKMeans(n_clusters=256, random_state=0).fit(frames).cluster_centers_
        ),
    }
    Path("/proc/self/clear_refs").write_text("5")  # the peak from here on
    before = _status_bytes("VmRSS")
    start = time.perf_counter()
    leaves = fits[method]()
    seconds = time.perf_counter() - start
    peak = _status_bytes("VmHWM")
    print(
        json.dumps(
            {
                "skmotion": str(Path(sys.modules["skmotion"].__file__).parents[1]),
                "seconds": seconds,
                "peak": peak,
                "before": before,
                "array": frames.nbytes,
                "leaves": int(leaves),
            }
        )
    )


def run(method, n, source=None):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if source is not None:
        env["SKMOTION_SOURCE"] = str(source)
    out = subprocess.run(
        [sys.executable, __file__, "--worker", method, str(n)],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(sizes, peers_up_to, before=None, only=None, name="scaling_frames"):
    methods = [(k, v, None) for k, v in METHODS.items() if only is None or v in only]
    if before is not None:
        # the old build, and the encoder fits of the old source on the same frames
        methods.append((f"MotionTree.build, {Path(before).name}", "before", before))
        methods += [
            (f"{k}, {Path(before).name}", v, before) for k, v, _ in methods if v in ENCODERS
        ]
    rows = []
    for label, method, source in methods:
        runs = []
        for n in sizes:
            if method in PEERS and n > peers_up_to:
                continue
            if method in ("tree", "before") and n > 1_000_000:
                continue  # the copying builds: their memory figure is clear by 10^6
            result = run(method, n, source)
            print(method, "skmotion from", result["skmotion"], flush=True)
            runs.append((n, result["seconds"]))
            rows.append(
                {
                    "method": label,
                    "frames": n,
                    "fit s": result["seconds"],
                    "frame array MB": result["array"] / 2**20,
                    "peak RSS MB": result["peak"] / 2**20,
                    "peak / frame array": result["peak"] / result["array"],
                    "growth over the array MB": (result["peak"] - result["before"]) / 2**20,
                    "clusters": result["leaves"],
                    "growth exponent": "",
                    "load": os.getloadavg()[0],
                }
            )
            print(rows[-1], f"load {os.getloadavg()[0]:.1f}", flush=True)
        if len(runs) >= 2:
            ns, secs = np.array(runs).T
            rows[-1]["growth exponent"] = float(np.polyfit(np.log(ns), np.log(secs), 1)[0])
    # seconds relative to the in-place tree build of the same size
    tree = {r["frames"]: r["fit s"] for r in rows if r["method"] == "MotionTree.build(copy=False)"}
    for row in rows:
        row["s / tree s"] = row["fit s"] / tree[row["frames"]] if row["frames"] in tree else ""
    write_results(
        name,
        rows,
        notes=(
            "Each fit in a fresh process; peak RSS is that process's VmHWM from just before "
            "the fit (the frames included), so 'peak / frame array' is the whole memory the "
            "fit needs relative to the float64 frames (60 channels). Synthetic frames (50 "
            "correlated Gaussian clusters). OPENBLAS/OMP/MKL threads = 1."
        ),
    )
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worker", nargs=2, metavar=("METHOD", "N"))
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--sizes", type=int, nargs="+")
    parser.add_argument("--peers-up-to", type=int, default=10_000_000)
    parser.add_argument("--before", type=Path, help="another skmotion source tree to compare")
    parser.add_argument("--methods", nargs="+", choices=list(METHODS.values()))
    parser.add_argument("--name", default="scaling_frames", help="results file name")
    args = parser.parse_args()
    if args.worker:
        worker(args.worker[0], int(args.worker[1]))
    else:
        default = [10_000, 100_000] if args.quick else [100_000, 1_000_000, 3_000_000, 10_000_000]
        main(args.sizes or default, args.peers_up_to, args.before, args.methods, args.name)
