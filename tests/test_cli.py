import subprocess
import sys

import pytest

from skmotion import __version__
from skmotion._demo import run_demo
from skmotion.cli import main


def test_demo_reports_the_data(demo_report):
    out = demo_report
    assert "== Data: built-in synthetic motions ==" in out
    assert "84 clips" in out
    assert "classes (7): walk 12, jog 12, jump 12, kick 12, wave 12, punch 12, squat 12" in out
    assert "subjects (4)" in out
    accuracy = float(out.split("subject-wise 4-fold CV: accuracy ")[1].split()[0])
    assert 0.3 < accuracy < 0.95


def test_demo_seed_changes_the_data():
    reports = []
    for seed in (1, 2):
        lines = []
        run_demo(lines.append, random_state=seed, sections=("skmotion._demo.data",))
        reports.append("\n".join(lines))
    assert reports[0].split("frames")[0] != reports[1].split("frames")[0]


def test_version_and_help(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"skmotion {__version__}"
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out


def test_python_dash_m():
    result = subprocess.run(
        [sys.executable, "-m", "skmotion", "--version"], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == f"skmotion {__version__}"
