"""Metrics of similarity search and of detection in streams; scorers for ``GridSearchCV``.

"Similar" means "has the same label". For a query, the stored clips with its label
are relevant and the others irrelevant; an index returns a candidate set.
"""

from skmotion.metrics._candidates import pruning_efficiency, recall
from skmotion.metrics._ceiling import pruning_ceiling
from skmotion.metrics._detection import detection_counts, detection_f1

# _SearchScorer is imported here too: scorers pickled before the split name it here.
from skmotion.metrics._scorers import (
    SEARCH_SCORES,
    _SearchScorer,  # noqa: F401
    make_pruning_scorer,
    make_search_scorer,
    pruning_scorer,
    recall_scorer,
)

__all__ = [
    "SEARCH_SCORES",
    "detection_counts",
    "detection_f1",
    "make_pruning_scorer",
    "make_search_scorer",
    "pruning_ceiling",
    "pruning_efficiency",
    "pruning_scorer",
    "recall",
    "recall_scorer",
]
