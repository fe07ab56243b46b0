"""Reading and writing motion files."""

from skmotion.io._errors import MotionFileError
from skmotion.io._ts import read_ts

__all__ = ["MotionFileError", "read_ts"]
