"""Per-clip parallelism through joblib, serial by default."""

from joblib import effective_n_jobs
from sklearn.utils.parallel import Parallel, delayed

__all__ = ["parallel_map"]


def parallel_map(func, items, *, n_jobs=None, prefer="threads"):
    """Apply ``func`` to every item, in order, possibly in parallel.

    With one effective job (``n_jobs=None`` outside a ``joblib.parallel_config``
    context) this is a plain loop, so results never depend on ``n_jobs``: work is
    split into the same tasks, in the same order, on both paths.

    Parameters
    ----------
    func : callable
        Function of one item.
    items : sequence
        The work items (clips, classes, slices of queries, ...).
    n_jobs : int, default=None
        Number of jobs, in joblib's meaning (``-1`` for all cores).
    prefer : {"threads", "processes"}, default="threads"
        joblib's soft hint; NumPy-heavy work releases the GIL, so threads suit it.

    Returns
    -------
    results : list
        ``[func(item) for item in items]``.

    Examples
    --------
    >>> from skmotion.utils import parallel_map
    >>> parallel_map(abs, [-1, 2, -3], n_jobs=2)
    [1, 2, 3]
    """
    items = list(items)
    if effective_n_jobs(n_jobs) == 1 or len(items) <= 1:
        return [func(item) for item in items]
    return Parallel(n_jobs=n_jobs, prefer=prefer)(delayed(func)(item) for item in items)
