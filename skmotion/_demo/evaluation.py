"""Demo section: subject-wise nested evaluation, and a saved model that loads back identical."""

import pickle

import numpy as np
import sklearn
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate

import skmotion
from skmotion.neighbors import IntervalIndexNeighbors

TITLE = "Evaluation by subject, and persistence"


def run(context):
    data = context.data
    clips = [c[:, 6:] for c in data.clips]  # joint angles without the root
    y, groups = data.target, data.groups
    _, per_subject = np.unique(groups, return_counts=True)
    n_subjects = len(per_subject)
    if n_subjects < 3:
        return [
            f"nested subject-wise CV: not run ({len(clips)} clips of {n_subjects} subject(s); needs 3)"
        ]
    # The smallest inner training set: all clips but the two largest subjects'.
    fewest = len(clips) - np.sort(per_subject)[-2:].sum()
    search = GridSearchCV(
        IntervalIndexNeighbors(n_levels=int(max(1, min(5, fewest)))),
        {"epsilon": [0.5, 1.0]},
        cv=GroupKFold(n_subjects - 1),
    )
    # Metadata routing sends the outer training subjects on to the inner GroupKFold.
    with sklearn.config_context(enable_metadata_routing=True):
        result = cross_validate(
            search,
            clips,
            y,
            cv=GroupKFold(n_subjects),
            params={"groups": groups},
            return_estimator=True,
        )
    chosen = [est.best_params_["epsilon"] for est in result["estimator"]]
    model = result["estimator"][0].best_estimator_
    restored = pickle.loads(pickle.dumps(model))
    same = np.array_equal(restored.predict_proba(clips), model.predict_proba(clips))
    return [
        f"nested CV, interval index: outer GroupKFold({n_subjects}) by subject, inner GroupKFold({n_subjects - 1}) "
        f"over epsilon with groups routed: accuracy {result['test_score'].mean():.3f} "
        f"+/- {result['test_score'].std():.3f}; epsilon chosen per outer fold {chosen}",
        f"pickle round trip of a fitted index: predictions identical: {same}; the pickle records "
        f"skmotion {skmotion.__version__} and loads only into skmotion {'.'.join(skmotion.__version__.split('.')[:2])}.x",
    ]
