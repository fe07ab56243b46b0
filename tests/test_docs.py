"""The README and the user guide stay true: their Python examples run."""

import re
import textwrap
from pathlib import Path

import pytest

from tests.conftest import SHARED_DATA

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# A block that reads ../shared/data carries this comment; it runs when the data is there.
NEEDS_DATA = "# doc: needs ../shared/data"
# A block that imports an optional extra names its module; it runs when that is installed.
NEEDS_MODULE = re.compile(r"^# doc: needs module (\S+)$", flags=re.M)


def _python_blocks(path):
    return [
        textwrap.dedent(b) for b in re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)
    ]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_python_examples_run(page, tmp_path, monkeypatch):
    blocks = _python_blocks(page)
    if any(NEEDS_DATA in b for b in blocks) and not SHARED_DATA.is_dir():
        pytest.skip(f"{page.name} reads {SHARED_DATA}, which is absent")
    # Run from a scratch folder beside a link to the shared data, so that the pages'
    # relative paths (../shared/data) resolve as they do from the project root.
    work = tmp_path / "project"
    work.mkdir()
    if SHARED_DATA.is_dir():
        (tmp_path / "shared").symlink_to(SHARED_DATA.parent)
    monkeypatch.chdir(work)
    namespace = {"__name__": "__main__"}  # as when the page's code runs as a script
    for block in blocks:
        for module in NEEDS_MODULE.findall(block):
            pytest.importorskip(module, reason=f"{page.name} needs the optional {module}")
        exec(compile(block, str(page), "exec"), namespace)


def test_readme_gives_the_two_setup_commands():
    text = (ROOT / "README.md").read_text()
    assert 'pip install ".[plot]" && skmotion demo' in text
    assert 'pip install -e ".[test]" && pytest' in text
    assert ". .venv-demo/bin/activate" in text and ". .venv-test/bin/activate" in text


def test_architecture_lists_every_module():
    text = (ROOT / "docs" / "architecture.md").read_text()
    modules = [
        p.relative_to(ROOT).as_posix()
        for pattern in ("*.py", "*.pyx")
        for p in (ROOT / "skmotion").rglob(pattern)
        if p.name != "__init__.py"
    ]
    missing = [m for m in modules if Path(m).name not in text]
    assert not missing, f"docs/architecture.md does not mention {missing}"
