"""Stick figures and animations: what is drawn is where forward kinematics or the given
positions put it; the planning figure's axes are x ahead, y left."""

import types

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from skmotion import plotting  # noqa: E402
from skmotion.plotting import body_frames  # noqa: E402


def _segments(ax):
    """The (start, end) points of every 2-D or 3-D line of an axes, in data coordinates."""
    out = []
    for line in ax.get_lines():
        if hasattr(line, "get_data_3d"):
            x, y, z = line.get_data_3d()
            out.append(np.column_stack([x, y, z]))
        else:
            out.append(line.get_xydata())
    return out


def test_pose_of_a_skeleton_is_its_forward_kinematics(skeleton):
    channels = np.zeros(skeleton.n_channels)
    channels[:3] = [0.5, 0.0, -0.25]  # the root's position channels
    # No rotation: offsets add up from the root, which the position channels place
    # (they replace the root's own offset).
    pose = skeleton.rest_positions() - skeleton.offsets[0] + [0.5, 0.0, -0.25]
    figure = plotting.plot_pose(channels, skeleton)
    ax = figure.axes[0]
    # y is up: the view draws (z, x) horizontally and y vertically
    drawn = _segments(ax)
    parents = skeleton.parents
    expected = [pose[[parents[j], j]][:, [2, 0, 1]] for j in range(1, skeleton.n_joints)]
    assert len(drawn) == len(expected)
    for got, want in zip(drawn, expected):
        np.testing.assert_allclose(got, want, atol=1e-12)
    assert ax.get_zlabel().startswith("y") and "up" in ax.get_zlabel()
    labels = ax.get_legend_handles_labels()[1]
    assert labels[:2] == ["bones", "joints"] and labels[2].startswith("root (root)")


def test_positions_with_a_layout_object_in_2d():
    layout = types.SimpleNamespace(
        joint_names=["pelvis", "neck", "head", "hand"], parents=[-1, 0, 1, 1]
    )
    pose = np.array([[0.0, 0.0], [0.0, 1.0], [0.0, 1.3], [0.4, 0.8]])
    figure = plotting.plot_pose(pose, layout)
    drawn = _segments(figure.axes[0])
    want = [pose[[0, 1]], pose[[1, 2]], pose[[1, 3]]]
    for got, w in zip(drawn, want):
        np.testing.assert_allclose(got, w)
    # the same with plain arrays: bones as pairs of indices, and as names with a layout
    same = body_frames(pose, bones=[(0, 1), (1, 2), (1, 3)])
    np.testing.assert_array_equal(same.bones, [[0, 1], [1, 2], [1, 3]])
    named = types.SimpleNamespace(names=layout.joint_names, bones=[("neck", "hand")])
    assert body_frames(pose.ravel(), named).bones.tolist() == [[1, 3]]


@pytest.mark.parametrize(
    "frames, kwargs, message",
    [
        (np.zeros((4, 3)), {"bones": [(0, 9)]}, "bone 0 joins joint 9"),
        (np.zeros((4, 3)), {"bones": [-1, 0, 5, 0]}, r"parents\[2\] = 5"),
        (np.zeros((4, 3)), {}, "no bones"),
        (np.full((4, 3), np.nan), {"bones": [-1, 0, 0, 0]}, "NaN"),
        (np.zeros((4, 4)), {"bones": [-1, 0, 0, 0]}, r"must be \(n_joints, 2 or 3\)"),
        (np.zeros((3, 5)), {"bones": [(0, 1)]}, "cannot read"),
    ],
)
def test_bad_bodies_are_named(frames, kwargs, message):
    with pytest.raises(ValueError, match=message):
        body_frames(frames, **kwargs)


def test_clip_poses_are_coloured_by_time_with_a_colour_bar(skeleton):
    clip = np.zeros((50, skeleton.n_channels))
    clip[:, 0] = np.linspace(0, 3, 50)  # the root travels 3 m along x
    figure = plotting.plot_clip(clip, skeleton, frame_rate=25.0, n_poses=5)
    ax, bar = figure.axes
    assert bar.get_ylabel() == "time (s)"
    n_bones = skeleton.n_joints - 1
    lines = ax.get_lines()
    assert len(lines) == 5 * n_bones + 1  # five poses and the root path
    assert lines[-1].get_label() == "root path (root)"
    # travelling: poses are not set apart; the last pose's root is 3 m along x
    last = _segments(ax)[4 * n_bones]  # first bone of the fifth pose: root -> spine
    np.testing.assert_allclose(last[0], [0.0, 3.0, 0.0], atol=1e-12)  # (z, x, y)
    # a motion in place is spread out, and the title says so
    still = plotting.plot_clip(np.zeros((10, skeleton.n_channels)), skeleton, n_poses=3)
    assert "apart" in still.axes[0].get_title()
    assert still.axes[1].get_ylabel() == "frame"


def test_gif_has_one_picture_per_drawn_frame(tmp_path):
    from PIL import Image

    t = np.linspace(0, 1, 12)
    clip = np.stack([np.zeros((12, 2)), np.column_stack([np.cos(t), np.sin(t)])], axis=1)
    path = plotting.animate_clip(clip, bones=[(0, 1)], path=tmp_path / "arm.gif", step=3)
    with Image.open(path) as gif:
        assert gif.n_frames == 4  # frames 0, 3, 6, 9
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.gif"]
    with pytest.raises(ValueError, match=".gif or .mp4"):
        plotting.animate_clip(clip, bones=[(0, 1)], path=tmp_path / "arm.avi")


def test_mp4_needs_ffmpeg(tmp_path):
    from matplotlib import animation

    clip = np.zeros((3, 2, 3))
    clip[:, 1, 2] = 1.0
    if animation.FFMpegWriter.isAvailable():
        path = plotting.animate_clip(clip, bones=[(0, 1)], path=tmp_path / "a.mp4")
        assert path.stat().st_size > 0
    else:
        with pytest.raises(RuntimeError, match="ffmpeg"):
            plotting.animate_clip(clip, bones=[(0, 1)], path=tmp_path / "a.mp4")


def test_plan_is_drawn_with_x_ahead_and_y_left():
    # A walk 2 m ahead then 1 m to the left, as the planner reports it (x ahead, y left).
    x = np.r_[np.linspace(0, 2, 20), np.full(10, 2.0)]
    y = np.r_[np.zeros(20), np.linspace(0, 1, 10)]
    heading = np.r_[np.zeros(20), np.full(10, np.pi / 2)]
    plan = types.SimpleNamespace(root=np.column_stack([x, y, heading]), goal=np.array([2.0, 1.0]))
    ax = plotting.plot_plan(plan).axes[0]
    path, start, goal = ax.get_lines()
    np.testing.assert_allclose(path.get_xydata(), np.column_stack([x, y]))
    np.testing.assert_allclose(goal.get_xydata(), [[2.0, 1.0]])  # left is +y, drawn upwards
    assert ax.get_xlabel() == "x, ahead (m)" and ax.get_ylabel() == "y, left (m)"
    arrows = ax.collections[0]
    np.testing.assert_allclose(arrows.U[-1], 0.0, atol=1e-12)  # heading pi/2 points to +y
    np.testing.assert_allclose(arrows.V[-1], 1.0)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "root path",
        "start",
        "goal",
        "heading",
    ]


@pytest.mark.parametrize("name", ["kinect_v2", "mediapipe_pose33"])
def test_a_named_layout_is_drawn_upright_with_its_own_bones(name):
    """A layout's bones and up axis (signed: MediaPipe's y points down) give an upright figure."""
    from skmotion.datasets import make_position_motions
    from skmotion.kinematics import get_layout

    layout = get_layout(name)
    clip = make_position_motions(name, n_clips_per_class=1, random_state=0).clips[0]
    body = body_frames(clip[:5], layout)
    assert len(body.bones) == len(layout.bones)
    on = {m: j for j, m in layout.shared_markers}
    shoulder, ankle = layout.index(on["left_shoulder"]), layout.index(on["left_ankle"])
    # the shoulder is above the ankle along the drawn up axis, whichever sign the layout uses
    assert (body.positions[:, shoulder, body.up] > body.positions[:, ankle, body.up]).all()


@pytest.mark.parametrize("motion", ["squat", "walk", "wave"])
def test_clip_poses_never_overlap_and_the_root_path_runs_through_them(motion):
    from skmotion.datasets import make_motions

    data = make_motions(n_clips_per_class=1, classes=[motion], random_state=0)
    figure = plotting.plot_clip(data.clips[0], data.skeletons[0], frame_rate=30.0, n_poses=6)
    ax = figure.axes[0]
    lines = ax.get_lines()
    path = np.column_stack(lines[-1].get_data_3d())
    assert lines[-1].get_label() == "root path (Hips)"
    n_bones = (len(lines) - 1) // 6
    poses = [
        np.vstack([np.column_stack(line.get_data_3d()) for line in lines[k : k + n_bones]])
        for k in range(0, 6 * n_bones, n_bones)
    ]
    # along the direction from the first pose's root to the last's, each pose starts after
    # the previous one ends
    roots = np.array(
        [np.column_stack(lines[k].get_data_3d())[0] for k in range(0, 6 * n_bones, n_bones)]
    )
    direction = (roots[-1] - roots[0]) / np.linalg.norm(roots[-1] - roots[0])
    spans = [(p @ direction).min() for p in poses], [(p @ direction).max() for p in poses]
    assert all(start > end for start, end in zip(spans[0][1:], spans[1][:-1]))
    # the path passes through every drawn pose's root
    for root in roots:
        assert np.min(np.linalg.norm(path - root, axis=1)) < 1e-9
