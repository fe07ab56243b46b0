"""The demo's planning section reaches its goal and saves Figure 13 (left)."""

import pytest

from skmotion._demo import run_demo


def test_planning_section(tmp_path):
    pytest.importorskip("matplotlib")
    lines = []
    context = run_demo(lines.append, sections=("skmotion._demo.planning",), out=tmp_path)
    text = "\n".join(lines)
    assert "== Planning: a walk to a goal on the transition graph ==" in text
    assert context.plan.reached <= 0.15 and (context.plan.seen_counts > 0).all()
    assert "unreachable" in text
    assert (tmp_path / "planned_root_path.png").stat().st_size > 0
