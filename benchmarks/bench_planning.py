"""The planning experiment of paper 000 (section VI-E, Figure 13): goal 2.0 m ahead and 1.0 m left.

Databases: synthetic walks (forward, sideways, backward), and the same plus CMU
walks of subjects 02 and 03 (ASF/AMC) and 07 (BVH, Character Creator skeleton)
when ../shared/data is present, all in one marker space through ``to_markers``.
For each: the search time (target under 5 s), the distance of the final root to
the goal (target 0.15 m), whether every transition was seen in the data, and the
ratio of the weighted search's time to plain A* (heuristic_weight=1, capped at
20k expansions) in the same run.

    /work/venv/bin/python benchmarks/bench_planning.py
"""

import time

import numpy as np
from _common import SHARED_DATA, write_results

from skmotion.datasets import load_bvh_folder, load_cmu_asfamc, make_walks
from skmotion.io import Motion, as_motions
from skmotion.planning import UnreachableGoalError
from skmotion.preprocessing import VirtualMarkerTransform, to_markers
from skmotion.tree import MotionTreeHMM

FRAME_RATE = 30.0
GOAL = (2.0, 1.0)


def _at_rate(motion):
    step = max(1, int(round(motion.frame_rate / FRAME_RATE)))
    return Motion(motion.skeleton, motion.channels[::step], frame_rate=motion.frame_rate / step)


def _cmu_walks():
    if not SHARED_DATA.is_dir():
        return []
    asf = load_cmu_asfamc(
        SHARED_DATA / "cmu-asfamc", SHARED_DATA / "cmu-index.csv", subjects=[2, 3]
    )
    motions = [m for m, d in zip(asf.motions, asf.description) if "walk" in str(d).lower()]
    bvh = load_bvh_folder(SHARED_DATA / "cmu-bvh" / "07", channel_layouts="any")
    motions += list(bvh.motions)
    return [_at_rate(m) for m in motions]


def _run(name, X, target, transformer, body_size):
    rows = []
    for depth in (5, 7):
        model = MotionTreeHMM(max_depth=depth, split="median").fit(X, target)
        for root_motion, tf in (("skeleton", transformer), ("rigid", None)):
            kwargs = dict(
                frame_rate=FRAME_RATE, transformer=tf, body_size=body_size, tolerance=0.15
            )
            began = time.perf_counter()
            try:
                plan = model.plan((0, 0, 0), GOAL, **kwargs)
            except UnreachableGoalError as exc:
                rows.append(
                    {
                        "database": name,
                        "layer_nodes": int(model.n_nodes_[-1]),
                        "root_motion": root_motion,
                        "frames": 0,
                        "goal_distance_m": float("nan"),
                        "all_seen": "-",
                        "log_p": float("nan"),
                        "search_s": float("nan"),
                        "total_s": time.perf_counter() - began,
                        "plain_astar_ratio": str(exc)[:60],
                    }
                )
                continue
            total = time.perf_counter() - began
            assert (plan.seen_counts > 0).all()
            try:
                plain = model.plan(
                    (0, 0, 0), GOAL, heuristic_weight=1.0, max_expansions=20_000, **kwargs
                )
                ratio = (
                    f"{plain.search_seconds / plan.search_seconds:.3g} "
                    f"(log_p {plain.log_probability:.1f})"
                )
            except UnreachableGoalError:
                ratio = "plain A* gave up at 20k expansions"
            rows.append(
                {
                    "database": name,
                    "layer_nodes": int(model.n_nodes_[-1]),
                    "root_motion": root_motion,
                    "frames": plan.n_frames,
                    "goal_distance_m": plan.reached,
                    "all_seen": bool((plan.seen_counts > 0).all()),
                    "log_p": plan.log_probability,
                    "search_s": plan.search_seconds,
                    "total_s": total,
                    "plain_astar_ratio": ratio,
                }
            )
            print(rows[-1])
    return rows


def main():
    walks = make_walks(3, random_state=0)
    synthetic = as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    transformer = VirtualMarkerTransform(walks.skeleton, frame_rate=walks.frame_rate).fit(
        walks.clips[:1]
    )
    # The humanoid is in metres: one data unit is its size along the ankle-to-head chain.
    rows = _run(
        "synthetic walks",
        VirtualMarkerTransform().fit_transform(synthetic),
        walks.target,
        transformer,
        None,
    )
    cmu = _cmu_walks()
    if cmu:
        X, _ = to_markers(synthetic + cmu)
        target = np.r_[walks.target, np.full(len(cmu), walks.target.max() + 1)]
        rows += _run(f"synthetic + CMU 02/03/07 ({len(cmu)} walks)", X, target, transformer, None)
    write_results(
        "planning",
        rows,
        notes=(
            f"goal {GOAL[0]} m ahead, {GOAL[1]} m left; tolerance 0.15 m; {FRAME_RATE:g} fps; "
            "heuristic_weight=8 (plain_astar_ratio: search time of heuristic_weight=1 over it, "
            "same run)"
        ),
    )


if __name__ == "__main__":
    main()
