"""Progress output for long steps: silent unless asked, tqdm when installed.

Library calls are silent by default (``verbose=0``, the sklearn convention). With
``verbose >= 1`` a step reports its progress on standard error: through ``tqdm``
(extra ``progress``) when it is installed, else as one plain line per tenth of the
work, so a log file stays readable.
"""

import sys
import time

__all__ = ["progress", "say"]


def say(verbose, message):
    """Print one line on standard error when ``verbose >= 1``.

    Parameters
    ----------
    verbose : int
        The caller's verbosity; nothing is printed below 1.
    message : str
        The line to print.

    Examples
    --------
    >>> from skmotion.utils import say
    >>> say(0, "never shown")
    """
    if verbose and verbose >= 1:
        print(f"[skmotion] {message}", file=sys.stderr, flush=True)


def progress(items, *, verbose=0, desc="", total=None):
    """Iterate over ``items``, reporting progress when ``verbose >= 1``.

    Parameters
    ----------
    items : iterable
        What to iterate over; it is yielded unchanged.
    verbose : int, default=0
        0 prints nothing; 1 or more reports progress on standard error.
    desc : str, default=""
        What is being done, e.g. ``"reading files"``.
    total : int, default=None
        The number of items when ``items`` has no length.

    Yields
    ------
    item
        Each item of ``items``, in order.

    Examples
    --------
    >>> from skmotion.utils import progress
    >>> [x * 2 for x in progress([1, 2, 3], verbose=0, desc="doubling")]
    [2, 4, 6]
    """
    if not verbose or verbose < 1:
        yield from items
        return
    if total is None and hasattr(items, "__len__"):
        total = len(items)
    try:
        from tqdm.auto import tqdm
    except ImportError:
        yield from _plain_progress(items, desc, total)
        return
    yield from tqdm(items, desc=f"[skmotion] {desc}", total=total, file=sys.stderr)


def _plain_progress(items, desc, total):
    start = time.perf_counter()
    step = max(1, (total or 0) // 10)
    done = 0
    for item in items:
        yield item
        done += 1
        if done % step == 0 or done == total:
            of = f"/{total}" if total else ""
            elapsed = time.perf_counter() - start
            print(
                f"[skmotion] {desc}: {done}{of} ({elapsed:.1f} s)",
                file=sys.stderr,
                flush=True,
            )
