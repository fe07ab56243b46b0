"""The demo's similarity-search section: what it reports is what the index does."""

import re
from types import SimpleNamespace

from skmotion._demo import index
from skmotion.datasets import make_motions
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.io import as_motions
from skmotion.preprocessing import to_markers


def _percentages(line):
    return [float(v) / 100 for v in re.findall(r"([\d.]+)%", line)]


def test_index_section_reports_pruning_and_why_the_marker_index_prunes_little():
    # What the data and markers sections leave on the context.
    data = make_motions(random_state=0)
    context = SimpleNamespace(random_state=0, data=data)
    context.marker_clips, _ = to_markers(as_motions(data.clips, data.skeletons, data.frame_rate))
    lines = index.run(context)
    repeated = next(line for line in lines if line.strip().startswith("pruning efficiency"))
    pruning, found = _percentages(repeated)
    assert pruning > 0.8 and found > 0.95  # the paper's set-up: repetitions of one motion
    paper = _percentages(next(line for line in lines if "paper's rule, epsilon 1.0" in line))
    tuned = _percentages(next(line for line in lines if "epsilon 0.8, weighted first two" in line))
    assert paper[0] < 0.2 and paper[1] == 1.0
    assert tuned[0] > paper[0] + 0.4 and tuned[1] > 0.95
    assert abs(context.index_pruning - tuned[0]) < 5e-4  # printed to 0.1%
    # The class the explanation names really spans the whole range of that component.
    why = next(line for line in lines if "why so little" in line)
    name, share, component = re.search(r"class '(\w+)' spans (\d+)% of component (\d+)", why).groups()
    features = SVDFeatureExtractor(n_components=7).fit_transform(context.marker_clips)
    rows = features[context.data.target == list(context.data.target_names).index(name)]
    span = features.max(axis=0) - features.min(axis=0)
    relative = (rows.max(axis=0) - rows.min(axis=0)) / span
    assert round(100 * relative[int(component)]) == int(share) and relative[int(component)] > 0.9
