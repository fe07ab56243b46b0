"""Reading and writing motion files."""

from skmotion.io._amc import read_amc
from skmotion.io._asf import acclaim_order, read_asf
from skmotion.io._bvh import detect_up_axis, read_bvh
from skmotion.io._bvh_write import write_bvh
from skmotion.io._c3d import read_c3d
from skmotion.io._errors import MotionFileError
from skmotion.io._formats import FORMATS, FileFormat, file_format, folder_suffixes
from skmotion.io._keypoints import read_keypoints
from skmotion.io._motion import Motion, as_motions
from skmotion.io._recording import AnalogChannels, MotionEvent
from skmotion.io._ts import read_ts

__all__ = [
    "AnalogChannels",
    "FORMATS",
    "FileFormat",
    "Motion",
    "MotionEvent",
    "MotionFileError",
    "acclaim_order",
    "as_motions",
    "detect_up_axis",
    "file_format",
    "folder_suffixes",
    "read_amc",
    "read_asf",
    "read_bvh",
    "read_c3d",
    "read_keypoints",
    "read_ts",
    "write_bvh",
]
