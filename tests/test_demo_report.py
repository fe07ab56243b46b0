"""`skmotion demo` writes its figures and one self-contained HTML report into --out."""

import base64
import html
import re

import pytest

from skmotion._demo import run_demo
from skmotion.cli import build_parser


def test_default_output_folder_and_where_it_is_said(demo_report):
    assert build_parser().parse_args(["demo"]).out == "skmotion-demo"
    assert re.search(r"figures and report\.html .* written to \S+/", demo_report)


def test_report_embeds_every_figure_and_the_text(tmp_path):
    pytest.importorskip("matplotlib")
    lines = []
    context = run_demo(
        lines.append, sections=("skmotion._demo.data", "skmotion._demo.planning"), out=tmp_path
    )
    report = (tmp_path / "report.html").read_text()
    assert context.report_path == tmp_path / "report.html"
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["clip.gif", "clip.png", "planned_root_path.png", "pose.png", "report.html"]
    for line in lines:
        if line.startswith("== "):  # a section's title is its heading
            assert f"<h2>{html.escape(line.strip('= '))}</h2>" in report
        else:
            assert html.escape(line) in report
    images = re.findall(r'src="data:(image/\w+);base64,([^"]+)"', report)
    assert len(images) == 4  # nothing refers to a file outside the report
    by_bytes = {base64.b64decode(data) for _, data in images}
    for name in ("pose.png", "clip.png", "clip.gif", "planned_root_path.png"):
        assert (tmp_path / name).read_bytes() in by_bytes
    assert sorted(kind for kind, _ in images) == [
        "image/gif",
        "image/png",
        "image/png",
        "image/png",
    ]
    assert not list(tmp_path.glob("*.part*"))


def test_no_output_folder_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    lines = []
    context = run_demo(lines.append, sections=("skmotion._demo.data",))
    assert context.report_path is None and not list(tmp_path.iterdir())
    assert not any("figure" in line for line in lines)


def test_long_lines_wrap_and_tables_keep_their_spaces(tmp_path):
    from skmotion._demo._report import write_report

    long_line = "error: " + "x" * 400
    table = "  walk     3     0"
    path = write_report(tmp_path / "r.html", "t", [("s", [long_line, table], [])])
    text = path.read_text()
    style = re.search(r"pre\{([^}]*)\}", text).group(1)
    assert "white-space:pre-wrap" in style and "overflow-wrap:anywhere" in style
    assert "overflow-x" not in style  # no horizontal scrolling that hides the end of a line
    assert html.escape(table) in text  # the aligning spaces are still there
