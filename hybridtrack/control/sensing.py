"""The sensor gate: which readings of the sun sensor the controller believes, and its filter.

A reading is refused when the sensor says it sees no sun, when its offset stays put over
`stuck_scans` scans while the offset it should read has moved (its range below a third of the
sensor's datasheet σ while the expected offset, from the computed sun or the filtered rate less
the encoder, moved ten times that: the sun and the drive never both stand still, so a sensor
whose answer does is stuck, noise or no noise), when it is further from the calibrated model
than the plausibility bound, or when it fails the Kalman filter's innovation gate. After
`reacquire` gated readings in a row, or at once when the filter has coasted so long that its
predicted angle is less certain than the plausibility bound and the calibrated model vouches for
the reading, the filter restarts from the latest reading at the rate it is given (the computed
sun's, where there is one): a filter that drifted away from the sun must not go on rejecting it,
nor restart with the rate that drifted (a heliostat's azimuth near the zenith speeds up faster
than the filter's process noise allows, and a filter that kept its own rate there was rejected
again at once and coasted the drive away), nor, coasted across a gap, take the gap's swing for a
rate (a heliostat's zenith pass between 30-minute scans had taught it 1.2°/min).
"""

from __future__ import annotations

import math
from collections import deque

from .kalman import make_filter
from .modes import IMPLAUSIBLE, INVALID, LOW_LIGHT, OK, OUT_OF_VIEW, OUTLIER, STUCK

__all__ = ["SensorGate"]


class SensorGate:
    """One axis: judge the reading, and keep the Kalman-filtered sun angle (encoder coordinates)."""

    __slots__ = ("filter", "ready", "rejected", "angles", "expected", "stuck_spread", "gate2", "reacquire")

    def __init__(self, engine: str, process_noise: float, variance: float, stuck_scans: int, gate: float,
                 reacquire: int, noise: float):
        self.filter = make_filter(engine, process_noise, variance)
        self.ready = False
        self.rejected = 0
        self.angles: deque = deque(maxlen=stuck_scans)
        self.expected: deque = deque(maxlen=stuck_scans)
        self.stuck_spread = noise / 3.0
        self.gate2 = gate * gate
        self.reacquire = reacquire

    def judge(self, measured: float, valid: bool, coarse: float, expected: float) -> int:
        """The status of a raw reading before it meets the model and the filter; `expected` is the
        offset it should read (the expected sun less the encoder reading)."""
        if math.isnan(measured) or math.isnan(expected):
            self.angles.clear()
            self.expected.clear()
        else:
            self.angles.append(measured)
            self.expected.append(expected)
            if len(self.angles) == self.angles.maxlen and max(self.angles) - min(self.angles) < self.stuck_spread \
                    and max(self.expected) - min(self.expected) > 10.0 * self.stuck_spread:
                return STUCK
        if not valid:
            return LOW_LIGHT if math.isnan(coarse) else OUT_OF_VIEW
        if math.isnan(measured) or abs(measured) > 90.0:
            return INVALID
        return OK

    def take(self, z: float, dt: float, miss: float, bound: float, rate: float) -> int:
        """Offer the sun angle `z` (reading plus offset); `miss` is z less the calibrated model (NaN:
        none); `rate` (degrees a minute) is the sun's to start the filter at."""
        if abs(miss) > bound:
            return IMPLAUSIBLE
        kf = self.filter
        if not self.ready:
            kf.reset(z, rate)
            self.ready = True
            return OK
        kf.predict(dt)
        y, s = kf.innovation(z)
        if s > bound * bound and not math.isnan(miss):  # coasted until it knows the angle worse than the model
            kf.reset(z, rate)  # that vouches for this reading: an update's rate gain would take the gap's swing
            self.rejected = 0  # for a rate (a heliostat's zenith pass across 30-minute scans: 1.2°/min)
            return OK
        if y * y > self.gate2 * s:
            self.rejected += 1
            if self.rejected < self.reacquire:
                return OUTLIER
            kf.reset(z, rate)
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
