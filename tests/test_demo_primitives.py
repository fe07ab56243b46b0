from types import SimpleNamespace

import numpy as np

from skmotion._demo import SECTIONS, primitives
from skmotion.datasets import make_motions


def test_primitives_section_reports_consistent_errors():
    assert "skmotion._demo.primitives" in SECTIONS
    context = SimpleNamespace(random_state=0, data=make_motions(random_state=0))
    lines = primitives.run(context)
    text = "\n".join(lines)
    pca, controller = context.eigenmovements, context.primitives
    n = pca.components_.shape[1]
    assert f"gives {pca.n_segments_} segments" in text
    assert f"projection RMS {pca.projection_rms_:.2f} deg" in text
    total = np.sqrt((pca.projection_mse_ + controller.clustering_mse_) / n)
    assert f"total {total:.2f} deg" in text
    assert context.primitive_accuracy > 0.8  # 7 classes: chance is 0.14
    assert any(line.startswith("arm simulation") for line in lines)
