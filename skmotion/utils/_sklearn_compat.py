"""The one module that imports private scikit-learn names.

scikit-learn's parameter-validation helpers and ``_fit_context`` are private and
may change without deprecation (scikit-learn issue #28963). Every skmotion module
imports them from here, so a change in scikit-learn is mended in one place.
"""

from sklearn.base import _fit_context
from sklearn.utils._param_validation import (
    HasMethods,
    Interval,
    Options,
    StrOptions,
    validate_params,
)

__all__ = [
    "HasMethods",
    "Interval",
    "Options",
    "StrOptions",
    "_fit_context",
    "validate_params",
]
