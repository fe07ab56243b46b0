"""read_bvh / write_bvh: hand-made files, every rotation order, round trips, errors, real files."""

import itertools
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from skmotion.datasets import make_motions
from skmotion.io import Motion, MotionFileError, read_bvh, write_bvh
from skmotion.kinematics import Skeleton

LEG = """HIERARCHY
ROOT hip
{
\tOFFSET 1 2 3
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT knee
\t{
\t\tOFFSET 0 -40 0
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 -40 0
\t\t}
\t}
\tJOINT tail
\t{
\t\tOFFSET 0 0 -10
\t\tCHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation
\t}
}
MOTION
Frames: 3
Frame Time: 0.008333
0 90 0 0 0 0 0 0 0 1 2 3 0 0 0
10 90 0 90 0 0 0 90 0 1 2 3 0 0 0
10 90 5 0 0 0 0 0 0 0 0 -10 0 45 0
"""


def write(tmp_path, text, name="clip.bvh"):
    path = tmp_path / name
    path.write_bytes(text.encode())
    return path


def test_hand_made_file(tmp_path):
    motion = read_bvh(write(tmp_path, LEG))
    sk = motion.skeleton
    assert sk.joints == ("hip", "knee", "knee_end", "tail")
    assert sk.parents == (-1, 0, 1, 0)
    np.testing.assert_array_equal(sk.offsets, [[1, 2, 3], [0, -40, 0], [0, -40, 0], [0, 0, -10]])
    assert sk.channels[2] == () and 2 in sk.end_sites
    assert sk.rotation_orders[:2] == ("ZXY", "ZXY") and sk.rotation_orders[3] == "YXZ"
    assert motion.frame_rate == 120.0 and motion.n_frames == 3 and motion.n_channels == 15
    assert motion.channels[1, 3] == pytest.approx(np.pi / 2)  # degrees became radians
    positions = motion.forward_kinematics().positions
    # Frame 1: root at (10, 90, 0) turned 90 degrees about Z: the thigh (0, -40, 0) points to +x.
    np.testing.assert_allclose(positions[1, 1], [50, 90, 0], atol=1e-9)
    # ...and the knee, bent 90 degrees about its X, sends the shin along the root's -z.
    np.testing.assert_allclose(positions[1, 2], [50, 90, -40], atol=1e-9)
    # A 6-channel joint: its position channels replace its offset.
    np.testing.assert_allclose(positions[2, 3], [10, 90, 5 - 10], atol=1e-9)


def test_windows_line_endings_and_blank_lines(tmp_path):
    text = LEG.replace("\n", "\r\n") + "\r\n\r\n"
    motion = read_bvh(write(tmp_path, text))
    reference = read_bvh(write(tmp_path, LEG, "unix.bvh"))
    np.testing.assert_array_equal(motion.channels, reference.channels)


@pytest.mark.parametrize("order", ["".join(p) for p in itertools.permutations("XYZ")])
def test_every_rotation_order_matches_scipy(tmp_path, order):
    angles = [23.0, -41.0, 67.0]
    channels = " ".join(f"{a}rotation" for a in order)
    text = (
        "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 "
        + channels
        + "\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n"
        + " ".join(map(str, angles))
        + "\n"
    )
    motion = read_bvh(write(tmp_path, text), up_axis="y")
    rotation = motion.forward_kinematics().rotations[0, 0]
    expected = Rotation.from_euler(order, angles, degrees=True).as_matrix()  # upper case: intrinsic
    np.testing.assert_allclose(rotation, expected, atol=1e-12)


def test_up_axis_detection_and_override(tmp_path):
    z_up = LEG.replace("OFFSET 0 -40 0", "OFFSET 0 0 -40").replace(
        "0 90 0 0 0 0 0 0 0 1 2 3 0 0 0", "0 0 90 0 0 0 0 0 0 1 2 3 0 0 0"
    )
    path = write(
        tmp_path,
        z_up.replace(
            "10 90 0 90 0 0 0 90 0 1 2 3 0 0 0\n10 90 5 0 0 0 0 0 0 0 0 -10 0 45 0\n",
            "0 0 90 0 0 0 0 0 0 1 2 3 0 0 0\n0 0 90 0 0 0 0 0 0 1 2 3 0 0 0\n",
        ),
    )
    assert read_bvh(path).skeleton.up_axis == "z"
    assert read_bvh(path, up_axis="x").skeleton.up_axis == "x"
    with pytest.raises(ValueError, match="up_axis"):
        read_bvh(path, up_axis="w")


def test_frame_rate_is_kept_when_not_a_whole_number(tmp_path):
    motion = read_bvh(write(tmp_path, LEG.replace("0.008333", "0.03")))
    assert motion.frame_rate == pytest.approx(1 / 0.03)


def _make_motion(random_state=0):
    data = make_motions(
        n_clips_per_class=1, classes=["kick"], duration=(1.0, 1.0), random_state=random_state
    )
    return Motion(data.skeletons[0], data.clips[0], frame_rate=data.frame_rate)


def test_round_trip_reproduces_channels_and_offsets(tmp_path):
    motion = _make_motion()
    write_bvh(motion, tmp_path / "kick.bvh")
    back = read_bvh(tmp_path / "kick.bvh")
    assert back.skeleton.joints == motion.skeleton.joints
    assert back.skeleton.channels == motion.skeleton.channels
    np.testing.assert_array_equal(back.skeleton.offsets, motion.skeleton.offsets)
    np.testing.assert_allclose(back.channels, motion.channels, rtol=0, atol=1e-13)
    assert back.frame_rate == motion.frame_rate and back.skeleton.up_axis == "y"


def test_round_trip_with_few_decimals_is_close(tmp_path):
    motion = _make_motion()
    write_bvh(motion, tmp_path / "kick.bvh", precision=4)
    text = (tmp_path / "kick.bvh").read_text()
    assert re.search(r"\n-?\d+\.\d{4} ", text.split("Frame Time")[1])
    back = read_bvh(tmp_path / "kick.bvh")
    rotations = np.array([c.endswith("rotation") for c in motion.channel_names])
    np.testing.assert_allclose(
        np.rad2deg(back.channels[:, rotations]),
        np.rad2deg(motion.channels[:, rotations]),
        atol=0.5e-4 + 1e-12,
    )
    np.testing.assert_allclose(
        back.channels[:, ~rotations], motion.channels[:, ~rotations], atol=0.5e-4 + 1e-12
    )
    with pytest.raises(ValueError, match="precision"):
        write_bvh(motion, tmp_path / "x.bvh", precision=-1)
    with pytest.raises(TypeError, match="Motion"):
        write_bvh(motion.channels, tmp_path / "x.bvh")


@st.composite
def skeletons_and_channels(draw):
    """Random trees with random channel subsets (in random order) and random poses."""
    n = draw(st.integers(1, 7))
    parents = [-1] + [draw(st.integers(0, j - 1)) for j in range(1, n)]
    kinds = ["Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"]
    channels = [
        draw(st.permutations(kinds))[: draw(st.sampled_from([0, 1, 2, 3, 6]))] for _ in range(n)
    ]
    offsets = draw(st.lists(st.tuples(*[st.floats(-50, 50)] * 3), min_size=n, max_size=n))
    skeleton = Skeleton([f"j{j}" for j in range(n)], parents, offsets, channels)
    rng = np.random.default_rng(draw(st.integers(0, 2**16)))
    values = rng.uniform(-3, 3, size=(draw(st.integers(1, 5)), skeleton.n_channels))
    return skeleton, values


def _depth_first(skeleton, j=0):
    return [j] + [k for child in skeleton.children(j) for k in _depth_first(skeleton, child)]


@settings(max_examples=30)
@given(skeletons_and_channels())
def test_round_trip_property(tmp_path_factory, case):
    skeleton, values = case
    if skeleton.n_channels == 0:
        return
    motion = Motion(skeleton, values, frame_rate=25.0)
    path = tmp_path_factory.mktemp("rt") / "r.bvh"
    write_bvh(motion, path)
    back = read_bvh(path, up_axis="y")
    # BVH lists joints depth first; the poses of corresponding joints are equal.
    order = _depth_first(skeleton)
    assert len(back.skeleton.joints) == len(order)
    np.testing.assert_allclose(
        back.forward_kinematics().positions,
        motion.forward_kinematics().positions[:, order],
        atol=1e-9,
    )
    np.testing.assert_array_equal(back.skeleton.offsets, np.asarray(skeleton.offsets)[order])


# -- malformed files name the file and the line -------------------------------------------


def _broken(text, old, new):
    assert old in text
    return text.replace(old, new, 1)


MALFORMED = [
    ("truncated", LEG.rsplit("\n", 2)[0] + "\n", r"line 25: the MOTION block ends after 2 frames"),
    (
        "value count",
        _broken(LEG, "10 90 5 0 0 0 0 0 0 0 0 -10 0 45 0", "10 90 5 0 0 0 0 0 0 0 0 -10 0 45"),
        r"line 26: 14 values on a frame line, but the hierarchy has 15 channels",
    ),
    (
        "non-numeric",
        _broken(LEG, "10 90 0 90", "10 ninety 0 90"),
        r"line 25: non-numeric value 'ninety'",
    ),
    (
        "missing brace",
        _broken(LEG, "\t\t\tOFFSET 0 -40 0\n\t\t}", "\t\t\tOFFSET 0 -40 0\n"),
        r"line 20: file ends where '}' closing joint 'hip' \(opened at line 3\)",
    ),
    (
        "missing joint brace",
        _broken(LEG, "\t\t}\n\t}\n\tJOINT tail", "\t\t}\n\tJOINT tail").rsplit("}\nMOTION", 1)[0]
        + "MOTION"
        + LEG.split("MOTION")[1],
        r"line 18: file ends where '}' closing joint 'knee' \(opened at line 7\)",
    ),
    (
        "unknown channel",
        _broken(
            LEG, "Zrotation Xrotation Yrotation\n\t\tEnd", "Zrotation Qrotation Yrotation\n\t\tEnd"
        ),
        r"line 9: unknown channel 'Qrotation'",
    ),
    (
        "non-numeric offset",
        _broken(LEG, "OFFSET 0 0 -10", "OFFSET 0 zero -10"),
        r"line 17: non-numeric value 'zero' in OFFSET of 'tail'",
    ),
    (
        "too many frames",
        _broken(LEG, "Frames: 3", "Frames: 2"),
        r"line 26: more frame lines than the 2 declared",
    ),
    (
        "bad frame count",
        _broken(LEG, "Frames: 3", "Frames: three"),
        r"line 22: Frames must be an integer",
    ),
    ("no motion", LEG.split("MOTION")[0], r"no MOTION block"),
    ("not hierarchy", "HELLO\n" + LEG, r"line 1: expected 'HIERARCHY'"),
]


@pytest.mark.parametrize("text, message", [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED])
def test_malformed_files_name_file_and_line(tmp_path, text, message):
    path = write(tmp_path, text, "broken.bvh")
    with pytest.raises(MotionFileError, match=re.escape(str(path)) + r".*" + message):
        read_bvh(path)


def test_written_file_is_read_alike_by_a_peer_reader(tmp_path):
    bvh = pytest.importorskip("bvh")
    motion = _make_motion()
    write_bvh(motion, tmp_path / "kick.bvh", precision=6)
    peer = bvh.Bvh((tmp_path / "kick.bvh").read_text())
    assert peer.nframes == motion.n_frames
    assert list(peer.get_joints_names()) == [
        j for j in motion.skeleton.joints if not j.endswith("_end")
    ]
    rotations = np.array([c.endswith("rotation") for c in motion.channel_names])
    expected = np.where(rotations, np.rad2deg(motion.channels), motion.channels)
    np.testing.assert_allclose(np.asarray(peer.frames, dtype=float), expected, atol=1e-6)


# -- the real files --------------------------------------------------------------------------


def test_reads_every_bvh_file_of_the_shared_data(shared_data, tmp_path):
    files = sorted(shared_data.glob("**/*.bvh"))
    assert files
    for path in files:
        motion = read_bvh(path)
        header = path.read_text(errors="replace").split("MOTION")[1]
        assert motion.n_frames == int(re.search(r"Frames:\s*(\d+)", header).group(1))
        assert motion.frame_rate in (60.0, 120.0)
        assert motion.skeleton.up_axis == "y"
        assert np.isfinite(motion.channels).all()
    sample = read_bvh(files[0])
    write_bvh(sample, tmp_path / "again.bvh")
    np.testing.assert_allclose(
        read_bvh(tmp_path / "again.bvh").channels, sample.channels, atol=1e-12
    )
