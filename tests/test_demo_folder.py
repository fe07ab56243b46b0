"""`skmotion demo --data FOLDER` is honest: labels from the CMU index at any depth, a split
that can work (or a one-line refusal), every section on the folder's own data, bad paths
as one line and exit status 2."""

import re
import subprocess
import sys

import numpy as np
import pytest

from skmotion._demo import run_demo
from skmotion._demo._split import choose_evaluation, confusion_lines
from skmotion._demo.data_folder import find_cmu_index, label_clips
from skmotion.datasets import make_motions
from skmotion.io import as_motions, write_bvh

INDEX = (
    '"Subject","Trial #","Motion Description","framerate"\n'
    '5,1,"walk on uneven terrain",60\n5,2,"run/jog",60\n5,3,"playground - climb, jump down",60\n'
    '6,1,"walk",60\n6,2,"slow walk",60\n6,3,"jumping jacks",60\n'
)


def _write_folder(root, names, classes, *, n_subjects=2, index=True, seed=0):
    """Write BVH files (the project's writer) under ``root`` at the given relative names."""
    data = make_motions(
        n_clips_per_class=max(1, len(names) // len(classes) + 1),
        n_subjects=n_subjects,
        classes=classes,
        duration=(1.0, 1.2),
        random_state=seed,
    )
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    for name, motion in zip(names, motions):
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bvh(motion, path)
    if index:
        (root / "cmu-index.csv").write_text(INDEX)
    return root


# -- the split --------------------------------------------------------------------------


def test_subject_wise_when_every_class_has_two_subjects():
    labels = np.array(["walk", "run"] * 6)
    groups = np.repeat([0, 1, 2], 4)
    evaluation = choose_evaluation(labels, groups)
    assert evaluation.kind == "subject" and "split by subject" in evaluation.reason
    for train, test in evaluation.split(labels):
        assert set(groups[train]).isdisjoint(groups[test])
        assert set(labels[test]) <= set(labels[train])


def test_a_class_of_one_subject_splits_by_trial_and_says_why():
    labels = np.array(["walk"] * 4 + ["climb"] * 4 + ["jump"])
    groups = np.array([0, 0, 1, 1, 0, 0, 0, 0, 1])
    evaluation = choose_evaluation(labels, groups, np.array(["01", "02"]))
    assert evaluation.kind == "trial"
    assert "climb (only subject 01)" in evaluation.reason
    assert "left out: jump (1 clip each" in evaluation.reason
    assert 8 not in evaluation.clips  # the lone jump is neither trained on nor tested
    for train, test in evaluation.split(labels):
        assert set(labels[test]) <= set(labels[train])  # stratified: every class on both sides
    assert evaluation.name == "by-trial stratified 4-fold CV"  # the smallest kept class: 4


@pytest.mark.parametrize(
    "labels, expected",
    [
        (["walk"] * 5, "every clip is 'walk' (one class)"),
        (["walk"] * 5 + ["run"], "fewer than 2 classes have 2 or more clips (run 1, walk 5)"),
    ],
)
def test_no_split_can_work(labels, expected):
    evaluation = choose_evaluation(np.array(labels), np.zeros(len(labels), int))
    assert evaluation.kind is None and expected in evaluation.reason


def test_confusion_counts_every_true_and_predicted_label():
    truth = np.array(["walk", "walk", "run", "climb"])
    predicted = np.array(["walk", "jump", "run", "walk"])  # "jump" never true, "climb" never
    lines = confusion_lines(truth, predicted)
    header = lines[1].split()
    assert header == ["climb", "jump", "run", "walk"]
    table = {line.split()[0]: [int(v) for v in line.split()[1:]] for line in lines[2:]}
    assert table == {
        "climb": [0, 0, 0, 1],
        "jump": [0, 0, 0, 0],
        "run": [0, 0, 1, 0],
        "walk": [0, 1, 0, 1],
    }


# -- labels -----------------------------------------------------------------------------


def test_labels_from_the_index_at_any_depth_then_file_names_then_folders(tmp_path):
    root = _write_folder(
        tmp_path,
        ["a/b/05_01.bvh", "05_02.bvh", "deep/er/06_03.bvh", "takes/Take_Walk2.bvh", "dance/x.bvh"],
        ["walk", "jog"],
    )
    index_path = find_cmu_index(root / "a" / "b")
    assert index_path == root / "cmu-index.csv"  # found in a folder above
    from skmotion.datasets import read_cmu_index

    files = sorted(root.rglob("*.bvh"))
    labels, sources, subjects = label_clips(files, root, read_cmu_index(index_path))
    got = {f.name: (lab, src, sub) for f, lab, src, sub in zip(files, labels, sources, subjects)}
    assert got["05_01.bvh"] == ("walk", "CMU index", "05")
    assert got["05_02.bvh"] == ("run", "CMU index", "05")
    assert got["06_03.bvh"] == ("jump", "CMU index", "06")
    assert got["Take_Walk2.bvh"] == ("walk", "file name", "takes")
    assert got["x.bvh"] == ("dance", "folder name", "dance")


# -- the command on folders ---------------------------------------------------------------


@pytest.mark.parametrize("kind", ["missing", "file", "empty"])
def test_bad_folders_give_one_line_and_status_2(tmp_path, kind):
    target = {"missing": tmp_path / "nope", "file": tmp_path / "f.txt", "empty": tmp_path / "e"}[
        kind
    ]
    if kind == "file":
        target.write_text("not motion")
    if kind == "empty":
        target.mkdir()
        (target / "notes.txt").write_text("no motion files here")
    result = subprocess.run(
        [sys.executable, "-m", "skmotion", "demo", "--data", str(target), "--no-out", "--quiet"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert str(target) in result.stderr


def _folder_report(folder, sections, capsys=None, **options):
    lines = []
    context = run_demo(
        lines.append, sections=sections, data_folder=str(folder), frame_rate=30.0, out=None,
        **options,
    )  # fmt: skip
    return "\n".join(lines), context


FOLDER_SECTIONS = (
    "skmotion._demo.data_folder",
    "skmotion._demo.markers",
    "skmotion._demo.recognition",
    "skmotion._demo.index",
    "skmotion._demo.evaluation",
    "skmotion._demo.checks",
    "skmotion._demo.planning",
)


def test_single_subject_classes_are_split_by_trial_with_every_section_on_the_folder(tmp_path):
    # Subject 05 walks, subject 06 jumps: subject-wise testing would test unseen classes.
    # (no index: the labels come from a labels file, the subjects from the NN of NN_TT;
    # folder-name labels, each of one subject, would be refused: see test_folder_labels)
    names = [f"walk/05_{t:02d}.bvh" for t in range(1, 5)]
    names += [f"jump/06_{t:02d}.bvh" for t in range(1, 5)]
    root = _write_folder(tmp_path, names, ["walk", "jump"], index=False)
    text, _ = _folder_report(root, ("skmotion._demo.data_folder",))
    assert "NOT EVALUATED: the labels come from folder names, and each of these labels" in text
    labels = tmp_path / "labels.csv"
    labels.write_text("path,label\n" + "".join(f"{n},{n.split('/')[0]}\n" for n in names))
    text, context = _folder_report(root, FOLDER_SECTIONS, labels=str(labels))
    assert "evaluation: split by trial (stratified)" in text
    assert "subject-wise" not in text.split("== Evaluation")[0]  # no subject-wise accuracy
    assert "nested subject-wise CV: not run" in text
    # each section on the folder's own data or a plain skip
    assert "make_repeated_motions:" not in text and "repeated-motion benchmark" in text
    assert "bad inputs made from the folder's first 4 clip(s) (from 06_01.bvh" in text
    assert f"not run on {root}" in text  # planning
    assert "make_walks" not in text.split("== Planning")[0]


def test_one_class_folder_prints_no_accuracy(tmp_path):
    root = _write_folder(tmp_path, ["w/walk_a.bvh", "w/walk_b.bvh"], ["walk"], index=False)
    text, _ = _folder_report(root, FOLDER_SECTIONS)
    assert "no classifier can be evaluated: every clip is 'walk' (one class)" in text
    assert "accuracy" not in text


@pytest.mark.parametrize("sub", ["cmu-asfamc", "cmu-bvh", "."])
def test_shared_data_gets_index_labels_and_a_possible_split(shared_data, sub):
    text, context = _folder_report(shared_data / sub, ("skmotion._demo.data_folder",))
    index = shared_data / "cmu-index.csv"
    assert f"from the CMU index ({index})" in text
    evaluation = context.evaluation
    data = context.data
    names = data.target_names[data.target]
    if sub == "cmu-bvh":
        assert evaluation.kind is None and "accuracy" not in text  # all 12 trials walk
        return
    # climb is subject 01's alone and strike subject 02's: no subject-wise split can work
    assert evaluation.kind == "trial" and "climb (only subject 01)" in text
    accuracy = re.search(r"by-trial stratified (\d)-fold CV: accuracy", text)
    assert accuracy is not None and "subject-wise" not in text
    for train, test in evaluation.split(names):
        assert set(names[test]) <= set(names[train])
    if sub == ".":
        # the lone non-CMU clip is labelled from its file name, not its folder
        k = [i for i, f in enumerate(data.filenames) if "bvh-samples" in f][0]
        assert names[k] == "walk" and data.label_sources[k] == "file name"


def test_progress_on_stderr_only_when_asked(tmp_path, capsys):
    names = [f"walk/05_{t:02d}.bvh" for t in range(1, 4)] + [f"jump/06_{t:02d}.bvh" for t in (1, 2)]
    root = _write_folder(tmp_path, names, ["walk", "jump"], index=False)
    labels = tmp_path / "labels.csv"
    labels.write_text("path,label\n" + "".join(f"{n},{n.split('/')[0]}\n" for n in names))
    sections = ("skmotion._demo.data_folder",)
    run_demo(
        lambda line: None, sections=sections, data_folder=str(root), verbose=1, labels=str(labels)
    )
    err = capsys.readouterr().err
    assert "[skmotion] demo: Data: motion files ..." in err
    assert re.search(r"\[skmotion\] baseline CV.*\d+/\d+", err)  # the folds, as they finish
    run_demo(lambda line: None, sections=sections, data_folder=str(root))
    assert capsys.readouterr().err == ""


def _write_c3d_folder(root):
    """C3D files of Kinect v2 joint positions (mm), named by class and subject."""
    import warnings

    c3d = pytest.importorskip("c3d")
    from skmotion.datasets import make_position_motions
    from skmotion.kinematics import get_layout

    data = make_position_motions("kinect_v2", n_clips_per_class=4, random_state=0)
    joints = list(get_layout("kinect_v2").joints)
    names = np.asarray(data.target_names)[data.target]
    for i, clip in enumerate(data.clips):
        writer = c3d.Writer(point_rate=float(data.frame_rate), analog_rate=0.0, point_scale=-1.0)
        writer.set_point_labels(joints)
        frames = []
        for xyz in clip.reshape(len(clip), -1, 3) * 1000.0:
            points = np.zeros((len(joints), 5), np.float32)
            points[:, :3] = xyz
            frames.append((points, np.zeros((0, 0))))
        writer.add_frames(frames)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with open(root / f"{names[i]}_{i:02d}.c3d", "wb") as handle:
                writer.write(handle)


def test_a_folder_of_joint_positions_runs_on_its_layout(tmp_path):
    """C3D positions: the layout is found, markers come from it, sections say what they skip."""
    _write_c3d_folder(tmp_path)
    lines = []
    sections = tuple(
        f"skmotion._demo.{name}"
        for name in ("data_folder", "markers", "recognition", "checks", "live")
    )
    run_demo(lines.append, sections=sections, data_folder=str(tmp_path))
    text = "\n".join(lines)
    assert "28 clips (28 C3D)" in text
    assert "joint positions (the kinect_v2 layout)" in text
    assert "placed by the kinect_v2 layout" in text
    assert re.search(r"tested on .*: accuracy [01]\.\d{3}", text)
    assert "truncated C3D: MotionFileError: " in text
    assert f"not run on {tmp_path}" in text  # the live section says it is skipped, and why
