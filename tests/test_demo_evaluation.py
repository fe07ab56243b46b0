"""The demo's evaluation section: it reports a nested subject-wise score and an identical reload."""

import re


def test_evaluation_section(demo_report):
    section = demo_report.split("== Evaluation by subject, and persistence ==")[1].split("\n== ")[0]
    nested = re.search(
        r"accuracy ([\d.]+) \+/- ([\d.]+); epsilon chosen per outer fold \[(.*)\]", section
    )
    assert nested is not None, section
    assert 0.5 < float(nested[1]) <= 1.0
    chosen = [float(v) for v in nested[3].split(",")]
    assert len(chosen) == 4 and set(chosen) <= {0.5, 1.0}  # make_motions: 4 subjects
    assert "predictions identical: True" in section
