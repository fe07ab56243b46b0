"""The demo's similarity-search section: what it reports is what the index does."""

import re

from skmotion.datasets import make_motions
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.io import as_motions
from skmotion.preprocessing import to_markers


def _percentages(line):
    return [float(v) / 100 for v in re.findall(r"([\d.]+)%", line)]


def test_index_section_reports_pruning_and_why_the_marker_index_prunes_little(demo_report):
    section = demo_report.split("== Similarity search: SVD features in an interval index ==")[
        1
    ].split("\n== ")[0]
    lines = section.splitlines()
    repeated = next(line for line in lines if line.strip().startswith("pruning efficiency"))
    pruning, found = _percentages(repeated)
    assert pruning > 0.8 and found > 0.95  # the paper's set-up: repetitions of one motion
    assert re.search(
        r"tree traversal [\d.]+ us per query batched, [\d.]+ us one at a time", section
    )
    paper = _percentages(next(line for line in lines if "paper's rule, epsilon 1.0" in line))
    tuned = _percentages(next(line for line in lines if "epsilon 0.8, weighted first two" in line))
    assert paper[0] < 0.2 and paper[1] == 1.0
    assert tuned[0] > paper[0] + 0.4 and tuned[1] > 0.95
    # The class the explanation names really spans the whole range of that component
    # (the demo's data: make_motions(random_state=0) as virtual markers).
    why = next(line for line in lines if "why so little" in line)
    name, share, component = re.search(
        r"class '(\w+)' spans (\d+)% of component (\d+)", why
    ).groups()
    data = make_motions(random_state=0)
    clips, _ = to_markers(as_motions(data.clips, data.skeletons, data.frame_rate))
    features = SVDFeatureExtractor(n_components=7).fit_transform(clips)
    rows = features[data.target == list(data.target_names).index(name)]
    relative = (rows.max(axis=0) - rows.min(axis=0)) / (features.max(axis=0) - features.min(axis=0))
    assert round(100 * relative[int(component)]) == int(share) and relative[int(component)] > 0.9
