"""The controller's modes, the sensor statuses it logs, and the sky classes it knows."""

__all__ = ["MODES", "SENSOR_STATUS", "SKY_CODES", "TRACKING"]

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
