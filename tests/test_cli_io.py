"""`skmotion info FILE` and `skmotion demo --data FOLDER`."""

import pathlib

import numpy as np
import pytest

from skmotion.cli import main
from skmotion.datasets import make_motions
from skmotion.io import as_motions, write_bvh
from tests.io.test_asf_amc import ASF, _amc, _frames


@pytest.fixture
def bvh_file(tmp_path):
    data = make_motions(n_clips_per_class=1, classes=["jump"], duration=(2.0, 2.0), random_state=0)
    path = tmp_path / "jump.bvh"
    write_bvh(as_motions(data.clips, data.skeletons, 30.0)[0], path)
    return path


def test_info_bvh(bvh_file, capsys):
    assert main(["info", str(bvh_file)]) == 0
    out = capsys.readouterr().out
    assert "format: BVH" in out
    assert (
        "skeleton: 26 joints (21 with channels or children, 5 end sites), root 'Hips', y-up" in out
    )
    assert "channels: 66: Hips_Xposition, Hips_Yposition" in out
    assert "frames: 60 at 30 Hz, duration 2.00 s" in out
    assert "marker preset: humanoid" in out


def test_info_asf_and_amc(tmp_path, rng, capsys):
    (tmp_path / "07.asf").write_text(ASF)
    (tmp_path / "07_01.amc").write_text(_amc(_frames(rng, 12)))
    assert main(["info", str(tmp_path / "07_01.amc")]) == 0
    out = capsys.readouterr().out
    assert "Acclaim motion (AMC)" in out and "07.asf" in out
    assert "frames: 12 at 120 Hz, duration 0.10 s" in out and "length unit 1/0.45 inch" in out
    assert main(["info", str(tmp_path / "07.asf")]) == 0
    assert "channels: 12 (an AMC frame of this skeleton)" in capsys.readouterr().out
    (tmp_path / "bad.bvh").write_text("HIERARCHY\nROOT a\n{\n")
    assert main(["info", str(tmp_path / "bad.bvh")]) == 1
    assert "bad.bvh" in capsys.readouterr().err


def test_demo_has_the_marker_section(demo_report):
    out = demo_report
    assert "== Virtual markers: positions and velocities in the body frame ==" in out
    assert "32 markers" in out and "humanoid 84 clips" in out and "192 channels per frame" in out
    accuracy = float(out.split("accuracy ")[2].split()[0])
    baseline = float(out.split("1-NN baseline ")[1].split(")")[0])
    assert accuracy > baseline + 0.1  # the body frame removes position and heading


def test_demo_on_a_folder_of_files(tmp_path, capsys):
    data = make_motions(
        n_clips_per_class=3,
        n_subjects=3,
        classes=["walk", "squat"],
        duration=(1.0, 1.5),
        frame_rate=60.0,
        random_state=1,
    )
    for k, motion in enumerate(as_motions(data.clips, data.skeletons, data.frame_rate)):
        folder = tmp_path / str(data.target_names[data.target[k]])
        folder.mkdir(exist_ok=True)
        write_bvh(motion, folder / f"{k:02d}_01.bvh")  # CMU-like names: subject k
    out_dir = tmp_path.parent / f"{tmp_path.name}-out"
    assert main(["demo", "--data", str(tmp_path), "--frame-rate", "20", "--out", str(out_dir)]) == 0
    out = capsys.readouterr().out
    assert f"{tmp_path}: 6 clips (6 BVH)" in out
    assert "recorded at 60 Hz" in out and "resampled to 20 Hz" in out
    assert "channels: 66 joint angles" in out
    # no index: labels from a keyword in the file name, else the folder (names 00_01 ... have none)
    assert "classes (2): squat 3 (3 subj.), walk 3 (3 subj.)" in out
    assert "0 from a keyword in the file name; 6 from the folder name (fallback)" in out
    assert "evaluation: split by subject" in out
    assert "humanoid 6 clips" in out


def test_demo_on_the_shared_data(shared_data, capsys, monkeypatch):
    from skmotion._demo import data_folder

    calls = []
    original = data_folder.load_motion_folder

    def smaller(folder, index=None):
        data = original(
            pathlib.Path(folder) / "cmu-bvh"
        )  # the real CC files (two skeletons); quick
        calls.append(folder)
        return data

    monkeypatch.setattr(data_folder, "load_motion_folder", smaller)
    assert main(["demo", "--data", str(shared_data), "--no-out", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert (
        calls
        and "12 clips (12 BVH" in out
        and "virtual markers (the files hold several skeletons)" in out
    )
    assert "character_creator 12 clips" in out
    heights = out.split("median height over all frames: ")[1]
    assert 0.9 < float(heights.split("head_top ")[1].split(",")[0]) < 1.1
    assert np.isfinite(float(heights.split("pelvis ")[1].split(",")[0]))
