"""How a motion tree is built: one description of the build's parameters, and the paper's settings.

:class:`TreeParams` names the parameters of a tree's build, their types and
constraints (``TREE_CONSTRAINTS``, sklearn's parameter-constraint form) and
their validation; :meth:`MotionTree.build`, :class:`MotionTreeHMM`,
:class:`MotionTreeEncoder` and ``MotionTreeHMM.partial_fit`` (the leaves it
splits, the subtrees it builds again) all go through it. Its defaults are
MotionTreeHMM's measured ones; where another caller's measured (or
published) value differs, it declares its own, and the user guide's table
(``docs/motion-database.md``, "Build parameters") lists every one.
"""

from dataclasses import asdict, dataclass, fields
from numbers import Integral, Real

from skmotion.tree._gaussian import COVARIANCE_TYPES
from skmotion.tree._build._split import SPLIT_CRITERIA
from skmotion.utils._sklearn_compat import Interval, StrOptions
from skmotion.utils._validation import check_int

__all__ = ["PAPER_SETTINGS", "PAPER_TREE", "TREE_CONSTRAINTS", "TreeParams"]

#: The constraints of the build's parameters, as ``_parameter_constraints`` entries.
TREE_CONSTRAINTS = {
    "max_depth": [Interval(Integral, 0, None, closed="left"), None],
    "min_samples_split": [Interval(Integral, 2, None, closed="left")],
    "min_samples_leaf": [Interval(Integral, 1, None, closed="left")],
    "split": [StrOptions(set(SPLIT_CRITERIA))],
    "covariance_type": [StrOptions(set(COVARIANCE_TYPES))],
    "reg_covar": [Interval(Real, 0, None, closed="neither")],
}


@dataclass(frozen=True)
class TreeParams:
    """The parameters of a motion tree's build, validated when made.

    Parameters
    ----------
    max_depth : int or None, default=12
        The deepest layer (the root is layer 0); None for no limit.
    min_samples_split : int, default=2
        A node with fewer frames is not split.
    min_samples_leaf : int, default=8
        A split is only made when both sides keep this many frames.
    split : {"two_means", "median", "min_error"}, default="two_means"
        How a node's projections on its first principal axis are cut
        (:data:`~skmotion.tree._build._split.SPLIT_RULES`).
    covariance_type : {"diag", "full", "spherical"}, default="diag"
        The covariance estimator of each node.
    reg_covar : float, default=1e-6
        Added to every variance, as a fraction of the mean variance of all frames.

    Examples
    --------
    >>> from skmotion.tree._build._params import PAPER_TREE, TreeParams
    >>> TreeParams(split="median").split, PAPER_TREE.max_depth
    ('median', None)
    >>> TreeParams(min_samples_leaf=0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: min_samples_leaf must be an int >= 1...
    """

    max_depth: int | None = 12
    min_samples_split: int = 2
    min_samples_leaf: int = 8
    split: str = "two_means"
    covariance_type: str = "diag"
    reg_covar: float = 1e-6

    def __post_init__(self):
        check_int("max_depth", self.max_depth, 0, allow_none=True)
        check_int("min_samples_split", self.min_samples_split, 2)
        check_int("min_samples_leaf", self.min_samples_leaf, 1)
        if self.split not in SPLIT_CRITERIA:
            raise ValueError(f"split must be one of {SPLIT_CRITERIA}; got {self.split!r}.")
        if self.covariance_type not in COVARIANCE_TYPES:
            raise ValueError(
                f"covariance_type must be one of {COVARIANCE_TYPES}; got {self.covariance_type!r}."
            )
        if not isinstance(self.reg_covar, Real) or not self.reg_covar > 0:
            raise ValueError(f"reg_covar must be a positive number; got {self.reg_covar!r}.")

    @classmethod
    def of(cls, estimator):
        """The build parameters an estimator holds (the defaults for those it has not)."""
        names = [f.name for f in fields(cls)]
        return cls(**{name: getattr(estimator, name) for name in names if hasattr(estimator, name)})

    def as_dict(self):
        """The parameters as keywords (of :meth:`MotionTree.build`)."""
        return asdict(self)


#: The tree of Yamane, Yamaguchi and Nakamura (2011) as published: minimum-error thresholding,
#: no depth limit, at least 16 frames per node: :meth:`MotionTree.build`'s defaults.
PAPER_TREE = TreeParams(max_depth=None, min_samples_leaf=16, split="min_error")

#: Yamane, Yamaguchi and Nakamura (2011) as published: minimum-error thresholding, no depth
#: limit, at least 16 frames per node, full Gaussian covariances of the frames as given (no
#: standardisation), one transition graph per training clip with the uniform node prior over
#: the nodes that graph's clip visits, and the generation probability at the bottom layer
#: alone, summed over the top few (here 3) node sequences. ``MotionTreeHMM(**PAPER_SETTINGS)``
#: builds it; the defaults differ where measurements on every development data set favoured
#: other settings (see the user guide, ``docs/motion-database.md``).
PAPER_SETTINGS = {
    "split": PAPER_TREE.split,
    "max_depth": PAPER_TREE.max_depth,
    "min_samples_leaf": PAPER_TREE.min_samples_leaf,
    "covariance_type": "full",
    "standardize": False,
    "graph": "clip",
    "node_prior": "graph",
    "score_layers": 1,
    "layer": None,
    "n_paths": 3,
}
