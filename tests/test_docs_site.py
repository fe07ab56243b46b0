"""The documentation site's API reference (docs/api.rst) names every public name once.

The site itself is built in CI (``sphinx-build -W``, extra ``docs``); this check needs no
Sphinx, so a new public name without a place in the reference fails the ordinary tests.
"""

import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _listed():
    listed, module = {}, None
    for line in (ROOT / "docs" / "api.rst").read_text().splitlines():
        match = re.match(r"\.\. currentmodule:: (\S+)", line)
        if match:
            module = match.group(1)
        elif module and line.startswith("   ") and line.strip() and not line.strip()[0] == ":":
            listed.setdefault(module, []).append(line.strip())
    return listed


def test_api_reference_lists_every_public_name_once():
    listed = _listed()
    names = [name for names in listed.values() for name in names]
    assert len(names) == len(set(names)), "a name is listed twice (duplicate object description)"
    for module, entries in listed.items():
        package = importlib.import_module(module)
        assert not [n for n in entries if not hasattr(package, n)], module
        public = [n for n in getattr(package, "__all__", []) if not n.isupper()]
        missing = [n for n in public if n not in names]
        assert not missing, f"docs/api.rst does not list {module}: {missing}"


def test_every_guide_page_is_in_the_site():
    contents = (ROOT / "docs" / "contents.rst").read_text()
    pages = sorted(p.stem for p in (ROOT / "docs").glob("*.md"))
    assert not [p for p in pages if f"\n   {p}\n" not in contents]
