"""Long inputs: time and peak memory of MotionTreeHMM and the readers on 10^4 to 10^6 frames.

Each measurement runs in a fresh subprocess, which reports its wall time and the
growth of its peak resident memory during the call (Linux's ``VmHWM``, reset just
before the call, minus the resident size then: the interpreter, the libraries and
the fitted model are not counted).
The ratio ``extra_MB / input_MB`` compares that growth with the input's own size:
the clip's float64 array for MotionTreeHMM, the channel array read for the
readers. Peers in the same run: hmmlearn's ``GaussianHMM.decode`` (Viterbi in C,
as many states as the tree layer decoded) on the same clip, and bvhio reading the
same BVH file.

- ``MotionTreeHMM``: three classes of synthetic motions (60 joint-angle channels),
  ``max_depth=3``; a long clip is their frames repeated. ``loglik_per_frame``
  (the best class's log-likelihood divided by the frame count) stays the same at
  every length when nothing underflows.
- readers: a BVH file of the 26-joint humanoid (66 channels) written by
  ``write_bvh``, an AMC file of the 5-bone toy ASF skeleton (12 channels).

Run: ``python benchmarks/bench_long_inputs.py`` (10^4 and 10^5 frames; ``--huge``
adds 10^6 frames for the readers; ``--quick`` runs 10^3 and 10^4). Needs the
``bench`` extra (hmmlearn, bvhio).
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_results  # noqa: E402

from tests.bad_input.long_inputs import fitted_hmm, long_clip, write_long_amc, write_long_bvh  # noqa: E402


def _status_bytes(field):
    """A memory figure of this process from /proc/self/status (Linux), in bytes."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(field)


def _measure(call):
    """(result, seconds, growth of peak resident memory during the call).

    The peak (VmHWM) is reset to the current resident size first: ``ru_maxrss``
    would not do, as a child process inherits its parent's peak across exec.
    """
    Path("/proc/self/clear_refs").write_text("5")
    before = _status_bytes("VmRSS")
    start = time.perf_counter()
    result = call()
    seconds = time.perf_counter() - start
    return result, seconds, _status_bytes("VmHWM") - before


def worker(operation, n_frames, folder):
    """One measurement, in this (fresh) process; prints a JSON line."""
    out = {}
    if operation.startswith("hmm") or operation == "hmmlearn_decode":
        model, base = fitted_hmm()
        clip = long_clip(base, n_frames)
        input_bytes = clip.nbytes
        if operation == "hmm_decode":
            states, seconds, extra = _measure(lambda: model.decode([clip])[1][0])
            out["finite"] = bool((states >= 0).all())
        elif operation == "hmm_score_samples":
            log_lik, seconds, extra = _measure(lambda: model.score_samples([clip])[0])
            out["finite"] = bool(np.isfinite(log_lik).all())
            out["loglik_per_frame"] = float(log_lik.max() / n_frames)
        else:
            from hmmlearn.hmm import GaussianHMM

            peer = GaussianHMM(
                len(model.tree_.node_ids(model.layer_)),
                covariance_type="diag",
                n_iter=5,
                random_state=0,
            )
            peer.fit(base)
            (log_lik, _), seconds, extra = _measure(lambda: peer.decode(clip))
            out["finite"] = bool(np.isfinite(log_lik))
    else:
        from skmotion.io import read_amc, read_asf, read_bvh

        folder = Path(folder)
        if operation == "read_bvh":
            motion, seconds, extra = _measure(lambda: read_bvh(folder / "long.bvh"))
            channels = motion.channels
        elif operation == "bvhio_read":
            import bvhio

            _, seconds, extra = _measure(lambda: bvhio.readAsBvh(str(folder / "long.bvh")))
            channels = np.empty((n_frames, 66))  # the same values as read_bvh's
        else:
            skeleton = read_asf(folder / "toy.asf")
            motion, seconds, extra = _measure(lambda: read_amc(folder / "long.amc", skeleton))
            channels = motion.channels
        assert channels.shape[0] == n_frames
        out["finite"] = bool(np.isfinite(channels).all())
        out["file_bytes"] = (
            (folder / ("long.amc" if operation == "read_amc" else "long.bvh")).stat().st_size
        )
        input_bytes = channels.nbytes
    out.update(seconds=seconds, extra_bytes=extra, input_bytes=input_bytes)
    print(json.dumps(out))


def run(operation, n_frames, folder):
    command = [sys.executable, __file__, "--worker", operation, str(n_frames), str(folder)]
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _row(what, n_frames, result, peer=None):
    row = {
        "what": what,
        "frames": n_frames,
        "seconds": result["seconds"],
        "us_per_frame": 1e6 * result["seconds"] / n_frames,
        "input_MB": result["input_bytes"] / 1e6,
        "file_MB": result["file_bytes"] / 1e6 if "file_bytes" in result else "",
        "extra_MB": result["extra_bytes"] / 1e6,
        "extra_per_input": result["extra_bytes"] / result["input_bytes"],
        "finite": result["finite"],
        "loglik_per_frame": result.get("loglik_per_frame", ""),
        "peer": "",
        "time_vs_peer": "",
        "extra_vs_peer": "",
    }
    if peer is not None:
        name, other = peer
        row["peer"] = name
        row["time_vs_peer"] = result["seconds"] / other["seconds"]
        row["extra_vs_peer"] = result["extra_bytes"] / max(other["extra_bytes"], 1)
    return row


def main(hmm_sizes, reader_sizes):
    rows = []
    for n in hmm_sizes:
        peer = run("hmmlearn_decode", n, "")
        rows.append(
            _row("MotionTreeHMM.decode", n, run("hmm_decode", n, ""), ("hmmlearn decode", peer))
        )
        rows.append(_row("MotionTreeHMM.score_samples", n, run("hmm_score_samples", n, "")))
        rows.append(_row("hmmlearn GaussianHMM.decode", n, peer))
        print(rows[-3:], flush=True)
    for n in reader_sizes:
        with tempfile.TemporaryDirectory() as folder:
            write_long_bvh(Path(folder) / "long.bvh", n)
            write_long_amc(Path(folder), n)
            bvh = run("read_bvh", n, folder)
            peer = run("bvhio_read", n, folder) if n <= 100_000 else None
            rows.append(_row("read_bvh", n, bvh, ("bvhio", peer) if peer else None))
            rows.append(_row("read_amc", n, run("read_amc", n, folder)))
            print(rows[-2:], flush=True)
    write_results(
        "long_inputs",
        rows,
        notes="Time and growth of peak resident memory (VmHWM reset before the call, each "
        "measurement in a fresh process) against the input's own size (extra_per_input; input: "
        "the clip, or the channel array read from a file of file_MB). time_vs_peer / "
        "extra_vs_peer: skmotion over the peer, same input. loglik_per_frame: the best class's "
        "log-likelihood per frame (the same at every length: no underflow).",
    )


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker(sys.argv[2], int(sys.argv[3]), sys.argv[4])
        sys.exit()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^3 and 10^4 frames only")
    parser.add_argument("--huge", action="store_true", help="also 10^6 frames through the readers")
    args = parser.parse_args()
    if args.quick:
        main([1_000, 10_000], [1_000, 10_000])
    else:
        main([10_000, 100_000], [10_000, 100_000] + ([1_000_000] if args.huge else []))
