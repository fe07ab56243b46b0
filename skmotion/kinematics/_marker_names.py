"""The 32 marker names every marker preset and position layout shares (data only)."""

__all__ = ["MARKER_NAMES"]

_CENTRE = ("head_top", "head", "neck", "chest", "spine", "pelvis")
_SIDE = (
    "clavicle",
    "shoulder",
    "upper_arm",
    "elbow",
    "forearm",
    "wrist",
    "hand",
    "hip",
    "thigh",
    "knee",
    "shin",
    "ankle",
    "toe",
)
#: The 32 marker names shared by every preset: 6 on the trunk and head, 13 per side.
MARKER_NAMES = _CENTRE + tuple(f"{side}_{part}" for side in ("left", "right") for part in _SIDE)
