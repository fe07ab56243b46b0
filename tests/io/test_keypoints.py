"""read_keypoints: .npy, .npz, .csv and Kinect-style text files against the arrays written."""

from types import SimpleNamespace

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_keypoints

LAYOUT = SimpleNamespace(joint_names=["head", "neck", "hip", "knee", "foot"])


@pytest.fixture
def frames(rng):
    """(n_frames=7, n_joints=5, x y z c) with a confidence per joint."""
    values = rng.normal(size=(7, 5, 4)).round(4)
    values[:, :, 3] = rng.random((7, 5)).round(3)
    return values


def _check(motion, frames, min_confidence=None):
    positions = frames[:, :, :3].copy()
    if min_confidence is not None:
        positions[frames[:, :, 3] < min_confidence] = np.nan
    np.testing.assert_array_equal(motion.channels, positions.reshape(len(frames), -1))
    np.testing.assert_array_equal(motion.extras["confidence"], frames[:, :, 3])


def test_npy_three_and_two_dimensional(tmp_path, frames):
    np.save(tmp_path / "a.npy", frames)
    motion = read_keypoints(tmp_path / "a.npy", LAYOUT, frame_rate=30, units="m")
    _check(motion, frames)
    assert motion.marker_names == tuple(LAYOUT.joint_names) and motion.n_dims == 3
    assert motion.channel_names[3:6] == ["neck_x", "neck_y", "neck_z"] and motion.units == "m"
    np.save(tmp_path / "flat.npy", frames.reshape(7, 20))
    _check(read_keypoints(tmp_path / "flat.npy", LAYOUT, frame_rate=30), frames)
    no_layout = read_keypoints(tmp_path / "a.npy", frame_rate=30)
    assert no_layout.marker_names == ("joint0", "joint1", "joint2", "joint3", "joint4")
    with pytest.raises(ValueError, match="give layout= .* or columns="):
        read_keypoints(tmp_path / "flat.npy", frame_rate=30)
    by_columns = read_keypoints(tmp_path / "flat.npy", frame_rate=30, columns="xyzc")
    _check(by_columns, frames)


def test_two_d_keypoints_with_confidence(tmp_path, frames):
    xyc = frames[:, :, [0, 1, 3]]
    np.save(tmp_path / "coco.npy", xyc)
    motion = read_keypoints(
        tmp_path / "coco.npy", LAYOUT, frame_rate=25, columns="xyc", min_confidence=0.5
    )
    expected = xyc[:, :, :2].copy()
    expected[xyc[:, :, 2] < 0.5] = np.nan
    np.testing.assert_array_equal(motion.channels, expected.reshape(7, -1))
    assert motion.n_dims == 2 and motion.channel_names[:3] == ["head_x", "head_y", "neck_x"]
    # Without columns=, three values are x, y, z: no confidence.
    assert "confidence" not in read_keypoints(tmp_path / "coco.npy", frame_rate=25).extras


def test_npz_with_names_and_confidence(tmp_path, frames):
    np.savez(
        tmp_path / "k.npz",
        keypoints=frames[:, :, :3],
        confidence=frames[:, :, 3],
        joint_names=np.array(LAYOUT.joint_names),
    )
    motion = read_keypoints(tmp_path / "k.npz", frame_rate=30, min_confidence=0.3)
    _check(motion, frames, 0.3)
    assert motion.marker_names == tuple(LAYOUT.joint_names)
    other = SimpleNamespace(joint_names=["a", "b", "c", "d", "e"])
    with pytest.raises(MotionFileError, match=r"k\.npz: joints .* are not the layout's"):
        read_keypoints(tmp_path / "k.npz", other, frame_rate=30)


def test_csv_with_and_without_header(tmp_path, frames):
    header = ",".join(f"{j}_{c}" for j in LAYOUT.joint_names for c in "xyzc")
    body = "\n".join(",".join(repr(v) for v in row) for row in frames.reshape(7, 20).tolist())
    (tmp_path / "h.csv").write_text(header + "\n" + body + "\n")
    motion = read_keypoints(tmp_path / "h.csv", frame_rate=30, columns="xyzc")
    _check(motion, frames)
    assert motion.marker_names == tuple(LAYOUT.joint_names)
    _check(read_keypoints(tmp_path / "h.csv", LAYOUT, frame_rate=30), frames)
    (tmp_path / "n.csv").write_text(body + "\n")
    _check(read_keypoints(tmp_path / "n.csv", LAYOUT, frame_rate=30), frames)
    bad = tmp_path / "bad.csv"
    bad.write_text(header.replace("knee_y", "ankle_y") + "\n" + body + "\n")
    with pytest.raises(MotionFileError, match=r"bad\.csv, line 1: columns .*knee_x.*ankle_y"):
        read_keypoints(bad, frame_rate=30, columns="xyzc")


def test_kinect_text_one_joint_per_line(tmp_path, frames):
    lines = [" ".join(repr(v) for v in joint) for joint in frames.reshape(35, 4).tolist()]
    text = "# recorded by a Kinect v2\n" + "\n".join(lines) + "\n"
    (tmp_path / "take.txt").write_text(text)
    _check(read_keypoints(tmp_path / "take.txt", LAYOUT, frame_rate=30), frames)
    # One frame per line, spaces or tabs.
    rows = ["\t".join(repr(v) for v in row) for row in frames.reshape(7, 20).tolist()]
    (tmp_path / "rows.txt").write_text("\n".join(rows))
    _check(read_keypoints(tmp_path / "rows.txt", LAYOUT, frame_rate=30), frames)
    (tmp_path / "cut.txt").write_text("\n".join(lines[:-2]) + "\n")
    with pytest.raises(MotionFileError, match=r"33 joint lines are not whole frames of 5 joints"):
        read_keypoints(tmp_path / "cut.txt", LAYOUT, frame_rate=30)
    with pytest.raises(ValueError, match="needs layout="):
        read_keypoints(tmp_path / "take.txt", frame_rate=30, per_line="joint")


@pytest.mark.parametrize(
    "line, message",
    [
        ("0.1 0.2 oops 1", r"line 4: not a finite number: 'oops'"),
        ("0.1 0.2 0.3", r"line 4: 3 values, expected 4"),
        ("0.1 0.2 1_000 1", r"line 4: not a finite number: '1_000'"),
        ("0.1 inf 0.3 1", r"line 4: not a finite number: 'inf'"),
    ],
)
def test_bad_lines_are_named(tmp_path, line, message):
    lines = ["# header comment", "0 0 0 1", "0 1 0 1", line, "1 1 1 1", "1 0 1 1"]
    path = tmp_path / "bad.txt"
    path.write_text("\n".join(lines) + "\n")
    layout = SimpleNamespace(joint_names=["a", "b"])
    with pytest.raises(MotionFileError, match=r"bad\.txt, " + message):
        read_keypoints(path, layout, frame_rate=30)


def test_missing_values_and_options(tmp_path):
    path = tmp_path / "nan.txt"
    path.write_text("\ufeff0 0 0\nnan nan nan\n1 1 1\n2 2 2\n")
    motion = read_keypoints(path, SimpleNamespace(joint_names=["a", "b"]), frame_rate=10)
    np.testing.assert_array_equal(
        motion.channels, [[0, 0, 0, np.nan, np.nan, np.nan], [1] * 3 + [2] * 3]
    )
    assert motion.extras == {}
    with pytest.raises(ValueError, match="no confidences"):
        read_keypoints(
            path, SimpleNamespace(joint_names=["a", "b"]), frame_rate=10, min_confidence=1
        )
    with pytest.raises(ValueError, match="columns must be"):
        read_keypoints(path, frame_rate=10, columns="xyzw")
    with pytest.raises(TypeError, match="joint_names"):
        read_keypoints(path, layout=3, frame_rate=10)
    with pytest.raises(ValueError, match="frame_rate"):
        read_keypoints(path, SimpleNamespace(joint_names=["a", "b"]), frame_rate=0)
    (tmp_path / "empty.txt").write_text("# nothing\n\n")
    with pytest.raises(MotionFileError, match=r"empty\.txt: no data lines"):
        read_keypoints(tmp_path / "empty.txt", frame_rate=10, columns="xyz")


def test_a_layout_name_gives_the_layouts_joint_names(tmp_path):
    """A layout name is resolved by skmotion.kinematics.get_layout: its joints name the channels."""
    from skmotion.kinematics import get_layout

    layout = get_layout("kinect_v1")
    frames = np.arange(5 * 20 * 3, dtype=float).reshape(5, 20, 3)
    np.save(tmp_path / "k.npy", frames)
    motion = read_keypoints(tmp_path / "k.npy", "kinect_v1", frame_rate=30)
    assert motion.marker_names == tuple(layout.joints)
    assert motion.channels.shape == (5, 60)
    np.testing.assert_array_equal(motion.channels, frames.reshape(5, 60))
