"""Nights a logger left out, put back: dark scans for a controller that scans all night.

Many loggers record only by day (they stop below a light threshold, or their exports are cut
to daylight). Replayed as it is, such a file has no scan between an evening and the next
morning: the controller sleeps the night at the morning's first scan (`hybridtrack.control.plan`)
but cannot pre-position before sunrise, so each morning's slew from stow is scored, which a
PLC scanning through the night never shows. `fill_nights` puts the night's scans back, at the
frame's own step:

* irradiance (``ghi``, ``dni``, ``dhi``) 0 W/m² where the site's sun is below the horizon, and
  between those and the file's first and last readings of the day (twilight under the logger's
  threshold) a straight line in time to them;
* every other number (``wind_speed``, ``temp_air``, ...) a straight line in time from the
  evening's last reading to the morning's first: a missing wind reading would stow the
  collector all night and hold it in the morning (missing wind is never calm);
* any other column missing.

A gap is a night when the sun is down at one of its instants at least and up for no longer than
`TWILIGHT`; gaps by day, and a logger down for a day or more, are left as they are (the reader
reports them). So are the first day's start before the first reading
and the last day's end after the last (local midnight to midnight, as a PLC's day runs), so that
the first morning is pre-positioned too. Every row put back is counted in the validation report.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import sites
from ..errors import HybridtrackError
from ..times import local_steps
from .columns import IRRADIANCE

__all__ = ["fill_nights", "night_gaps", "TWILIGHT"]

#: The longest the sun may be up within a gap filled as a night: the twilight either side that a
#: logger's light threshold leaves out (the sun's first few degrees take half an hour to an hour at
#: mid-latitudes, longer towards the poles). A gap with more daylight in it is a logger down by
#: day as well, whose light nobody can tell: left as a gap.
TWILIGHT = pd.Timedelta(hours=3)
#: A step longer than this many of its local steps is a gap (as `hybridtrack.io` counts gaps).
GAP = 1.5


def _step(index: pd.DatetimeIndex) -> pd.Timedelta:
    """The frame's own step: its median."""
    return pd.TimedeltaIndex(index[1:] - index[:-1]).median()  # by time, whatever the index's unit


def _instants(index: pd.DatetimeIndex, step: pd.Timedelta, tz: str) -> tuple[pd.DatetimeIndex, np.ndarray]:
    """The stamps at `step` strictly inside each gap, a step longer than `GAP` times its local one
    (`hybridtrack.times.local_steps`: a frame's 15-minute day beside its 1-minute day has none),
    and each one's gap
    (its row before; -1 and ``len(index)`` for the first local day's start before the first row
    and the last one's end after the last row, which the file leaves out as well)."""
    steps = np.diff(index.as_unit("ns").asi8).astype(float)
    gaps = np.flatnonzero(steps > GAP * local_steps(steps, GAP))
    first = index[0].tz_convert(tz).normalize().tz_convert(index.tz)
    last = (index[-1].tz_convert(tz).normalize() + pd.Timedelta(days=1)).tz_convert(index.tz)
    inside = [pd.date_range(index[0] - step * ((index[0] - first) // step), index[0] - step / 2, freq=step),
              *(pd.date_range(index[k] + step, index[k + 1] - step / 2, freq=step) for k in gaps),
              pd.date_range(index[-1] + step, last - step / 2, freq=step)]
    owner = np.repeat([-1, *gaps, len(index)], [len(stamps) for stamps in inside])
    return inside[0].append(inside[1:]), owner


def _sun_down(instants: pd.DatetimeIndex, site) -> np.ndarray:
    from ..sun import solar_position

    return solar_position(instants, site, "plc")["apparent_altitude"].to_numpy(float) < 0.0


def _nights(owner: np.ndarray, down: np.ndarray, step: pd.Timedelta) -> np.ndarray:
    """The gaps (by owner) with the sun down at one instant at least and up for `TWILIGHT` at most."""
    dark = np.unique(owner[down])
    up = pd.Series(~down).groupby(owner).sum()
    return dark[(up.reindex(dark).to_numpy() * step) <= TWILIGHT]


def _found(frame: pd.DataFrame, site) -> tuple:
    """What both functions look at: the frame's index and step, the instants inside its gaps and
    the days' ends, each one's gap, whether the sun is down at each, and the gaps that are nights."""
    index = _checked(frame)
    step = _step(index)
    instants, owner = _instants(index, step, site.tz)
    down = _sun_down(instants, site) if len(instants) else np.zeros(0, bool)
    return index, step, instants, owner, down, _nights(owner, down, step)


def _between_readings(nights: np.ndarray, rows: int) -> np.ndarray:
    """The `nights` that lie between two readings (not the first day's start or the last's end)."""
    return nights[(nights >= 0) & (nights < rows)]


def night_gaps(frame: pd.DataFrame, site) -> int:
    """How many gaps of `frame` run from a night into a morning (the site's sun down at one
    instant of the gap at least, and up at the reading that ends it): the nights a logger left
    out, each of whose mornings the controller meets at stow. A gap that ends in the dark (a logger
    down for two hours around midnight, or across dusk) costs the controller nothing, and is not
    counted; `fill_nights` fills it all the same."""
    site = sites.get(site)
    index, *_, nights = _found(frame, site)
    inner = _between_readings(nights, len(index))
    return int((~_sun_down(index[inner + 1], site)).sum()) if len(inner) else 0


def _checked(frame: pd.DataFrame) -> pd.DatetimeIndex:
    index = frame.index
    if not isinstance(index, pd.DatetimeIndex) or index.tz is None or len(index) < 2:
        raise HybridtrackError("fill_nights needs a weather frame on a time-zone-aware index of two stamps or more")
    if not index.is_monotonic_increasing or index.has_duplicates:
        raise HybridtrackError("fill_nights needs a frame's stamps in order, each once (read it with read_weather)")
    return index


def fill_nights(frame: pd.DataFrame, site) -> pd.DataFrame:
    """`frame` with the scans of the nights it leaves out put back at its own step (see the module).

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame (`hybridtrack.io.read_weather`) on a tz-aware index, pvlib's columns.
    site : Site or str
        Where it was recorded: whose sun says which instants are night.

    Returns
    -------
    pandas.DataFrame
        A new frame; ``attrs["validation"]["nights_filled"]`` counts the nights and rows put
        back and says how (none when the frame leaves no night out).

    References
    ----------
    .. [1] I. Reda and A. Andreas, "Solar position algorithm for solar radiation applications",
       Solar Energy 76(5), 577-589, 2004, doi:10.1016/j.solener.2003.12.003 (the sun below the
       horizon: no direct or diffuse light to fill but 0).
    """
    index, step, instants, owner, down, nights = _found(frame, sites.get(site))
    keep = np.isin(owner, nights)
    added = instants[keep]
    if not len(added):
        return frame
    filled = frame.reindex(index.append(added).sort_values())
    new = ~filled.index.isin(index)
    dark = pd.Series(False, index=filled.index)
    dark[added[down[keep]]] = True
    numbers = [c for c in filled.columns if pd.api.types.is_numeric_dtype(frame[c].dtype)
               and not pd.api.types.is_bool_dtype(frame[c].dtype)]
    for column in numbers:
        values = filled[column].astype(float)
        if column.split("_")[0] in IRRADIANCE:  # a clear sky's too (ghi_clear): dark at night
            values = values.mask(dark & new, 0.0)
        through = values.interpolate(method="time", limit_area="inside").ffill().bfill()  # the edges: held
        filled[column] = values.where(~new, through)
    inner = len(_between_readings(nights, len(index)))
    attrs = {**frame.attrs, "validation": dict(frame.attrs.get("validation", {}))}
    attrs["validation"]["nights_filled"] = {
        "nights": inner, "ends of the first and last days": int(len(nights) - inner), "rows": int(len(added)),
        "how": "irradiance 0 with the sun down and a line to the day's readings; "
               + (", ".join(c for c in numbers if c.split("_")[0] not in IRRADIANCE) or "no other number")
               + " a line across",
    }
    report = attrs["validation"]
    report["rows_out"], report["date_range"] = int(len(filled)), f"{filled.index[0]} to {filled.index[-1]}"
    if "gaps" in report and report["gaps"].get("count", 0) <= inner:  # the gaps found were these nights
        report.pop("gaps")
    filled.attrs = attrs
    return filled
