"""The one integer check, for arguments that sklearn's parameter validation does not cover."""

from numbers import Integral

__all__ = ["check_int"]


def check_int(name, value, low=1, *, allow_none=False):
    """``value`` as an int when it is an integer (not a bool) at least ``low``, else a ValueError.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
    low : int, default=1
        The smallest value allowed.
    allow_none : bool, default=False
        Whether None passes (and is returned as None).

    Returns
    -------
    value : int or None

    Examples
    --------
    >>> from skmotion.utils._validation import check_int
    >>> check_int("n_steps", 3)
    3
    >>> check_int("max_depth", None, 0, allow_none=True) is None
    True
    >>> check_int("n_steps", True)
    Traceback (most recent call last):
    ...
    ValueError: n_steps must be an int >= 1; got True.
    """
    if allow_none and value is None:
        return None
    if not isinstance(value, Integral) or isinstance(value, bool) or value < low:
        raise ValueError(
            f"{name} must be an int >= {low}{' or None' if allow_none else ''}; got {value!r}."
        )
    return int(value)
