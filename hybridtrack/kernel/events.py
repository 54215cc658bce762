"""The compiled controller's events: a code and two numbers per event, worded here afterwards.

The kernel cannot build text, so each mode change or alarm is recorded as (scan, from mode, to
mode, code, value, value, value); `wording` words it exactly as the reference controller does
(`hybridtrack.control.controller`), and a parity test holds every reason equal.
"""

from __future__ import annotations

from ..control.encoder import AXIS_NAMES
from ..control.modes import SENSOR_STATUS, SKY_CODES
from ..control.wind import STUCK_HOURS, unreadable_reason

__all__ = ["wording"]

(PLAN_ALARM, CLOCK_STEPPED, ENCODER_FROZEN, ENCODER_BELIEVED, ENCODER_GLITCH, ANEMOMETER_MOVING, ANEMOMETER_STUCK,
 WIND_MISSING, WIND_HIGH, WIND_RELEASED, WIND_RELEASED_FROZEN, NEW_DAY_PROBE, NIGHT, WAKE, SENSOR_LOST, SKY_NOT_SUNNY,
 TRUE_SKY_NOT_SUNNY, SENSOR_TRUSTED, SKY_SUNNY, SUN_BACK, OUT_OF_FINE_VIEW, DISAGREEMENT, CLOCK_OFF,
 CLOCK_DRIFTING, DISAGREEMENT_FOLLOWED, HELD_OFF, NIGHT_GAP, WIND_UNREADABLE) = range(1, 29)
#: A flag added to the wind codes when the stow is a timed move from the reckoned position.
BLIND = 100


def wording(config, plan_alarms: dict, axes: int):
    """`reason(code, value, other, scan, third)`: the reference controller's text for an event, for a
    run of controller `config` on `axes` axes whose plan raised `plan_alarms` (by scan); an
    encoder's events carry its axis in `third`."""
    names = AXIS_NAMES[axes]
    distrust = config.minutes("distrust")
    released = f"wind at or below {config.wind_release} m/s for {config.wind_hold}"
    texts = {
        PLAN_ALARM: lambda value, other, scan, third: plan_alarms[scan],
        CLOCK_STEPPED: lambda value, other, scan, third:
            f"controller clock stepped by {value:+.0f} s against the scan timer; clock re-based",
        ENCODER_FROZEN: lambda value, other, scan, third:
            f"{names[int(third)]}encoder frozen: commanded {value:+.2f}°, reading unchanged; drive halted",
        ENCODER_BELIEVED: lambda value, other, scan, third:
            f"{names[int(third)]}encoder reading {value:.3f}° held for {int(other)} scans; believed",
        ENCODER_GLITCH: lambda value, other, scan, third:
            f"{names[int(third)]}encoder glitch: read {value:.3f}°, expected {other:.3f}°; ignored",
        ANEMOMETER_MOVING: lambda value, other, scan, third: f"anemometer moving again ({value:.1f} m/s)",
        ANEMOMETER_STUCK: lambda value, other, scan, third: (f"anemometer stuck at {value:.2f} m/s for {STUCK_HOURS:g} h of "
                                                      "daylight; its readings count as missing"),
        WIND_MISSING: lambda value, other, scan, third: "wind reading missing",
        WIND_HIGH: lambda value, other, scan, third: f"wind {value:.1f} m/s > {config.wind_stow}",
        WIND_UNREADABLE: lambda value, other, scan, third: unreadable_reason(value),
        WIND_RELEASED: lambda value, other, scan, third: released,
        WIND_RELEASED_FROZEN: lambda value, other, scan, third: released + "; encoder still judged frozen: drive halted",
        NEW_DAY_PROBE: lambda value, other, scan, third: "a new day: probing the encoder again",
        NIGHT: lambda value, other, scan, third: "dark for 30 minutes" if config.sensor_only
            else "outside working hours or sun down",
        NIGHT_GAP: lambda value, other, scan, third: f"no scans for {value / 60.0:.1f} h across the night: asleep through it",
        WAKE: lambda value, other, scan, third: "awake and sun up" if config.uses_model else "daylight",
        SENSOR_LOST: lambda value, other, scan, third: f"sensor lost ({SENSOR_STATUS[int(value)]})",
        SKY_NOT_SUNNY: lambda value, other, scan, third: f"sky {SKY_CODES[int(value)]}",
        TRUE_SKY_NOT_SUNNY: lambda value, other, scan, third: "true sky not sunny",
        SENSOR_TRUSTED: lambda value, other, scan, third: "sensor valid and trusted",
        SKY_SUNNY: lambda value, other, scan, third: "sky sunny and sensor valid",
        SUN_BACK: lambda value, other, scan, third: "sun back in the sensor's view",
        OUT_OF_FINE_VIEW: lambda value, other, scan, third: "the acquisition cells see the sun outside the fine view",
        DISAGREEMENT: lambda value, other, scan, third: (
            f"sensor and calibrated model disagree: mean residual {value:+.3f}° over {int(other)} readings; "
            f"calibration rolled back, sensor not trusted for {distrust:.0f} min"),
        DISAGREEMENT_FOLLOWED: lambda value, other, scan, third: (
            f"sensor and calibrated model disagree: mean residual {value:+.3f}° over {int(other)} readings; "
            "sensor trusted, calibration follows it (on_disagreement = 'sensor')"),
        HELD_OFF: lambda value, other, scan, third: (
            f"sensor {value:+.2f}° from the calibrated model, held beyond the plausibility bound for {other:.0f} min: "
            "a faulty sensor, or a collector off its encoder (a slipping coupling, a moved mount); the computed "
            "target is followed"),
        CLOCK_OFF: lambda value, other, scan, third: (
            f"controller clock off by {value:+.0f} s (±{other:.0f} s) against the sun the sensor shows, "
            f"over {int(third)} readings"),
        CLOCK_DRIFTING: lambda value, other, scan, third: (
            f"controller clock drifting {value:+.1f} s a day (±{other:.1f}) against the sun the sensor shows, "
            f"over {third:.1f} days"),
    }

    def reason(code: int, value: float, other: float, scan: int, third: float = 0.0) -> str:
        if code >= BLIND:  # a wind stow from fault: a timed move
            return texts[code - BLIND](value, other, scan, third) + \
                "; encoder judged frozen: timed stow move from the position reckoned from the moves commanded"
        return texts[code](value, other, scan, third)

    return reason
