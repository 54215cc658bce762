"""The compiled controller's events: a code and two numbers per event, worded here afterwards.

The kernel cannot build text, so each mode change or alarm is recorded as (scan, from mode, to
mode, code, value, value); `reason` words it exactly as the reference controller does
(`hybridtrack.control.controller`), and a parity test holds every reason equal.
"""

from __future__ import annotations

from ..control.controller import DISTRUST_MINUTES
from ..control.modes import SENSOR_STATUS, SKY_CODES
from ..control.wind import STUCK_HOURS

__all__ = ["reason"]

(PLAN_ALARM, CLOCK_STEPPED, ENCODER_FROZEN, ENCODER_BELIEVED, ENCODER_GLITCH, ANEMOMETER_MOVING, ANEMOMETER_STUCK,
 WIND_MISSING, WIND_HIGH, WIND_RELEASED, WIND_RELEASED_FROZEN, NEW_DAY_PROBE, NIGHT, WAKE, SENSOR_LOST, SKY_NOT_SUNNY,
 TRUE_SKY_NOT_SUNNY, SENSOR_TRUSTED, SKY_SUNNY, SUN_BACK, OUT_OF_FINE_VIEW, DISAGREEMENT) = range(1, 23)
#: A flag added to the wind codes when the stow is a timed move from the last trusted reading.
BLIND = 100


def reason(code: int, value: float, other: float, config, plan_alarms: dict, scan: int) -> str:
    """The reference controller's text for event `code` with its two numbers."""
    blind = code >= BLIND
    code = code - BLIND if blind else code
    if code in (WIND_MISSING, WIND_HIGH):
        text = "wind reading missing" if code == WIND_MISSING else f"wind {value:.1f} m/s > {config.wind_stow}"
        return text + ("; encoder judged frozen: timed stow move from the last trusted reading" if blind else "")
    released = f"wind at or below {config.wind_release} m/s for {config.wind_hold}"
    texts = {
        PLAN_ALARM: lambda: plan_alarms[scan],
        CLOCK_STEPPED: lambda: f"controller clock stepped by {value:+.0f} s against the scan timer; clock re-based",
        ENCODER_FROZEN: lambda: f"encoder frozen: commanded {value:+.2f}°, reading unchanged; drive halted",
        ENCODER_BELIEVED: lambda: f"encoder reading {value:.3f}° held for {int(other)} scans; believed",
        ENCODER_GLITCH: lambda: f"encoder glitch: read {value:.3f}°, expected {other:.3f}°; ignored",
        ANEMOMETER_MOVING: lambda: f"anemometer moving again ({value:.1f} m/s)",
        ANEMOMETER_STUCK: lambda: (f"anemometer stuck at {value:.2f} m/s for {STUCK_HOURS:g} h of daylight; "
                                   "its readings count as missing"),
        WIND_RELEASED: lambda: released,
        WIND_RELEASED_FROZEN: lambda: released + "; encoder still judged frozen: drive halted",
        NEW_DAY_PROBE: lambda: "a new day: probing the encoder again",
        NIGHT: lambda: "dark for 30 minutes" if config.sensor_only else "outside working hours or sun down",
        WAKE: lambda: "awake and sun up" if config.uses_model else "daylight",
        SENSOR_LOST: lambda: f"sensor lost ({SENSOR_STATUS[int(value)]})",
        SKY_NOT_SUNNY: lambda: f"sky {SKY_CODES[int(value)]}",
        TRUE_SKY_NOT_SUNNY: lambda: "true sky not sunny",
        SENSOR_TRUSTED: lambda: "sensor valid and trusted",
        SKY_SUNNY: lambda: "sky sunny and sensor valid",
        SUN_BACK: lambda: "sun back in the sensor's view",
        OUT_OF_FINE_VIEW: lambda: "the acquisition cells see the sun outside the fine view",
        DISAGREEMENT: lambda: (f"sensor and calibrated model disagree: mean residual {value:+.3f}° over {int(other)} "
                               f"readings; calibration rolled back, sensor not trusted for {DISTRUST_MINUTES:.0f} min"),
    }
    return texts[code]()
