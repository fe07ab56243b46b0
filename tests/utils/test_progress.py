"""progress/say: silent by default, every item yielded in order, a line per tenth."""

import builtins

import pytest

from skmotion.utils import progress, say


def test_silent_by_default(capsys):
    assert list(progress(range(5), desc="x")) == [0, 1, 2, 3, 4]
    say(0, "hidden")
    assert capsys.readouterr().err == ""


def test_plain_lines_without_tqdm(monkeypatch, capsys):
    real_import = builtins.__import__

    def no_tqdm(name, *args, **kwargs):
        if name.startswith("tqdm"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_tqdm)
    assert list(progress(list(range(20)), verbose=1, desc="reading")) == list(range(20))
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 10
    assert lines[-1].startswith("[skmotion] reading: 20/20")


def test_tqdm_when_installed(capsys):
    pytest.importorskip("tqdm")
    assert list(progress(iter([3, 1, 2]), verbose=1, desc="sorting", total=3)) == [3, 1, 2]
    assert "sorting" in capsys.readouterr().err


def test_say_prints_on_stderr(capsys):
    say(1, "fitting the tree")
    assert capsys.readouterr().err == "[skmotion] fitting the tree\n"
