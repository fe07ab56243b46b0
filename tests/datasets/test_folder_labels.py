"""Labels a user can trust: a labels file, a warning when folder names are the subjects,
bad files skipped by name (load_motion_folder, load_bvh_folder, skmotion demo --data)."""

import warnings

import numpy as np
import pytest

from skmotion._demo import run_demo
from skmotion.datasets import load_bvh_folder, load_motion_folder, make_motions, read_labels
from skmotion.io import as_motions, write_bvh

CLASSES = ["walk", "jump", "kick"]


def _subject_folder(root, *, n_subjects=3, names=("S01", "S02", "S03")):
    """``root/<subject>/trialK.bvh``: each subject performs every class; the truth returned."""
    data = make_motions(
        n_clips_per_class=2 * n_subjects, n_subjects=n_subjects, classes=CLASSES,
        duration=(0.8, 1.0), random_state=0,
    )  # fmt: skip
    truth = {}
    counts = {}
    for k, motion in enumerate(as_motions(data.clips, data.skeletons, data.frame_rate)):
        subject = names[data.groups[k]]
        counts[subject] = counts.get(subject, 0) + 1
        relative = f"{subject}/trial{counts[subject]}.bvh"
        (root / subject).mkdir(parents=True, exist_ok=True)
        write_bvh(motion, root / relative)
        truth[relative] = (str(data.target_names[data.target[k]]), subject)
    return truth


def _labels_file(path, truth, *, subject=True):
    lines = ["path,label" + (",subject" if subject else "")]
    lines += [f"{p},{lab}" + (f",{sub}" if subject else "") for p, (lab, sub) in truth.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def _load(load, *args, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = load(*args, **kwargs)
    return data, [str(w.message) for w in caught]


def test_read_labels_errors_name_the_line(tmp_path):
    path = tmp_path / "l.csv"
    path.write_text("path,label\na.bvh,walk\na.bvh,run\n")
    with pytest.raises(ValueError, match=r"l\.csv, line 3: 'a\.bvh' is labelled twice"):
        read_labels(path)
    path.write_text("file,what\na.bvh,walk\n")
    with pytest.raises(ValueError, match=r"line 1: .* lacks a 'label' column"):
        read_labels(path)
    path.write_text("stem,label\na,\n")
    with pytest.raises(ValueError, match=r"line 2: an empty label"):
        read_labels(path)


def test_subject_folders_warn_and_a_labels_file_gives_the_truth(tmp_path):
    truth = _subject_folder(tmp_path / "data")
    guessed, messages = _load(load_bvh_folder, tmp_path / "data")
    assert guessed.target_names.tolist() == ["S01", "S02", "S03"]  # the people
    assert guessed.label_warning is not None
    assert any("the folder names look like people (S01, S02, S03)" in m for m in messages)
    labels = _labels_file(tmp_path / "labels.csv", truth)
    data, messages = _load(load_bvh_folder, tmp_path / "data", labels=labels)
    assert messages == [] and data.label_warning is None
    got = [data.target_names[t] for t in data.target]
    root = (tmp_path / "data").as_posix() + "/"
    assert got == [truth[f.replace(root, "")][0] for f in data.filenames]
    assert sorted(data.subject_names) == ["S01", "S02", "S03"]
    assert set(data.label_source) == {"labels file"}


def test_a_subject_level_gives_the_subjects_and_the_rest_the_labels(tmp_path):
    data = make_motions(n_clips_per_class=2, n_subjects=2, classes=["walk", "kick"],
                        duration=(0.5, 0.6), random_state=0)  # fmt: skip
    for k, motion in enumerate(as_motions(data.clips, data.skeletons, data.frame_rate)):
        folder = tmp_path / f"sub-{k % 2 + 1}" / str(data.target_names[data.target[k]])
        folder.mkdir(parents=True, exist_ok=True)
        write_bvh(motion, folder / f"t{k}.bvh")
    loaded, messages = _load(load_motion_folder, tmp_path)
    assert messages == []
    assert loaded.target_names.tolist() == ["kick", "walk"]
    assert loaded.subject_names.tolist() == ["sub-1", "sub-2"]


def test_same_trial_names_in_class_folders_are_no_sign_of_subjects(tmp_path):
    # walk/take1.bvh, kick/take1.bvh: numbered takes per motion folder are common
    truth = _subject_folder(tmp_path, names=("walk", "kick", "jump"))
    assert len(truth) == 18
    _, messages = _load(load_bvh_folder, tmp_path)
    assert not [m for m in messages if "labels come from folder names" in m]


def test_a_labels_file_must_name_every_file(tmp_path):
    truth = _subject_folder(tmp_path / "data")
    first = next(iter(truth))
    del truth[first]
    labels = _labels_file(tmp_path / "labels.csv", truth)
    with pytest.raises(ValueError, match=f"does not label 1 of 18 files: {first}"):
        load_bvh_folder(tmp_path / "data", labels=labels)


def test_bad_files_are_skipped_by_name_and_the_rest_load(tmp_path):
    _subject_folder(tmp_path)
    (tmp_path / "S01" / "broken.bvh").write_text("HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\nMOTION\n")
    (tmp_path / "S02" / "empty.bvh").write_bytes(b"")
    data, messages = _load(load_motion_folder, tmp_path)
    assert len(data.clips) == 18
    assert [p.rsplit("/", 1)[1] for p, _ in data.skipped] == ["broken.bvh", "empty.bvh"]
    skipped = [m for m in messages if m.startswith("Skipped 2 of 20 motion files")]
    assert len(skipped) == 1 and "broken.bvh" in skipped[0] and "line 5" in skipped[0]
    with pytest.raises(ValueError, match=r"broken\.bvh, line 5"):
        load_motion_folder(tmp_path, errors="raise")
    for name in ("S01", "S02", "S03"):
        for path in (tmp_path / name).glob("trial*.bvh"):
            path.write_text("not a bvh file")
    with pytest.raises(ValueError, match="None of the 20 motion files under .* could be read"):
        load_motion_folder(tmp_path)


def _demo(folder, **options):
    lines = []
    context = run_demo(
        lines.append, sections=("skmotion._demo.data_folder",), data_folder=str(folder), **options
    )
    return "\n".join(lines), context


def test_demo_refuses_subjects_as_classes_and_scores_real_labels(tmp_path):
    truth = _subject_folder(tmp_path / "data")
    text, context = _demo(tmp_path / "data")
    assert "NOT EVALUATED: the labels come from folder names" in text
    assert "the folder names look like people (S01, S02, S03)" in text
    assert "--labels FILE" in text and "accuracy" not in text.replace("an accuracy would", "")
    assert context.evaluation.kind is None
    labels = _labels_file(tmp_path / "labels.csv", truth)
    text, context = _demo(tmp_path / "data", labels=str(labels))
    assert f"labels: all 18 clips from the labels file {labels}" in text
    assert context.evaluation.kind == "subject"  # every class by 3 subjects
    accuracy = float(text.split("subject-wise 3-fold CV: accuracy ")[1].split()[0])
    assert accuracy > 1 / 3  # better than chance on 3 balanced classes
    names = context.data.target_names[context.data.target]
    assert sorted(set(names)) == sorted(CLASSES)


def test_demo_lists_skipped_files_and_goes_on(tmp_path):
    truth = _subject_folder(tmp_path / "data")
    (tmp_path / "data" / "S03" / "broken.bvh").write_text("HIERARCHY\n")
    labels = _labels_file(tmp_path / "labels.csv", {**truth, "S03/broken.bvh": ("walk", "S03")})
    text, context = _demo(tmp_path / "data", labels=str(labels))
    assert "warning: Skipped 1 of 19 motion files" in text and "broken.bvh" in text
    assert len(context.data.clips) == 18


def test_demo_on_a_folder_of_ts_files(shared_data, tmp_path):
    for name in ("BasicMotions_TRAIN.ts", "BasicMotions_TEST.ts"):
        (tmp_path / name).symlink_to(shared_data / "uea" / name)
    text, context = _demo(tmp_path)
    assert "80 labelled series in 2 .ts files" in text
    assert "classes (4): Badminton 20, Running 20, Standing 20, Walking 20" in text
    assert "by-trial stratified" in text and context.baseline_accuracy > 0.5
    assert np.array_equal(np.bincount(context.data.target), [20, 20, 20, 20])
