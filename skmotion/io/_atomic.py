"""Writing a file so that it is either complete or not there: a temporary name, then a rename."""

import contextlib
import errno
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_writer"]


def _default_mode():
    """The permissions a new file gets (0o666 less the umask), read without changing it."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    except OSError:
        pass
    return 0o644


@contextlib.contextmanager
def atomic_writer(path, *, encoding="utf-8"):
    """A text file handle whose content replaces ``path`` only when the block succeeds.

    The text goes to a temporary file in the same folder (so the rename never crosses
    file systems), is flushed to disk, and is renamed over ``path`` with
    :func:`os.replace`. If anything fails on the way (disk full, an exception, an
    interrupt) the temporary file is removed and ``path`` keeps its old content.
    A symlink is written through (its target gets the content, the link stays);
    a read-only file is refused (:class:`PermissionError`), even for a user who
    could override its mode; every :class:`OSError` names ``path``, never the
    temporary file.

    Parameters
    ----------
    path : str or path-like
        The file to create or replace.
    encoding : str, default="utf-8"

    Yields
    ------
    fh : file object
        Open for writing text with LF line breaks.

    Examples
    --------
    >>> import os, tempfile
    >>> from skmotion.io._atomic import atomic_writer
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "a.txt")
    ...     with atomic_writer(path) as fh:
    ...         _ = fh.write("complete\\n")
    ...     open(path).read(), os.listdir(folder)
    ('complete\\n', ['a.txt'])
    """
    shown = str(path)
    # Write through a symlink to its target: the link stays a link.
    path = Path(os.path.realpath(path))
    exists = path.is_file()
    mode = path.stat().st_mode & 0o777 if exists else _default_mode()
    if exists and (not mode & 0o222 or not os.access(path, os.W_OK)):
        raise PermissionError(errno.EACCES, "the file is read-only; not overwritten", shown)
    temporary = None
    try:
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        with os.fdopen(fd, "w", encoding=encoding, newline="\n") as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(temporary, mode)
        os.replace(temporary, path)
    except BaseException as exc:
        if temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
        if isinstance(exc, OSError) and exc.errno is not None:
            # The error names the user's path, not the hidden temporary file.
            raise type(exc)(exc.errno, exc.strerror, shown) from None
        raise
