"""Demo section: subject-wise nested evaluation, and a saved model that loads back identical."""

import pickle

import numpy as np
import sklearn
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate

import skmotion
from skmotion._demo._split import evaluation_of
from skmotion.neighbors import IntervalIndexNeighbors
from skmotion.utils import say

TITLE = "Evaluation by subject, and persistence"


def _persistence_line(model, clips):
    restored = pickle.loads(pickle.dumps(model))
    same = np.array_equal(restored.predict_proba(clips), model.predict_proba(clips))
    version = skmotion.__version__
    return (
        f"pickle round trip of a fitted index: predictions identical: {same}; the pickle records "
        f"skmotion {version} and loads only into skmotion {'.'.join(version.split('.')[:2])}.x"
    )


def _nested(context, clips, y, groups):
    """Nested subject-wise CV: subjects held out outside, an inner GroupKFold over epsilon."""
    n_subjects = len(np.unique(groups))
    # Leave one subject out (valid: every class has 2 subjects or more), unless that is many.
    outer = GroupKFold(n_subjects) if n_subjects <= 8 else evaluation_of(context).cv
    folds = list(outer.split(clips, y, groups))
    n_inner = min(5, min(len(np.unique(groups[train])) for train, _ in folds))
    inner = GroupKFold(n_inner)
    # The smallest inner training set bounds the index depth.
    fewest = min(
        len(inner_train)
        for train, _ in folds
        for inner_train, _ in inner.split(train, y[train], groups[train])
    )
    search = GridSearchCV(
        IntervalIndexNeighbors(n_levels=int(max(1, min(5, fewest)))),
        {"epsilon": [0.5, 1.0]},
        cv=inner,
    )
    n_folds = len(folds)
    say(getattr(context, "verbose", 0), f"demo: nested CV, {n_folds} outer folds x 2 epsilons ...")
    # Metadata routing sends the outer training subjects on to the inner GroupKFold.
    with sklearn.config_context(enable_metadata_routing=True):
        result = cross_validate(
            search, clips, y, cv=outer, params={"groups": groups}, return_estimator=True
        )
    chosen = [est.best_params_["epsilon"] for est in result["estimator"]]
    line = (
        f"nested CV, interval index: outer {type(outer).__name__}({n_folds}) by subject, "
        f"inner GroupKFold({n_inner}) over epsilon with groups routed: accuracy "
        f"{result['test_score'].mean():.3f} +/- {result['test_score'].std():.3f}; epsilon "
        f"chosen per outer fold {chosen}"
    )
    return line, result["estimator"][0].best_estimator_


def run(context):
    data = context.data
    # without the root's (or pelvis marker's) channels; time series have no root
    clips = data.clips if data.get("kind") == "series" else [c[:, 6:] for c in data.clips]
    y, groups = np.asarray(data.target), np.asarray(data.groups)
    evaluation = evaluation_of(context)
    n_subjects = len(np.unique(groups))
    if evaluation.kind == "subject" and n_subjects >= 3:
        line, model = _nested(context, clips, y, groups)
        return [line, _persistence_line(model, clips)]
    why = (
        f"{n_subjects} subjects; it needs 3, one outer test subject and two inner folds"
        if evaluation.kind == "subject"
        else "the demo's split is by trial; the data section says why"
        if evaluation.kind == "trial"
        else evaluation.reason
    )
    lines = [f"nested subject-wise CV: not run ({why})"]
    if len(np.unique(y)) < 2:
        return lines + ["persistence: not run (one class: there is nothing to predict)"]
    model = IntervalIndexNeighbors(n_levels=int(max(1, min(5, len(clips) - 1)))).fit(clips, y)
    return lines + [_persistence_line(model, clips)]
