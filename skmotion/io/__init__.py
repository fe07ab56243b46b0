"""Reading and writing motion files."""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.io._amc": ["read_amc"],
        "skmotion.io._asf": ["acclaim_order", "read_asf"],
        "skmotion.io._bvh": ["detect_up_axis", "read_bvh"],
        "skmotion.io._bvh_write": ["write_bvh"],
        "skmotion.io._c3d": ["read_c3d"],
        "skmotion.io._errors": ["MotionFileError"],
        "skmotion.io._formats": ["FORMATS", "FileFormat", "file_format", "folder_suffixes"],
        "skmotion.io._keypoints": ["read_keypoints"],
        "skmotion.io._motion": ["Motion", "as_motions"],
        "skmotion.io._recording": ["AnalogChannels", "MotionEvent"],
        "skmotion.io._ts": ["read_ts"],
    },
)

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
