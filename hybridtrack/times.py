"""Parsing user dates and building local clock ranges, with clear errors."""

from __future__ import annotations

import datetime as dt
import re

import pandas as pd

from . import params
from .budget import check_steps
from .errors import HybridtrackError

__all__ = ["parse_date", "check_dates", "FIRST_DATE", "LAST_DATE", "parse_clock", "parse_freq", "local_range",
           "local_midnight", "check_tz", "clock_hours", "clock_nanoseconds", "calendar_days", "day_of_year",
           "plus_seconds", "stamp_minutes", "local_steps", "HOUR_NS", "DAY_NS"]


def clock_nanoseconds(local: pd.DatetimeIndex):
    """What the clock shows at each time, as integer nanoseconds since 1970-01-01 00:00 on that clock."""
    import numpy as np

    wall = local.tz_localize(None) if local.tz is not None else local
    return np.asarray(wall.as_unit("ns").asi8)


#: Minutes a stamp stands for at most (`stamp_minutes`): a run's longest step, an hour.
LONGEST_STAMP_MINUTES = 60.0
#: Steps either side of a step whose median is its local step (`stamp_minutes`).
LOCAL_STEPS = 4
#: A step longer than this many local steps is a gap that counts no time (`stamp_minutes`): a
#: reading or two missed is integrated across, as the trapezoid rule does, and a logger's jitter
#: (±20 s on 1-minute stamps makes steps of 20 to 100 s) is never a gap.
GAP_STEPS = 2.5


def stamp_minutes(index: pd.DatetimeIndex):
    """Minutes each stamp of `index` stands for: half of each step beside it (the midpoint rule,
    so jittered stamps lose no time: the halves add up to the span), at most
    `LONGEST_STAMP_MINUTES`. A step that is a gap (longer than `GAP_STEPS` times the median of the
    `LOCAL_STEPS` steps either side of it) counts no time: a stamp beside one takes its other step
    whole, as an end stamp does, and a stamp between two the local step.

    So a stamp alone in a 3-hour gap of a 1-minute frame is a minute; a frame of mixed steps (a
    15-minute day beside a 1-minute day) weighs each stamp by its own steps, where the frame's
    median step had made the 15-minute day count a fifteenth of its light; two stamps 1 ns apart
    share one step. On a regular grid every stamp stands for the step, exactly; a lone stamp
    for a minute.
    """
    import numpy as np

    ns = np.asarray(index.as_unit("ns").asi8)
    if len(ns) < 2:
        return np.ones(len(ns))
    steps = np.diff(ns) / 6e10
    if steps.min() == steps.max():  # a regular grid, the common case, at a field's every collector
        return np.full(len(ns), min(steps[0], LONGEST_STAMP_MINUTES))
    local = local_steps(steps, GAP_STEPS)
    counted = np.where(steps > GAP_STEPS * local, np.nan, steps)
    before, after = np.concatenate(([np.nan], counted)), np.concatenate((counted, [np.nan]))
    halves = np.where(np.isnan(before), after, np.where(np.isnan(after), before, 0.5 * (before + after)))
    alone = np.fmin(np.concatenate(([np.nan], local)), np.concatenate((local, [np.nan])))
    return np.minimum(np.where(np.isnan(halves), alone, halves), LONGEST_STAMP_MINUTES)


def local_steps(steps, gap: float):
    """The median of the `LOCAL_STEPS` steps either side of (and with) each of `steps` that may be
    a gap, longer than `gap` times the shortest; NaN for the rest, which cannot be. A step is a gap
    where it is longer than `gap` times its local step: a regular grid has none to judge, and a
    day-only logger's year a few hundred nights, not 525,600 medians; a 15-minute day beside a
    1-minute day is no gap at each step, as it is against the frame's median step."""
    import numpy as np

    steps = np.asarray(steps, float)
    local = np.full(len(steps), np.nan)
    if not len(steps):
        return local
    maybe = np.flatnonzero(steps > gap * steps.min())
    if len(maybe):
        padded = np.concatenate((np.full(LOCAL_STEPS, np.nan), steps, np.full(LOCAL_STEPS, np.nan)))
        windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * LOCAL_STEPS + 1)[maybe]
        local[maybe] = np.nanmedian(windows, axis=1)
    return local


def plus_seconds(times: pd.DatetimeIndex, seconds) -> pd.DatetimeIndex:
    """`times` plus `seconds` (finite floats within ±9e9, one per time; a single time takes them
    all), in nanoseconds.

    ``times + pd.to_timedelta(seconds, unit="s")`` to the nanosecond, at a seventh of its cost
    (17 ms for a year of minutes): the seconds are cast as pandas casts them (whole seconds, then
    the fraction rounded to 9 digits and truncated to nanoseconds). A NaN second gives NaT.
    """
    import numpy as np

    seconds = np.asarray(seconds, float)
    finite = np.isfinite(seconds)
    if np.any(np.abs(seconds[finite]) > 9e9):
        raise HybridtrackError(f"a time shift of {np.max(np.abs(seconds[finite])):.3g} s is beyond ±9e9 s")
    whole = np.trunc(np.where(finite, seconds, 0.0))
    fraction = np.round(np.where(finite, seconds, 0.0) - whole, 9)
    shift = whole.astype(np.int64) * 1_000_000_000 + (fraction * 1e9).astype(np.int64)
    stamps = times.as_unit("ns")
    nanoseconds = np.where(finite & ~np.asarray(stamps.isna()), stamps.asi8 + shift, np.iinfo(np.int64).min)
    return pd.DatetimeIndex(nanoseconds, dtype=stamps.dtype, name=times.name)


def clock_hours(local: pd.DatetimeIndex):
    """What the local clock reads, in hours (13:30 -> 13.5).

    Not the time since midnight: on a DST day the two differ by the hour the clock skipped
    or repeated.
    """
    import numpy as np

    hours = (clock_nanoseconds(local) % DAY_NS) / 3.6e12
    return np.where(np.asarray(local.isna()), np.nan, hours)


def calendar_days(local: pd.DatetimeIndex):
    """The local calendar's day of year (1 on 1 January) and year at each time, as floats.

    Integer arithmetic on the clock's reading: the same as ``local.day_of_year`` and
    ``local.year`` at a fraction of pandas' cost for each field.
    """
    return day_of_year(clock_nanoseconds(local) // DAY_NS)


def day_of_year(day_number):
    """Day of year (1 on 1 January) and year, as floats, of days counted from 1970-01-01 (day 0)."""
    import numpy as np

    days = np.asarray(day_number, np.int64).astype("datetime64[D]")
    years = days.astype("datetime64[Y]")
    return ((days - years.astype("datetime64[D]")).astype(np.int64) + 1).astype(float), \
        years.astype(np.int64).astype(float) + 1970.0


#: Nanoseconds in an hour and in a day of the clock.
HOUR_NS, DAY_NS = 3_600_000_000_000, 86_400_000_000_000


def check_tz(tz: str, where: str = "") -> str:
    """Return `tz` if it is an IANA time-zone name, else raise `HybridtrackError`."""
    import zoneinfo

    try:
        zoneinfo.ZoneInfo(str(tz))
    except (zoneinfo.ZoneInfoNotFoundError, ValueError, TypeError):
        raise HybridtrackError(f"{where}unknown time zone {tz!r} (use an IANA name such as 'Asia/Shanghai')") from None
    return str(tz)


#: The first and last dates a run may cover: whole years inside pandas' nanosecond timestamps
#: (1677-09-21 to 2262-04-11), which leaves any time zone room.
FIRST_DATE, LAST_DATE = dt.date(1678, 1, 1), dt.date(2261, 12, 31)


#: A date as the command line and configs write it: ``YYYY-MM-DD``.
_ISO_DATE = re.compile(r"\d{4}-\d{2}-\d{2}", re.ASCII)
#: A clock time as they write it: ``HH:MM`` or ``HH:MM:SS``.
_CLOCK = re.compile(r"\d{2}:\d{2}(:\d{2})?", re.ASCII)


def parse_date(text) -> dt.date:
    """Parse ``YYYY-MM-DD`` (or pass a date through), refusing dates that do not exist or that a
    run cannot cover (`FIRST_DATE` to `LAST_DATE`)."""
    if isinstance(text, dt.datetime):
        day = text.date()
    elif isinstance(text, dt.date):
        day = text
    else:
        day = _as_written(str(text).strip(), _ISO_DATE, dt.date.fromisoformat)
        if day is None:
            raise HybridtrackError(f"date {text!r} does not exist or is not YYYY-MM-DD")
    check_dates(day, day, f"date {text!r}" if isinstance(text, str) else f"date {day}")
    return day


def check_dates(first: dt.date, last: dt.date, what: str) -> None:
    """Refuse a span that reaches outside `FIRST_DATE` to `LAST_DATE`, naming `what` it is."""
    if first < FIRST_DATE or last > LAST_DATE:
        raise HybridtrackError(f"{what} is outside the dates a run can cover, {FIRST_DATE} to {LAST_DATE} "
                               "(pandas' nanosecond timestamps)")


def parse_clock(text: str) -> dt.time:
    """Parse a local clock time ``HH:MM`` (or ``HH:MM:SS``); ``24:00`` means the day's end."""
    value = str(text).strip()
    if value in ("24:00", "24:00:00"):
        return dt.time.max
    clock = _as_written(value, _CLOCK, dt.time.fromisoformat)
    if clock is None:
        raise HybridtrackError(f"clock time {text!r} is not HH:MM")
    return clock


def _as_written(value: str, form: re.Pattern, parse):
    """``parse(value)`` where `value` is in the written `form`, else None: ``fromisoformat`` alone
    also takes 20210621, the week date 2021W251, 1200 and 12:00+08:00 (a time in another zone),
    which no message offers."""
    if not form.fullmatch(value):
        return None
    try:
        return parse(value)
    except ValueError:  # the form, but no such day or time (2021-02-30, 25:00)
        return None


def parse_freq(text: str) -> pd.Timedelta:
    """Parse a positive step such as ``1min``, ``10s`` or ``1h``; a bare number is refused."""
    params.refuse_unitless(text, "step")
    try:
        step = params.timedelta(str(text))
    except ValueError:
        raise HybridtrackError(f"step {text!r} is not a duration such as '1min' or '10s'") from None
    if pd.isna(step):
        raise HybridtrackError(f"step {text!r} is not a duration such as '1min' or '10s'")
    if step <= pd.Timedelta(0):
        raise HybridtrackError(f"step {text!r} must be positive")
    return step


def _localise(day: dt.date, clock: dt.time, tz: str) -> pd.Timestamp:
    stamp = pd.Timestamp(dt.datetime.combine(day, clock))
    # a clock time skipped or repeated by a DST change maps to the first valid instant
    return stamp.tz_localize(tz, nonexistent="shift_forward", ambiguous=True)


def local_midnight(day: dt.date, tz: str) -> pd.Timestamp:
    """The instant `day` begins on the local clock of `tz` (a midnight a DST change skips: the
    first instant after it)."""
    return _localise(day, dt.time(0), tz)


def local_range(start_date, tz: str, *, end_date=None, start: str = "00:00", end: str | None = None,
                freq: str = "1min") -> pd.DatetimeIndex:
    """Stamps on the local clock of `tz` from `start` on `start_date` up to `end` on `end_date`.

    With no `end`, the range runs to the end of `end_date` (exclusive of the next midnight);
    `end_date` defaults to `start_date`. Steps are equal in absolute time, so a DST change
    shows as a jump of the local clock, never as a repeated or missing stamp.
    """
    first_day = parse_date(start_date)
    last_day = parse_date(end_date) if end_date is not None else first_day
    step = parse_freq(freq)
    if last_day < first_day:  # had been told its last day did not exist on the zone's clock (Apia's case below)
        raise HybridtrackError(f"the range ends on {last_day}, before it starts on {first_day}")
    t0 = _localise(first_day, parse_clock(start), tz)
    if end is None:
        t1 = _localise(last_day + dt.timedelta(days=1), dt.time(0), tz) - pd.Timedelta(1, "ns")
    else:
        t1 = _localise(last_day, parse_clock(end), tz)
    if t1 < t0 and t0.date() > last_day:  # Apia skipped 2011-12-30 crossing the date line
        raise HybridtrackError(f"{last_day} does not exist on the local clock of {tz}: the zone skipped that day; "
                               "choose another date")
    if t1 < t0:
        raise HybridtrackError(f"the range ends ({t1}) before it starts ({t0})")
    check_steps(t0, t1, step, what=f"{first_day} to {last_day}")
    return pd.date_range(t0, t1, freq=step)
