"""The out-of-core build on a 2-worker Dask LocalCluster, from frames kept on disk as .npy chunks.

The frames are those of ``bench_scaling_frames.py`` (60 channels, a mixture of 50
correlated Gaussian clusters, made block by block), written to ``--dir`` as ``.npy``
files of 524,288 frames (8 blocks) each, never held whole. The tree is the one that
benchmark builds: ``max_depth=8``, median cuts, ``min_samples_leaf=16``.

- ``--frames N`` (default 10^7): ``build_tree_out_of_core`` on a ``LocalCluster`` of
  two worker processes with one thread each; wall seconds, the frames each subtree task
  held (its share of all frames), each worker's peak resident memory (``ru_maxrss``,
  the worker's whole life: streamed passes and subtrees) and the client's.
- ``--compare N``: on ``N`` frames that fit in memory, ``MotionTree.build`` (in
  memory, ``copy=False``) against the out-of-core build of the same frames from files:
  the same number of nodes in every layer, and the share of frames whose node agrees
  in every layer (the recognition features of a frame are those of its nodes, so an
  agreement of 1 means identical encodings).

- ``--dev``: on MSRC-12 repetitions (odd people train, even people test), the tree of
  ``MotionTreeEncoder().fit`` and the out-of-core build over the same standardised
  training frames: the share of test frames in the same node in every layer, and the
  test accuracy of a logistic regression on the encoder's features with either tree.

Results: ``results/<--name, default out_of_core>.{csv,md}`` (one row: name each
run). Run: ``python benchmarks/bench_out_of_core.py --frames 10000000``.
"""

import os

# before NumPy loads BLAS (and inherited by the cluster's worker processes)
os.environ.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")

import argparse  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_results  # noqa: E402
from bench_scaling_frames import BLOCK, N_CHANNELS, make_frames  # noqa: E402

FILE_BLOCKS = 8  # blocks of make_frames per file: 524,288 frames, 252 MB
TREE = dict(max_depth=8, split="median", min_samples_leaf=16)


def write_frame_files(n, folder):
    """``make_frames(n)``, written file by file (``FILE_BLOCKS`` of its blocks each)."""
    rng = np.random.default_rng(0)  # the same draws as make_frames
    centers = rng.normal(size=(50, N_CHANNELS)) * 2.0
    mixing = rng.normal(size=(N_CHANNELS, N_CHANNELS)) / 8.0
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    rows = BLOCK * FILE_BLOCKS
    for first in range(0, n, rows):
        part = np.empty((min(rows, n - first), N_CHANNELS))
        for start in range(0, len(part), BLOCK):
            block = part[start : start + BLOCK]
            local = np.random.default_rng([1, first + start])
            noise = local.normal(size=block.shape)
            block[:] = centers[local.integers(0, 50, len(block))] + noise @ mixing
        path = folder / f"frames{first // rows:04d}.npy"
        np.save(path.with_suffix(".tmp.npy"), part)
        os.replace(path.with_suffix(".tmp.npy"), path)
        paths.append(path)
    return paths


def cluster_run(paths, n):
    from distributed import Client, LocalCluster

    from skmotion.tree import build_tree_out_of_core

    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            memory_limit=0,
        ) as cluster,
        Client(cluster),
    ):
        start = time.perf_counter()
        tree = build_tree_out_of_core(paths, verbose=1, **TREE)
        seconds = time.perf_counter() - start
    report = tree.build_report_
    workers = {}
    for sub in report["subtrees"]:
        workers[sub["pid"]] = max(workers.get(sub["pid"], 0), sub["peak_rss_mb"])
    frame_mb = n * N_CHANNELS * 8 / 2**20
    return {
        "run": "LocalCluster, 2 worker processes",
        "frames": n,
        "frames MB": round(frame_mb),
        "seconds": round(seconds, 1),
        "leaves": int(tree.n_nodes[-1]),
        "streamed nodes": report["streamed_nodes"],
        "subtree tasks": len(report["subtrees"]),
        "largest task's share of the frames": max(s["frames_held"] for s in report["subtrees"]) / n,
        "workers' peak RSS MB": " / ".join(f"{v:.0f}" for v in sorted(workers.values())),
        "workers' peak RSS / frames": " / ".join(
            f"{v / frame_mb:.3f}" for v in sorted(workers.values())
        ),
        "client peak RSS MB": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
        "same layer sizes as in memory": "",
        "frames in the same node (worst layer)": "",
    }


def compare_run(paths, n):
    import dask

    from skmotion.tree import MotionTree, build_tree_out_of_core

    frames = make_frames(n)
    start = time.perf_counter()
    memory = MotionTree.build(frames, copy=False, **TREE)
    in_memory = time.perf_counter() - start
    start = time.perf_counter()
    with dask.config.set(scheduler="synchronous"):
        tree = build_tree_out_of_core(paths, **TREE)
    seconds = time.perf_counter() - start
    agree = [
        float(np.mean(tree.apply(frames, layer) == memory.apply(frames, layer)))
        for layer in range(min(tree.n_layers, memory.n_layers))
    ]
    return {
        "run": f"synchronous, against MotionTree.build ({in_memory:.1f} s)",
        "frames": n,
        "frames MB": round(frames.nbytes / 2**20),
        "seconds": round(seconds, 1),
        "leaves": int(tree.n_nodes[-1]),
        "streamed nodes": tree.build_report_["streamed_nodes"],
        "subtree tasks": len(tree.build_report_["subtrees"]),
        "largest task's share of the frames": max(
            s["frames_held"] for s in tree.build_report_["subtrees"]
        )
        / n,
        "workers' peak RSS MB": "",
        "workers' peak RSS / frames": "",
        "client peak RSS MB": "",
        "same layer sizes as in memory": tree.n_nodes.tolist() == memory.n_nodes.tolist(),
        "frames in the same node (worst layer)": min(agree),
    }


def dev_run(folder):
    """MSRC-12 repetitions (``bench_live``): the encoder's tree built in memory and out of
    core over the same standardised training frames, and the test accuracy of a logistic
    regression on the encoder's features with either tree."""
    import dask
    from bench_live import msrc12_repetitions
    from sklearn.linear_model import LogisticRegression

    from skmotion.tree import MotionTreeEncoder, build_tree_out_of_core
    from skmotion.tree._encoding import TreeRouter
    from skmotion.utils import stack_clips

    Xtr, ytr, Xte, yte = msrc12_repetitions()
    encoder = MotionTreeEncoder().fit(Xtr)
    frames, _ = stack_clips(Xtr)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, part in enumerate(np.array_split((frames - encoder.center_) / encoder.scale_, 3)):
        paths.append(folder / f"z{i}.npy")
        np.save(paths[-1], part)
    tree = encoder.tree_
    params = dict(max_depth=tree.n_layers - 1, split=encoder.split, covariance_type="spherical")
    with dask.config.set(scheduler="synchronous"):
        ooc = build_tree_out_of_core(
            paths, min_samples_leaf=encoder.min_samples_leaf, max_frames_per_task=len(frames) // 5,
            **params,
        )  # fmt: skip
    out = MotionTreeEncoder().fit(Xtr)  # the same fit, its tree then replaced by ooc
    out.tree_, out._router = ooc, TreeRouter(ooc, out.center_, out.scale_)
    out._residual_means = [ooc.means(layer) for layer in out.residual_layers_]
    test_z = (stack_clips(Xte)[0] - encoder.center_) / encoder.scale_
    agree = min(
        float(np.mean(tree.apply(test_z, layer) == ooc.apply(test_z, layer)))
        for layer in range(tree.n_layers)
    )
    scores = []
    for enc in (encoder, out):
        model = LogisticRegression(max_iter=3000).fit(enc.transform(Xtr), ytr)
        scores.append(model.score(enc.transform(Xte), yte))
    return {
        "run": "MSRC-12 repetitions: MotionTreeEncoder's tree in memory / out of core",
        "frames": len(frames),
        "same layer sizes as in memory": tree.n_nodes.tolist() == ooc.n_nodes.tolist(),
        "test frames in the same node (worst layer)": agree,
        "test accuracy, in-memory tree": scores[0],
        "test accuracy, out-of-core tree": scores[1],
        "largest feature difference": float(
            np.abs(encoder.transform(Xte) - out.transform(Xte)).max()
        ),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=10_000_000)
    parser.add_argument("--compare", type=int, default=None)
    parser.add_argument("--dev", action="store_true", help="MSRC-12: the encoder either way")
    parser.add_argument("--dir", default="/tmp/skmotion-out-of-core")
    parser.add_argument("--keep", action="store_true", help="keep the frame files")
    parser.add_argument("--name", default="out_of_core")
    args = parser.parse_args()
    n = args.compare or args.frames
    folder = Path(args.dir) / str(n)
    if args.dev:
        folder = Path(args.dir) / "dev"
        try:
            row = dev_run(folder)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        print(row)
        write_results(args.name, [row], notes="OPENBLAS/OMP/MKL threads = 1")
        return
    try:
        start = time.perf_counter()
        paths = write_frame_files(n, folder)
        print(f"{len(paths)} files in {time.perf_counter() - start:.0f} s", file=sys.stderr)
        row = compare_run(paths, n) if args.compare else cluster_run(paths, n)
    finally:
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)
    print(row)
    write_results(args.name, [row], notes="OPENBLAS/OMP/MKL threads = 1; " + str(TREE))


if __name__ == "__main__":
    main()
