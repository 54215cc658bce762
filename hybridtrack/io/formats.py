"""pvlib's weather formats: recognised by their content, read by `pvlib.iotools`, names mapped;
and the site lines of NSRDB and SAM CSV files, which are read as tables (`header_site`).

`detect_format` looks at a file's first lines: ``LOCATION,`` (EPW), a TMY3 station line
followed by ``Date (MM/DD/YYYY),Time (HH:MM)``, a TMY2 station line (WBAN, city, state, zone,
latitude and longitude in degrees and minutes), an SRML header (station, year, then element
numbers each followed by a 0 flag column, tab-separated), a SURFRAD station and coordinates block, or a
BSRN station-to-archive record (``*C0100`` ...). Anything else is read as a table, which covers
NREL MIDC's CSV (``DATE (MM/DD/YYYY),MST,...``) by its names.

Whatever pvlib returns, its columns are mapped to the frame's through the same alias table as
a CSV's (`columns.ALIASES`), plus pvlib's own names per format, with the format's units (TMY2
gives tenths of °C and m/s); a file from which no irradiance column can be mapped is refused,
so "clean" always means readable. Typical-year files (EPW, TMY3, TMY2) take one year, 2019,
since their months come from different years; an EPW whose stamps run forward through real years
(the year changing only at New Year, no 29 February skipped) is AMY data, or part of it, an hour
missing or not, and keeps its years, 29 February included. A typical-year EPW or
TMY2 file with a 29 February is refused naming its line: 2019 has none.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .columns import IRRADIANCE, WEATHER_COLUMNS, resolve_columns

__all__ = ["PVLIB_FORMATS", "TYPICAL_YEAR", "detect_format", "read_pvlib", "header_site", "one_typical_year"]

#: Formats read through pvlib.iotools.
PVLIB_FORMATS = {"epw": "read_epw", "tmy3": "read_tmy3", "tmy2": "read_tmy2", "midc": "read_midc",
                 "srml": "read_srml", "bsrn": "read_bsrn", "surfrad": "read_surfrad", "crn": "read_crn",
                 "solrad": "read_solrad"}
#: The formats `detect_format` recognises by their first lines (the others read as tables).
RECOGNISED_FORMATS = ("epw", "tmy3", "tmy2", "srml", "surfrad", "bsrn")
#: Typical-year formats: their months come from different years, so one year is coerced.
TYPICAL_YEAR_FORMATS = ("epw", "tmy3", "tmy2")
TYPICAL_YEAR = 2019  # any year that is not a leap year
#: The file line of the first data row, for messages: an EPW has eight header lines, a TMY2 one.
_FIRST_DATA_LINE = {"epw": 9, "tmy2": 2}

#: pvlib's names in each format that the alias table does not already know, and their scale.
PVLIB_NAMES = {
    "tmy2": {"GHI": ("ghi", 1.0), "DNI": ("dni", 1.0), "DHI": ("dhi", 1.0), "DryBulb": ("temp_air", 0.1),
             "Wspd": ("wind_speed", 0.1)},
    "midc": {},
}

_TMY2_FIRST = re.compile(r"^\s*\d{5}\s+\S.*\s+-?\d{1,2}\s+[NS]\s+\d+\s+\d+\s+[EW]\s+\d+\s+\d+\s+-?\d+\s*$")
_SRML_FIRST = re.compile(r"^\d{5}\t(19|20)\d{2}(\t\d{3,4}\t0)+\s*$")
_SURFRAD_SECOND = re.compile(r"^\s*-?\d+\.\d+\s+-?\d+\.\d+\s+\d+\s+m\s+version", re.I)


def detect_format(text: str) -> str:
    """``'epw'``, ``'tmy3'``, ``'tmy2'``, ``'srml'``, ``'surfrad'``, ``'bsrn'`` or ``'csv'``, from the first lines."""
    lines = text.lstrip("\ufeff").splitlines()[:3] + ["", ""]
    first, second = lines[0], lines[1]
    if first.upper().startswith("LOCATION,"):
        return "epw"
    if second.startswith("Date (MM/DD/YYYY),Time (HH:MM)"):
        return "tmy3"
    if _TMY2_FIRST.match(first):
        return "tmy2"
    if _SRML_FIRST.match(first):
        return "srml"
    if _SURFRAD_SECOND.match(second):
        return "surfrad"
    if re.match(r"^\*[CU]\d{4}", first):
        return "bsrn"
    return "csv"


def _call(path: Path, fmt: str, shown: Path | None = None):
    import pvlib

    reader = getattr(pvlib.iotools, PVLIB_FORMATS[fmt])
    options = {"coerce_year": TYPICAL_YEAR} if fmt == "tmy3" else {}
    try:
        result = reader(str(path), **options)
    except Exception as exc:  # pvlib raises many kinds; the user needs one line
        detail = str(exc).splitlines()[0] if str(exc) else ""
        raise HybridtrackError(f"{shown or path}: pvlib could not read it as {fmt.upper()}: {type(exc).__name__}: "
                               f"{detail}") from None
    data, meta = result if isinstance(result, tuple) else (result, {})
    return data, dict(meta) if isinstance(meta, Mapping) else {}


def _years_turn_at_new_year(naive: pd.DatetimeIndex) -> bool:
    """Whether the stamps' year changes, in the file's order, only from a December to the next
    January. A typical year's months come from different years, so its year changes between
    other months or goes back."""
    years, months = naive.year.to_numpy(), naive.month.to_numpy()
    new = np.flatnonzero(np.diff(years) != 0)
    return bool(((years[new + 1] == years[new] + 1) & (months[new] == 12) & (months[new + 1] == 1)).all())


def _real_years(index: pd.DatetimeIndex) -> bool:
    """Whether the stamps are real years (AMY data, or part of them, an hour missing or not): they
    run forward, their year turns only at New Year, and no 29 February of their span is missing
    (one written in a single leap year lacks it)."""
    naive = index.tz_localize(None)
    if len(naive) < 2 or not (np.diff(naive.as_unit("ns").asi8) > 0).all() or not _years_turn_at_new_year(naive):
        return False
    days = pd.date_range(naive[0].normalize(), naive[-1], freq="D")
    return bool(days[(days.month == 2) & (days.day == 29)].isin(naive.normalize()).all())


def one_typical_year(path: Path, index: pd.DatetimeIndex, lines: np.ndarray, report: dict) -> pd.DatetimeIndex:
    """Stamps from a table's year, month, day and hour columns in one year when their year changes
    between other months than December and January (a typical year's months from different years,
    as NSRDB's TMY files hold them), reported; they had been read as a decade with gaps."""
    if _years_turn_at_new_year(index.tz_localize(None)):
        return index
    report["time"] += f"; one year ({TYPICAL_YEAR}) for a typical-year file (its years change between months)"
    return _coerce_year(path, index, lines, "")


#: The numbers of an NSRDB or SAM CSV file's site lines: the name, its key in the site's
#: metadata, what it is, and the range it must lie in.
_SITE_NUMBERS = {"Latitude": ("latitude", "latitude", -90.0, 90.0),
                 "Longitude": ("longitude", "longitude", -180.0, 180.0),
                 "Elevation": ("altitude", "height in metres", -500.0, 9000.0),
                 "Time Zone": ("zone", "UTC offset in hours", -14.0, 14.0),
                 "Local Time Zone": ("local", "UTC offset in hours", -14.0, 14.0)}


def _site_number(path: Path, table, name: str) -> float | None:
    """A site line's number, None where it is empty or ``-``; refused naming its line and column
    where it is no number or out of its range."""
    text = table.site.get(name, "")
    if text in ("", "-"):
        return None
    _, what, low, high = _SITE_NUMBERS[name]
    try:
        value = float(text)
    except ValueError:
        value = np.nan
    if not low <= value <= high:
        raise HybridtrackError(f"{path}: line {table.site_line}, column {name!r}: {text!r} is not a {what} "
                               f"({low:g} to {high:g})")
    return value


def _offset(hours: float) -> str:
    """``-7`` -> ``'-07:00'``, ``5.5`` -> ``'+05:30'``."""
    minutes = round(abs(hours) * 60)
    return f"{'-' if hours < 0 else '+'}{minutes // 60:02d}:{minutes % 60:02d}"


def header_site(path: Path, table) -> dict:
    """An NSRDB or SAM CSV file's site lines (`tables.Table.site`) as the site's metadata
    (``latitude``, ``longitude``, ``altitude``, ``name``, and ``site_tz`` from ``Local Time Zone``
    in whole hours) and the stamps' zone, ``zone``: the UTC offset ``Time Zone`` gives (0 for a
    UTC download, else the site's standard time)."""
    numbers = {_SITE_NUMBERS[name][0]: _site_number(path, table, name) for name in _SITE_NUMBERS}
    meta = {key: value for key, value in numbers.items() if value is not None and key not in ("zone", "local")}
    if numbers["zone"] is not None:
        meta["zone"] = _offset(numbers["zone"])
    local = numbers["local"]
    if local is not None and local == int(local):
        meta["site_tz"] = "UTC" if local == 0 else f"Etc/GMT{-int(local):+d}"
    city, location = table.site.get("City", "-"), table.site.get("Location ID", "")
    meta["name"] = city if city not in ("", "-") else f"{table.site.get('Source', 'NSRDB')} {location}".strip()
    return meta


def _coerce_year(path: Path, index: pd.DatetimeIndex, lines: np.ndarray, why: str) -> pd.DatetimeIndex:
    """Typical-year stamps in one year, as pvlib does for TMY3; a 29 February is refused by its line."""
    naive = index.tz_localize(None)
    leap = np.flatnonzero((naive.month == 2) & (naive.day == 29))
    if len(leap):
        raise HybridtrackError(f"{path}: line {int(lines[leap[0]])}: 29 February in a typical-year file{why}, which "
                               f"is read in {TYPICAL_YEAR}, a year without one; remove that day")
    moved = pd.to_datetime({"year": TYPICAL_YEAR, "month": naive.month, "day": naive.day, "hour": naive.hour,
                            "minute": naive.minute})
    return pd.DatetimeIndex(moved).tz_localize(index.tz)


def _map(path: Path, fmt: str, data: pd.DataFrame, report: dict) -> pd.DataFrame:
    """The frame's columns from pvlib's: its own names, then the alias table (units in brackets)."""
    from .units import to_frame_units
    from .columns import split_header

    frame = pd.DataFrame(index=pd.DatetimeIndex(data.index))
    mapping, notes = {}, {}
    for header, (name, scale) in PVLIB_NAMES.get(fmt, {}).items():
        if header in data.columns and name not in mapping:
            frame[name] = pd.to_numeric(data[header], errors="coerce").to_numpy(float) * scale
            mapping[name] = header
            if scale != 1.0:
                notes[name] = f"{header} x {scale:g}"
    headers = [str(c) for c in data.columns if not str(c).lower().endswith(("flag", "_flag", "source", "uncert"))]
    headers = [re.sub(r"_\d+$", "", h) if fmt == "srml" else h for h in headers]  # SRML: ghi_0, dni_1 ...
    by_alias = resolve_columns(str(path), headers, {})
    originals = {re.sub(r"_\d+$", "", str(c)) if fmt == "srml" else str(c): c for c in data.columns}
    for name in WEATHER_COLUMNS:
        if name in mapping or name not in by_alias:
            continue
        header = by_alias[name]
        values = pd.to_numeric(data[originals[header]], errors="coerce").to_numpy(float)
        values, note = to_frame_units(values, name, split_header(header)[1], f"{path}: column {header!r}")
        frame[name] = values
        mapping[name] = header
        if note:
            notes[name] = note
    if not any(name in frame for name in IRRADIANCE):
        raise HybridtrackError(f"{path}: pvlib read it as {fmt.upper()}, but no irradiance column (ghi, dni, dhi) "
                               f"is among its columns: {', '.join(map(str, data.columns))}")
    report["columns"] = mapping
    if notes:
        report["units_converted"] = notes
    return frame


def _plain_copy(path: Path, text: str, folder: str) -> Path:
    """The decoded text in a UTF-8 file pvlib can open (for packed or UTF-16 sources)."""
    copy = Path(folder) / path.name.removesuffix(".gz").removesuffix(".zip")
    copy.write_text(text, encoding="utf-8")
    return copy


def read_pvlib(path: Path, fmt: str, tz: str | None, report: dict, text: str | None = None,
               encoding: str = "UTF-8") -> tuple[pd.DataFrame, dict]:
    """A pvlib format's data as a frame with the frame's names, and its metadata (site, zone).

    A packed, non-UTF-8 or NUL-padded file is handed to pvlib as a decoded copy (`text`).
    """
    import tempfile

    if fmt not in PVLIB_FORMATS:
        raise HybridtrackError(f"unknown format {fmt!r}; choose csv, {', '.join(PVLIB_FORMATS)}")
    if text is not None and (encoding != "UTF-8" or "padding" in report):
        with tempfile.TemporaryDirectory() as folder:
            data, meta = _call(_plain_copy(path, text, folder), fmt, shown=path)
    else:
        data, meta = _call(path, fmt)
    if len(data) == 0:
        raise HybridtrackError(f"{path}: pvlib read it as {fmt.upper()}, but it holds no rows")
    frame = _map(path, fmt, data, report)
    years = f", one year ({TYPICAL_YEAR}) for a typical-year file" if fmt in TYPICAL_YEAR_FORMATS else ""
    if fmt == "epw" and _real_years(frame.index):
        years = ", the file's own years (its stamps run forward in real years: AMY data)"
    elif fmt in _FIRST_DATA_LINE:
        why = " (its stamps do not run forward through real years)" if fmt == "epw" else ""
        frame.index = _coerce_year(path, frame.index, _FIRST_DATA_LINE[fmt] + np.arange(len(frame)), why)
    if frame.index.tz is None:
        if tz is None:
            raise HybridtrackError(f"{path}: the {fmt.upper()} stamps carry no time zone; give one (tz=..., --tz)")
        frame.index = frame.index.tz_localize(tz, ambiguous="infer", nonexistent="shift_forward")
    elif tz is not None:
        frame.index = frame.index.tz_convert(tz)
    report.update(format=fmt, time=f"from the {fmt.upper()} file ({frame.index.tz}){years}")
    frame["_line"] = np.arange(1, len(frame) + 1, dtype=float)
    return frame, meta
