"""Live recognition on long takes: motions detected as they happen, every frame labelled."""

from skmotion.live._detector import GestureDetector
from skmotion.live._events import Event
from skmotion.live._linear_detector import LinearDetectorStream, LinearGestureDetector
from skmotion.live._segmenter import ActivitySegmenter
from skmotion.live._stream import DetectorStream

__all__ = [
    "ActivitySegmenter",
    "DetectorStream",
    "Event",
    "GestureDetector",
    "LinearDetectorStream",
    "LinearGestureDetector",
]
