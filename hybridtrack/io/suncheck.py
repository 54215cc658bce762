"""The sun check: does the file's light rise and set with the site's computed sun?

A logger whose clock runs in UTC but is declared local (or a file from another site) puts
daylight at night. Two tests, on the measured light before any gap is filled:

* **Light at night**: direct (or, without any, global) irradiance above `LIGHT` W/m² while
  the sun is below the horizon at the stamp and the tolerance (below) either side of it, so
  that averages labelled at a step's start or end, or a clock a few minutes off, are not caught.
* **Offset of the daily light curve**: the shift of the computed sun's up/down pattern that
  best matches the file's global light/dark pattern (the fewest ten-minute bins where one says
  day and the other night), searched over ±14 hours; of equally good shifts, none if it is
  among them, else the middle one. Daylight gives diffuse light under any cloud, so the edges
  of the day are found on overcast days too. With DNI alone only the light-at-night side
  counts, and the smallest shift that explains it is named.

A file read in a zone whose clock changes within it (summer time) is judged on each side of the
change too, where a side holds a day of readings: a logger kept on standard time all year fits
the sun on one side and is an hour off on the other, which one shift for the whole file had
averaged to within the tolerance (`_clock_change_check`).

A shift beyond `max(45 min, step)`, or light at night in more than 2 % of the lit rows (and
more than 3 rows), refuses the file, naming the first such row, the shift that fits and the
UTC offset the stamps would then have. With ``lenient=True`` it is a warning in the report.
A few rows of light at night are reported and kept.

The sun is computed with the project's PLC model (`hybridtrack.sun`), well within a minute of
SPA, which is far finer than the ten-minute bins.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from ..sky import LIGHT_AT_NIGHT
from .checks import first_lines, place, span

__all__ = ["sun_check", "place_check", "meta_name", "LIGHT", "BIN", "FAR"]

#: W/m²: light a sensor cannot read with the sun below the horizon (`hybridtrack.sky.LIGHT_AT_NIGHT`).
LIGHT = LIGHT_AT_NIGHT
#: The resolution of the offset search.
BIN = pd.Timedelta(minutes=10)
_SEARCH = pd.Timedelta(hours=14)
#: km: a file whose header places it farther than this from the site is another place's weather.
#: A typical-year file from a station a few tens of km away is the usual stand-in for a site;
#: 300 km is a climate region and, east-west, a quarter of an hour of the sun's timing.
FAR = 300.0


def _sun_up(site, times: pd.DatetimeIndex) -> np.ndarray:
    from ..sun import solar_position

    return solar_position(times, site, model="plc")["apparent_altitude"].to_numpy(float)


def _binned(frame: pd.DataFrame, name: str) -> tuple[pd.DatetimeIndex, np.ndarray]:
    """Mean light in ten-minute bins over the file (NaN where the file has none)."""
    utc = frame[name].tz_convert("UTC") if frame.index.tz is not None else frame[name]
    means = utc.groupby(utc.index.floor(BIN)).mean()
    grid = pd.date_range(means.index[0], means.index[-1], freq=BIN)
    return grid, means.reindex(grid).to_numpy(float)


def _best_shift(site, grid: pd.DatetimeIndex, light: np.ndarray, symmetric: bool) -> tuple[pd.Timedelta, float]:
    """The shift of the sun that matches the light best, and the share of bins that then disagree."""
    reach = int(_SEARCH / BIN)
    wide = pd.date_range(grid[0] - reach * BIN, grid[-1] + reach * BIN, freq=BIN)
    up = _sun_up(site, wide) > 0.0
    known = np.isfinite(light)
    lit = light[known] > LIGHT
    where = np.flatnonzero(known)
    scores = np.empty(2 * reach + 1)
    for k, shift in enumerate(range(-reach, reach + 1)):
        sun = up[where + reach + shift]
        wrong = lit & ~sun
        if symmetric:
            wrong = wrong | (~lit & sun)
        scores[k] = wrong.mean() if len(wrong) else 0.0
    best = np.flatnonzero(scores <= scores.min() + 1e-12) - reach
    if best.min() <= 0 <= best.max() or not symmetric:
        chosen = int(best[np.argmin(np.abs(best))])  # the data do not tell a shift apart from none
    else:
        chosen = int(round(float(np.median(best))))  # the middle of the equally good shifts
    return chosen * BIN, float(scores[chosen + reach])


def _night_light(site, frame: pd.DataFrame, name: str, window: pd.Timedelta) -> np.ndarray:
    """Rows with light while the sun is down at the stamp and `window` either side."""
    values = frame[name].to_numpy(float)
    lit = np.isfinite(values) & (values > LIGHT)
    if not lit.any():
        return lit
    index = frame.index[lit]
    altitude = np.max([_sun_up(site, index + sign * window) for sign in (-1, 0, 1)], axis=0)
    night = np.zeros(len(frame), bool)
    night[np.flatnonzero(lit)[altitude < 0.0]] = True
    return night


def _offset_text(frame: pd.DataFrame, shift: pd.Timedelta) -> str:
    """The UTC offset the stamps would have if the light is right: theirs minus the shift."""
    return _utc(frame.index[len(frame) // 2].utcoffset() - shift)


def _utc(offset: pd.Timedelta) -> str:
    """A UTC offset as ``UTC+01:00``, to the minute."""
    minutes = int(round(offset / pd.Timedelta(minutes=1)))
    return f"UTC{'+' if minutes >= 0 else '-'}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def _fits(frame: pd.DataFrame, site, shift: pd.Timedelta) -> str:
    offset = frame.index[len(frame) // 2].utcoffset() - shift
    fits = f"the light fits the sun at {site.name} shifted by {_signed(shift)}"
    if abs(offset) > pd.Timedelta(hours=14):
        return fits + ", beyond any time zone: is the file from another site?"
    return fits + f", i.e. stamps in {_offset_text(frame, shift)}"


def _signed(shift: pd.Timedelta) -> str:
    return ("+" if shift >= pd.Timedelta(0) else "-") + span(abs(shift)) if shift != pd.Timedelta(0) else "0"


def _mismatch(path: Path, frame: pd.DataFrame, site, name: str, report: dict, night: np.ndarray,
              shift: pd.Timedelta | None, lenient: bool) -> str:
    """The one-line message: the first row of light at night (or the brightest), and the shift that fits."""
    values = frame[name].to_numpy(float)
    row = int(np.flatnonzero(night)[0]) if night.any() else int(np.nanargmax(values))
    where = place(path, report, name, first_lines(frame, np.arange(len(frame)) == row))
    lit = int((values > LIGHT).sum())
    if night.any():
        what = (f"{night.sum()} of {lit} lit rows have {name} while the sun is down, the first {values[row]:g} W/m² "
                f"at {frame.index[row]}")
    else:
        what = f"the daily light curve is offset from the sun, e.g. {values[row]:g} W/m² at {frame.index[row]}"
    fits = _fits(frame, site, shift) if shift is not None else "no shift of the sun explains it"
    ask = "" if lenient else ", or --lenient to read it anyway"
    return (f"{where}: {what}; {fits}{'' if fits.endswith('?') else '.'} Give the file's "
            f"time zone (--tz) or the right site{ask}")


def _no_light(frame: pd.DataFrame, site) -> str:
    """The sun check's word on a file without light: a warning (so the file is not called clean)
    when the site's sun is up at any of its stamps, since daylight gives light under any sky."""
    altitude = _sun_up(site, frame.index)
    if not (altitude > 0.0).any():
        return "not done (no light in the file, whose stamps are all at night)"
    return (f"WARNING: not done: no light above {LIGHT:g} W/m² in the file, while the sun at {site.name} is up in "
            f"{int((altitude > 0.0).sum())} rows (up to {np.nanmax(altitude):.0f}°); is the light in another unit, "
            "or the sensor dead?")


def sun_check(path: Path, frame: pd.DataFrame, site, report: dict, *, lenient: bool = False) -> None:
    """Refuse (or, `lenient`, warn about) light that does not follow the site's sun.

    The result goes into ``report["sun_check"]``; see the module's notes for the tests.
    """
    lit_in = [c for c in ("dni", "ghi", "dhi") if c in frame and (frame[c].to_numpy(float) > LIGHT).any()]
    if not lit_in:
        report["sun_check"] = _no_light(frame, site)
        return
    name = lit_in[0]  # direct light where there is some: it is the surest sign of the sun
    curve = "ghi" if "ghi" in lit_in else name  # global light has the day's edges under any sky
    tolerance = max(pd.Timedelta(minutes=45), pd.Timedelta(report.get("step", "1min")))
    shift, disagree = _best_shift(site, *_binned(frame, curve), symmetric=curve != "dni")
    night = _night_light(site, frame, name, tolerance)
    offset_wrong = abs(shift) > tolerance
    if not offset_wrong:
        _clock_change_check(path, frame, site, name, curve, tolerance, lenient, report)
        if "sun_check" in report:
            return
    if offset_wrong or night.sum() > max(3, 0.02 * (frame[name].to_numpy(float) > LIGHT).sum()):
        message = _mismatch(path, frame, site, name, report, night, shift if offset_wrong else None, lenient)
        if not lenient:
            raise HybridtrackError(message)
        report["sun_check"] = "WARNING: " + message.split(": ", 1)[1]
        return
    if night.any():
        report["light_at_night"] = {"count": int(night.sum()), "lines": first_lines(frame, night),
                                    "column": report.get("columns", {}).get(name, name), "action": "kept"}
    report["sun_check"] = (f"light follows the sun at {site.name} (best shift {_signed(shift)}, {disagree:.1%} of "
                           "bins disagree)")


#: Ten-minute bins of readings a side of a clock change needs to be judged on its own: a day.
SIDE_BINS = 144


def _clock_change_check(path: Path, frame: pd.DataFrame, site, name: str, curve: str, tolerance: pd.Timedelta,
                        lenient: bool, report: dict) -> None:
    """Refuse (or, `lenient`, warn about in ``report["sun_check"]``) a file whose stamps change
    their UTC offset (the zone's summer time) where one side fits the sun, another is off by more
    than `tolerance`, and the two sides' shifts differ by the change itself (`_kept_one_clock`): a
    logger that kept one offset through the change. A file with its nights left out fits each
    side loosely (no dark bin holds an edge of the day): its sides' shifts had differed by ten
    minutes across the tolerance, and correct London files were refused."""
    if frame.index.tz is None:
        return
    sides = _offset_sides(frame.index)
    if len(sides) < 2:
        return
    judged = []
    for side in sides:
        grid, light = _binned(frame.iloc[side], curve)
        if np.isfinite(light).sum() >= SIDE_BINS:
            judged.append((side, _best_shift(site, grid, light, symmetric=curve != "dni")[0]))
    pair = _kept_one_clock(frame.index, judged, tolerance)
    if pair is None:
        return
    (side, shift), (fitting, _) = pair
    first = int(side[0])
    kept = frame.index[int(fitting[0])].utcoffset()  # the clock the logger kept: the side that fits
    where = place(path, report, name, first_lines(frame, np.arange(len(frame)) == first))
    message = (f"{where}: the light fits the sun at {site.name} in the rows stamped {_utc(kept)} and is "
               f"{_signed(shift)} off in those stamped {_utc(frame.index[first].utcoffset())} (from "
               f"{frame.index[first]}): the logger kept one clock through the zone's change? Give its fixed zone "
               f"({_fixed_zone(kept)}), or --lenient to read it anyway")
    if not lenient:
        raise HybridtrackError(message)
    report["sun_check"] = "WARNING: " + message.split(": ", 1)[1].removesuffix(", or --lenient to read it anyway")


def _kept_one_clock(index: pd.DatetimeIndex, judged: list, tolerance: pd.Timedelta):
    """Of the `judged` sides (positions, best shift), the first pair, (off, fitting), where one is
    off by more than `tolerance`, the other within it, and their shifts differ by their offsets'
    difference within two bins: the signature of stamps kept on one offset through the change.
    None where no pair has it."""
    for side, shift in judged:
        if abs(shift) <= tolerance:
            continue
        for fitting, fit_shift in judged:
            step = index[int(side[0])].utcoffset() - index[int(fitting[0])].utcoffset()
            if abs(fit_shift) <= tolerance and abs(abs(shift - fit_shift) - abs(step)) <= 2 * BIN:
                return (side, shift), (fitting, fit_shift)
    return None


def _offset_sides(index: pd.DatetimeIndex) -> list[np.ndarray]:
    """The row positions of each run of stamps with one UTC offset."""
    offsets = index.tz_localize(None).as_unit("ns").asi8 - index.tz_convert("UTC").tz_localize(None).as_unit("ns").asi8
    return np.split(np.arange(len(index)), np.flatnonzero(np.diff(offsets)) + 1)


def _fixed_zone(offset: pd.Timedelta) -> str:
    """An IANA zone of the fixed UTC `offset` (+1 h -> ``--tz Etc/GMT-1``: the Etc zones' signs are
    POSIX's, reversed), or the offset itself where no Etc zone has it (a half hour)."""
    minutes = int(round(offset / pd.Timedelta(minutes=1)))
    if minutes % 60:
        return f"stamps in {_utc(offset)}"
    return "--tz Etc/GMT" + (f"{-minutes // 60:+d}" if minutes else "")


def _distance(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance, km."""
    p1, p2, dlon = np.radians(lat1), np.radians(lat2), np.radians(lon2 - lon1)
    cosine = np.sin(p1) * np.sin(p2) + np.cos(p1) * np.cos(p2) * np.cos(dlon)
    return float(6371.0 * np.arccos(np.clip(cosine, -1.0, 1.0)))


def meta_name(meta: dict, default: str) -> str:
    """The place a file's header (pvlib's `meta`, or NSRDB's site lines) names."""
    return next((str(meta[k]).strip('" ') for k in ("city", "City", "Name", "name") if meta.get(k)), default)


def place_check(path: Path, meta: dict, site, report: dict, *, lenient: bool = False) -> None:
    """Refuse (or, `lenient`, warn about in ``report["place"]``) a file whose header (EPW, TMY3,
    ...: pvlib's `meta`) places it more than `FAR` km from `site`.

    The sun check cannot see a place an hour of longitude away in hourly data; the header says
    where the file was made.
    """
    try:
        lat, lon = float(meta["latitude"]), float(meta["longitude"])
    except (KeyError, TypeError, ValueError):
        return
    if not (np.isfinite(lat) and np.isfinite(lon)):
        return
    km = _distance(lat, lon, site.latitude, site.longitude)
    if km <= FAR:
        return
    name = meta_name(meta, "a place")
    message = (f"{path}: line 1: the file's header places it at {name} ({lat:.3f}°, {lon:.3f}°), {km:,.0f} km from "
               f"the site {site.name} ({site.latitude:.3f}°, {site.longitude:.3f}°); give the right site"
               + ("" if lenient else ", or --lenient to read it anyway"))
    if not lenient:
        raise HybridtrackError(message)
    report["place"] = "WARNING: " + message.split(": line 1: ", 1)[1]
