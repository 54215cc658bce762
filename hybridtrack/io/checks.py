"""Validation: order, duplicates, gaps, impossible values, offsets, and each repair counted.

Every repair is recorded in the validation report with its count and the first file lines
it touched (`first_lines`), and `refuse_repairs` turns the first one into an error in strict
mode. The limits and their reasons:

* Irradiance below -50 W/m² or above 1500 (GHI), 1400 (DNI), 1000 (DHI) W/m² cannot be
  measured at the Earth's surface: the solar constant is 1361 W/m² (Kopp & Lean 2011,
  doi:10.1029/2010GL045777) and the BSRN "physically possible" limits of Long & Shi (2008,
  doi:10.2174/1874282300802010023) are of this size. Small negative irradiance (down to
  -50 W/m²) is a thermopile's night offset: clipped to 0 (`clip_offsets`). GHI or DHI below 0
  while the site's sun is well up is no offset (`_negative_under_high_sun`).
* Wind below -0.5 m/s or above 75 m/s: a cup or sonic anemometer's zero offset gives small
  negative readings in calm air (a few tenths of m/s), which are calm, so clipped to 0; 75 m/s
  is above any recorded surface gust outside tornadoes.
* Air temperature outside -90..65 °C: beyond the records of the surface (-89.2 °C at Vostok;
  56.7 °C in Death Valley).
* Non-finite values (``inf``, ``1e400``) are impossible everywhere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from ..sky import LIGHT_AT_NIGHT
from ..times import DAY_NS, clock_nanoseconds
from .columns import IRRADIANCE, WEATHER_COLUMNS
from .units import FRAME_UNITS

__all__ = ["LIMITS", "CLIPPED_AT_ZERO", "CALM_OFFSET", "first_lines", "span", "check_frame", "clip_offsets",
           "check_magnitude", "site_clear_sky", "kilowatts_without_site",
           "check_magnitude_by_day", "check_derived", "refuse_repairs"]

#: Physically possible range of each column; outside it a value is flagged (NaN).
LIMITS = {"ghi": (-50.0, 1500.0), "dni": (-50.0, 1400.0), "dhi": (-50.0, 1000.0), "wind_speed": (-0.5, 75.0),
          "temp_air": (-90.0, 65.0), "photocurrent": (0.0, 10_000.0), "pointing": (-90.0, 90.0),
          "pointing_2": (-90.0, 90.0)}

#: Columns whose small negative readings are an instrument's zero offset, clipped to 0 by the reader.
CLIPPED_AT_ZERO = (*IRRADIANCE, "wind_speed")

#: m/s: negative wind down to this is an anemometer's zero offset in calm air, read as 0.
CALM_OFFSET = -0.5

#: W/m² of clear-sky GHI (pvlib's Haurwitz) with the sun well up, about 35° above the horizon.
SUN_WELL_UP = 600.0
#: Clock hours with the clear sky at `SUN_WELL_UP` or more before a file's darkness is judged.
HOURS_WELL_UP = 2
#: W/m²: the largest value no sky keeps below for `HOURS_WELL_UP` hours of a high sun (see
#: `_refuse_too_dark`); it is also the light the sun check counts (`hybridtrack.sky.LIGHT_AT_NIGHT`).
DARKEST = LIGHT_AT_NIGHT

_HINT = {"ghi": "kW/m2", "dni": "kW/m2", "dhi": "kW/m2", "wind_speed": "km/h", "temp_air": "K", "photocurrent": "A",
         "pointing": "rad", "pointing_2": "rad"}

#: What each repair did, for strict mode's refusal.
REPAIRS = {
    "unreadable": "text in a numeric column", "truncated": "a last line cut short",
    "short_rows": "a line with fewer fields than the header",
    "missing_markers": "a logger's missing-value marker",
    "dst_dropped": "a time stamp that does not exist in the time zone",
    "sky_rewritten": "a sky label in capitals or with spaces", "sky_blank": "a blank sky label",
    "unsorted": "time stamps out of order", "duplicates": "a repeated time stamp",
    "impossible": "a physically impossible value",
    "negative_in_sun": "a negative irradiance with the sun well up", "negative_clipped": "a negative irradiance",
    "calm_clipped": "a negative wind reading", "empty_dropped": "an irradiance column without a readable value",
}


def first_lines(frame: pd.DataFrame, mask) -> list[int]:
    """The file lines of the first five rows in `mask` (resampled rows have none)."""
    lines = frame["_line"].to_numpy()[np.asarray(mask, bool)]
    return [int(v) for v in lines[np.isfinite(lines)][:5]]


def place(path: Path, report: dict, name: str, lines: list[int]) -> str:
    """Where a refusal points in a file: the first of `lines` (none for a resampled frame's rows) and
    the column of frame name `name` by its header in the file."""
    header = report.get("columns", {}).get(name, name)
    return f"{path}: line {lines[0]}, column {header!r}" if lines else f"{path}: column {header!r}"


def span(delta) -> str:
    """A duration in its largest whole unit: ``5min``, ``1h``, ``30s``, ``2d``."""
    delta = pd.Timedelta(delta)
    for unit, size in (("d", pd.Timedelta(days=1)), ("h", pd.Timedelta(hours=1)), ("min", pd.Timedelta(minutes=1)),
                       ("s", pd.Timedelta(seconds=1)), ("ms", pd.Timedelta(milliseconds=1)),
                       ("us", pd.Timedelta(microseconds=1)), ("ns", pd.Timedelta(nanoseconds=1))):
        if delta >= size and delta % size == pd.Timedelta(0):
            return f"{delta // size}{unit}"
    return str(delta)


def _order(path: Path, frame: pd.DataFrame, report: dict) -> pd.DataFrame:
    if not frame.index.is_monotonic_increasing:
        disorder = np.flatnonzero(np.diff(frame.index.as_unit("ns").asi8) < 0) + 1
        report["unsorted"] = {"count": int(len(disorder)),
                              "lines": first_lines(frame, np.isin(np.arange(len(frame)), disorder)),
                              "action": "sorted by time"}
        frame = frame.sort_index(kind="stable")
    duplicated = frame.index.duplicated(keep="first")
    if duplicated.sum() > 0.5 * len(frame):
        lines = first_lines(frame, duplicated)
        raise HybridtrackError(f"{path}: line {lines[0] if lines else '?'}: {duplicated.sum()} of {len(frame)} stamps "
                               "repeat an earlier one; is part of the time (a clock column) missing? map it with --map")
    if duplicated.any():
        report["duplicates"] = {"count": int(duplicated.sum()), "lines": first_lines(frame, duplicated),
                                "action": "dropped, the first of each kept"}
        frame = frame[~duplicated]
    if len(frame) < 2:
        raise HybridtrackError(f"{path}: fewer than two distinct time stamps; nothing to replay")
    return frame


def _gaps(frame: pd.DataFrame, report: dict) -> None:
    steps = np.diff(frame.index.as_unit("ns").asi8)
    step = int(np.median(steps))
    gap_at = np.flatnonzero(steps > 1.5 * step)
    report["step"] = span(pd.Timedelta(step, "ns"))
    if len(gap_at):
        report["gaps"] = {"count": int(len(gap_at)), "longest": span(pd.Timedelta(int(steps[gap_at].max()), "ns")),
                          "first_after_lines": first_lines(frame, np.isin(np.arange(len(frame)), gap_at))}


def _limits(path: Path, frame: pd.DataFrame, report: dict) -> None:
    impossible = {}
    for name, (low, high) in LIMITS.items():
        if name not in frame:
            continue
        values = frame[name].to_numpy(float)
        present = ~np.isnan(values)
        bad = present & ~((values >= low) & (values <= high))  # inf and 1e400 included
        _refuse_mostly_impossible(path, report, frame, name, bad)
        if bad.any():
            first = values[bad][0]
            impossible[name] = {"count": int(bad.sum()), "lines": first_lines(frame, bad),
                                "first": float(first) if np.isfinite(first) else str(first), "action": "set to NaN"}
            values = np.where(bad, np.nan, values)
        frame[name] = values
    if impossible:
        report["impossible"] = impossible


def clip_offsets(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray | None) -> None:
    """Clip an instrument's zero offset to 0 in place, counted in `report`: irradiance between
    -50 and 0 W/m² (a thermopile's night offset, ``negative_clipped``) and wind between -0.5 and
    0 m/s (an anemometer's in calm air, ``calm_clipped``). With the site's clear sky on the
    frame's stamps (`clear_ghi`, once the sun check has found the light on the site's clock),
    GHI or DHI below 0 under a high sun is judged first (`_negative_under_high_sun`): no offset.
    Without it the reader cannot tell night from day, and every such value is clipped."""
    if clear_ghi is not None:
        _negative_under_high_sun(path, frame, report, clear_ghi)
    clipped, calm = {}, {}
    for name in CLIPPED_AT_ZERO:
        if name not in frame:
            continue
        values = frame[name].to_numpy(float)
        with np.errstate(invalid="ignore"):
            negative = values < 0
        if negative.any():
            entry = {"count": int(negative.sum()), "lines": first_lines(frame, negative),
                     "lowest": float(values[negative].min())}
            (calm if name == "wind_speed" else clipped)[name] = entry
            frame[name] = np.where(negative, 0.0, values)
    for key, entry in (("negative_clipped", clipped), ("calm_clipped", calm)):
        if entry:
            report[key] = entry


def _negative_under_high_sun(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray) -> None:
    """Set to NaN, counted as ``negative_in_sun``, GHI or DHI below 0 W/m² while the site's clear
    sky is `SUN_WELL_UP` or more; refuse the file, naming the first such line, when more than half
    of the column's readings under such a sun are so.

    Under a sun that high the thickest cloud still gives tens of W/m² (`_refuse_too_dark`), and a
    thermopile's offset is a few W/m²: a working pyranometer reads well above 0. A reading below
    it is a sensor covered, disconnected or wired with its sign reversed, not the night offset the
    reader clips; clipped to 0 it had been replayed as a sky without light, and a file of GHI at
    -5 W/m² in every row was refused as "at most 0 W/m²" or, beside a day of light, called usable.
    DNI is not judged so: an overcast day's DNI is 0 and its offset below it.
    """
    high = np.asarray(clear_ghi) >= SUN_WELL_UP
    for name in ("ghi", "dhi"):
        if name not in frame:
            continue
        values = frame[name].to_numpy(float)
        with np.errstate(invalid="ignore"):
            below = high & (values < 0.0)
        if not below.any():
            continue
        lines, judged = first_lines(frame, below), int((high & np.isfinite(values)).sum())
        if below.sum() > 0.5 * judged:
            first = int(np.argmax(below))
            where = place(path, report, name, lines)
            raise HybridtrackError(
                f"{where}: {name} reads {values[first]:g} W/m² with the sun well up (clear sky "
                f"{clear_ghi[first]:.0f} W/m²), and {below.sum()} of its {judged} readings under such a sun are below "
                "0: a pyranometer reads below 0 only at night (its offset); is it covered, disconnected, or its sign "
                "reversed? make its cells empty if it failed")
        report.setdefault("negative_in_sun", {})[name] = {
            "count": int(below.sum()), "lines": lines, "lowest": float(values[below].min()), "action": "set to NaN"}
        frame[name] = np.where(below, np.nan, values)


def _refuse_mostly_impossible(path: Path, report: dict, frame: pd.DataFrame, name: str, bad: np.ndarray) -> None:
    """Refuse a column most of whose values are outside `LIMITS`: a unit mistake, not spikes. The
    refusal names the file's line of the first value judged outside (`where`).

    An irradiance column is judged on its finite daylight values too (above `DARKEST` W/m², or
    beyond the limits): hourly kJ/m² sums (3.6 times W/m²) pass 1500 at every bright hour, but
    the nights' zeros had kept the share under half, so the noons were set to NaN and the rest
    kept 3.6 times too high. A non-finite cell (``inf``, ``1e400``) is damage, not a unit: not
    judged in any column (set to NaN and counted, as a logger's missing-value marker is; a column
    of them had been refused as a unit mistake, ``--units temp_air=K`` for an air temperature of
    ``inf``).
    """
    values = frame[name].to_numpy(float)
    judged, what = np.isfinite(values), "values"
    bad = bad & judged
    if name in IRRADIANCE and bad.sum() <= 0.5 * judged.sum():
        judged, what = np.isfinite(values) & (bad | (values > DARKEST)), "daylight values"
        bad = bad & judged
    if not judged.sum() or bad.sum() <= 0.5 * judged.sum():
        return
    low, high = LIMITS[name]
    where = place(path, report, name, first_lines(frame, bad))
    given, converted, _ = report.get("units_converted", {}).get(name, "").partition(" -> ")
    if converted:  # the unit the file or --units gave is the one to doubt, not another to give
        hint = f"it was read in {given} and converted; if {given} is not its unit, give it, e.g. --units " \
               f"{name}={FRAME_UNITS[name]}"
    elif name in IRRADIANCE and (values[bad] < low).all():  # no unit turns daylight negative
        raise HybridtrackError(f"{where}: {bad.sum() / judged.sum():.0%} of {what} are below "
                               f"{low:g} {FRAME_UNITS[name]}: its sign reversed? (a pyranometer wired the wrong way "
                               "round reads below 0 in daylight) convert the column (×−1)")
    elif name not in IRRADIANCE or not (values[bad] > high).all():
        hint = f"give it, e.g. --units {name}={_HINT[name]}"
    else:
        hint = "kJ/m² or J/m² sums? convert the column to W/m²"
    raise HybridtrackError(f"{where}: {bad.sum() / judged.sum():.0%} of {what} are outside "
                           f"{low:g}..{high:g} ({FRAME_UNITS[name]}); wrong unit? {hint}")


def check_frame(path: Path, frame: pd.DataFrame, report: dict) -> pd.DataFrame:
    """`frame` sorted, without repeated stamps, with impossible values flagged (instruments'
    offsets are clipped later, by `clip_offsets`, once the sun can tell night from day).

    Each repair is counted in `report`; gaps and NaN are reported, not changed.
    """
    frame = _order(path, frame, report)
    _gaps(frame, report)
    nan = {name: int(frame[name].isna().sum()) for name in WEATHER_COLUMNS
           if name in frame and frame[name].isna().any()}
    if nan:
        report["nan"] = nan
    frame = frame.copy()
    _limits(path, frame, report)
    light = [name for name in (*IRRADIANCE, "photocurrent") if name in frame]
    if light and all(frame[name].isna().all() for name in light):
        header = report.get("columns", {}).get(light[0], light[0])
        raise HybridtrackError(f"{path}: column {header!r}: no readable value in any irradiance column")
    return _drop_empty(frame, report)


def _drop_empty(frame: pd.DataFrame, report: dict) -> pd.DataFrame:
    """Drop an irradiance column without one readable value (a logger's dead pyrheliometer) beside
    one that has values, so that it is derived from the others as a missing column is
    (`hybridtrack.io.gapfill`), not replayed as a day without light; counted in `report`."""
    empty = [name for name in IRRADIANCE if name in frame and frame[name].isna().all()]
    if empty:
        report["empty_dropped"] = {name: {"rows": int(len(frame))} for name in empty}
        nan = {name: count for name, count in report.get("nan", {}).items() if name not in empty}
        report.pop("nan", None)
        report.update({"nan": nan} if nan else {})
        frame = frame.drop(columns=empty)
    return frame


#: The largest value of a day's irradiance in kW/m² (the solar constant is 1.361 kW/m²): at most
#: this, where the clear sky reaches `JUDGED_FROM`, is kW/m² read as W/m².
KILOWATT_TOP = 1.5
#: W/m² of the site's clear-sky GHI (Haurwitz) the span must reach before its magnitude is judged.
JUDGED_FROM = 300.0


def kilowatts_without_site(top: float, hours: float) -> bool:
    """`check_magnitude`'s judgement without a site: light whose largest value is above 0 and at
    most `KILOWATT_TOP` over six hours or more (some of them daylight) is kW/m²."""
    return hours >= 6.0 and 0.0 < top <= KILOWATT_TOP


def site_clear_sky(index: pd.DatetimeIndex, site) -> tuple[pd.Series, np.ndarray]:
    """The sun's apparent zenith at each stamp (the PLC model: ample for judging magnitudes) and the
    site's clear-sky GHI there (Haurwitz 1945), W/m²: what the magnitude checks judge light by."""
    import pvlib

    from ..sun import solar_position

    zenith = solar_position(index, site, model="plc")["apparent_zenith"]
    return zenith, pvlib.clearsky.haurwitz(zenith)["ghi"].to_numpy(float)


def check_magnitude(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray | None, *,
                    remedy: str = "give the unit (--units {name}=kW/m2)", whole_file: bool = True) -> None:
    """Refuse irradiance a thousand times too small (kW/m² read as W/m²), or darker than any sky.

    In kW/m² a day's largest reading is at most 1.4; in W/m² the darkest overcast still gives
    tens of W/m² while the sun is well up. So GHI (or DHI) whose largest value is above 0 and at
    most 1.5 is refused when the site's clear sky (`clear_ghi`, W/m², on the frame's stamps)
    reaches 300 W/m² during the file, or, without a site, when the file spans six hours. DNI is
    judged so only in a file without GHI and DHI, since an overcast day has none. With a site,
    GHI or DHI that stays darker than any sky while the sun is high is refused too
    (`_refuse_too_dark`). `remedy` ends the kW/m² message (``{name}`` is the column). Not on the
    `whole_file` (on one day of it), only kW/m² is judged: not a sky too dark nor a dead pyrheliometer, which a day of a
    sensor's outage in a longer file shows (`check_magnitude_by_day`), nor DNI alone, which an
    overcast day of a DNI-only file has none of.
    """
    _refuse_dni_in_kw_beside_beam(path, frame, report, remedy, clear_ghi, whole_file=whole_file)
    hours = (frame.index[-1] - frame.index[0]) / pd.Timedelta(hours=1)
    judged = [name for name in ("ghi", "dhi") if name in frame] or [name for name in ("dni",) if name in frame and whole_file]
    for name in judged:
        values = frame[name].to_numpy(float)
        if not np.isfinite(values).any():
            continue
        top = float(np.nanmax(values))
        if clear_ghi is not None:
            reference = float(np.nanmax(clear_ghi)) if len(clear_ghi) else 0.0
            suspicious = reference >= JUDGED_FROM and 0.0 < top <= KILOWATT_TOP
            why = f"at most {top:g} while the clear sky reaches {reference:.0f} W/m²"
        else:
            suspicious = kilowatts_without_site(top, hours)
            why = f"at most {top:g} over {hours:.0f} hours"
        where = place(path, report, name, first_lines(frame, np.arange(len(frame)) == int(np.nanargmax(values))))
        if suspicious:
            raise HybridtrackError(f"{where}: {name} is {why}; the values look like kW/m² read as W/m²: "
                                   f"{remedy.format(name=name)}")
        if clear_ghi is not None and whole_file:
            _refuse_too_dark(path, report, frame, name, top, clear_ghi)


def check_magnitude_by_day(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray, tz, *,
                           part: bool = False) -> None:
    """`_check_days` in the site's zone `tz` and, where the file's stamps are in another (a logger
    on UTC at a site eight hours east), in theirs: a logger changes its unit on its own day, whose
    W/m² hours had kept each of the site's days above the limit. `frame` is `part` of a longer
    file that passed as a whole (a streamed file's days): a day of it is judged alone too."""
    zones = [tz] + ([frame.index.tz] if str(frame.index.tz) != str(tz) else [])
    for zone in zones:
        _check_days(path, frame, report, clear_ghi, zone, part=part)


def _check_days(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray, tz, *,
                part: bool = False) -> None:
    """`check_magnitude`'s kW/m² judgement on each local day (in zone `tz`) of a file longer than
    a day (or of `part` of one), as `hybridtrack.simulate` judges a frame: a file whose second day
    was in kW/m² had been called clean (the first day's W/m² above the limit), and its replay then
    refused by the run with no file or line named (a day of a dead sensor's noise, 1 W/m² at most,
    is refused so too, by the reader as by the run); then hours of a day in kW/m² (`_check_hours`)."""
    days = clock_nanoseconds(frame.index.tz_convert(tz)) // DAY_NS  # the local calendar's day
    starts = np.concatenate([[0], np.flatnonzero(days[1:] != days[:-1]) + 1, [len(days)]])
    for start, stop in zip(starts[:-1], starts[1:]):
        if stop - start >= 2 and (len(starts) > 2 or part):  # the whole file passed: some other day is in W/m²
            check_magnitude(path, frame.iloc[start:stop], report, clear_ghi[start:stop], whole_file=False,
                            remedy="the file's other days are in W/m²: convert this day's {name} to W/m² (×1000) "
                                   "if its unit changes within the file, or make it empty if the sensor was dead")
    _check_hours(path, frame, report, clear_ghi, days)


def _check_hours(path: Path, frame: pd.DataFrame, report: dict, clear_ghi: np.ndarray, days: np.ndarray) -> None:
    """Refuse GHI or DHI that reads like kW/m² (`DARKEST` / 1000 to `KILOWATT_TOP`) through
    `HOURS_WELL_UP` hours of a high sun (clear sky `SUN_WELL_UP` W/m² or more) of a day (`days`,
    a label per row) whose other readings under that sun are W/m² (above `KILOWATT_TOP`): a
    logger whose unit changed within the day. No sky is so dark for so long (`_refuse_too_dark`),
    and a dead sensor's noise reads below `DARKEST` / 1000 at times; such hours had passed as a
    dark morning, the day's top in W/m² keeping the whole-day judgements quiet. DNI is judged so
    where GHI shows a direct beam (`horizontal_beam`, `BEAM_SEEN` W/m² or more): an afternoon's
    DNI in kW/m² beside a morning's in W/m² had replayed a clear afternoon as overcast."""
    high = np.asarray(clear_ghi) >= SUN_WELL_UP
    judged_where = {name: (high, "a high sun") for name in ("ghi", "dhi") if name in frame}
    beam = horizontal_beam(frame, clear_ghi) if {"ghi", "dni"} <= set(frame.columns) else None
    if beam is not None:
        with np.errstate(invalid="ignore"):
            judged_where["dni"] = (beam[0] >= BEAM_SEEN, f"a direct beam ({beam[1]} {BEAM_SEEN:g} W/m² or more)")
    hours = frame.index.as_unit("ns").asi8 // pd.Timedelta(hours=1).value  # the hour each stamp is in
    for name, (where, what) in judged_where.items():
        values = frame[name].to_numpy(float)
        judged = where & np.isfinite(values)
        kilowatt = judged & (values >= DARKEST / 1000.0) & (values <= KILOWATT_TOP)
        watts = judged & (values > KILOWATT_TOP)
        if not (kilowatt.any() and watts.any()):
            continue
        counts = pd.DataFrame({"hour": hours, "day": days, "judged": judged, "kilowatt": kilowatt, "watts": watts}
                              ).groupby("hour").agg(day=("day", "first"), judged=("judged", "sum"),
                                                    kilowatt=("kilowatt", "sum"), watts=("watts", "sum"))
        counts["in_kilowatts"] = (counts["judged"] > 0) & (counts["judged"] == counts["kilowatt"])
        by_day = counts.groupby("day").agg(hours=("in_kilowatts", "sum"), watts=("watts", "sum"))
        mixed = by_day.index[(by_day["hours"] >= HOURS_WELL_UP) & (by_day["watts"] > 0)]
        if len(mixed):
            in_kilowatts = counts.index[counts["in_kilowatts"] & (counts["day"] == mixed[0])]
            _refuse_hours_in_kilowatts(path, frame, report, name, np.isin(hours, in_kilowatts) & kilowatt,
                                       watts & (days == mixed[0]), f"{len(in_kilowatts)} hours of {what}")


def _refuse_hours_in_kilowatts(path: Path, frame: pd.DataFrame, report: dict, name: str, stretch: np.ndarray,
                               watts: np.ndarray, hours: str) -> None:
    """`_check_hours`' refusal of a day's `hours` in kW/m² (`stretch`) beside its readings in W/m²."""
    values = frame[name].to_numpy(float)
    lines, other = first_lines(frame, stretch), first_lines(frame, watts)
    where = place(path, report, name, lines)
    off_sun = " or a pyrheliometer off the sun" if name == "dni" else ""
    raise HybridtrackError(
        f"{where}: {name} reads {np.min(values[stretch]):g} to {np.max(values[stretch]):g} through {hours}, "
        f"while the same day reads {np.max(values[watts]):g} W/m²{f' (line {other[0]})' if other else ''}: "
        f"those hours look like kW/m² (a unit changed within the day){off_sun}: convert them to W/m² (×1000), or "
        "make them empty if the sensor failed")


def _refuse_too_dark(path: Path, report: dict, frame: pd.DataFrame, name: str, top: float,
                     clear_ghi: np.ndarray) -> None:
    """Refuse GHI or DHI whose largest value is at most `DARKEST` W/m² through `HOURS_WELL_UP` clock
    hours of a clear sky of `SUN_WELL_UP` W/m² or more: no sky is so dark. The first line under
    such a sun is named (the line of the top had been a night's, for a column of one value).

    The thickest clouds (optical depth about 100) still pass some 8 % of the light, by the
    two-stream transmittance of a thick scattering cloud, 1 / (1 + 0.75 (1 - g) tau) with g = 0.85:
    about 50 W/m² under a 600 W/m² clear sky; 20 W/m² would need an optical depth of some 260.
    Such a column is in another unit: a pyranometer's raw millivolts (5-20 µV per W/m²) or sums
    of energy (hourly MJ/m², one-minute Wh/m²). It had been read as a day without light, the sun
    check skipped and the file called clean.
    """
    high = np.asarray(clear_ghi) >= SUN_WELL_UP
    well_up = frame.index[high].floor("h").nunique()
    if well_up < HOURS_WELL_UP or top > DARKEST:
        return
    values = frame[name].to_numpy(float)
    where = place(path, report, name, first_lines(frame, high & np.isfinite(values)))
    with np.errstate(invalid="ignore"):
        negative = bool((values[high] < 0).any()) and not (values[high] > 0).any()
    cause = ("below 0 under that sun: no night offset; is the pyranometer covered, disconnected, or its sign reversed?"
             if negative else "a wrong unit? raw mV, MJ/m² or Wh/m² sums? convert the column to W/m²")
    raise HybridtrackError(f"{where}: {name} is at most {top:g} W/m² through {well_up} hours in which the clear sky "
                           f"is above {SUN_WELL_UP:g} W/m²; no sky is that dark with the sun so high (the thickest "
                           f"cloud still gives tens of W/m²): {cause}")


#: W/m² of direct light on the horizontal (GHI - DHI) that only a direct beam of as much again or
#: more gives: a DNI that stays at 1.5 or less beside it is in kW/m².
BEAM_SEEN = 100.0
#: Share of the clear sky (Haurwitz) that GHI reaches only with the sun out: at such a clearness
#: two thirds or more of GHI is beam (Erbs, Klein & Duffie 1982, doi:10.1016/0038-092X(82)90302-4).
SUN_OUT = 0.8


def horizontal_beam(frame: pd.DataFrame, clear_ghi: np.ndarray | None) -> tuple[np.ndarray, str] | None:
    """Direct light on the horizontal the file shows, and how it was seen: GHI - DHI, or, without
    DHI but with the site's clear sky, GHI where it reaches `SUN_OUT` of the clear sky."""
    if "dhi" in frame:
        return (frame["ghi"] - frame["dhi"]).to_numpy(float), "ghi - dhi reaches"
    if clear_ghi is None:
        return None
    ghi = frame["ghi"].to_numpy(float)
    seen = np.where(ghi >= SUN_OUT * np.asarray(clear_ghi), ghi, np.nan)
    return seen, f"ghi, at {SUN_OUT:.0%} of the clear sky, reaches"


def _refuse_dni_in_kw_beside_beam(path: Path, frame: pd.DataFrame, report: dict, remedy: str,
                                  clear_ghi: np.ndarray | None, *, whole_file: bool = True) -> None:
    """Refuse DNI of at most 1.5 while GHI shows a direct beam of `BEAM_SEEN` W/m² or more
    (`horizontal_beam`): kW/m² beside W/m² columns had been read as W/m², the file called clean,
    and a clear day replayed as overcast (the magnitude check judges DNI alone only without GHI
    and DHI). Without DHI a DNI of 0 all day is refused too (a dead pyrheliometer), on the
    `whole_file` only: DHI derived from it is GHI itself, and no closure check can see it."""
    if not {"ghi", "dni"} <= set(frame.columns):
        return
    beam = horizontal_beam(frame, clear_ghi)
    dni = frame["dni"].to_numpy(float)
    if beam is None or not (np.isfinite(dni).any() and np.isfinite(beam[0]).any()):
        return
    top, seen = float(np.nanmax(dni)), float(np.nanmax(beam[0]))
    lowest = 0.0 if "dhi" in frame or not whole_file else -np.inf
    if lowest < top <= KILOWATT_TOP and seen >= BEAM_SEEN:
        why = ("is the pyrheliometer dead or off the sun? remove the column from the file to derive DNI from GHI"
               if top <= 0.0 else f"the values look like kW/m² read as W/m²: {remedy.format(name='dni')}")
        line = first_lines(frame, np.arange(len(frame)) == int(np.nanargmax(beam[0]))) if "_line" in frame else []
        where = place(path, report, "dni", line)
        raise HybridtrackError(f"{where}: dni is at most {top:g} while {beam[1]} {seen:.0f} W/m² (a direct beam); "
                               f"{why}")


def check_derived(path: Path, frame: pd.DataFrame, name: str, report: dict) -> None:
    """Judge a component derived from the others (`hybridtrack.io.gapfill`) by `LIMITS` as a
    measured one is: most of its daylight values beyond them refuse the file, a few are set to NaN
    and counted as impossible. DHI derived from kW/m² DNI beside GHI had reached 1100 W/m²."""
    low, high = LIMITS[name]
    values = frame[name].to_numpy(float)
    bad = np.isfinite(values) & ((values < low) | (values > high))
    if not bad.any():
        return
    lit = int((bad | (values > DARKEST)).sum())
    line = first_lines(frame, bad)
    where = f"line {line[0]}, " if line else ""
    if bad.sum() > 0.5 * lit:
        raise HybridtrackError(f"{path}: {where}{name} derived from the other components is outside "
                               f"{low:g}..{high:g} W/m² in {bad.sum()} of {lit} daylight rows, first "
                               f"{values[bad][0]:.0f}; is a measured column in a wrong unit (kW/m²?) or its sensor "
                               "dead?")
    report.setdefault("impossible", {})[name] = {"count": int(bad.sum()), "lines": line,
                                                 "first": float(values[bad][0]), "action": "set to NaN (derived)"}
    frame[name] = np.where(bad, np.nan, values)


def refuse_repairs(path: Path, report: dict) -> None:
    """In strict mode, the first thing the checks would have repaired is an error."""
    for key, what in REPAIRS.items():
        if key not in report:
            continue
        entry = report[key]
        if "lines" in entry:
            raise HybridtrackError(f"{path}: line {entry['lines'][0]}: {what} (strict)")
        column, detail = next(iter(entry.items()))
        raise HybridtrackError(f"{place(path, report, column, detail.get('lines', []))}: {what} (strict)")
