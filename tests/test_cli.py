import subprocess
import sys

import pytest

from skmotion import __version__
from skmotion.cli import main


def test_demo_reports_the_data(capsys):
    assert main(["demo"]) == 0
    out = capsys.readouterr().out
    assert "== Data: built-in synthetic motions ==" in out
    assert "84 clips" in out
    assert "classes (7): walk 12, jog 12, jump 12, kick 12, wave 12, punch 12, squat 12" in out
    assert "subjects (4)" in out
    accuracy = float(out.split("subject-wise 4-fold CV: accuracy ")[1].split()[0])
    assert 0.3 < accuracy < 0.95


def test_demo_seed_changes_the_data(capsys):
    main(["demo", "--random-state", "1"])
    first = capsys.readouterr().out
    main(["demo", "--random-state", "2"])
    second = capsys.readouterr().out
    assert first.split("frames")[0] != second.split("frames")[0]


def test_version_and_help(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"skmotion {__version__}"
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out


def test_python_dash_m():
    result = subprocess.run([sys.executable, "-m", "skmotion", "--version"], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == f"skmotion {__version__}"
