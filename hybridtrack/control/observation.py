"""What the controller receives each scan: the readings a PLC has, and nothing of the world."""

from __future__ import annotations

__all__ = ["Observation"]


class Observation:
    """One scan's readings, filled in place by the world and read by the controller.

    Attributes
    ----------
    i : int
        Scan number (the index into the controller's own plan).
    t : float
        The scan timer, minutes since the run began.
    encoder : list of float
        Encoder reading per axis, degrees.
    offset : list of float
        The sun sensor's pointing offset per axis, degrees; NaN when it gives none.
    valid : bool
        The sensor's own "sun present" output: enough light on its fine cells.
    coarse : list of float
        The wide-angle acquisition cells' rough estimate of the sun's offset per axis, degrees;
        NaN when they see no sun.
    intensity : float
        The sensor's photocurrent, mA.
    wind : float
        The anemometer, m/s.
    true_sky : int
        The true sky class (an index into ``SKY_CODES``), given only to the ``hybrid-oracle``
        reference policy; -1 otherwise.
    """

    __slots__ = ("i", "t", "encoder", "offset", "valid", "coarse", "intensity", "wind", "true_sky")

    def __init__(self, axes: int):
        self.i = 0
        self.t = 0.0
        self.encoder = [0.0] * axes
        self.offset = [float("nan")] * axes
        self.valid = False
        self.coarse = [float("nan")] * axes
        self.intensity = float("nan")
        self.wind = 0.0
        self.true_sky = -1
