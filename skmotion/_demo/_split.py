"""How the demo evaluates a classifier: a split that can work on the data, or a reason why none can.

Subject-wise cross-validation measures recognition of new people, and is used when
every class is performed by at least two subjects (so that each held-out subject's
classes also occur in training). Otherwise the clips are split by trial, stratified
by class, and the report says why; a class with a single clip cannot be both trained
and tested and is left out, by name. With fewer than two classes left, nothing is
evaluated and the reason is one line.
"""

from dataclasses import dataclass, field

import numpy as np
from sklearn.base import clone
from sklearn.model_selection import GroupKFold, LeaveOneGroupOut, StratifiedKFold

from skmotion.utils import progress

__all__ = ["Evaluation", "choose_evaluation", "confusion_lines", "evaluation_of"]


@dataclass
class Evaluation:
    """The split chosen for a data set.

    Attributes
    ----------
    kind : {"subject", "trial"} or None
        None when no split can evaluate a classifier (``reason`` says why).
    cv : cross-validator or None
    clips : ndarray of int
        The clips evaluated (all but those of classes with a single clip).
    reason : str
        One line: the split and why it was chosen, or why there is none.
    groups : ndarray
        Subject of every clip of the data set.
    """

    kind: object
    cv: object
    clips: np.ndarray
    reason: str
    groups: np.ndarray = field(repr=False)
    subject_names: object = field(default=None, repr=False)

    @property
    def name(self):
        """``"subject-wise 4-fold CV"`` or ``"by-trial stratified 2-fold CV"``."""
        n = self.cv.get_n_splits(groups=self.groups[self.clips])
        return f"{'subject-wise' if self.kind == 'subject' else 'by-trial stratified'} {n}-fold CV"

    def split(self, y):
        """The (train, test) index pairs over the whole data set."""
        keep = self.clips
        groups = self.groups[keep] if self.kind == "subject" else None
        for train, test in self.cv.split(keep, np.asarray(y)[keep], groups):
            yield keep[train], keep[test]

    def scores(self, model, X, y, *, verbose=0, desc="cross-validation"):
        """Accuracy of a clone of ``model`` on each test fold."""
        y = np.asarray(y)
        out = []
        folds = list(self.split(y))
        for train, test in progress(folds, verbose=verbose, desc=desc):
            fitted = clone(model).fit([X[i] for i in train], y[train])
            out.append(float(np.mean(fitted.predict([X[i] for i in test]) == y[test])))
        return np.asarray(out)

    def holdout(self, y):
        """One (train, test, description): a held-out subject, or the first stratified fold."""
        y = np.asarray(y)
        if self.kind == "subject":
            held_out = self.groups[self.clips].max()
            test = self.clips[self.groups[self.clips] == held_out]
            train = self.clips[self.groups[self.clips] != held_out]
            name = self.subject_names[held_out] if self.subject_names is not None else held_out
            return train, test, f"subject {name}"
        train, test = next(self.split(y))
        return train, test, f"a stratified 1/{self.cv.get_n_splits()} of the trials"


def _class_names(values):
    return ", ".join(str(v) for v in values)


def _subject_wise(labels, groups, keep, max_splits):
    """GroupKFold when every fold's test classes occur in its training part, else leave-one-out."""
    n_subjects = len(np.unique(groups[keep]))
    cv = GroupKFold(min(n_subjects, max_splits))
    for train, test in cv.split(keep, labels[keep], groups[keep]):
        if not np.isin(labels[keep][test], labels[keep][train]).all():
            return LeaveOneGroupOut()
    return cv


def choose_evaluation(labels, groups, subject_names=None, *, random_state=0, max_splits=5):
    """The split that can evaluate a classifier on these clips, with the reason.

    Parameters
    ----------
    labels : array-like of str
        Class of every clip.
    groups : array-like of int
        Subject of every clip.
    subject_names : array-like of str, default=None
        Names of the subjects (``groups`` indexes them).
    random_state : int, default=0
        Seed of the stratified split.
    max_splits : int, default=5

    Returns
    -------
    Evaluation
    """
    labels, groups = np.asarray(labels).astype(str), np.asarray(groups)
    classes, counts = np.unique(labels, return_counts=True)
    name = (lambda g: str(subject_names[g])) if subject_names is not None else str
    n_subjects = {c: len(np.unique(groups[labels == c])) for c in classes}
    everything = np.arange(len(labels))
    if len(classes) < 2:
        return Evaluation(
            None, None, everything, "no classifier can be evaluated: every clip is "
            f"{_class_names(classes)!r} (one class)", groups, subject_names
        )  # fmt: skip
    if len(np.unique(groups)) >= 2 and min(n_subjects.values()) >= 2:
        cv = _subject_wise(labels, groups, everything, max_splits)
        return Evaluation(
            "subject", cv, everything,
            "split by subject: every class is performed by 2 or more subjects, so each held-out "
            "subject's classes also occur in training", groups, subject_names,
        )  # fmt: skip
    single = classes[counts < 2]
    kept = classes[counts >= 2]
    keep = np.flatnonzero(np.isin(labels, kept))
    left_out = (
        f"; left out: {_class_names(single)} (1 clip each: a class needs one clip to train on "
        "and one to test)"
        if len(single)
        else ""
    )
    if len(kept) < 2:
        return Evaluation(
            None, None, keep, "no split can evaluate a classifier: fewer than 2 classes have 2 or "
            f"more clips ({', '.join(f'{c} {n}' for c, n in zip(classes, counts))})",
            groups, subject_names,
        )  # fmt: skip
    lone = [c for c in kept if n_subjects[c] < 2]
    who = ", ".join(f"{c} (only subject {name(groups[labels == c][0])})" for c in lone[:3])
    more = f" and {len(lone) - 3} more" if len(lone) > 3 else ""
    why = (
        f"not by subject, because some classes have one subject only: {who}{more}"
        if lone and len(np.unique(groups)) > 1
        else "not by subject: the clips come from one subject (or the subjects are unknown)"
    )
    n_splits = int(min(max_splits, counts[counts >= 2].min()))
    cv = StratifiedKFold(n_splits, shuffle=True, random_state=random_state)
    reason = (
        f"split by trial (stratified), {why}; scores measure new trials of known subjects, "
        f"not new people{left_out}"
    )
    return Evaluation("trial", cv, keep, reason, groups, subject_names)


def confusion_lines(truth, predicted):
    """A confusion table over every true and predicted label (rows: true, columns: predicted)."""
    truth, predicted = np.asarray(truth).astype(str), np.asarray(predicted).astype(str)
    names = sorted(set(truth) | set(predicted))
    width = max(len(n) for n in names)
    lines = [
        "confusion (rows: true, columns: predicted):",
        " " * (width + 2) + " ".join(n[:5].rjust(5) for n in names),
    ]
    for name in names:
        row = [int(np.sum((truth == name) & (predicted == other))) for other in names]
        lines.append(f"  {name.rjust(width)} " + " ".join(str(v).rjust(5) for v in row))
    return lines


def evaluation_of(context):
    """The context's evaluation, chosen from its data when no section has chosen one yet."""
    if getattr(context, "evaluation", None) is None:
        data = context.data
        names = np.asarray(data.target_names)[data.target]
        context.evaluation = choose_evaluation(
            names, data.groups, data.get("subject_names"), random_state=context.random_state
        )
    return context.evaluation
