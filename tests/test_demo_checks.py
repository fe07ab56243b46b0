"""The demo's bad-input section: each bad input is rejected where the message says."""

import re

from skmotion.datasets import make_motions
from skmotion.io import Motion, write_bvh


def test_checks_section_names_what_and_where(demo_report, tmp_path):
    section = demo_report.split("== Bad input: what skmotion checks ==")[1].split("\n== ")[0]
    assert "clip 3 contains NaN at frame 17, channel 8" in section
    assert "clip 1 has 64 channels, but clip 0 has 66" in section
    assert "NotFittedError" in section and "'frame_rate' parameter of ResampleClips" in section
    assert "For a single clip pass [clip]" in section
    line, values = re.search(
        r"walk\.bvh, line (\d+): (\d+) values on a frame line, but the hierarchy has 66", section
    ).groups()
    # The file was cut halfway through its 20th frame line: half of the 66 values, on
    # the 20th line after 'Frame Time' in the same file written whole.
    assert int(values) == 33
    data = make_motions(random_state=0)
    write_bvh(
        Motion(data.skeleton, data.clips[0][:40], frame_rate=data.frame_rate),
        tmp_path / "w.bvh",
        precision=4,
    )
    text = (tmp_path / "w.bvh").read_text().splitlines()
    frame_time_line = next(
        k for k, words in enumerate(text, start=1) if words.startswith("Frame Time")
    )
    assert int(line) == frame_time_line + 20
