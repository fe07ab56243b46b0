"""DetectorStream: a detector fed one frame at a time, in constant memory."""

import numpy as np

from skmotion.live._events import TriggerState, next_events

__all__ = ["DetectorStream"]


class DetectorStream:
    """The live side of :class:`GestureDetector`: a ring buffer of the last ``window`` frames.

    Made by :meth:`GestureDetector.stream`. Each frame is written twice into
    a buffer of ``2 * window`` rows (at ``i`` and ``i + window``), so the last
    ``window`` frames are always one contiguous slice, in order, without a
    copy; every ``step`` frames (the first at frame ``window - 1``) that slice
    is scored and the decision rule of :func:`next_events` runs on it. Memory
    is the buffer and the decision rule's state (a few numbers), whatever the stream's length;
    a frame costs a row copy, and every ``step``-th one a window's scoring.

    Parameters
    ----------
    score : callable
        ``score(window)`` returns the class probabilities of one window, an
        array of shape (1, n_classes).
    n_channels, window, step : int
    classes : ndarray
    none_index : int
    threshold : float
    refractory : int
    trigger : {"fall", "maximum", "peak", "rise"}, default="fall"
    delay : int, default=0
        The look-ahead of ``"maximum"``, in frames.

    Attributes
    ----------
    n_frames : int
        Frames seen since the start (or the last :meth:`reset`).
    last_proba : ndarray of shape (n_classes,) or None
        The probabilities of the last scored window.
    """

    def __init__(
        self,
        score,
        *,
        n_channels,
        window,
        step,
        classes,
        none_index,
        threshold,
        refractory,
        trigger="fall",
        delay=0,
    ):
        self._score = score
        self._window, self._step = int(window), int(step)
        self._classes, self._none = classes, none_index
        self._threshold, self._refractory, self._trigger = threshold, refractory, trigger
        self._delay = int(delay)
        self._buffer = np.zeros((2 * self._window, int(n_channels)))
        self.reset()

    def reset(self):
        """Forget every frame: the stream starts again."""
        self.n_frames = 0
        self.last_proba = None
        self._state = TriggerState()
        self._buffer[:] = 0.0

    def update(self, frames):
        """Add one frame (or a chunk of frames) and return the events they complete.

        Parameters
        ----------
        frames : array-like of shape (n_channels,) or (n_frames, n_channels)

        Returns
        -------
        events : list of Event
            The events emitted at these frames (usually none).
        """
        frames = np.asarray(frames, dtype=float)
        if frames.ndim == 1:
            frames = frames[None, :]
        width = self._buffer.shape[1]
        if frames.ndim != 2 or frames.shape[1] != width:
            raise ValueError(
                f"update: frames must have {width} channels, got an array of shape {frames.shape}."
            )
        if not np.isfinite(frames).all():
            row = int(np.flatnonzero(~np.isfinite(frames).all(axis=1))[0])
            raise ValueError(f"update: frame {self.n_frames + row} holds NaN or infinity.")
        events = []
        w = self._window
        for frame in frames:
            i = self.n_frames % w
            self._buffer[i] = frame
            self._buffer[i + w] = frame
            t = self.n_frames
            self.n_frames += 1
            if t >= w - 1 and (t - w + 1) % self._step == 0:
                proba = self._score(self._buffer[i + 1 : i + 1 + w])
                self.last_proba = proba[0]
                new, self._state = next_events(
                    np.array([t]),
                    proba,
                    self._classes,
                    self._none,
                    threshold=self._threshold,
                    refractory=self._refractory,
                    trigger=self._trigger,
                    delay=self._delay,
                    state=self._state,
                )
                events += new
        return events
