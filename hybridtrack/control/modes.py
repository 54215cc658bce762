"""The controller's modes, the sensor statuses it logs, and the sky classes it knows."""

__all__ = ["MODES", "SENSOR_STATUS", "SKY_CODES", "TRACKING", "sky_code"]

#: ``stow_night`` asleep at stow (or, for the sensor-only tracker, parked toward the morning sun);
#: ``stow_wind`` stowed for wind; ``astronomical`` following the computed sun; ``sensor`` following
#: the sun sensor; ``search`` the sensor-only tracker's acquisition; ``fault`` position unknown.
MODES = ("stow_night", "stow_wind", "astronomical", "sensor", "search", "fault")
STOW_NIGHT, STOW_WIND, ASTRONOMICAL, SENSOR, SEARCH, FAULT = range(len(MODES))
TRACKING = (ASTRONOMICAL, SENSOR, SEARCH)

SENSOR_STATUS = ("ok", "low light", "out of view", "invalid reading", "outlier", "not read", "stuck", "implausible")
OK, LOW_LIGHT, OUT_OF_VIEW, INVALID, OUTLIER, NOT_READ, STUCK, IMPLAUSIBLE = range(len(SENSOR_STATUS))
#: Statuses that say the sensor is wrong, not merely clouded or out of view.
FAULTY = (STUCK, IMPLAUSIBLE, INVALID)

SKY_CODES = ("sunny", "cloudy", "overcast", "unknown")
SUNNY, CLOUDY, OVERCAST, UNKNOWN = range(len(SKY_CODES))


def sky_code(name, otherwise: int = -1) -> int:
    """The code of a sky label in `SKY_CODES`, or `otherwise` for a label outside them (a band
    named another way, a missing label)."""
    return SKY_CODES.index(name) if name in SKY_CODES else otherwise
