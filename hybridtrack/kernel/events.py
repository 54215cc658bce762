"""The compiled controller's events: a code and two numbers per event, worded here afterwards.

The kernel cannot build text, so each mode change or alarm is recorded as (scan, from mode, to
mode, code, value, value); `wording` words it exactly as the reference controller does
(`hybridtrack.control.controller`), and a parity test holds every reason equal.
"""

from __future__ import annotations

from ..control.controller import DISTRUST_MINUTES
from ..control.modes import SENSOR_STATUS, SKY_CODES
from ..control.wind import STUCK_HOURS

__all__ = ["wording"]

(PLAN_ALARM, CLOCK_STEPPED, ENCODER_FROZEN, ENCODER_BELIEVED, ENCODER_GLITCH, ANEMOMETER_MOVING, ANEMOMETER_STUCK,
 WIND_MISSING, WIND_HIGH, WIND_RELEASED, WIND_RELEASED_FROZEN, NEW_DAY_PROBE, NIGHT, WAKE, SENSOR_LOST, SKY_NOT_SUNNY,
 TRUE_SKY_NOT_SUNNY, SENSOR_TRUSTED, SKY_SUNNY, SUN_BACK, OUT_OF_FINE_VIEW, DISAGREEMENT) = range(1, 23)
#: A flag added to the wind codes when the stow is a timed move from the last trusted reading.
BLIND = 100


def wording(config, plan_alarms: dict):
    """`reason(code, value, other, scan)`: the reference controller's text for an event, for a
    run of controller `config` whose plan raised `plan_alarms` (by scan)."""
    released = f"wind at or below {config.wind_release} m/s for {config.wind_hold}"
    texts = {
        PLAN_ALARM: lambda value, other, scan: plan_alarms[scan],
        CLOCK_STEPPED: lambda value, other, scan:
            f"controller clock stepped by {value:+.0f} s against the scan timer; clock re-based",
        ENCODER_FROZEN: lambda value, other, scan:
            f"encoder frozen: commanded {value:+.2f}°, reading unchanged; drive halted",
        ENCODER_BELIEVED: lambda value, other, scan:
            f"encoder reading {value:.3f}° held for {int(other)} scans; believed",
        ENCODER_GLITCH: lambda value, other, scan:
            f"encoder glitch: read {value:.3f}°, expected {other:.3f}°; ignored",
        ANEMOMETER_MOVING: lambda value, other, scan: f"anemometer moving again ({value:.1f} m/s)",
        ANEMOMETER_STUCK: lambda value, other, scan: (f"anemometer stuck at {value:.2f} m/s for {STUCK_HOURS:g} h of "
                                                      "daylight; its readings count as missing"),
        WIND_MISSING: lambda value, other, scan: "wind reading missing",
        WIND_HIGH: lambda value, other, scan: f"wind {value:.1f} m/s > {config.wind_stow}",
        WIND_RELEASED: lambda value, other, scan: released,
        WIND_RELEASED_FROZEN: lambda value, other, scan: released + "; encoder still judged frozen: drive halted",
        NEW_DAY_PROBE: lambda value, other, scan: "a new day: probing the encoder again",
        NIGHT: lambda value, other, scan: "dark for 30 minutes" if config.sensor_only
            else "outside working hours or sun down",
        WAKE: lambda value, other, scan: "awake and sun up" if config.uses_model else "daylight",
        SENSOR_LOST: lambda value, other, scan: f"sensor lost ({SENSOR_STATUS[int(value)]})",
        SKY_NOT_SUNNY: lambda value, other, scan: f"sky {SKY_CODES[int(value)]}",
        TRUE_SKY_NOT_SUNNY: lambda value, other, scan: "true sky not sunny",
        SENSOR_TRUSTED: lambda value, other, scan: "sensor valid and trusted",
        SKY_SUNNY: lambda value, other, scan: "sky sunny and sensor valid",
        SUN_BACK: lambda value, other, scan: "sun back in the sensor's view",
        OUT_OF_FINE_VIEW: lambda value, other, scan: "the acquisition cells see the sun outside the fine view",
        DISAGREEMENT: lambda value, other, scan: (
            f"sensor and calibrated model disagree: mean residual {value:+.3f}° over {int(other)} readings; "
            f"calibration rolled back, sensor not trusted for {DISTRUST_MINUTES:.0f} min"),
    }

    def reason(code: int, value: float, other: float, scan: int) -> str:
        if code >= BLIND:  # a wind stow from fault: a timed move
            return texts[code - BLIND](value, other, scan) + \
                "; encoder judged frozen: timed stow move from the last trusted reading"
        return texts[code](value, other, scan)

    return reason
