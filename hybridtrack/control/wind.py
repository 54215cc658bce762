"""The wind guard: stow above the threshold at once; release only after a calm spell."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["WindGuard", "STUCK_HOURS", "STUCK_SPREAD", "READABLE", "unreadable", "unreadable_reason"]

#: Hours of daylight readings within `STUCK_SPREAD` of each other that mark an anemometer stuck:
#: the wind by day moves more than that within minutes (a calm night may read 0 for hours).
STUCK_HOURS = 3.0
#: m/s: the spread a working cup anemometer's readings exceed within `STUCK_HOURS` of daylight.
STUCK_SPREAD = 0.05
#: m/s: the readings an anemometer can give. Below: a working one reads a few tenths below zero in
#: calm air (its zero offset; the WMO asks ±0.5 m/s at low speeds, and the file reader clips as
#: much to calm), so a lower reading is a failed instrument or signal (an open 4-20 mA loop reads
#: below 4 mA, a negative speed), never calm: -5 m/s, or -inf, had been taken as calm and the
#: collector tracked through whatever blew. Above: the strongest gust on record is 113 m/s
#: (Barrow Island, 1996, WMO); 1e300 is no wind.
READABLE = (-0.5, 120.0)


def unreadable(wind: float) -> bool:
    """Whether a reading is outside what an anemometer can give (`READABLE`); NaN is missing, not this."""
    return wind < READABLE[0] or wind > READABLE[1]


def unreadable_reason(wind: float) -> str:
    """The stow's reason for a reading outside `READABLE`, the reading written out exactly (in
    three figures, -0.50001 and 120.0001 m/s had read as -0.5 and 120, readings that are wind)."""
    return (f"wind reading {float(wind)!r} m/s is no wind (an anemometer reads {READABLE[0]:g} to "
            f"{READABLE[1]:g} m/s): the instrument or its signal failed; counted as missing")


class WindGuard:
    """Judges each anemometer reading.

    A reading that is not a number is missing wind data, never calm: with ``missing="stow"``
    (a live controller's default) it counts as a gust; with ``missing="track"`` (replaying a
    file that has no wind at all) it counts as no gust, and the run says the wind was missing.
    A reading outside what an anemometer reads (`READABLE`), or stuck within `STUCK_SPREAD` for
    `STUCK_HOURS` of daylight, is missing too.
    """

    __slots__ = ("stow_above", "release_at", "hold", "calm_since", "stow_when_missing", "flat_value", "flat_since",
                 "stuck")

    def __init__(self, stow_above: float, release_at: float, hold_minutes: float, missing: str = "stow"):
        self.stow_above = stow_above
        self.release_at = release_at
        self.hold = hold_minutes
        self.calm_since = -math.inf
        self.stow_when_missing = missing == "stow"
        self.flat_value = math.nan
        self.flat_since = math.nan
        self.stuck = False

    def gusty(self, wind: float) -> bool:
        """Whether this reading demands a stow."""
        if math.isnan(wind):
            return self.stow_when_missing
        return not wind <= self.stow_above

    def watch(self, t: float, wind: float, daylight: bool) -> str | None:
        """Watch for a stuck anemometer; return an alarm text when it sticks or comes back.

        A flat spell is counted over daylight only (a calm night may read 0 for hours), and a
        missing reading neither breaks it nor counts as a move. Once stuck, the anemometer stays
        stuck, through the night too, until a reading moves off its value: at each dusk the guard
        had forgotten the value, so every morning the same stuck reading passed as wind for the
        three hours it takes to judge it again."""
        if math.isnan(wind) or unreadable(wind):
            return None
        if self.stuck:
            if abs(wind - self.flat_value) <= STUCK_SPREAD:
                return None
            self.stuck = False
            self.flat_value, self.flat_since = (wind, t) if daylight else (math.nan, math.nan)
            return f"anemometer moving again ({wind:.1f} m/s)"
        if not daylight:
            self.flat_value = math.nan
            return None
        if math.isnan(self.flat_value) or abs(wind - self.flat_value) > STUCK_SPREAD:
            self.flat_value, self.flat_since = wind, t
            return None
        if t - self.flat_since >= 60.0 * STUCK_HOURS:
            self.stuck = True
            return (f"anemometer stuck at {self.flat_value:.2f} m/s for {STUCK_HOURS:g} h of daylight; "
                    "its readings count as missing")
        return None

    def gusts(self, readings: np.ndarray) -> np.ndarray:
        """Per reading, whether `update` takes it for a gust once `heard`, a stuck anemometer aside:
        the scans a night asleep in bulk must not pass over (no night is passed over in bulk while
        the guard holds the anemometer stuck, `Controller`)."""
        readings = np.asarray(readings, float)
        with np.errstate(invalid="ignore"):
            missing = np.isnan(readings) | (readings < READABLE[0]) | (readings > READABLE[1])
            return np.where(missing, self.stow_when_missing, readings > self.stow_above)

    def heard(self, wind: float) -> float:
        """The reading as the guard counts it: NaN (missing) outside `READABLE`, or while the
        anemometer is stuck at it."""
        if unreadable(wind) or self.stuck and not math.isnan(wind) and abs(wind - self.flat_value) <= STUCK_SPREAD:
            return math.nan
        return wind

    def update(self, t: float, wind: float) -> bool:
        """Take a reading at scan time `t` (minutes), as `heard`; return whether it is a gust."""
        if self.gusty(wind):
            self.calm_since = math.inf
            return True
        if wind <= self.release_at or math.isnan(wind):
            if math.isinf(self.calm_since):
                self.calm_since = t
        else:
            self.calm_since = math.inf
        return False

    def released(self, t: float) -> bool:
        """Whether the wind has stayed at or below the release speed for the hold time."""
        return not math.isinf(self.calm_since) and t - self.calm_since >= self.hold
