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

A heliostat's sensor sits on the mirror and reads its azimuth offset across its own face: an
azimuth miss Δaz at elevation e is about Δaz·cos e there (docs/world.md, "The sensor's frame").
The controller turns it back into azimuth degrees with the elevation its own encoder reads and
the sensor's elevation reading (`axis_offset`).
"""

from __future__ import annotations

import math
from collections import deque

from .kalman import make_filter
from .modes import IMPLAUSIBLE, INVALID, LOW_LIGHT, OK, OUT_OF_VIEW, OUTLIER, STUCK

__all__ = ["SensorGate", "axis_offset", "reading_scale", "AZIMUTH", "ELEVATION", "COSINE_FLOOR"]

#: A heliostat's axes, in the order of its drives and encoders (`hybridtrack.control.encoder.AXIS_NAMES`).
AZIMUTH, ELEVATION = 0, 1

#: The least size of the cosine a heliostat's azimuth reading is divided by (`axis_offset`):
#: cos 85°. The divisor is the cosine of the sun's elevation as the controller sees it, which is
#: off the true one by the installation (encoder zero, pedestal tilt and turn: with the clock and
#: site, the 1.8° open-loop budget at most); toward the zenith cos(e - 1.8°)/cos e grows without
#: bound, and an over-converted reading swings the azimuth past the sun and back. With the floor
#: the gain on a reading (true cosine over divisor) is at most cos 83.2°/cos 85° = 1.36, short of
#: the 2 at which a proportional correction diverges; below 1 near the zenith the loop converges
#: in more scans. The sensor's noise is multiplied 11.5 times at most (0.03° to 0.34° of azimuth,
#: still 0.03° of pointing).
COSINE_FLOOR = math.cos(math.radians(85.0))


def axis_offset(sensed, a: int, reading) -> tuple[float, bool]:
    """A sensor's offset on axis `a` in that axis's degrees.

    Parameters
    ----------
    sensed : sequence of float
        The offsets the sensor (or its acquisition cells) reads per axis, degrees in its own
        frame (NaN: none).
    a : int
        The axis.
    reading : sequence of float
        Where the controller's encoders say each axis stands, degrees (one: a single axis).

    Returns
    -------
    (float, bool)
        The offset, and whether it measures the axis. A single axis's reading is its offset. A
        heliostat's are turned back into axis degrees (Notes), with the sun's elevation in the
        sensor's plane ``φ`` taken as the encoder's elevation plus the elevation reading (the
        encoder's alone without one). The azimuth's ``cos φ`` is held to `COSINE_FLOOR` in size
        (NaN counts as the floor): a floored reading only turns the axis toward the sun (its
        size is the floor's, not the sun's), so it may steer but not calibrate (at 89° it had
        taught the calibration a 30° azimuth offset that held the mirror 20° of azimuth off all
        afternoon). It steers only a controller without a model (sensor-only); one with a
        calibrated model takes it as no measure of the azimuth (an invalid reading) and lets the
        model steer the pass: fed to the filter, a 10° miss at 89.5° read as 1° and the gate's
        outliers and restarts had made a 1-minute hybrid's zenith pass its worst (0.205° with a
        perfect sensor, 0.037° with the model).

    Notes
    -----
    The sensor reads ``c = asin(cos e · sin Δaz)`` across its face and ``φ - elevation`` along it,
    ``φ = atan2(sin e, cos e · cos Δaz)`` (`hybridtrack.sensor.sensor_frame`, ``e`` the sun's
    elevation on the mount). Inverted: ``Δaz = atan2(sin c, cos c · cos φ)``, which is ``c / cos φ``
    for a small ``c`` (the division by the cosine of the elevation), and turns the azimuth a half
    turn for a sun past the zenith (``φ`` above 90°, where the elevation axis cannot follow);
    ``e = asin(cos c · sin φ)``. The sun's elevation, not the mirror's, is the divisor: between
    coarse scans they part by what the sun climbed (7° an hour), and the mirror's had taken 4.6°
    of a 7.9° azimuth miss at 82° on a 60-minute scan.
    """
    if len(reading) == 1:
        return sensed[a], True
    across, along = sensed[AZIMUTH], sensed[ELEVATION]
    if math.isnan(sensed[a]):
        return math.nan, True
    c = 0.0 if math.isnan(across) else math.radians(across)
    phi = math.radians(reading[ELEVATION] + (0.0 if math.isnan(along) else along))
    if a == ELEVATION:
        return math.degrees(math.asin(math.cos(c) * math.sin(phi))) - reading[ELEVATION], True
    cosine = math.cos(phi)
    if abs(cosine) >= COSINE_FLOOR:
        return math.degrees(math.atan2(math.sin(c), math.cos(c) * cosine)), True
    floor = -COSINE_FLOOR if cosine < 0.0 else COSINE_FLOOR
    return math.degrees(math.atan2(math.sin(c), math.cos(c) * floor)), False


def reading_scale(sensed, a: int, reading) -> float:
    """What the filter's R, the datasheet's variance of a reading across the sensor's face, is
    multiplied by in axis `a`'s degrees: 1 for a single axis and a heliostat's elevation; for its
    azimuth ``1 / cos² φ``, the square of `axis_offset`'s division (``φ`` and the floor
    `COSINE_FLOOR` as it takes them). A small angle ``c`` across the face is ``c / cos φ`` of
    azimuth, so the reading's noise is too: with R fixed the filter had taken azimuth readings near
    the zenith as sure as at the horizon, and more of them as outliers."""
    if len(reading) == 1 or a == ELEVATION:
        return 1.0
    along = sensed[ELEVATION]
    phi = math.radians(reading[ELEVATION] + (0.0 if math.isnan(along) else along))
    cosine = max(abs(math.cos(phi)), COSINE_FLOOR)
    return 1.0 / (cosine * cosine)


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

    def take(self, z: float, dt: float, miss: float, bound: float, rate: float, scale: float = 1.0) -> int:
        """Offer the sun angle `z` (reading plus offset); `miss` is z less the calibrated model (NaN:
        none); `rate` (degrees a minute) is the sun's to start the filter at; `scale` multiplies
        the filter's R, the reading's variance in this axis's degrees (`reading_scale`)."""
        if abs(miss) > bound:
            return IMPLAUSIBLE
        kf = self.filter
        if not self.ready:
            kf.reset(z, rate)
            self.ready = True
            return OK
        kf.predict(dt)
        y, s = kf.innovation(z, scale)
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
            kf.update(z, scale)
        self.rejected = 0
        return OK

    def coast(self, dt: float) -> None:
        """No reading taken this scan: the filter predicts only."""
        if self.ready:
            self.filter.predict(dt)

    def forget(self) -> None:
        """Start afresh at the next reading (after a night)."""
        self.ready = False
