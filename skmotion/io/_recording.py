"""What a lab recording carries beside its points: analog channels and events."""

from dataclasses import dataclass

import numpy as np

__all__ = ["AnalogChannels", "MotionEvent"]


class AnalogChannels:
    """Analog channels recorded with a motion (force plates, EMG, ...).

    Parameters
    ----------
    values : ndarray of shape (n_samples, n_channels), or a callable returning one
        Samples in ``units``, after the file's offsets and scales. A reader
        gives a callable, so that the samples are decoded on first use of
        ``values`` and reading the points costs nothing more.
    rate : float
        Samples per second (a whole multiple of the motion's frame rate in
        C3D files).
    labels : sequence of str
        One name per channel.
    units : sequence of str
        One unit per channel (``""`` when the file gives none).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.io import AnalogChannels
    >>> forces = AnalogChannels(np.zeros((1000, 3)), 1000.0, ("Fx", "Fy", "Fz"), ("N",) * 3)
    >>> forces
    AnalogChannels(n_channels=3, rate=1000.0, labels=('Fx', 'Fy', 'Fz'))
    >>> forces.values.shape, forces.duration
    ((1000, 3), 1.0)
    """

    def __init__(self, values, rate, labels, units):
        self.rate = float(rate)
        self.labels = tuple(labels)
        self.units = tuple(units)
        if len(self.units) != len(self.labels):
            raise ValueError(f"{len(self.labels)} labels but {len(self.units)} units.")
        self._values = values if callable(values) else self._checked(values)

    def _checked(self, values):
        values = np.asarray(values, dtype=float)
        if values.ndim != 2 or values.shape[1] != len(self.labels):
            raise ValueError(
                f"values must be (n_samples, {len(self.labels)}) for {len(self.labels)} labels; "
                f"got {values.shape}."
            )
        return values

    @property
    def values(self):
        """The samples, ndarray of shape (n_samples, n_channels)."""
        if callable(self._values):
            self._values = self._checked(self._values())
        return self._values

    @property
    def duration(self):
        """``n_samples / rate`` seconds."""
        return len(self.values) / self.rate

    def __repr__(self):
        shown = f"{self.labels[:6]!r}" + (" ..." if len(self.labels) > 6 else "")
        return f"AnalogChannels(n_channels={len(self.labels)}, rate={self.rate!r}, labels={shown})"


@dataclass(frozen=True)
class MotionEvent:
    """A labelled instant of a motion (a foot strike, a toe-off, ...).

    Parameters
    ----------
    label : str
        What happened (``"Foot Strike"``).
    context : str
        Where or to what (``"Left"``, ``"Right"``, ``"General"``), ``""`` if unknown.
    time : float
        Seconds on the file's clock (C3D ``EVENT:TIMES``).
    frame : int
        The row of the motion nearest that time (may lie outside
        ``0 .. n_frames - 1`` when the file marks an event outside its frames).
    subject : str, default=""
        Whose event, when the file says.

    Examples
    --------
    >>> from skmotion.io import MotionEvent
    >>> MotionEvent("Foot Strike", "Left", 3.43, 2).frame
    2
    """

    label: str
    context: str
    time: float
    frame: int
    subject: str = ""
