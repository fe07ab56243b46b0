"""The table of formats: one row per suffix, used by skmotion info and the folder loaders."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import skmotion.io as io
from skmotion.cli import main
from skmotion.datasets import load_motion_folder, make_motions
from skmotion.io import FORMATS, FileFormat, as_motions, file_format, folder_suffixes, write_bvh


def test_every_row_names_a_public_reader():
    suffixes = [row.suffix for row in FORMATS]
    assert len(set(suffixes)) == len(suffixes)
    for row in FORMATS:
        assert getattr(io, row.reader.__name__) is row.reader
        assert row.kind in ("angles", "positions", "skeleton", "series")
        if row.skeleton_suffix:
            assert file_format("x" + row.skeleton_suffix).kind == "skeleton"
    assert file_format("A/B/walk.BvH").reader is io.read_bvh
    assert folder_suffixes() == (".bvh", ".amc", ".c3d")
    with pytest.raises(
        ValueError, match=r"x\.fbx: unknown motion file type '\.fbx' .*\.bvh, \.amc"
    ):
        file_format("x.fbx")
    with pytest.raises(ValueError, match="kind must be one of"):
        FileFormat(".xyz", "XYZ", "meshes", io.read_bvh, "no")


def test_io_imports_nothing_from_preprocessing_or_estimators():
    code = (
        "import sys, skmotion.io, skmotion.io._info; "
        "bad = [m for m in sys.modules if m.startswith(('skmotion.preprocessing', 'skmotion.tree', "
        "'skmotion.neighbors', 'skmotion.decomposition', 'skmotion.planning'))]; print(bad)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_info_on_keypoints_and_series(tmp_path, capsys):
    values = np.arange(2 * 3 * 4, dtype=float).reshape(2, 3, 4)
    values[1, 2, :3] = np.nan
    np.save(tmp_path / "k.npy", values)
    assert main(["info", str(tmp_path / "k.npy"), "--frame-rate", "30"]) == 0
    out = capsys.readouterr().out
    assert "format: keypoint array" in out
    assert "markers: 3 (3-D, length unit unknown): joint0, joint1, joint2" in out
    assert "missing: 16.7% of marker positions; 0 markers never seen" in out
    assert "extras: confidence" in out and "frames: 2 at 30 Hz, duration 0.07 s" in out
    assert main(["info", str(tmp_path / "k.npy")]) == 0
    assert "frames: 2 (no frame rate in the file; give --frame-rate)" in capsys.readouterr().out
    (tmp_path / "t.ts").write_text("@dimensions 2\n@classLabel true a b\n@data\n1,2:3,4:a\n5:6:b\n")
    assert main(["info", str(tmp_path / "t.ts")]) == 0
    out = capsys.readouterr().out
    assert "series: 2, 2 dimensions, length 1-2" in out and "labels: a 1, b 1" in out
    assert main(["info", str(tmp_path / "x.fbx")]) == 1
    assert "unknown motion file type '.fbx'" in capsys.readouterr().err


def test_c3d_files_need_no_optional_package(tmp_path, monkeypatch, capsys):
    """read_c3d parses the file itself: with the c3d package hidden, a file reads, and a
    broken one is the reader's own error in read_c3d, skmotion info and the folder loader."""
    from tests.io.c3d_files import c3d_bytes

    monkeypatch.setitem(sys.modules, "c3d", None)
    monkeypatch.setitem(sys.modules, "ezc3d", None)
    (tmp_path / "walk").mkdir()
    (tmp_path / "walk" / "t.c3d").write_bytes(c3d_bytes(np.ones((4, 2, 3))))
    assert io.read_c3d(tmp_path / "walk" / "t.c3d", units=None).channels.tolist() == [[1.0] * 6] * 4
    assert main(["info", str(tmp_path / "walk" / "t.c3d")]) == 0
    assert "markers: 2 (3-D, length unit m)" in capsys.readouterr().out
    assert len(load_motion_folder(tmp_path).clips) == 1
    (tmp_path / "walk" / "t.c3d").write_bytes(b"\x02P" + bytes(510))
    with pytest.raises(io.MotionFileError, match=r"t\.c3d: the parameter section"):
        io.read_c3d(tmp_path / "walk" / "t.c3d")
    assert main(["info", str(tmp_path / "walk" / "t.c3d")]) == 1
    assert "the parameter section (block 2) is missing" in capsys.readouterr().err
    with pytest.raises(io.MotionFileError, match=r"t\.c3d"):
        load_motion_folder(tmp_path)


def test_load_motion_folder_refuses_mixed_layouts_on_request(tmp_path):
    data = make_motions(n_clips_per_class=1, classes=["wave"], duration=(0.5, 0.5), random_state=0)
    motion = as_motions(data.clips, data.skeletons, 30.0)[0]
    write_bvh(motion, tmp_path / "a.bvh")
    np.save(tmp_path / "ignored.npy", np.zeros((3, 2, 3)))  # keypoint files are not folder files
    sk = motion.skeleton
    # The same skeleton without its last joint's channels: another channel layout.
    from skmotion.kinematics import Skeleton

    fewer = Skeleton(sk.joints, sk.parents, sk.offsets, [*sk.channels[:-2], [], []], units=sk.units)
    n = fewer.n_channels
    write_bvh(io.Motion(fewer, motion.channels[:, :n], frame_rate=30.0), tmp_path / "b.bvh")
    loaded = load_motion_folder(tmp_path)
    assert loaded.layout.tolist() == [0, 1] and len(loaded.filenames) == 2
    with pytest.raises(ValueError, match=rf"66 channels .* a\.bvh\n  {n} channels .* b\.bvh"):
        load_motion_folder(tmp_path, channel_layouts="same")
    with pytest.raises(ValueError, match="channel_layouts must be"):
        load_motion_folder(tmp_path, channel_layouts="some")


def test_a_position_motion_is_marker_input_for_virtual_markers(rng):
    from skmotion.preprocessing import VirtualMarkerTransform

    data = make_motions(n_clips_per_class=1, classes=["walk", "kick"], random_state=0)
    names = ["pelvis", "left_hip", "right_hip", "head"]
    joints = ["Hips", "LeftUpLeg", "RightUpLeg", "Head"]
    clips = []
    for clip, skeleton in zip(data.clips, data.skeletons):
        fk = skeleton.forward_kinematics(clip).positions
        clips.append(fk[:, [skeleton.joints.index(j) for j in joints]].reshape(len(clip), -1))
    motions = [io.Motion(None, c, frame_rate=30.0, marker_names=names, units="m") for c in clips]
    params = dict(markers=names, size_markers=None, up_axis="y")
    from_motions = VirtualMarkerTransform(**params).fit_transform(motions)
    from_arrays = VirtualMarkerTransform(frame_rate=30.0, **params).fit_transform(clips)
    for a, b in zip(from_motions, from_arrays):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="no skeleton to pose"):
        motions[0].forward_kinematics()
    with pytest.raises(ValueError, match=r"\(n_frames, 12\) .* for 4 markers"):
        io.Motion(None, clips[0][:, :5], frame_rate=30.0, marker_names=names)
    with pytest.raises(ValueError, match="needs marker_names"):
        io.Motion(None, clips[0], frame_rate=30.0)
    with pytest.raises(ValueError, match=r"extras\['r'\] must have"):
        io.Motion(None, clips[0], frame_rate=30.0, marker_names=names, extras={"r": [1]})


def test_the_user_guide_lists_every_format():
    text = (Path(__file__).resolve().parents[2] / "docs" / "motion-files.md").read_text()
    table = text.split("| suffix | format |")[1].split("\n\n")[0]
    for row in FORMATS:
        assert f"`{row.suffix}`" in table, row.suffix


def test_folder_loading_reports_progress_when_verbose(tmp_path, capsys):
    from skmotion.datasets import load_bvh_folder

    data = make_motions(n_clips_per_class=2, classes=["wave"], duration=(0.5, 0.5), random_state=0)
    for k, motion in enumerate(as_motions(data.clips, data.skeletons, 30.0)):
        write_bvh(motion, tmp_path / f"{k}.BVH")
    assert len(load_bvh_folder(tmp_path).clips) == 2  # any case of the suffix
    assert capsys.readouterr().err == ""
    load_bvh_folder(tmp_path, verbose=1)
    assert "reading motion files" in capsys.readouterr().err
