"""write_bvh never destroys a file and writes only what read_bvh reads back equal;
the BVH hierarchy parser is iterative, linear and keeps names verbatim."""

import errno
import os
import re
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.io import Motion, MotionFileError, _bvh_write, read_bvh, write_bvh
from skmotion.io._bvh_hierarchy import parse_hierarchy
from skmotion.kinematics import Skeleton

ROTATIONS = ["Xrotation", "Yrotation", "Zrotation"]
POSITIONS = ["Xposition", "Yposition", "Zposition"]


def _motion(random_state=0):
    data = make_motions(n_clips_per_class=1, classes=["wave"], random_state=random_state)
    return Motion(data.skeletons[0], data.clips[0], frame_rate=data.frame_rate)


# -- atomic writes --


def test_an_interrupted_write_leaves_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "clip.bvh"
    write_bvh(_motion(0), path)
    before = path.read_bytes()

    def disk_full(fh, values, fmt):
        np.savetxt(
            fh, values[: len(values) // 2], fmt=fmt
        )  # half the frames, then the disk is full
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(_bvh_write, "_write_frames", disk_full)
    with pytest.raises(OSError, match="No space left"):
        write_bvh(_motion(1), path)
    assert path.read_bytes() == before
    assert os.listdir(tmp_path) == ["clip.bvh"], "the temporary file was left behind"
    monkeypatch.undo()
    write_bvh(_motion(1), path)
    assert path.read_bytes() != before and os.listdir(tmp_path) == ["clip.bvh"]


def test_a_new_file_gets_ordinary_permissions_and_an_old_one_keeps_its_own(tmp_path):
    path = tmp_path / "clip.bvh"
    write_bvh(_motion(), path)
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask
    path.chmod(0o640)
    write_bvh(_motion(), path)
    assert path.stat().st_mode & 0o777 == 0o640


# -- validation before writing --


def _leg(names=("hip", "knee", "foot"), channels=None):
    channels = channels or [POSITIONS + ROTATIONS, ROTATIONS, []]
    return Skeleton(names, [-1, 0, 1], [[0, 0, 0], [0, -1, 0], [0, -1, 0]], channels)


@pytest.mark.parametrize(
    "name, problem",
    [
        ("", "is empty"),
        ("  ", "is empty"),
        (" knee", "starts or ends with a blank"),
        ("knee\t", "starts or ends with a blank"),
        ("kn{ee", "contains a brace"),
        ("knee}", "contains a brace"),
        ("knee\nfoot", "line break"),
        ("knee\x00", "control character"),
    ],
)
def test_names_bvh_cannot_store_are_refused_before_writing(tmp_path, name, problem):
    skeleton = _leg(("hip", name, "foot"))
    path = tmp_path / "leg.bvh"
    with pytest.raises(ValueError, match=f"Joint 1 name .* {problem}"):
        write_bvh(Motion(skeleton, np.zeros((2, 9)), frame_rate=30.0), path)
    assert not path.exists() and not os.listdir(tmp_path)


@pytest.mark.parametrize(
    "bad, message",
    [
        (np.nan, r"Frame 1, channel 'knee_Yrotation' is nan"),
        (np.inf, r"Frame 1, channel 'knee_Yrotation' is inf"),
        (1e307, r"Frame 1, channel 'knee_Yrotation' is inf when written"),  # radians to degrees
    ],
)
def test_non_finite_values_are_refused_with_frame_and_channel(tmp_path, bad, message):
    channels = np.zeros((3, 9))
    channels[1, 7] = bad
    with pytest.raises(ValueError, match=message):
        write_bvh(Motion(_leg(), channels, frame_rate=30.0), tmp_path / "leg.bvh")
    assert not os.listdir(tmp_path)


def test_no_frames_is_refused(tmp_path):
    with pytest.raises(ValueError, match="no frames"):
        write_bvh(Motion(_leg(), np.zeros((0, 9)), frame_rate=30.0), tmp_path / "leg.bvh")


def test_names_with_spaces_and_channel_less_leaves_read_back_verbatim(tmp_path):
    skeleton = Skeleton(
        ["Bip01 Pelvis", "Bip01  Spine", "Bip01\tHead", "tip", "Bip01  Spine_end"],
        [-1, 0, 1, 2, 1],
        np.arange(15.0).reshape(5, 3),
        [POSITIONS + ROTATIONS, ROTATIONS[::-1], ["Yrotation", "Xrotation"], [], []],
    )
    channels = np.random.default_rng(0).normal(size=(4, skeleton.n_channels))
    path = tmp_path / "biped.bvh"
    write_bvh(Motion(skeleton, channels, frame_rate=25.0), path)
    text = path.read_text()
    assert "JOINT tip" in text and "CHANNELS 0" in text  # a leaf with its own name
    assert text.count("End Site") == 1  # the leaf named as read_bvh names End Sites
    back = read_bvh(path, up_axis="y")
    assert back.skeleton.joints == skeleton.joints
    assert back.skeleton.channels == skeleton.channels
    np.testing.assert_allclose(back.channels, channels, rtol=1e-13, atol=1e-13)


# -- property: random skeletons written then read back equal --


@st.composite
def skeletons(draw):
    n = draw(st.integers(1, 9))
    parents = [-1] + [draw(st.integers(0, j - 1)) for j in range(1, n)]
    alphabet = st.sampled_from(list("abcXYZ _1é") + ["Bip01 ", "_end"])
    names, taken = [], set()
    for j in range(n):
        name = "".join(draw(st.lists(alphabet, min_size=1, max_size=4))).strip() or f"j{j}"
        while name in taken:
            name += "x"
        taken.add(name)
        names.append(name)
    has_children = {p for p in parents if p >= 0}
    channels = []
    for j in range(n):
        kinds = ["rot", "six"] + ([] if j == 0 else ["none"])
        kind = draw(st.sampled_from(kinds))
        if kind == "none":
            chans = []
        else:
            chans = draw(st.permutations(ROTATIONS))
            if kind == "six":
                chans = list(draw(st.permutations(POSITIONS))) + list(chans)
                if draw(st.booleans()):
                    chans = chans[3:] + chans[:3]  # rotations first
        channels.append(list(chans))
    # Some channel-less leaves named as read_bvh names End Sites.
    for j in range(1, n):
        if not channels[j] and j not in has_children and draw(st.booleans()):
            candidate = f"{names[parents[j]]}_end"
            if candidate not in names:
                names[j] = candidate
    offsets = draw(
        st.lists(
            st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=3, max_size=3),
            min_size=n,
            max_size=n,
        )
    )
    return Skeleton(names, parents, offsets, channels)


def _preorder(skeleton):
    order, stack = [], [0]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(skeleton.children(j)))
    return order


@settings(max_examples=60, deadline=None)
@given(skeleton=skeletons(), n_frames=st.integers(1, 4), seed=st.integers(0, 2**16))
def test_random_skeletons_read_back_equal(tmp_path_factory, skeleton, n_frames, seed):
    if skeleton.n_channels == 0:
        return
    channels = np.random.default_rng(seed).uniform(-3, 3, size=(n_frames, skeleton.n_channels))
    path = tmp_path_factory.mktemp("rt") / "random.bvh"
    write_bvh(Motion(skeleton, channels, frame_rate=60.0), path)
    back = read_bvh(path, up_axis="y")
    order = _preorder(skeleton)  # BVH lists joints depth first
    assert back.skeleton.joints == tuple(skeleton.joints[j] for j in order)
    assert [back.skeleton.joints[p] if p >= 0 else None for p in back.skeleton.parents] == [
        skeleton.joints[skeleton.parents[j]] if j else None for j in order
    ]
    assert back.skeleton.channels == tuple(skeleton.channels[j] for j in order)
    np.testing.assert_array_equal(back.skeleton.offsets, skeleton.offsets[order])
    columns = [skeleton.channel_names.index(c) for c in back.channel_names]
    np.testing.assert_allclose(back.channels, channels[:, columns], rtol=1e-12, atol=1e-12)
    assert back.frame_rate == 60.0


# -- the hierarchy parser --


def _chain(depth):
    lines = [
        "HIERARCHY",
        "ROOT j0",
        "{",
        "OFFSET 0 1 0",
        "CHANNELS 3 Zrotation Xrotation Yrotation",
    ]
    for i in range(1, depth):
        lines += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    lines += ["}"] * depth
    return "\n".join(lines) + "\n"


def test_nesting_ten_thousand_deep(tmp_path):
    depth = 10_000
    text = _chain(depth) + "MOTION\nFrames: 1\nFrame Time: 0.1\n" + " ".join(["0"] * 3 * depth)
    path = tmp_path / "deep.bvh"
    path.write_text(text + "\n")
    motion = read_bvh(path, up_axis="y")
    assert motion.skeleton.n_joints == depth and motion.skeleton.parents[-1] == depth - 2
    # The writer is iterative too, and what it writes reads back equal.
    write_bvh(motion, tmp_path / "again.bvh")
    again = read_bvh(tmp_path / "again.bvh", up_axis="y")
    assert again.skeleton == motion.skeleton


def _siblings(n):
    body = "".join(
        f"  JOINT Bip01 J{i}\n  {{\n    OFFSET {i} 0 0\n    CHANNELS 3 Zrotation Xrotation"
        " Yrotation\n  }\n"
        for i in range(n)
    )
    return (
        "HIERARCHY\nROOT Bip01\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xrotation Yrotation Zrotation\n"
        + body
        + "}\n"
    )


def test_sibling_joints_parse_in_linear_time():
    """10^5 siblings: the old parser took > 20 s (a list lookup per name). The bounds are
    relative to work measured in the same run, for a loaded 2-core machine: four
    times the joints take about four times the time (linear, not quadratic), and the parse
    costs a bounded multiple of one C-level tokenizing pass over the same text."""
    small, large = _siblings(25_000), _siblings(100_000)
    start = time.perf_counter()
    parse_hierarchy("small.bvh", small)
    t_small = time.perf_counter() - start
    start = time.perf_counter()
    joints, parents, offsets, _ = parse_hierarchy("large.bvh", large)
    t_large = time.perf_counter() - start
    start = time.perf_counter()
    re.findall(r"[{}]|[^ \t\n{}]+", large)
    t_tokens = time.perf_counter() - start
    assert len(joints) == 100_001 and parents[-1] == 0 and offsets[-1] == [99_999.0, 0.0, 0.0]
    assert t_large < max(8.0, 60 * t_tokens), (t_large, t_tokens)
    assert t_large < 10 * max(t_small, 0.05), (t_small, t_large)  # linear, not quadratic


@pytest.mark.parametrize(
    "line, name",
    [
        ("JOINT Bip01 Neck", "Bip01 Neck"),
        ("JOINT   Bip01  Neck  ", "Bip01  Neck"),
        ("JOINT Bip01\tNeck", "Bip01\tNeck"),
        ("JOINT Bip01 Neck {", "Bip01 Neck"),
        ("joint Bip01 Neck{", "Bip01 Neck"),
        ("JOINT Schulter é", "Schulter é"),
    ],
)
def test_a_joint_name_is_the_rest_of_its_line(line, name):
    text = (
        "HIERARCHY\nROOT Bip01 Pelvis\n{\n OFFSET 0 0 0\n"
        " CHANNELS 3 Zrotation Xrotation Yrotation\n"
        f" {line}\n"
        + (" {\n" if not line.rstrip().endswith("{") else "")
        + "  OFFSET 0 1 0\n  CHANNELS 1 Xrotation\n }\n}\n"
    )
    joints = parse_hierarchy("x.bvh", text)[0]
    assert joints == ["Bip01 Pelvis", name]


@pytest.mark.parametrize(
    "line, message",
    [
        ("JOINT", "a joint without a name"),
        ("JOINT {", "a joint without a name"),
        ("JOINT a}b", "joint name 'a}b' contains a brace"),
        ("JOINT Bip01 Pelvis", "joint name 'Bip01 Pelvis' appears twice"),
    ],
)
def test_bad_joint_names_are_named_with_their_line(line, message):
    text = (
        "HIERARCHY\nROOT Bip01 Pelvis\n{\n OFFSET 0 0 0\n"
        " CHANNELS 3 Zrotation Xrotation Yrotation\n"
        f" {line}\n {{\n  OFFSET 0 1 0\n  CHANNELS 1 Xrotation\n }}\n}}\n"
    )
    with pytest.raises(MotionFileError, match=message) as info:
        parse_hierarchy("x.bvh", text)
    assert info.value.line == 6
