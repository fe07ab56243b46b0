"""Demo section: planning a walk to a goal on the transition graph (Yamane et al. 2011, V-C)."""

from skmotion._demo._figures import save_figure
from skmotion.datasets import make_walks
from skmotion.io import as_motions
from skmotion.planning import UnreachableGoalError
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM

TITLE = "Planning: a walk to a goal on the transition graph"


def run(context):
    folder = getattr(context, "data_folder", None)
    if folder:
        return [
            f"not run on {folder}: the planner needs a database of walks that turn and side-step "
            "(a transition graph with somewhere to go); run `skmotion demo` without --data to "
            "see it on the built-in make_walks data"
        ]
    # A walking database of its own: the recognition data's walks travel forward only.
    walks = make_walks(2, random_state=context.random_state)
    X = VirtualMarkerTransform().fit_transform(
        as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    )
    model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
    transformer = VirtualMarkerTransform(walks.skeleton, frame_rate=walks.frame_rate).fit(
        walks.clips[:1]
    )
    plan = model.plan(
        (0, 0, 0), (2.0, 1.0), frame_rate=walks.frame_rate, transformer=transformer, tolerance=0.15
    )
    context.plan = plan
    x, y, heading = plan.root[-1]
    lines = [
        f"database: {len(walks.clips)} walks ({', '.join(walks.target_names)}), layer "
        f"{plan.layer} with {model.n_nodes_[plan.layer]} nodes",
        "goal 2.0 m ahead and 1.0 m left:",
        f"  {plan.n_frames} frames ({plan.n_frames / plan.frame_rate:.1f} s) through "
        f"{len(set(plan.nodes.tolist()))} nodes, log probability {plan.log_probability:.1f}, "
        "every transition seen in the data "
        f"({int(plan.seen_counts.min())}+ times)",
        f"  root ends at x={x:.2f} m, y={y:.2f} m ({plan.reached:.3f} m from the goal), search "
        f"{plan.search_seconds * 1000:.0f} ms; IK joint angles fit within "
        f"{plan.ik_rms.max() * 100:.1f} cm (plan.to_motion() writes with write_bvh)",
    ]
    try:
        model.plan(
            (0, 0, 0), (30.0, 0.0), frame_rate=walks.frame_rate, body_size=1.6, max_frames=120
        )
    except UnreachableGoalError as exc:
        lines.append(f"goal 30 m ahead within 120 frames: unreachable, {exc}")
    return lines + save_figure(
        context,
        "planned_root_path.png",
        lambda plotting: plotting.plot_plan(plan),
        "the planned root path and the goal (Yamane et al. 2011, Figure 13 left)",
    )
