"""The sensor gate: which readings of the sun sensor the controller believes, and its filter.

A reading is refused when the sensor says it sees no sun, when it repeats exactly for
`stuck_scans` scans (a real one always has noise), when it is further from the calibrated model
than the plausibility bound, or when it fails the Kalman filter's innovation gate. After
`reacquire` gated readings in a row the filter restarts from the latest reading: a filter that
drifted away from the sun must not go on rejecting it.
"""

from __future__ import annotations

import math

from .kalman import make_filter
from .modes import IMPLAUSIBLE, INVALID, LOW_LIGHT, OK, OUT_OF_VIEW, OUTLIER, STUCK

__all__ = ["SensorGate"]


class SensorGate:
    """One axis: judge the reading, and keep the Kalman-filtered sun angle (encoder coordinates)."""

    __slots__ = ("filter", "ready", "rejected", "repeats", "last_measured", "stuck_scans", "gate2", "reacquire")

    def __init__(self, engine: str, process_noise: float, variance: float, stuck_scans: int, gate: float,
                 reacquire: int):
        self.filter = make_filter(engine, process_noise, variance)
        self.ready = False
        self.rejected = 0
        self.repeats = 0
        self.last_measured = math.nan
        self.stuck_scans = stuck_scans
        self.gate2 = gate * gate
        self.reacquire = reacquire

    def judge(self, measured: float, valid: bool, coarse: float) -> int:
        """The status of a raw reading before it meets the model and the filter."""
        self.repeats = self.repeats + 1 if measured == self.last_measured else 0
        self.last_measured = measured
        if self.repeats >= self.stuck_scans - 1:
            return STUCK
        if not valid:
            return LOW_LIGHT if math.isnan(coarse) else OUT_OF_VIEW
        if math.isnan(measured) or abs(measured) > 90.0:
            return INVALID
        return OK

    def take(self, z: float, dt: float, miss: float, bound: float, rate: float) -> int:
        """Offer the sun angle `z` (reading plus offset); `miss` is z less the calibrated model (NaN: none)."""
        if abs(miss) > bound:
            return IMPLAUSIBLE
        kf = self.filter
        if not self.ready:
            kf.reset(z, rate)
            self.ready = True
            return OK
        kf.predict(dt)
        y, s = kf.innovation(z)
        if y * y > self.gate2 * s:
            self.rejected += 1
            if self.rejected < self.reacquire:
                return OUTLIER
            kf.reset(z, kf.rate)
        else:
            kf.update(z)
        self.rejected = 0
        return OK

    def coast(self, dt: float) -> None:
        """No reading taken this scan: the filter predicts only."""
        if self.ready:
            self.filter.predict(dt)

    def forget(self) -> None:
        """Start afresh at the next reading (after a night)."""
        self.ready = False
