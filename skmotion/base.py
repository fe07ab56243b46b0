"""Base mixins for estimators whose samples are motion clips."""

import re
from dataclasses import dataclass

import numpy as np
import pandas as pd
from sklearn import get_config
from sklearn.base import TransformerMixin

from skmotion.utils._clips import to_container

__all__ = [
    "ClipEstimatorMixin",
    "ClipFeatureMixin",
    "ClipTransformerMixin",
    "IncompatibleVersionError",
    "MotionTags",
    "VersionedStateMixin",
    "compatible_versions",
]

OUTPUT_KINDS = frozenset({"aeon", "clips", "table", "labels", "scores", "segments"})


@dataclass(frozen=True)
class MotionTags:
    """skmotion-specific facts about an estimator, beside sklearn's tags.

    Parameters
    ----------
    variable_length : bool, default=True
        Clips of one collection may have different numbers of frames.
    output_kind : {"clips", "table", "labels", "scores", "segments", "aeon"}, default="labels"
        What ``transform``/``predict`` returns: clips (clip-to-clip transformer),
        a table ``(n_clips, n_features)``, one label per clip, scores, or per
        clip a list of segment rows (``(n_segments_i, n_features)`` arrays),
        or aeon's channels-first collection (:class:`~skmotion.preprocessing.ToAeon`).
    requires_skeleton : bool, default=False
        Whether the estimator needs a ``Skeleton`` to interpret its input.
    min_frames : int, default=1
        The fewest frames per clip the estimator accepts (with its current
        parameters when the tags are computed from them). ``check_clips`` reads
        it when called with ``estimator=`` and no ``min_frames``, so an estimator
        states its minimum in one place.
    """

    variable_length: bool = True
    output_kind: str = "labels"
    requires_skeleton: bool = False
    min_frames: int = 1

    def __post_init__(self):
        if self.output_kind not in OUTPUT_KINDS:
            raise ValueError(
                f"output_kind must be one of {sorted(OUTPUT_KINDS)}, got {self.output_kind!r}."
            )


class IncompatibleVersionError(ValueError):
    """A pickled skmotion object was saved by an incompatible skmotion version.

    See :func:`compatible_versions` for what "compatible" means.
    """


_VERSION_KEY = "_skmotion_version"


def _major_minor(version):
    match = re.match(r"(\d+)\.(\d+)", str(version))
    return (int(match[1]), int(match[2])) if match else None


def compatible_versions(saved, running):
    """Whether an object pickled by skmotion ``saved`` can load into skmotion ``running``.

    Two versions are compatible when their major and minor numbers agree
    (``0.1.0`` and ``0.1.3`` are, ``0.1.3`` and ``0.2.0`` are not): patch
    releases keep the layout of fitted state, minor releases may change it. An
    unknown or unparsable version is compatible with nothing.

    Parameters
    ----------
    saved : str or None
        The version recorded in the pickle.
    running : str
        The version trying to load it.

    Returns
    -------
    compatible : bool

    Examples
    --------
    >>> from skmotion.base import compatible_versions
    >>> compatible_versions("0.1.0", "0.1.4"), compatible_versions("0.1.4", "0.2.0")
    (True, False)
    """
    saved_mm, running_mm = _major_minor(saved), _major_minor(running)
    return saved_mm is not None and saved_mm == running_mm


def _running_version():
    import skmotion  # at call time, so a test can stand in another version

    return skmotion.__version__


class VersionedStateMixin:
    """Pickles record the skmotion version; loading refuses an incompatible one.

    ``__getstate__`` adds ``_skmotion_version`` to the pickled state (beside
    sklearn's own); ``__setstate__`` raises :class:`IncompatibleVersionError`
    when the recorded version is not :func:`compatible_versions` with the running
    one. scikit-learn only warns on a version mismatch; skmotion refuses because
    its fitted state holds its own data structures (motion trees, interval
    indexes, transition graphs) whose layout may change between minor versions,
    and loading an old layout would give wrong results or fail far from the cause.
    Every clip estimator gets this through :class:`ClipEstimatorMixin`; the
    data structures of fitted state (``MotionTree``, ``TransitionGraphs``)
    derive from it directly.
    """

    def __getstate__(self):
        parent = getattr(super(), "__getstate__", None)  # object has none before Python 3.11
        state = parent() if parent is not None else self.__dict__
        return dict(state, **{_VERSION_KEY: _running_version()})

    def __setstate__(self, state):
        state = dict(state)
        saved, running = state.pop(_VERSION_KEY, None), _running_version()
        if not compatible_versions(saved, running):
            saved_text = f"skmotion {saved}" if saved is not None else "an unknown skmotion version"
            raise IncompatibleVersionError(
                f"This {type(self).__name__} was saved by {saved_text} and cannot be loaded by "
                f"skmotion {running}: fitted state is only compatible within one major.minor "
                f"version. Load it with skmotion {saved or '(the saving version)'} installed, or "
                f"refit it with skmotion {running}."
            )
        parent = getattr(super(), "__setstate__", None)
        if parent is None:  # a plain object: its state is its __dict__
            self.__dict__.update(state)
        else:
            parent(state)


class ClipEstimatorMixin(VersionedStateMixin):
    """Mixin for estimators whose ``X`` is a collection of clips.

    Sets sklearn's input tags (no 2-D tables, 3-D arrays accepted) and exposes
    :class:`MotionTags` through ``__skmotion_tags__``. Pickles record the skmotion
    version (:class:`VersionedStateMixin`). Put it first in the bases, before
    sklearn's mixins and ``BaseEstimator``.
    """

    _motion_tags = MotionTags()

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        return tags

    def __skmotion_tags__(self):
        """Return the estimator's :class:`MotionTags`."""
        return self._motion_tags


_OUTPUT_OPTIONS = frozenset({"default", "pandas"})


def _check_output_option(transform):
    if transform not in _OUTPUT_OPTIONS:
        raise ValueError(
            f"set_output(transform={transform!r}) is not supported; skmotion "
            f"transformers support {sorted(_OUTPUT_OPTIONS)}."
        )


class _OutputConfigMixin(TransformerMixin):
    """``set_output`` for clip transformers, without sklearn's automatic wrapping.

    sklearn's wrapper would index a pandas result by the input's rows, which are
    frames for a DataFrame collection; skmotion builds its containers itself.
    """

    def __init_subclass__(cls, **kwargs):
        kwargs["auto_wrap_output_keys"] = None
        super().__init_subclass__(**kwargs)

    def set_output(self, *, transform=None):
        """Choose the output container of ``transform`` and ``fit_transform``.

        Parameters
        ----------
        transform : {"default", "pandas"}, default=None
            ``"pandas"`` returns DataFrames; ``"default"`` the estimator's usual
            output; ``None`` leaves the configuration unchanged.

        Returns
        -------
        self : estimator instance
            The estimator.
        """
        if transform is None:
            return self
        _check_output_option(transform)
        self._sklearn_output_config = {"transform": transform}
        return self

    def _output_config(self):
        config = getattr(self, "_sklearn_output_config", {}).get(
            "transform", get_config()["transform_output"]
        )
        _check_output_option(config)
        return config


class ClipTransformerMixin(ClipEstimatorMixin, _OutputConfigMixin):
    """Mixin for clip-to-clip transformers.

    ``transform`` returns the container kind it was given (list, tuple, 3-D array
    or DataFrame); after ``set_output(transform="pandas")`` it always returns a
    ``(clip, frame)`` DataFrame.
    """

    _motion_tags = MotionTags(output_kind="clips")

    def _wrap_clips(self, clips_out, clips_in, columns=None):
        """Return ``clips_out`` in the kind of ``clips_in`` (a ``Clips``)."""
        if columns is None and hasattr(self, "get_feature_names_out"):
            columns = self.get_feature_names_out()
        target = "pandas" if self._output_config() == "pandas" else clips_in.container
        if target == "pandas" and clips_in.container.kind == "dataframe":
            target = clips_in.container
        return to_container(clips_out, target, columns=columns)


class ClipFeatureMixin(ClipEstimatorMixin, _OutputConfigMixin):
    """Mixin for clip-to-vector transformers: one row of features per clip.

    ``transform`` returns an array ``(n_clips, n_features)``; after
    ``set_output(transform="pandas")`` a DataFrame whose index holds the clip
    labels of a DataFrame input (else ``0..n_clips-1``) and whose columns are
    ``get_feature_names_out()``.
    """

    _motion_tags = MotionTags(output_kind="table")

    def _wrap_table(self, table, clips_in):
        """Return ``table`` as an array or, when configured, a DataFrame."""
        if self._output_config() != "pandas":
            return table
        labels = clips_in.container.clip_labels
        index = labels if labels is not None else pd.RangeIndex(len(table))
        if clips_in.container.index_names:
            index = pd.Index(
                np.asarray(index, dtype=object), name=clips_in.container.index_names[0]
            )
        return pd.DataFrame(table, index=index, columns=self.get_feature_names_out())
