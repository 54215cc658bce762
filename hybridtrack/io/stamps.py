"""Time stamps: text (or epoch seconds, or a date and a clock column) to a tz-aware index.

Decided for the whole column, never cell by cell:

* **Day, month or year first.** ``dd/mm/yyyy`` and ``mm/dd/yyyy`` (and, with two-digit years,
  ``yy/mm/dd``: ``21-06-15`` is 2021-06-15 or 2015-06-21) are told apart first by the rows that
  are a date in only some readings (a first number above 12 is no month, above 31 no day), then
  by how the dates run: read in the right order, neighbouring rows' dates move by days (or by
  more only at a gap in the record); read in a wrong one, a day's change moves a month or a year,
  or back. The reading whose dates move a month or more least often is taken. A column that no reading makes
  all dates is refused; so is one that more than one reading makes dates running as days do, and
  the user asked (``dayfirst=True``/``False``, ``--dayfirst``/``--monthfirst``, or four-digit
  years). Dotted dates (``05.06.2021``) are never month-first. Dates after their clock
  (``12:00 05/06/2021``) and six-digit dates (``210605``) are decided so too.
* **Epoch seconds**: a column of 9- or 10-digit numbers is seconds since 1970-01-01 UTC, and a
  column of 13-digit numbers milliseconds (as JavaScript, Grafana and InfluxDB write them).
* **Stamps without a date** (``12:00``) are refused: the date cannot be guessed.
* **The file's zone**: stamps with UTC offsets (``+08:00``, ``Z``, `` UTC``) keep them, or are
  converted to `tz`; naive stamps are in `tz`, or in the zone a clock column's name gives
  (``MST``, as NREL's MIDC files write), or else in the site's own zone, which the report
  says and the sun check tests. Without any of these, naive stamps are refused.
"""

from __future__ import annotations

import datetime as dt
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError, quoted_cut

__all__ = ["parse_stamps", "fixed_zone", "offset_in_name", "has_offset", "CLOCK_ZONES"]

#: Zones named by a clock column's header: US standard times (no daylight saving), as MIDC writes.
CLOCK_ZONES = {"mst": "-07:00", "pst": "-08:00", "cst": "-06:00", "est": "-05:00", "ast": "-04:00", "hst": "-10:00",
               "akst": "-09:00", "utc": "+00:00", "gmt": "+00:00"}

#: A day-and-month date, its year, and the clock after it (after a space, a T, or a comma, as
#: ``toLocaleString('en-GB')`` writes ``10/06/2021, 00:00:00``, or a dash, ``10/06/2021-00:00``:
#: such stamps had been read by pandas one at a time, 10-12 June as 6 October, November and December).
_DMY = re.compile(r"^(\d{1,2})([./-])(\d{1,2})\2(\d{4}|\d{2})(?=$|[ T,]|-\d)(.*)$")
#: A date after its clock (``12:00 05/06/2021``): pandas read such stamps one at a time,
#: month-first, and ``12:00 21-06-22`` as 21 June 2022, without a word.
#: (Both written as pyarrow's regular expressions read them, without look-ahead: Python's took seconds.)
_CLOCK_FIRST = r"^(\d{1,2}:\d{2}(?::\d{2}(?:\.\d+)?)?)[ ,]+(\d{1,2}[./-]\d{1,2}[./-]\d{2,4})$"
#: A date of six digits (``210622``: yymmdd, ddmmyy or mmddyy), alone or before its clock: pandas
#: read ``210622`` as 21 June 2022, day-first, without a word.
_SIX_DIGITS = r"^(\d{2})(\d{2})(\d{2})($|[ T].*)$"
#: A weekday's name before a date (``Thu 10/06/2021 00:00``, ``Thursday, 10.06.2021``): pandas read
#: such stamps one at a time, month-first where it could, 10 June as 6 October, dotted dates too.
_WEEKDAY = r"^(?:[Mm]on|[Tt]ue|[Ww]ed|[Tt]hu|[Ff]ri|[Ss]at|[Ss]un)[A-Za-z]*\.?,?\s+"
_CLOCK_ONLY = re.compile(r"^\d{1,2}:\d{2}(:\d{2}(\.\d+)?)?$")
_EPOCH = re.compile(r"^\d{9,10}(\.\d+)?$")
#: Epoch milliseconds (2001-09-09 to 2286): thirteen digits, refused as no time stamp before.
_EPOCH_MS = re.compile(r"^\d{13}$")
#: A UTC offset after a clock time: ``+08:00``, ``+0800``, ``Z``, and the hour alone (``+08``, as
#: PostgreSQL writes a timestamptz), which pandas reads as an offset too (and a traceback followed).
_OFFSET = re.compile(r"\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?\s*(?:[+-]\d{2}(?::?\d{2})?|Z)$")
#: An offset written after ``UTC`` or ``GMT`` (``UTC+8``, ``GMT+8``, ``UTC+08:00``), as loggers write
#: it: pandas reads ``UTC+8`` with the POSIX sign, 16 h off, and a traceback followed.
_NAMED_OFFSET = re.compile(r"\s*(?:UTC|GMT)\s*([+-])(\d{1,2})(?::?(\d{2}))?$")
#: The same in a column's name, anywhere in it, in any case (``Time UTC-5``, ``Date Time, GMT+08:00``).
_OFFSET_IN_NAME = re.compile(r"(?:UTC|GMT)\s*([+-])(\d{1,2})(?::?(\d{2}))?(?!\d)", re.I)
#: A zone's abbreviation in brackets after a numeric offset (``+0800 (CST)``, as ``date`` writes it).
_ZONE_NOTE = re.compile(r"([+-]\d{2}:?\d{2})\s*\([A-Za-z]{2,5}\)$")
#: A stamp written ``yyyymmddHH`` (hourly exports): ten digits, like epoch seconds of 2030-2033.
_COMPACT_HOURS = re.compile(r"^(?:19|20)\d{2}(?:0[1-9]|1[0-2])(?:0[1-9]|[12]\d|3[01])(?:[01]\d|2[0-3])$")
#: A stamp written ``yymmddHHMM`` (a logger's compact minutes): ten digits, read as epoch seconds
#: they had been 2001-2052 without a word (1306211200, Nanjing's 21 June 2013 at noon, as 24 May
#: 2011). A column of epoch seconds of `COMPACT_MINUTES_ROWS` rows is never all of this form at a
#: logger's steps (1, 2, 5, 10, 15, 30 min, 1 h, 1 day): its last two digits pass 59, or the two
#: before them 23, within eight rows (5-min steps add 3 to those two digits a row).
COMPACT_MINUTES_ROWS = 12
_COMPACT_MINUTES = re.compile(r"^\d{2}(?:0[1-9]|1[0-2])(?:0[1-9]|[12]\d|3[01])(?:[01]\d|2[0-3])[0-5]\d$")


def fixed_zone(offset: str) -> dt.timezone:
    """``'+08:00'`` or ``'+0800'`` -> a fixed-offset time zone."""
    sign = -1 if offset.startswith("-") else 1
    digits = offset[1:].replace(":", "")
    hours, minutes = int(digits[:2]), int(digits[2:4] or 0)
    if hours > 14 or minutes >= 60:
        raise HybridtrackError(f"UTC offset {offset!r} is not a real one (beyond ±14:00)")
    return dt.timezone(sign * dt.timedelta(hours=hours, minutes=minutes))


class _Column:
    """The stamps' text with where each came from, for messages."""

    def __init__(self, path: Path, header: str, text: pd.Series, lines: np.ndarray):
        self.path, self.header, self.text, self.lines = path, header, text.reset_index(drop=True), lines

    def refuse(self, row: int, problem: str):
        raise HybridtrackError(f"{self.path}: line {int(self.lines[row])}, column {self.header!r}: "
                               f"{shown(self.text.iloc[row])} {problem}")


#: The longest cell read as a time stamp: the longest form read (``Thursday, 10/06/2021 12:00:00.000000
#: +08:00 (CST)``) is about 50 characters. A corrupted cell of 200,000 digits had been handed to the
#: date parser, which took minutes over it, and then quoted whole in the message.
LONGEST_STAMP = 80


def shown(cell: str) -> str:
    """A cell as a message quotes it: a long one cut, with its length."""
    return quoted_cut(str(cell), LONGEST_STAMP)


#: The readings of an ``a/b/c`` date: which of its numbers (groups 0, 2 and 3 of `_DMY`) is the
#: day, the month and the year. Year-first is a reading only where every last number has two digits.
_READINGS = {"day-first": (0, 2, 3), "month-first": (2, 0, 3), "year-first": (3, 2, 0)}
#: Read in a wrong order, a date that moves on by one day moves by a month or a year (or back):
#: dates that run as days do move by less between neighbouring rows.
_WRONG_ORDER_MOVE = np.timedelta64(28, "D")


def _two_digit_year(year: str) -> int:
    value = int(year)
    return value if len(year) == 4 else value + (2000 if value < 70 else 1900)


def _either(words) -> str:
    """``'a'``, ``'a or b'``, ``'a, b or c'``."""
    words = list(words)
    return " or ".join(words) if len(words) < 3 else ", ".join(words[:-1]) + " or " + words[-1]


def _possible_readings(parts: pd.DataFrame, dayfirst: bool | None) -> list[str]:
    """The readings the written years and `dayfirst` leave: all the years allow, or the one a flag
    or the column's name gives (``--monthfirst`` is month-first, not year-first too: a one-day
    ``06/12/21`` file so flagged had still been refused as either)."""
    if dayfirst is not None:
        return ["day-first" if dayfirst else "month-first"]
    return list(_READINGS) if (parts[3].str.len() <= 2).all() else ["day-first", "month-first"]


def _dates_read(parts: pd.DataFrame, readings: list[str]) -> dict[str, np.ndarray]:
    """Each row's date in each of `readings`, NaT where it is none (computed once per distinct date)."""
    codes, _ = pd.factorize(parts[0] + "/" + parts[2] + "/" + parts[3])
    distinct = parts.iloc[np.unique(codes, return_index=True)[1]]
    dates = {}
    for reading in readings:
        day, month, year = (distinct[i] for i in _READINGS[reading])
        fields = pd.DataFrame({"year": year.map(_two_digit_year), "month": month.astype(int), "day": day.astype(int)})
        dates[reading] = pd.to_datetime(fields, errors="coerce").to_numpy()[codes]
    return dates


def _jumps(dates: np.ndarray) -> np.ndarray:
    """The rows whose date moves a month or more from the row before it."""
    return np.flatnonzero(np.abs(np.diff(dates)) >= _WRONG_ORDER_MOVE) + 1


def _refuse_mixed(column: _Column, valid: dict[str, np.ndarray], flagged: bool):
    """Refuse a column in which no reading makes every row a date, at the row where the last fails."""
    names = np.array(list(valid))
    allowed = np.stack(list(valid.values()), axis=1)  # rows x readings
    row = int(np.flatnonzero(~np.logical_and.accumulate(allowed, axis=0).any(axis=1))[0])
    if not allowed[row].any():
        column.refuse(row, f"is no date read {_either(names)}" + (" (as a flag or the column's name says)"
                                                                  if flagged else ""))
    disjoint = np.flatnonzero(~(allowed[:row] & allowed[row]).any(axis=1))
    other = (f"line {int(column.lines[disjoint[0]])} reads {_either(names[allowed[disjoint[0]]])}" if len(disjoint)
             else "no reading fits it and every line before it")
    column.refuse(row, f"reads {_either(names[allowed[row]])}, but {other}; the column mixes both")


def _refuse_undecided(column: _Column, fitting: list[str], dates: dict[str, np.ndarray]):
    """Refuse a column that two or more readings make dates running as days do."""
    if "year-first" not in fitting:
        ask = "give --dayfirst or --monthfirst (dayfirst=True/False)"
    else:
        ask = "write the years with four digits" + (", or give --dayfirst (dayfirst=True) if they are day-first"
                                                    if "day-first" in fitting else "")
    column.refuse(0, f"could be {_either(fitting)} ({_either(str(dates[r][0])[:10] for r in fitting)}), and no date "
                     f"in the column tells; {ask}")


def _date_reading(column: _Column, parts: pd.DataFrame, dayfirst: bool | None) -> tuple[str, str]:
    """The reading of the column's ``a/b/c`` dates (a key of `_READINGS`), and why (see the module's notes)."""
    readings = _possible_readings(parts, dayfirst)
    dates = _dates_read(parts, readings)
    valid = {reading: ~np.isnat(values) for reading, values in dates.items()}
    fitting = [reading for reading in readings if valid[reading].all()]
    if not fitting:
        _refuse_mixed(column, valid, dayfirst is not None)
    why = ["as a flag or the column's name says"] if dayfirst is not None else []
    why += [f"line {int(column.lines[np.argmin(valid[r])])} is no date {r}" for r in readings if r not in fitting]
    same = [r for i, r in enumerate(fitting) if any(np.array_equal(dates[r], dates[o]) for o in fitting[:i])]
    fitting = [reading for reading in fitting if reading not in same]
    why += [f"{reading} reads the same dates" for reading in same]
    if len(fitting) > 1 and "month-first" in fitting and (parts[1] == ".").all():
        fitting.remove("month-first")
        why.append("dotted dates")
    jumps = {reading: _jumps(dates[reading]) for reading in fitting} if len(fitting) > 1 else {}
    fewest = min(map(len, jumps.values()), default=0)
    if sum(len(rows) == fewest for rows in jumps.values()) == 1:  # a gap in the record moves the right one too
        why += [f"read {r}, line {int(column.lines[rows[0]])} moves a month or more" for r, rows in jumps.items()
                if len(rows) > fewest]
        fitting = [reading for reading, rows in jumps.items() if len(rows) == fewest]
        if fewest:
            why.append(f"read {fitting[0]}, only {fewest} line{'s' * (fewest > 1)} move{'s' * (fewest == 1)} a month "
                       "or more: a gap")
    if len(fitting) > 1:
        _refuse_undecided(column, fitting, dates)
    return fitting[0], f"{fitting[0]} ({'; '.join(why)})"


def _date_before_clock(text: pd.Series) -> pd.Series:
    """Dates written after their clock, or as six digits, rewritten as ``a-b-c clock``, and dates
    after a weekday's name without it, so that their order is decided for the whole column as any
    other's is."""
    if not text.str.match(f"(?:{_CLOCK_FIRST})|(?:{_SIX_DIGITS})|(?:{_WEEKDAY})").any():
        return text  # as nearly every file: a look costs a tenth of rewriting
    for pattern, written in ((_WEEKDAY, ""), (_CLOCK_FIRST, r"\2 \1"), (_SIX_DIGITS, r"\1-\2-\3\4")):
        text = text.str.replace(pattern, written, regex=True)
    return text


#: A day and month written with a year anywhere in a stamp (``@ 10/06/2021 12:00``), not at its start.
_LOOSE_DMY = r"(?:^|[^\d./-])\d{1,2}[./-]\d{1,2}[./-]\d{2,4}(?:[^\d./-]|$)"


def _refuse_undecided_form(column: _Column, text: pd.Series) -> None:
    """Refuse a column whose ``a/b/c`` dates are written in a form whose order is not decided for
    the whole column (`_DMY`): the parser would read them one at a time, month-first where it
    could (``Thu 10/06/2021`` had been 6 October), without a word."""
    loose = np.flatnonzero(text.str.contains(_LOOSE_DMY, regex=True).to_numpy())
    if len(loose):
        column.refuse(int(loose[0]), "writes its day and month in a form whose order cannot be decided for the "
                                     "whole column; write the stamps as yyyy-mm-dd HH:MM, or as dd/mm/yyyy HH:MM "
                                     "(or mm/dd/yyyy HH:MM)")


def _to_iso(column: _Column, dayfirst: bool | None, report: dict) -> pd.Series:
    """Dates in ``d/m/y``, ``m/d/y`` or ``yy/m/d`` form rewritten as ``yyyy-mm-dd``, decided for the whole column."""
    text = _date_before_clock(column.text)
    if not text.str.contains(r"^\d{1,2}[./-]\d{1,2}[./-]\d", regex=True).any():
        _refuse_undecided_form(column, text)
        return column.text  # year first (ISO) or another form the parser reads whole
    parts = text.str.extract(_DMY)
    matched = parts[0].notna().to_numpy()
    if not matched.any():
        _refuse_undecided_form(column, text)
        return column.text
    if not matched.all():
        column.refuse(int(np.flatnonzero(~matched)[0]), f"is not written like the column's other dates "
                                                        f"({column.text.iloc[int(np.flatnonzero(matched)[0])]!r})")
    reading, report["date_order"] = _date_reading(column, parts, dayfirst)
    day, month, year = (parts[i] for i in _READINGS[reading])
    clock = parts[4].str.replace(r"^(?:,\s*|-)", " ", regex=True)  # '10/06/2021-12:00' as a space
    return (year.map(_two_digit_year).astype(str) + "-" + month.str.zfill(2) + "-" + day.str.zfill(2) + clock).str.strip()


def _parse(column: _Column, text: pd.Series, utc: bool) -> pd.DatetimeIndex:
    for fmt in ("ISO8601", "mixed"):
        try:
            parsed = pd.to_datetime(text, utc=utc, format=fmt)
            break
        except (ValueError, TypeError, OverflowError) as exc:
            error = exc
    else:
        for row, value in enumerate(text):
            try:
                if pd.isna(pd.to_datetime(value, format="mixed", utc=utc)):
                    column.refuse(row, "is not a time stamp")
            except (ValueError, TypeError, OverflowError):
                column.refuse(row, "is not a time stamp")
        raise HybridtrackError(f"{column.path}: column {column.header!r}: the stamps cannot be read together "
                               f"({str(error).splitlines()[0]})")
    if parsed.isna().any():
        column.refuse(int(np.flatnonzero(parsed.isna().to_numpy())[0]), "is not a time stamp")
    index = pd.DatetimeIndex(parsed)
    years = np.asarray(index.year)
    odd = np.flatnonzero((years < 1900) | (years > 2200))
    if len(odd):  # '-0.5' or '1,5' parse as dates in year 0; no logger recorded then
        column.refuse(int(odd[0]), "is not a plausible time stamp (outside 1900-2200)")
    return index


def has_offset(stamps: pd.Series) -> pd.Series:
    """Whether each ISO 8601 stamp (text) ends in a UTC offset (``+08:00``, ``-0500``, ``Z``) after
    its time of day; a date alone (``2021-06-21``) has none."""
    return stamps.str.contains(_OFFSET)


def _epoch(column: _Column, report: dict, unit: str = "s") -> pd.DatetimeIndex:
    report["time"] = f"epoch {'milliseconds' if unit == 'ms' else 'seconds'} (since 1970-01-01 UTC)"
    values = column.text.astype("int64" if unit == "ms" else float)  # 13 digits: exact as integers
    return pd.DatetimeIndex(pd.to_datetime(values, unit=unit, utc=True))


def _with_offsets(column: _Column, index: pd.DatetimeIndex, text: pd.Series, has_offset: pd.Series, tz: str | None,
                  report: dict):
    if not has_offset.all():
        column.refuse(int(np.flatnonzero(~has_offset.to_numpy())[0]), "has no UTC offset, but other stamps in "
                                                                       "the column have one")
    endings = pd.Series(text.str.slice(-6).unique())  # a few distinct endings, however long the file
    offsets = endings.str.extract(r"([+-]\d{2}(?::?\d{2})?|Z)$")[0].str.replace("Z", "+00:00")
    if tz is not None:
        report["time"] = f"stamps with UTC offsets, converted to {tz}"
        return index.tz_convert(tz)
    if offsets.nunique() == 1:
        try:
            zone = fixed_zone(offsets.iloc[0])
        except HybridtrackError as exc:
            column.refuse(0, str(exc))
        report["time"] = f"stamps with UTC offset {offsets.iloc[0]}, kept"
        return index.tz_convert(zone)
    report["time"] = f"stamps with {offsets.nunique()} different UTC offsets, kept as UTC (give a time zone to convert)"
    return index


def _localise(column: _Column, index: pd.DatetimeIndex, tz, how: str, report: dict):
    try:
        local = index.tz_localize(tz, ambiguous="infer", nonexistent="NaT")
        resolved = "repeated DST stamps resolved by their order"
    except (ValueError, TypeError):  # the order cannot tell the repeated hour apart
        local = index.tz_localize(tz, ambiguous="NaT", nonexistent="NaT")
        resolved = "ambiguous DST stamps dropped (their order did not resolve them)"
    keep = ~np.asarray(local.isna())
    report["time"] = how
    dropped = np.flatnonzero(~keep)
    if len(dropped):
        report["dst_dropped"] = {"count": int(len(dropped)), "lines": [int(v) for v in column.lines[dropped][:5]],
                                 "why": "stamps that do not exist in the time zone (spring-forward gap) "
                                        "or could not be resolved"}
    ambiguous = int(index.tz_localize(tz, ambiguous="NaT", nonexistent="shift_forward").isna().sum())
    if ambiguous:
        report["dst_repeated"] = {"count": ambiguous, "resolution": resolved}
    return local, keep


def parse_stamps(path: Path, header: str, text: pd.Series, lines: np.ndarray, *, tz: str | None,
                 site_tz: str | None = None, clock_zone: str | None = None, dayfirst: bool | None = None,
                 report: dict,
                 zone_from: str = "the time or clock column's name") -> tuple[pd.DatetimeIndex, np.ndarray]:
    """The column's stamps as a tz-aware index, and which rows to keep (DST gaps dropped).

    Parameters
    ----------
    path, header, lines
        For messages: the file, the column (or ``'date + time'``) and each row's file line.
    text : pandas.Series of str
        The stamps as written.
    tz : str, optional
        The file's time zone: naive stamps are in it, stamps with offsets are converted to it.
    site_tz : str, optional
        The site's zone, taken for naive stamps when nothing else says (and reported so).
    clock_zone : str, optional
        A UTC offset named by the time or clock column's header (``'-07:00'`` for ``MST``,
        ``'+00:00'`` for ``time_utc``), or by what `zone_from` says (an NSRDB file's ``Time Zone``).
    dayfirst : bool, optional
        Whether ``a/b/yyyy`` dates are day-first; None decides from the column.
    report : dict
        The validation report, which gets ``time`` (and ``date_order``, ``dst_*``).
    zone_from : str
        What gives `clock_zone`, for the report.
    """
    column = _Column(path, header, text.astype(str).str.strip(), lines)
    cut = _cut_short_last(column, report)
    index, keep = _read_stamps(column, tz, site_tz, clock_zone, dayfirst, report, zone_from)
    if cut:
        keep = keep.copy()
        keep[-1] = False
    return index, keep


def _cut_short_last(column: _Column, report: dict) -> bool:
    """Whether the last stamp is cut short (a logger's power lost mid-line): written in another
    shape than every stamp before it, which all share one. It is then read as the one before it
    and dropped, and the report says so: ``2021-06-2`` had been read as 2 June, and the replay
    started 19 days early."""
    text = column.text
    if len(text) < 3:
        return False
    shapes = text.str.replace(r"\d", "0", regex=True)
    if shapes.iloc[:-1].nunique() != 1 or shapes.iloc[-1] == shapes.iloc[0] or \
            len(text.iloc[-1]) >= len(text.iloc[0]):
        return False
    report["truncated"] = {"count": 1, "lines": [int(column.lines[-1])],
                           "why": f"the last line is cut short (its stamp {text.iloc[-1]!r})"}
    column.text = text.copy()
    column.text.iloc[-1] = text.iloc[-2]
    return True


def _iso_offset(match: re.Match) -> str:
    return f"{match[1]}{int(match[2]):02d}:{match[3] or '00'}"


def offset_in_name(name: str) -> str | None:
    """The ISO UTC offset a column's name writes after ``UTC`` or ``GMT`` (``'Time UTC-5'`` ->
    ``'-05:00'``, ``'Date Time, GMT+08:00'`` -> ``'+08:00'``, east of Greenwich plus as the stamps'
    own are read), or None."""
    match = _OFFSET_IN_NAME.search(name)
    return _iso_offset(match) if match else None


def _written_offsets(iso: pd.Series, report: dict) -> pd.Series:
    """Offsets written ``UTC``, ``UTC+8``, ``GMT+8``, ``UTC+08:00`` or ``+0800 (CST)`` as ISO
    offsets (``+00:00``, ``+08:00``, ``+0800``), with the ISO sign: east of Greenwich is plus, as a
    logger means it. The report says how they were read (``offset_written``)."""
    tails = [tail for tail in iso.str.slice(-16).unique()  # a few distinct endings, however long the file
             if ")" in tail or "UTC" in tail or "GMT" in tail]
    noted = next(filter(None, map(_ZONE_NOTE.search, tails)), None)
    if noted is not None:
        report["offset_written"] = f"{noted[0]!r}: the zone's name ignored, the offset kept"
        iso = iso.str.replace(_ZONE_NOTE, r"\1", regex=True)
    if any(tail.endswith(("UTC", "GMT")) for tail in tails):
        iso = iso.str.replace(r"\s*(UTC|GMT)$", "+00:00", regex=True)
    named = next(filter(None, map(_NAMED_OFFSET.search, tails)), None)
    if named is not None:
        report["offset_written"] = (f"{named[0].strip()!r} read as UTC{_iso_offset(named)} (east of Greenwich is "
                                    "plus, as in ISO 8601; POSIX zone strings invert the sign)")
        iso = iso.str.replace(_NAMED_OFFSET, _iso_offset, regex=True)
    return iso


def _end_of_day(iso: pd.Series) -> tuple[pd.Series, np.ndarray]:
    """Stamps of ``24:00`` (the end of a day, as many European hourly files close it) as ``00:00``,
    and which they were, to be moved to the next day: they had been refused as no time stamp."""
    midnight = iso.str.contains(r"[ T]24:00(?::00)?$", regex=True).to_numpy()
    if not midnight.any():
        return iso, midnight
    return iso.str.replace(r"([ T])24:00((?::00)?)$", r"\g<1>00:00\g<2>", regex=True), midnight


def _refuse_twelve_hour_clock(column: _Column, index: pd.DatetimeIndex) -> None:
    """Refuse stamps of a 12-hour clock written without AM or PM (``6/21/2021 1:00:00`` for both
    1 AM and 1 PM): every hour is 1 to 12, and the clock goes back from 12 to 1 within a date,
    which a 24-hour clock never does. Read as a 24-hour clock, each afternoon had been dropped as
    repeated stamps, the night's first hour read as noon, and the file called usable."""
    hours = np.asarray(index.hour)
    if len(hours) < 2 or not ((hours >= 1) & (hours <= 12)).all():
        return
    days = np.asarray(index.normalize().asi8)
    back = np.flatnonzero((hours[:-1] == 12) & (hours[1:] == 1) & (days[:-1] == days[1:]))
    if len(back):
        column.refuse(int(back[0]) + 1, "goes back from 12 to 1 o'clock within a date, and no stamp is before 1:00 "
                                        "or after 12:59: a 12-hour clock without AM or PM? write the stamps with "
                                        "AM/PM, or on a 24-hour clock")


def _read_stamps(column: _Column, tz, site_tz, clock_zone, dayfirst, report: dict, zone_from: str):
    """`parse_stamps` on a column whose stamps are whole."""
    path, header, lines = column.path, column.header, column.lines
    empty = np.flatnonzero((column.text == "").to_numpy())
    if len(empty):
        column.refuse(int(empty[0]), "is an empty time stamp")
    long = np.flatnonzero((column.text.str.len() > LONGEST_STAMP).to_numpy())
    if len(long):  # before any parser sees it: dateutil's takes minutes over a long cell
        column.refuse(int(long[0]), f"is not a time stamp (longer than {LONGEST_STAMP} characters)")
    if column.text.str.fullmatch(_COMPACT_HOURS).all():
        report["date_order"] = "written yyyymmddHH"
        column.text = column.text.str.replace(r"^(\d{4})(\d{2})(\d{2})(\d{2})$", r"\1-\2-\3 \4:00", regex=True)
    elif len(column.text) >= COMPACT_MINUTES_ROWS and column.text.str.fullmatch(_COMPACT_MINUTES).all():
        report["date_order"] = "written yymmddHHMM (20yy)"
        column.text = column.text.str.replace(r"^(\d{2})(\d{2})(\d{2})(\d{2})(\d{2})$", r"20\1-\2-\3 \4:\5",
                                              regex=True)
    for pattern, unit in ((_EPOCH, "s"), (_EPOCH_MS, "ms")):
        if column.text.str.fullmatch(pattern).all():
            index = _epoch(column, report, unit)
            return (index.tz_convert(tz) if tz else index), np.ones(len(index), bool)
    clock_only = np.flatnonzero(column.text.str.fullmatch(_CLOCK_ONLY).to_numpy())
    if len(clock_only):
        column.refuse(int(clock_only[0]), "has no date; stamps need the date (add a date column, or write "
                                          "'2021-06-21 12:00')")
    iso = _written_offsets(_to_iso(column, dayfirst, report), report)
    with_offset = has_offset(iso)
    iso, midnight = _end_of_day(iso)
    index = _parse(column, iso, utc=bool(with_offset.any()))
    if index.tz is not None and not with_offset.any():  # a zone pandas reads and hybridtrack does not
        column.refuse(0, "ends in a time zone hybridtrack does not read; write its UTC offset (+08:00), or "
                         "remove it and give the zone (--tz)")
    if midnight.any():
        index = index + pd.to_timedelta(midnight.astype(int), unit="D")
        at = np.flatnonzero(midnight)
        lines_at = ", ".join(str(int(v)) for v in column.lines[at[:5]]) + (", ..." if len(at) > 5 else "")
        report["end_of_day"] = (f"{len(at)} stamp{'s' if len(at) > 1 else ''} of 24:00 read as 00:00 of the next day "
                                f"(line{'s' if len(at) > 1 else ''} {lines_at})")
    _refuse_twelve_hour_clock(column, index)
    if with_offset.any():
        return _with_offsets(column, index, iso, with_offset, tz, report), np.ones(len(index), bool)
    if tz is not None:
        return _localise(column, index, tz, f"naive stamps localised to {tz}", report)
    if clock_zone is not None:
        try:
            zone = fixed_zone(clock_zone)
        except HybridtrackError as exc:  # 'Time UTC+15': named by the file and column
            raise HybridtrackError(f"{path}: column {header!r}: {exc}, as {zone_from} says") from None
        report["time"] = f"naive stamps in UTC{clock_zone}, as {zone_from} says"
        return index.tz_localize(zone), np.ones(len(index), bool)
    if site_tz is not None:
        return _localise(column, index, site_tz, f"naive stamps read as the site's local time ({site_tz}); give "
                                                 "the file's zone if it is another (--tz)", report)
    raise HybridtrackError(f"{path}: line {int(lines[0])}, column {header!r}: naive time stamps (no UTC offset, e.g. "
                           f"{column.text.iloc[0]!r}); give the time zone they were logged in (tz=..., --tz "
                           "Asia/Shanghai), or a site")
