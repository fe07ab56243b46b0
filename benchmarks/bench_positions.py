"""Joint positions: gap-filling error by gap length, speed, memory, recognition.

On CMU subjects 01-03 (``../shared/data/cmu-asfamc``) turned into the joint
positions of every layout by forward kinematics (each layout in 3-D), 5-20% of
the values of each clip are removed in gaps of 1-30 frames and filled again:

- ``FillGaps`` (rigid-body fill, then cubic spline), ``FillGaps(method="linear")``
  and the peer ``pandas.DataFrame.interpolate`` (linear, same ``limit``), error
  in cm against the removed true values, by gap length;
- frames per second of ``VirtualMarkerTransform(layout=...)`` without and with
  velocities, against the previous implementations run in the same process
  (``body_frame_features``, one root marker; and, with ``--before-src``, the
  ``position_frame_features`` of that source tree, e.g. the numpy one of commit
  467af5c), and of gap filling;
- peak memory (VmHWM of a fresh process) of ``VirtualMarkerTransform`` on one
  10^5-frame joint-angle clip;
- recognition from positions vs from joint angles of the same clips (synthetic
  subjects, and windows of CMU trials), through :func:`recognition_pipeline`.

Run ``python benchmarks/bench_positions.py`` (quick: 4 trials per subject, at most
2400 frames each) or ``--full``; ``--data`` points at the shared data folder;
``--only-speed`` runs the timings alone (set ``OPENBLAS_NUM_THREADS=1`` for one core).
Timings are CPU seconds of this process (``time.process_time``) as well as wall
seconds: the machine may be shared.
"""

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import FunctionTransformer

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, write_results  # noqa: E402

from skmotion.datasets import layout_positions, make_position_motions  # noqa: E402
from skmotion.io import Motion, as_motions, read_amc, read_asf  # noqa: E402
from skmotion.preprocessing import (  # noqa: E402
    LAYOUTS,
    FillGaps,
    VirtualMarkerTransform,
    body_frame_features,
    get_layout,
)
from skmotion.tree import MotionTreeEncoder  # noqa: E402

CM_PER_UNIT = 2.54 / 0.45  # CMU ASF lengths are in 1/0.45 inch
BINS = ((1, 2), (3, 5), (6, 10), (11, 20), (21, 30))


def recognition_pipeline(first):
    """The recogniser compared on positions and on angles: the recommended one.

    ``first`` (the virtual markers of the input), then ``MotionTreeEncoder()`` and a
    ``LogisticRegression``, every parameter at its default (see docs/motion-database.md).
    """
    return make_pipeline(first, MotionTreeEncoder(), LogisticRegression(max_iter=5000))


def cut_gaps(clip, dim, rng, fraction):
    """Remove about ``fraction`` of the point-frames in interior gaps of 1-30 frames."""
    n_frames, n_points = len(clip), clip.shape[1] // dim
    mask = np.zeros((n_frames, n_points), dtype=bool)
    target, tries = fraction * mask.size, 0
    while mask.sum() < target and tries < 50 * n_points:
        tries += 1
        length = int(rng.integers(1, 31))
        start = int(rng.integers(2, max(3, n_frames - length - 2)))
        point = int(rng.integers(n_points))
        if not mask[max(start - 2, 0) : start + length + 2, point].any():
            mask[start : start + length, point] = True
    holed = clip.copy()
    holed.reshape(n_frames, n_points, dim)[mask] = np.nan
    return holed, mask


def pandas_fill(clip, max_gap):
    """Peer: pandas linear interpolation of interior gaps up to ``max_gap`` frames."""
    frame = pd.DataFrame(clip)
    return frame.interpolate(method="linear", limit=max_gap, limit_area="inside").to_numpy()


def load_cmu(data, max_trials, max_frames):
    clips = []
    for subject in ("01", "02", "03"):
        folder = data / "cmu-asfamc" / subject
        skeleton = read_asf(folder / f"{subject}.asf")
        for amc in sorted(folder.glob("*.amc"))[:max_trials]:
            motion = read_amc(amc, skeleton)
            clips.append(
                (amc.stem, Motion(skeleton, motion.channels[:max_frames], frame_rate=120.0))
            )
    return clips


def fill_errors(motions, rng):
    rows = []
    for name in LAYOUTS:
        layout = get_layout(name, dim=3)
        methods = {
            "FillGaps cubic + rigid": FillGaps(max_gap=30, layout=layout),
            "FillGaps linear": FillGaps(max_gap=30, layout=layout, method="linear", groups=[]),
            "pandas interpolate (linear)": None,
        }
        errors = {m: [] for m in methods}
        lengths, seconds = [], dict.fromkeys(methods, 0.0)
        for _, motion in motions:
            truth = layout_positions(motion.skeleton, motion.channels, layout)
            holed, mask = cut_gaps(truth, 3, rng, rng.uniform(0.05, 0.20))
            run_length = _run_lengths(mask)
            lengths.append(run_length[mask])
            for method, fill in methods.items():
                start = time.process_time()
                out = pandas_fill(holed, 30) if fill is None else fill.fit_transform([holed])[0]
                seconds[method] += time.process_time() - start
                diff = (out - truth).reshape(len(truth), -1, 3)[mask]
                errors[method].append(np.linalg.norm(diff, axis=1) * CM_PER_UNIT)
        lengths = np.concatenate(lengths)
        n_frames = sum(len(m.channels) for _, m in motions)
        for method, errs in errors.items():
            errs = np.concatenate(errs)
            row = {"layout": name, "method": method}
            for lo, hi in BINS:
                sel = (lengths >= lo) & (lengths <= hi)
                row[f"median cm, gaps {lo}-{hi}"] = float(np.nanmedian(errs[sel]))
            row["p90 cm, gaps 1-10"] = float(np.nanpercentile(errs[lengths <= 10], 90))
            row["frames/s (cpu)"] = n_frames / seconds[method]
            rows.append(row)
    return rows


def _run_lengths(mask):
    """For each missing point-frame, the length of its gap."""
    out = np.zeros(mask.shape, dtype=int)
    for j in range(mask.shape[1]):
        edges = np.flatnonzero(np.diff(np.r_[0, mask[:, j].astype(int), 0]))
        for start, stop in zip(edges[::2], edges[1::2]):
            out[start:stop, j] = stop - start
    return out


def _rates(steps, rounds=5):
    """Median CPU and wall frames/s of each ``(func, n_frames)``, timed in alternation."""
    for func, _ in steps.values():
        func()  # warm-up
    cpu = {name: [] for name in steps}
    wall = {name: [] for name in steps}
    for _ in range(rounds):
        for name, (func, n_frames) in steps.items():
            c, w = time.process_time(), time.perf_counter()
            func()
            cpu[name].append(n_frames / (time.process_time() - c))
            wall[name].append(n_frames / (time.perf_counter() - w))
    return {name: (float(np.median(cpu[name])), float(np.median(wall[name]))) for name in steps}


def _previous_frame_features(src):
    """``position_frame_features`` of an older source tree (its module needs only numpy)."""
    path = Path(src) / "skmotion" / "preprocessing" / "_position_frame.py"
    spec = importlib.util.spec_from_file_location("previous_position_frame", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.position_frame_features


def _previous_steps(features, vmt, clip):
    """The previous body frame with ``vmt``'s fitted roles, without and with velocities."""
    layout = vmt.layout_
    points = clip.reshape(len(clip), layout.n_joints, layout.dim)
    kw = dict(root=vmt.root_index_, lefts=vmt.facing_indices_[0], rights=vmt.facing_indices_[1])
    kw.update(size_chain=vmt.size_indices_, up=layout.up, frame_rate=120.0)
    return {
        f"previous position_frame_features, velocities={v}": (
            partial(features, points, velocities=v, outputs=vmt._outputs, **kw),
            len(clip),
        )
        for v in (False, True)
    }


def speed(motions, n_frames, before_src=None):
    before = None if before_src is None else _previous_frame_features(before_src)
    skeleton, channels = motions[0][1].skeleton, motions[0][1].channels
    reps = -(-n_frames // len(channels))
    rows = []
    for name in ("kinect_v2", "mediapipe_pose33", "coco17"):
        layout = get_layout(name, dim=3)
        clip = np.tile(layout_positions(skeleton, channels, layout), (reps, 1))[:n_frames]
        if LAYOUTS[name].dim == 2:  # image keypoints: drop depth (a projection does not matter)
            layout = LAYOUTS[name]
            clip = clip.reshape(n_frames, -1, 3)[..., :2].reshape(n_frames, -1)
        steps, fitted = {}, {}
        for velocities in (False, True):
            vmt = VirtualMarkerTransform(
                layout=layout, markers="all", velocities=velocities, frame_rate=120.0
            ).fit([clip])
            steps[f"layout transform, velocities={velocities}"] = (
                partial(vmt.transform, [clip]),
                n_frames,
            )
            fitted[velocities] = vmt
        short = [clip[i : i + 100] for i in range(0, n_frames, 100)]  # 1000 windows
        steps["layout transform, 100-frame clips, velocities=False"] = (
            partial(fitted[False].transform, short),
            n_frames,
        )
        if before is not None:
            steps.update(_previous_steps(before, vmt, clip))
        if layout.dim == 3:
            points = clip.reshape(n_frames, layout.n_joints, 3)
            left, right = layout.index(layout.left_hip), layout.index(layout.right_hip)
            previous = partial(
                body_frame_features, points, frame_rate=120.0, root=left, left=left, right=right
            )
            steps["previous body_frame_features (velocities)"] = (previous, n_frames)
        holed, _ = cut_gaps(clip[:20_000], layout.dim, np.random.default_rng(0), 0.10)
        fill = FillGaps(max_gap=30, layout=layout).fit([holed])
        steps["FillGaps, 10% missing"] = (partial(fill.transform, [holed]), len(holed))
        for step, (cpu, wall) in _rates(steps).items():
            rows.append(_speed_row(name, step, cpu, wall))
    return rows


def _speed_row(layout, what, cpu, wall):
    return {"layout": layout, "step": what, "frames/s (cpu)": cpu, "frames/s (wall)": wall}


_MEMORY_SCRIPT = """
import sys, numpy as np
sys.path.insert(0, {src!r})
from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.preprocessing import VirtualMarkerTransform
data = make_motions(n_clips_per_class=1, classes=["walk"], frame_rate=120.0, random_state=0)
clip = np.tile(data.clips[0], (100_000 // len(data.clips[0]) + 1, 1))[:100_000]
vmt = VirtualMarkerTransform(data.skeletons[0], frame_rate=120.0).fit([clip[:10]])
def status(key):
    lines = open("/proc/self/status").read().splitlines()
    return int([line for line in lines if line.startswith(key)][0].split()[1]) / 1024
before = status("VmRSS")
out = vmt.transform([clip])[0]
print(status("VmHWM"), before, out.nbytes / 2**20)
"""


def memory(src):
    """Peak resident MB of a fresh process transforming one 10^5-frame joint-angle clip."""
    script = _MEMORY_SCRIPT.format(src=str(src))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(done.stderr)
    peak, before, output = (float(v) for v in done.stdout.split())
    return {
        "source": str(src),
        "peak MB": peak,
        "resident before transform MB": before,
        "output MB": output,
    }


def recognition_synthetic():
    rows = []
    kw = dict(n_clips_per_class=8, n_subjects=4, duration=(1.5, 2.5), random_state=0)
    angles = make_position_motions("kinect_v2", **kw)
    motions = as_motions(angles.angles, angles.skeletons, angles.frame_rate)
    cv = GroupKFold(4)
    score = cross_val_score(
        recognition_pipeline(VirtualMarkerTransform()), motions, angles.target,
        groups=angles.groups, cv=cv,
    ).mean()  # fmt: skip
    rows.append(
        {"data": "synthetic, 4 subjects", "input": "joint angles -> 32 markers", "acc": score}
    )
    raw = FunctionTransformer(lambda X: X)
    score = cross_val_score(
        recognition_pipeline(raw), angles.angles, angles.target, groups=angles.groups, cv=cv
    ).mean()
    rows.append({"data": "synthetic, 4 subjects", "input": "joint angles, raw", "acc": score})
    for name in ("kinect_v2", "coco17", "mediapipe_pose33"):
        data = make_position_motions(name, **kw)
        vmt = VirtualMarkerTransform(layout=name, frame_rate=data.frame_rate)
        score = cross_val_score(
            recognition_pipeline(vmt), data.clips, data.target, groups=data.groups, cv=cv
        ).mean()
        rows.append({"data": "synthetic, 4 subjects", "input": f"positions, {name}", "acc": score})
    return rows


def recognition_cmu(motions):
    """Windows of CMU trials, classes by description, folds grouped by trial."""
    classes = {"01": "playground", "02_01": "walk", "02_02": "walk", "03": "walk"}
    classes.update({f"02_0{t}": "swordplay" for t in (7, 8, 9)})
    windows, labels, groups, sources = [], [], [], []
    for trial, motion in motions:
        label = classes.get(trial) or classes.get(trial[:2])
        if label is None:
            continue
        for start in range(0, len(motion.channels) - 120, 120):
            windows.append(
                Motion(motion.skeleton, motion.channels[start : start + 120], frame_rate=120.0)
            )
            labels.append(label)
            groups.append(trial)
    labels, groups = np.asarray(labels), np.asarray(groups)
    if len(set(labels)) < 2 or len(set(groups)) < 3:
        return []
    cv = GroupKFold(3)
    rows = []
    score = cross_val_score(
        recognition_pipeline(VirtualMarkerTransform()), windows, labels, groups=groups, cv=cv
    ).mean()
    rows.append(
        {"data": "CMU 01-03, 1 s windows", "input": "joint angles -> 32 markers", "acc": score}
    )
    for name in ("kinect_v2", "mediapipe_pose33"):
        layout = get_layout(name)
        sources = [layout_positions(w.skeleton, w.channels, layout) for w in windows]
        vmt = VirtualMarkerTransform(layout=name, up_axis="y", frame_rate=120.0)
        score = cross_val_score(
            recognition_pipeline(vmt), sources, labels, groups=groups, cv=cv
        ).mean()
        rows.append({"data": "CMU 01-03, 1 s windows", "input": f"positions, {name}", "acc": score})
    return rows


def figure(rows, folder):
    """Median fill error by gap length, per method, for three layouts."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    centres = [(lo + hi) / 2 for lo, hi in BINS]
    labels = [f"{lo}-{hi}" for lo, hi in BINS]
    shown = ("kinect_v2", "mediapipe_pose33", "h36m17")
    fig, axes = plt.subplots(1, len(shown), figsize=(11, 3.4), sharey=True)
    for ax, name in zip(axes, shown):
        for row in (r for r in rows if r["layout"] == name):
            values = [row[f"median cm, gaps {lo}-{hi}"] for lo, hi in BINS]
            style = "--" if row["method"].startswith("pandas") else "-"
            ax.plot(centres, values, style, marker="o", label=row["method"])
        ax.axhline(1.0, color="grey", lw=0.8, ls=":")
        ax.set_xticks(centres, labels)
        ax.set_title(name)
        ax.set_xlabel("gap length (frames at 120 Hz)")
    axes[0].set_ylabel("median error (cm)")
    axes[0].legend(fontsize=8)
    fig.suptitle("Gaps cut into CMU subjects 01-03 (joint positions by FK), filled again")
    fig.tight_layout()
    folder.mkdir(exist_ok=True)
    fig.savefig(folder / "positions_fill_error.png", dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="every trial, whole length")
    default = os.environ.get("SKMOTION_SHARED_DATA", str(SHARED_DATA))
    parser.add_argument("--data", default=default, help="the shared data folder")
    parser.add_argument(
        "--before-src", help="a source tree of an older skmotion, for memory and the body frame"
    )
    parser.add_argument("--figure", action="store_true", help="write docs/images/positions_*.png")
    parser.add_argument("--only-speed", action="store_true", help="only the timings")
    parser.add_argument("--only-recognition", action="store_true", help="only positions vs angles")
    args = parser.parse_args(argv)
    data = Path(args.data)
    if not (data / "cmu-asfamc").is_dir():
        data = Path("/work/shared/data") if Path("/work/shared/data/cmu-asfamc").is_dir() else data
    if not (data / "cmu-asfamc").is_dir():
        sys.exit(f"CMU data not found under {data}; give --data")
    motions = load_cmu(data, 99 if args.full else 4, None if args.full else 2400)
    n_frames = sum(len(m.channels) for _, m in motions)
    rng = np.random.default_rng(0)
    note = f"{len(motions)} CMU trials (subjects 01-03), {n_frames} frames at 120 Hz."
    if args.only_speed:
        rows = speed(motions, 100_000, args.before_src)
        write_results("positions_speed", rows, notes="10^5-frame clips.")
        return
    if args.only_recognition:
        rows = recognition_synthetic() + recognition_cmu(motions)
        write_results("positions_recognition", rows, notes=recognition_pipeline.__doc__.strip())
        return
    fill_rows = fill_errors(motions, rng)
    write_results("positions_fill", fill_rows, notes=note)
    if args.figure:
        figure(fill_rows, Path(__file__).resolve().parents[1] / "docs" / "images")
    rows = speed(motions, 100_000, args.before_src)
    write_results("positions_speed", rows, notes="10^5-frame clips.")
    mem = [memory(Path(__file__).resolve().parents[1])]
    if args.before_src:
        mem.insert(0, memory(Path(args.before_src)))
    write_results("positions_memory", mem, notes="VmHWM of a fresh process, 10^5 frames.")
    rows = recognition_synthetic() + recognition_cmu(motions)
    write_results("positions_recognition", rows, notes=recognition_pipeline.__doc__.strip())
    print(json.dumps({"trials": len(motions), "frames": n_frames}))


if __name__ == "__main__":
    main()
