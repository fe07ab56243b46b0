"""read_asf / read_amc against a slow reference written from the Acclaim formulas."""

import re

import numpy as np
import pytest

from skmotion.io import (
    Motion,
    MotionFileError,
    acclaim_order,
    read_amc,
    read_asf,
    read_bvh,
    write_bvh,
)
from skmotion.preprocessing import VirtualMarkerTransform

ASF = """# a small Acclaim skeleton with tilted bone axes and dof subsets
:version 1.10
:name toy
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
  made for the tests
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name hipjoint
     direction 0.6 -0.7 0.2
     length 2.5
     axis 0 0 0  XYZ
  end
  begin
     id 2
     name femur
     direction 0.34202 -0.939693 0
     length 7.6
     axis 10 -25 20  XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-60.0 70.0)
  end
  begin
     id 3
     name tibia
     direction 0.1 -0.9 0.3
     length 7.3
     axis -90 15 20  XYZ
    dof rx rz
    limits (-10.0 170.0)
           (-10.0 10.0)
  end
  begin
     id 4
     name back
     direction 0 1 -0.1
     length 6
     axis 5 0 -12 XYZ
    dof ry
    limits (-20.0 45.0)
  end
:hierarchy
  begin
    root hipjoint back
    hipjoint femur
    femur tibia
  end
"""


def _amc(frames):
    lines = [":FULLY-SPECIFIED", ":DEGREES"]
    for k, f in enumerate(frames, start=1):
        lines += [
            str(k),
            "root " + " ".join(f"{v:.6f}" for v in f[:6]),
            "femur " + " ".join(f"{v:.6f}" for v in f[6:9]),
            "tibia " + " ".join(f"{v:.6f}" for v in f[9:11]),
            "back " + f"{f[11]:.6f}",
        ]
    return "\r\n".join(lines) + "\r\n"


def _frames(rng, n=6):
    frames = rng.uniform(-60, 60, size=(n, 12))
    frames[:, :3] = rng.uniform(-20, 20, size=(n, 3))
    return np.round(frames, 6)


@pytest.fixture
def toy(tmp_path, rng):
    (tmp_path / "toy.asf").write_text(ASF)
    frames = _frames(rng)
    (tmp_path / "toy_01.amc").write_bytes(_amc(frames).encode())
    return tmp_path / "toy.asf", tmp_path / "toy_01.amc", frames


# -- the slow reference: the Acclaim formulas, bone by bone, frame by frame ------------------


def _rot(axis, degrees):
    c, s = np.cos(np.deg2rad(degrees)), np.sin(np.deg2rad(degrees))
    return {
        "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def _parse_asf_for_reference(text):
    bones = {}
    for block in re.findall(r"begin(.*?)end", text.split(":hierarchy")[0], flags=re.S):
        fields = {
            line.split()[0]: line.split()[1:] for line in block.strip().splitlines() if line.split()
        }
        bones[fields["name"][0]] = {
            "direction": np.array(fields["direction"], dtype=float),
            "length": float(fields["length"][0]),
            "axis": np.array(fields["axis"][:3], dtype=float),
            "dof": fields.get("dof", []),
        }
    children = {}
    for line in text.split(":hierarchy")[1].splitlines():
        words = line.split()
        if len(words) >= 2:
            children.setdefault(words[0], []).extend(words[1:])
    return bones, children


def _parse_amc_for_reference(text):
    frames, current = [], None
    for line in text.splitlines():
        words = line.split()
        if not words or words[0].startswith((":", "#")):
            continue
        if words[0].isdigit():
            current = {}
            frames.append(current)
        else:
            current[words[0]] = [float(w) for w in words[1:]]
    return frames


def acclaim_positions(asf_text, amc_text):
    """{bone: (start, end)} per frame, straight from the Acclaim definitions."""
    bones, children = _parse_asf_for_reference(asf_text)
    result = []
    for frame in _parse_amc_for_reference(amc_text):
        tx, ty, tz, rx, ry, rz = frame["root"]
        root_rotation = (
            _rot("z", rz) @ _rot("y", ry) @ _rot("x", rx)
        )  # axis XYZ: x first, fixed axes
        out = {}

        def visit(name, start, parent_rotation):
            bone = bones[name]
            ax, ay, az = bone["axis"]
            c = _rot("z", az) @ _rot("y", ay) @ _rot("x", ax)
            m = np.eye(3)
            for dof, value in zip(bone["dof"], frame.get(name, [])):
                m = _rot(dof[1], value) @ m  # each dof applied after the previous, about fixed axes
            rotation = parent_rotation @ c @ m @ c.T
            end = start + rotation @ (
                bone["length"] * bone["direction"] / np.linalg.norm(bone["direction"])
            )
            out[name] = (start, end)
            for child in children.get(name, []):
                visit(child, end, rotation)

        origin = np.array([tx, ty, tz])
        for child in children["root"]:
            visit(child, origin, root_rotation)
        result.append(out)
    return result


def _assert_matches_reference(motion, asf_text, amc_text):
    reference = acclaim_positions(asf_text, amc_text)
    positions = motion.forward_kinematics().positions
    sk = motion.skeleton
    for f, bones in enumerate(reference):
        for name, (start, end) in bones.items():
            np.testing.assert_allclose(positions[f, sk.joint_index(name)], start, atol=1e-9)
            tip = [c for c in sk.children(name)] or []
            if f"{name}_end" in sk.joints:
                np.testing.assert_allclose(
                    positions[f, sk.joint_index(f"{name}_end")], end, atol=1e-9
                )
            for child in tip:
                np.testing.assert_allclose(positions[f, child], end, atol=1e-9)


def test_acclaim_order():
    assert acclaim_order("XYZ") == "ZYX"
    assert acclaim_order("ZXY") == "YXZ"
    assert acclaim_order("Y") == "YXZ"


def test_toy_skeleton_structure_and_units(toy):
    asf, amc, _ = toy
    sk = read_asf(asf)
    assert sk.joints == ("root", "hipjoint", "femur", "tibia", "tibia_end", "back", "back_end")
    assert sk.channels[0] == (
        "Xposition",
        "Yposition",
        "Zposition",
        "Xrotation",
        "Yrotation",
        "Zrotation",
    )
    assert sk.channels[1] == () and sk.channels[3] == ("Xrotation", "Zrotation")
    assert sk.rotation_orders[2] == "ZYX" and sk.rotation_orders[3] == "ZXY"
    assert sk.meters_per_unit == pytest.approx(0.0254 / 0.45) and sk.up_axis == "y"
    direction = np.array([0.34202, -0.939693, 0])
    np.testing.assert_allclose(sk.offsets[3], 7.6 * direction / np.linalg.norm(direction))


def test_toy_motion_matches_the_acclaim_formulas(toy):
    asf, amc, frames = toy
    motion = read_amc(amc, read_asf(asf))
    assert motion.n_frames == len(frames) and motion.frame_rate == 120.0
    np.testing.assert_allclose(motion.channels[:, :3], frames[:, :3])
    np.testing.assert_allclose(np.rad2deg(motion.channels[:, 3:]), frames[:, 3:], atol=1e-9)
    _assert_matches_reference(motion, ASF, amc.read_text())


def test_bones_in_any_order_within_a_frame(toy, tmp_path):
    asf, amc, _ = toy
    lines = amc.read_text().splitlines()
    swapped = lines[:3] + [lines[5], lines[3], lines[6], lines[4]] + lines[7:]
    (tmp_path / "swapped.amc").write_text("\n".join(swapped) + "\n")
    sk = read_asf(asf)
    np.testing.assert_array_equal(
        read_amc(tmp_path / "swapped.amc", sk).channels, read_amc(amc, sk).channels
    )


def test_radians_header(toy, tmp_path):
    asf, amc, frames = toy
    text = amc.read_text().replace(":DEGREES", ":RADIANS")
    (tmp_path / "rad.amc").write_text(text)
    motion = read_amc(tmp_path / "rad.amc", read_asf(asf))
    np.testing.assert_allclose(motion.channels[:, 3:], frames[:, 3:], atol=1e-9)


def test_asf_amc_to_bvh_and_back_gives_the_same_markers(toy, tmp_path):
    asf, amc, _ = toy
    motion = read_amc(amc, read_asf(asf))
    write_bvh(motion, tmp_path / "toy.bvh")
    back = read_bvh(tmp_path / "toy.bvh", up_axis="y")
    np.testing.assert_allclose(
        back.forward_kinematics().positions, motion.forward_kinematics().positions, atol=1e-9
    )


# -- malformed files --------------------------------------------------------------------------


def _replace(text, old, new):
    assert old in text
    return text.replace(old, new, 1)


AMC_ERRORS = [
    ("unknown bone", lambda t: _replace(t, "tibia ", "fibula "), r"line 6: unknown bone 'fibula'"),
    (
        "value count",
        lambda t: re.sub(r"(\nback \S+)", r"\1 1.0", t, count=1),
        r"line 7: bone 'back' has 2 values, but its dof has 1",
    ),
    (
        "truncated",
        lambda t: t.rsplit("\n", 3)[0] + "\n",
        r"frame 6 lacks bone 'tibia' \(truncated file\?\)",
    ),
    (
        "non-numeric",
        lambda t: re.sub(r"(\nfemur )\S+", r"\1abc", t, count=1),
        r"line 5: non-numeric value 'abc'",
    ),
    ("frame numbers", lambda t: _replace(t, "\n2\n", "\n3\n"), r"line 8: frame number 3 follows 1"),
    (
        "bone before frame",
        lambda t: _replace(t, ":DEGREES\n1\n", ":DEGREES\nroot 0 0 0 0 0 0\n1\n"),
        r"line 3: bone data before the first frame number",
    ),
    (
        "twice",
        lambda t: _replace(t, "\n2\n", "\nback 1.0\n2\n"),
        r"line 3: frame 1 lists twice bone 'back'",
    ),
]


@pytest.mark.parametrize(
    "edit, message", [e[1:] for e in AMC_ERRORS], ids=[e[0] for e in AMC_ERRORS]
)
def test_malformed_amc_names_file_and_line(toy, tmp_path, edit, message):
    asf, amc, _ = toy
    path = tmp_path / "broken.amc"
    path.write_text(edit(amc.read_text().replace("\r\n", "\n")))
    with pytest.raises(MotionFileError, match=re.escape(str(path)) + ".*" + message):
        read_amc(path, read_asf(asf))


ASF_ERRORS = [
    (
        "missing end",
        lambda t: _replace(t, "    dof ry\n    limits (-20.0 45.0)\n  end\n", "    dof ry\n"),
        r"line 5[0-9]: the bone opened at line 4[0-9] has no 'end'",
    ),
    (
        "unknown bone",
        lambda t: _replace(t, "femur tibia", "femur fibula"),
        r"line \d+: unknown bone 'fibula'",
    ),
    (
        "non-numeric",
        lambda t: _replace(t, "length 7.3", "length seven"),
        r"line 3[0-9]: non-numeric value 'seven'",
    ),
    ("bad dof", lambda t: _replace(t, "dof ry", "dof ry l"), r"dof 'l' is not supported"),
    ("hierarchy end", lambda t: t.rsplit("end", 1)[0], r"file ends where 'end' of the hierarchy"),
    ("no root", lambda t: t.replace(":root", ":rooted"), r"no :root section"),
]


@pytest.mark.parametrize(
    "edit, message", [e[1:] for e in ASF_ERRORS], ids=[e[0] for e in ASF_ERRORS]
)
def test_malformed_asf_names_file_and_line(tmp_path, edit, message):
    path = tmp_path / "broken.asf"
    path.write_text(edit(ASF))
    with pytest.raises(MotionFileError, match=re.escape(str(path)) + ".*" + message):
        read_asf(path)


def test_read_amc_needs_a_skeleton(toy):
    with pytest.raises(TypeError, match="Skeleton"):
        read_amc(toy[1], "toy.asf")


# -- the CMU files ------------------------------------------------------------------------------


def test_cmu_trial_matches_the_acclaim_formulas(shared_data, tmp_path):
    folder = shared_data / "cmu-asfamc" / "02"
    asf_text = (folder / "02.asf").read_text()
    amc_text = (folder / "02_01.amc").read_text()
    head = amc_text.split("\n11\n")[0] + "\n"  # ten frames are plenty for the slow reference
    (tmp_path / "02_01.amc").write_text(head)
    motion = read_amc(tmp_path / "02_01.amc", read_asf(folder / "02.asf"))
    assert motion.n_frames == 10
    _assert_matches_reference(motion, asf_text, head)


def test_reads_every_cmu_file(shared_data):
    files = sorted((shared_data / "cmu-asfamc").glob("*/*.amc"))
    assert len(files) >= 25
    for asf in sorted((shared_data / "cmu-asfamc").glob("*/*.asf")):
        skeleton = read_asf(asf)
        assert skeleton.n_channels == 62 and skeleton.n_joints == 38
        for amc in sorted(asf.parent.glob("*.amc")):
            motion = read_amc(amc, skeleton)
            last = re.findall(rb"^(\d+)\s*$", amc.read_bytes()[-3000:], flags=re.M)[-1]
            assert motion.n_frames == int(last)
            assert np.isfinite(motion.channels).all()


def test_cmu_trial_to_bvh_and_back_gives_the_same_markers(shared_data, tmp_path):
    folder = shared_data / "cmu-asfamc" / "02"
    motion = read_amc(folder / "02_01.amc", read_asf(folder / "02.asf"))
    motion = Motion(motion.skeleton, motion.channels[:120], frame_rate=motion.frame_rate)
    write_bvh(motion, tmp_path / "02_01.bvh")
    back = read_bvh(tmp_path / "02_01.bvh")
    assert back.skeleton.up_axis == "y"
    markers = VirtualMarkerTransform().fit([motion])
    np.testing.assert_allclose(
        VirtualMarkerTransform().fit_transform([back])[0], markers.transform([motion])[0], atol=1e-9
    )
