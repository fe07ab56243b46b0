"""The demo's recognition section reports a working classifier and its tree."""

import re

import numpy as np
import pytest

from skmotion._demo import run_demo

SECTIONS = ("skmotion._demo.data", "skmotion._demo.markers", "skmotion._demo.recognition")


def test_recognition_section(capsys):
    lines = []
    context = run_demo(lines.append, sections=SECTIONS)
    text = "\n".join(lines)
    assert "== Recognition: the motion database (MotionTreeHMM) ==" in text
    accuracy = float(
        re.search(r"tested on subject \S+ \((\d+) clips\): accuracy ([\d.]+)", text).group(2)
    )
    assert accuracy >= 0.8
    # the confusion table counts every test clip once
    start = lines.index("confusion (rows: true, columns: predicted):") + 2
    table = np.array([[int(v) for v in line.split()[1:]] for line in lines[start : start + 7]])
    assert table.sum() == 21 and np.trace(table) / 21 == pytest.approx(accuracy, abs=1e-3)
    tree = context.motion_tree.tree_
    assert f"{tree.n_layers} layers, {tree.n_tree_nodes} nodes" in text
    assert "figure:" not in text  # no output folder: no figure


def test_plots_are_saved(tmp_path):
    pytest.importorskip("matplotlib")
    lines = []
    run_demo(lines.append, sections=SECTIONS, out=tmp_path)
    assert (tmp_path / "motion_tree_layers.png").stat().st_size > 0
    assert any(str(tmp_path) in line for line in lines)
