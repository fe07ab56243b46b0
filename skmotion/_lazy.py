"""Lazy exports of a package: each public name is imported from its module on first use.

The command line answers at once only if ``import skmotion.io`` (say) does not pull in
scikit-learn, pandas and scipy for names it never touches. A package's ``__init__``
therefore lists where each name lives, and the module is imported when the name is
first asked for (``from skmotion.io import read_bvh`` included), the pattern of
PEP 562's module ``__getattr__``.
"""

import importlib
import sys

__all__ = ["attach"]


def attach(package, exports):
    """``__getattr__`` and ``__dir__`` of a package whose names load on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    exports : dict of str to sequence of str
        Module (absolute name) -> the names the package exports from it.

    Returns
    -------
    getattr, dir : callables
        To assign to the package's ``__getattr__`` and ``__dir__``.

    Examples
    --------
    >>> from skmotion._lazy import attach
    >>> getattr_, dir_ = attach("json", {"json.decoder": ["JSONDecodeError"]})
    >>> getattr_("JSONDecodeError").__name__
    'JSONDecodeError'
    >>> dir_()
    ['JSONDecodeError']
    """
    where = {name: module for module, names in exports.items() for name in names}

    def __getattr__(name):
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)  # later look-ups skip this function
        return value

    def __dir__():
        return sorted(where)

    return __getattr__, __dir__
