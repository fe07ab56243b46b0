"""Where downloaded or user-provided datasets live."""

import os
from pathlib import Path

__all__ = ["get_data_home"]


def get_data_home(data_home=None):
    """The folder for skmotion's datasets, created if missing.

    ``data_home`` when given, else the ``SKMOTION_DATA`` environment variable,
    else ``~/skmotion_data`` (as sklearn's ``get_data_home`` does).

    Parameters
    ----------
    data_home : str or path-like, default=None
        The folder to use.

    Returns
    -------
    data_home : pathlib.Path

    Examples
    --------
    >>> import tempfile
    >>> from skmotion.datasets import get_data_home
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     get_data_home(folder).is_dir()
    True
    """
    if data_home is None:
        data_home = os.environ.get("SKMOTION_DATA", Path.home() / "skmotion_data")
    data_home = Path(data_home).expanduser()
    data_home.mkdir(parents=True, exist_ok=True)
    return data_home
