"""The error every reader raises for a malformed file: it names the file and line."""

__all__ = ["MotionFileError"]


class MotionFileError(ValueError):
    """A motion file could not be read; the message names the file and the line.

    Parameters
    ----------
    path : str or path-like
        The file.
    line : int or None
        1-based line number where the problem is, when known.
    message : str
        What is wrong.

    Examples
    --------
    >>> from skmotion.io import MotionFileError
    >>> str(MotionFileError("walk.bvh", 12, "expected 'OFFSET'"))
    "walk.bvh, line 12: expected 'OFFSET'"
    """

    def __init__(self, path, line, message):
        self.path = str(path)
        self.line = line
        self.message = message
        where = self.path if line is None else f"{self.path}, line {line}"
        super().__init__(f"{where}: {message}")

    def __reduce__(self):
        return (type(self), (self.path, self.line, self.message))
