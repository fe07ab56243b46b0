"""Planning on the transition graph: optimality, the paper's experiment, unreachable goals, BVH."""

import itertools

import numpy as np
import pytest

from skmotion.datasets import make_walks
from skmotion.io import as_motions, read_bvh, write_bvh
from skmotion.planning import UnreachableGoalError, astar_search, plan_axes
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM


def _brute_force(succ, costs, steps, start_costs, goal, tol, max_frames):
    """The cheapest path by enumerating every node sequence (tiny graphs only)."""
    best = np.inf
    n_nodes = len(steps)
    for length in range(1, max_frames + 1):
        for path in itertools.product(range(n_nodes), repeat=length):
            if not np.isfinite(start_costs[path[0]]) or any(
                b not in succ[a] for a, b in zip(path, path[1:])
            ):
                continue
            x = y = h = 0.0
            for n in path[:-1]:
                dx, dy, dh = steps[n]
                x, y, h = (
                    x + np.cos(h) * dx - np.sin(h) * dy,
                    y + np.sin(h) * dx + np.cos(h) * dy,
                    h + dh,
                )
            if np.hypot(goal[0] - x, goal[1] - y) <= tol:
                best = min(
                    best, start_costs[path[0]] + sum(costs[a, b] for a, b in zip(path, path[1:]))
                )
    return best


@pytest.mark.parametrize(
    "succ",
    [
        {0: [0, 1, 2], 1: [1, 2], 2: [0, 2]},
        {0: [0, 1, 2], 1: [2], 2: [0, 1]},  # nodes 1 and 2 without a self-loop
    ],
)
def test_astar_finds_the_brute_force_optimum(succ):
    rng = np.random.default_rng(3)
    costs = np.full((3, 3), np.inf)
    for a, bs in succ.items():
        p = rng.dirichlet(np.ones(len(bs)))
        costs[a, bs] = -np.log(p)
    steps = np.array([[0.3, 0.0, 0.0], [0.0, 0.25, 0.0], [0.1, 0.0, 0.5]])
    indptr = np.cumsum([0] + [len(succ[a]) for a in range(3)])
    indices = np.concatenate([succ[a] for a in range(3)])
    flat = np.concatenate([costs[a, succ[a]] for a in range(3)])
    start_costs = np.array([0.0, 1.0, np.inf])
    for goal in [(0.9, 0.5), (0.6, 0.75), (0.4, 0.4)]:
        expected = _brute_force(succ, costs, steps, start_costs, goal, 0.12, 8)
        found = astar_search(
            indptr,
            indices,
            flat,
            steps,
            start_costs,
            (0, 0, 0),
            goal,
            tolerance=0.12,
            max_frames=8,
            heuristic_weight=1.0,
            cell=1e-3,
            heading_bins=100000,
        )
        assert found.cost == pytest.approx(expected)
        assert np.hypot(*(found.poses[-1, :2] - goal)) <= 0.12


@pytest.fixture(scope="module")
def walk_database():
    walks = make_walks(2, random_state=0)
    motions = as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    X = VirtualMarkerTransform().fit_transform(motions)
    model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
    transformer = VirtualMarkerTransform(walks.skeleton, frame_rate=walks.frame_rate).fit(
        walks.clips[:1]
    )
    return walks, X, model, transformer


def test_the_papers_experiment_2m_ahead_1m_left(walk_database):
    walks, _, model, transformer = walk_database
    plan = model.plan(
        (0, 0, 0), (2.0, 1.0), frame_rate=walks.frame_rate, transformer=transformer, tolerance=0.15
    )
    assert plan.reached <= 0.15
    assert (plan.seen_counts > 0).all()  # only transitions seen in the data
    counts = model.global_graph_.counts(plan.layer, 0).toarray()
    assert (counts[plan.nodes[:-1], plan.nodes[1:]] > 0).all()
    # The log probability is the path's, recomputed from the graph.
    g = model.global_graph_
    visits = g.visits(plan.layer)[0]
    expected = (
        np.log(visits[plan.nodes[0]] / visits.sum())
        + g.log_prob(plan.layer, 0, plan.nodes[:-1], plan.nodes[1:]).sum()
    )
    assert plan.log_probability == pytest.approx(expected)
    # The root integrates the nodes' motion: forward then left, never far behind.
    assert plan.root[:, 0].min() > -0.2 and plan.root[-1, 0] > 1.8


def test_a_goal_behind_a_forward_only_database_is_reported():
    walks = make_walks(2, directions=["forward"], random_state=1)
    X = VirtualMarkerTransform().fit_transform(
        as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    )
    model = MotionTreeHMM(max_depth=4, split="median").fit(X, walks.target)
    with pytest.raises(UnreachableGoalError, match="closest approach"):
        model.plan((0, 0, 0), (-1.5, 0.0), frame_rate=30, body_size=1.6, max_frames=90)
    with pytest.raises(UnreachableGoalError, match="covers at most"):
        model.plan((0, 0, 0), (30.0, 0.0), frame_rate=30, body_size=1.6, max_frames=60)


def test_plan_rejects_bad_arguments(walk_database):
    walks, _, model, _ = walk_database
    with pytest.raises(ValueError, match="goal"):
        model.plan((0, 0, 0), (1.0,), frame_rate=30)
    with pytest.raises(ValueError, match="frame_rate"):
        model.plan((0, 0, 0), (1.0, 0.0), frame_rate=0)
    with pytest.raises(ValueError, match="start_node"):
        model.plan((0, 0, 0), (1.0, 0.0), frame_rate=30, start_node=10**6)
    joint_model = MotionTreeHMM(max_depth=2).fit([c[:, :65] for c in walks.clips], walks.target)
    with pytest.raises(ValueError, match="6 channels"):
        joint_model.plan((0, 0, 0), (1.0, 0.0), frame_rate=30)


def test_bvh_export_reproduces_the_planned_markers(walk_database, tmp_path):
    walks, _, model, transformer = walk_database
    plan = model.plan(
        (0.0, 0.0, 0.3),
        (1.0, 0.5),
        frame_rate=walks.frame_rate,
        transformer=transformer,
        tolerance=0.15,
    )
    path = tmp_path / "plan.bvh"
    write_bvh(plan.to_motion(), path)
    motion = read_bvh(path)
    markers = transformer.marker_set(motion.skeleton)
    world = (
        markers.positions(motion.skeleton, motion.channels) * transformer.skeleton.meters_per_unit
    )  # BVH: no units
    planned = plan.marker_positions()
    error = np.linalg.norm(world @ plan_axes(motion.skeleton.up_axis) - planned, axis=-1)
    # A node's mean marker state is an average of poses, not a pose: IK fits it as
    # well as the skeleton allows (ik_rms); the export adds nothing beyond that.
    rms = np.sqrt((error**2).mean(axis=1))
    np.testing.assert_allclose(rms, plan.ik_rms, atol=1e-3)
    assert plan.ik_rms.max() < 0.02  # 2 cm: the averaged poses stay close to real ones
