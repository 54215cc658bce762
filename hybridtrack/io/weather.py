"""`read_weather`: a recorded weather file to a checked weather frame, every change counted.

The steps, each in its own module: the file's bytes and encoding (`files`), the table and its
header (`tables`) or a pvlib format (`formats`), the columns (`columns`) and their units
(`units`), the stamps (`stamps`), the checks (`checks`), the sun check (`suncheck`), the
missing components (`gapfill`) and the step (`resample`). docs/records.md says what each accepts.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .checks import (check_frame, check_magnitude, check_magnitude_by_day, clip_offsets, first_lines, refuse_repairs,
                     site_clear_sky, span)
from .closure import closure_check
from .columns import (IRRADIANCE, LABEL_COLUMN, LONGEST_NAME, STAMP_PARTS, WEATHER_COLUMNS, check_names, label_header,
                      name_shown, not_read, resolve_columns, split_header)
from .files import file_text
from .formats import PVLIB_FORMATS, RECOGNISED_FORMATS, detect_format, header_site, one_typical_year, read_pvlib
from .gapfill import fill_components
from .resample import logger_step, native_step, resample
from .stamps import CLOCK_ZONES, offset_in_name, parse_stamps
from .suncheck import meta_name
from .tables import COMMA_GROUPED, MISSING, UNITS_ROW_ZONE, Table, locate_table
from .units import looks_like_unit, spellings, to_frame_units

__all__ = ["read_weather"]

_SEPARATOR_NAMES = {",": "comma", ";": "semicolon", "\t": "tab", "|": "bar"}


#: A number whose thousands are grouped with dots beside a decimal comma: ``1.073,3``, ``12.000``.
_GROUPED = re.compile(r"[-+]?\d{1,3}(\.\d{3})+(,\d*)?")


def _numbers(path: Path, table: Table, header: str, column: list[str], decimal: str, strict: bool,
             report: dict, name: str) -> np.ndarray:
    """A column's text as floats; a few unreadable cells become NaN (counted), many are refused."""
    values = _read_numbers(path, table, header, column, decimal, strict, report, name)
    return _thousands_by_dots(column, values, name, report) if decimal == "." and name in IRRADIANCE else values


#: The longest cell read as a number (a double's digits, a sign, an exponent and room to spare):
#: a corrupted cell of 140,000 digits had been read as infinity.
LONGEST_NUMBER = 64


def _shown(cell: str) -> str:
    """A cell as a message quotes it: a long one cut, with its length."""
    return repr(cell) if len(cell) <= LONGEST_NUMBER else f"{cell[:20]!r}... ({len(cell):,} characters)"


def _read_numbers(path: Path, table: Table, header: str, column: list[str], decimal: str, strict: bool,
                  report: dict, name: str) -> np.ndarray:
    if decimal == "." and max(map(len, column), default=0) <= LONGEST_NUMBER:
        try:  # the common case, fast: every cell a number ('nan', 'inf' and '1e400' included)
            return np.array(column, dtype=float)
        except ValueError:
            pass
    strings = pd.Series(column, dtype=str).str.strip()
    missing = strings.str.lower().isin(MISSING)
    if decimal == ".":
        strings = _thousands_by_commas(strings, name, report)
    if decimal == ",":
        grouped = strings.str.fullmatch(_GROUPED)
        if grouped.any():  # '1.073,3': with a decimal comma, a dot can only group thousands
            strings = strings.where(~grouped, strings.str.replace(".", "", regex=False))
            report["thousands"] = "'.' (with the decimal comma)"
        strings = strings.str.replace(",", ".", regex=False)
    values = pd.to_numeric(strings.where(~missing & (strings.str.len() <= LONGEST_NUMBER)), errors="coerce")
    bad = (values.isna() & ~missing).to_numpy()
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        where = f"{path}: line {table.lines[row]}, column {header!r}: {_shown(column[row])} is not a number"
        filled = int((~missing).sum())
        if strict or bad.sum() * 2 >= max(filled, 1):
            raise HybridtrackError(where if strict else f"{where} (nor are {bad.sum()} of its {filled} values)")
        report.setdefault("unreadable", {})[name] = {"count": int(bad.sum()),
                                                     "lines": [int(v) for v in table.lines[bad][:5]],
                                                     "first": _shown(column[row]), "action": "set to NaN"}
    return values.to_numpy(float)


def _thousands_by_commas(strings: pd.Series, name: str, report: dict) -> pd.Series:
    """A dot-decimal column's cells with thousands grouped by commas (US Excel's quoted
    ``"1,060.2"``) without their commas, counted: every value of 1000 or more had been unreadable
    text, a clear noon set to NaN. A column with any other comma (``0,5``) is left as it is."""
    commas = strings.str.contains(",", regex=False)
    if not commas.any():
        return strings
    grouped = strings.str.fullmatch(COMMA_GROUPED)
    if not grouped[commas].all():
        return strings
    _count_thousands(report, name, int(grouped.sum()), "','", "with the decimal point")
    return strings.str.replace(",", "", regex=False)


#: Irradiance (W/m²) a logger writes whole that shows the sun well up: a column whose other
#: values are whole reaches it before its values pass 1000 W/m².
WHOLE_BRIGHT = 500.0
#: A cell whose dot groups thousands, a dot-decimal file's reading: ``1.063``, ``1.000``.
_DOT_GROUPED = re.compile(r"\+?\d{1,3}(\.\d{3})+")


def _thousands_by_dots(column: list[str], values: np.ndarray, name: str, report: dict) -> np.ndarray:
    """An irradiance column written whole with its thousands grouped by dots (German Excel's
    ``1.063`` beside ``998``), read as the thousands it means; any other column as it is.

    With no decimal comma in the file, such a dot cannot be told from a decimal point by itself;
    the column tells: values written without a dot reach `WHOLE_BRIGHT` W/m² (the sun well up,
    so 1,000 W/m² is a noon's reading), and every value written with a dot looks grouped
    (``d.ddd``). A column of decimals (``850.2``, ``850.000``, kW/m²'s ``0.850``) is left."""
    dotted = np.fromiter(("." in cell for cell in column), bool, len(column))
    if not dotted.any() or not (values[~dotted] >= WHOLE_BRIGHT).any():
        return values
    rows = np.flatnonzero(dotted)
    text = [column[i].strip() for i in rows]
    if not all(_DOT_GROUPED.fullmatch(cell) for cell in text):
        return values
    values = values.copy()
    values[rows] = [float(cell.replace(".", "")) for cell in text]
    _count_thousands(report, name, len(rows), "'.'", "every other value whole")
    return values


def _count_thousands(report: dict, name: str, count: int, separator: str, why: str) -> None:
    """Count `name`'s values read with their thousands grouped (``thousands_values``), and say how
    in the table line (``thousands``)."""
    counts = report.setdefault("thousands_values", {})
    counts[name] = count
    report["thousands"] = f"{separator} in {sum(counts.values()):,} values of {', '.join(counts)} ({why})"


def _stamp_from_parts(mapping: dict, cells) -> tuple[pd.Series, str]:
    """Year, month, day, hour and minute columns (NSRDB, SAM CSV) as ``yyyy-mm-dd HH:MM`` stamps,
    and the columns' names."""
    names = [mapping[part] for part in STAMP_PARTS if part in mapping]
    year, month, day, hour, *minute = (pd.Series(cells(name)).str.strip() for name in names)
    minute = minute[0].str.zfill(2) if minute else "00"
    text = year + "-" + month.str.zfill(2) + "-" + day.str.zfill(2) + " " + hour.str.zfill(2) + ":" + minute
    return text, " + ".join(names)


def _stamps(path: Path, table: Table, mapping: dict, cells, tz, site, dayfirst, report, file_zone=None):
    """The stamps as a tz-aware index and the rows kept (`stamps.parse_stamps`), from a time
    column, a date and a clock column, or year, month, day and hour columns; naive ones in
    `file_zone` (a UTC offset an NSRDB file's site lines give), else a zone the clock's name gives,
    else one its units row gives (`_zone_in_units_row`)."""
    if "year" in mapping:
        (text, header), zone = _stamp_from_parts(mapping, cells), None
    elif "date" in mapping:
        text = pd.Series(cells(mapping["date"])).str.strip() + " " + pd.Series(cells(mapping["clock"])).str.strip()
        header = f"{mapping['date']} + {mapping['clock']}"
        zone = _zone_in_name(mapping["clock"])
        written = mapping["date"].lower().replace(" ", "")  # 'DATE (MM/DD/YYYY)' says its order
        if dayfirst is None and ("mm/dd/y" in written or "dd/mm/y" in written):  # not 'yy/mm/dd'
            dayfirst = "dd/mm/y" in written
    else:
        text, header = pd.Series(cells(mapping["time"])), mapping["time"]
        zone = _zone_in_name(header)
    zone_from = {"zone_from": f"the file's Time Zone (line {table.site_line})"} if file_zone else {}
    if not file_zone and zone is None and "year" not in mapping:
        zone, zone_from = _zone_in_units_row(table, mapping.get("clock", header))
    index, keep = parse_stamps(path, header, text, table.lines, tz=tz, site_tz=site.tz if site is not None else None,
                               clock_zone=file_zone or zone, dayfirst=dayfirst, report=report, **zone_from)
    return (one_typical_year(path, index, table.lines, report) if "year" in mapping else index), keep


def _zone_in_units_row(table: Table, header: str) -> tuple[str | None, dict]:
    """The UTC offset the units row writes for the time or clock column (``UTC``, ``UTC+8``,
    ``[GMT-05:00]``: `tables.UNITS_ROW_ZONE`), and where it comes from for the report; a zone's
    abbreviation (``CST``: China's or the US's?) is not read. Such a row had been skipped and its
    zone ignored: UTC stamps read as the site's local time."""
    written = table.units.get(header, "")
    if not UNITS_ROW_ZONE.fullmatch(written):
        return None, {}
    line = table.skipped.get("units and processing rows", ["?"])[0]
    return offset_in_name(written) or "+00:00", {"zone_from": f"the units row (line {line})"}


def _without_cut_last(table: Table, report: dict) -> Table:
    """`table` without its last row when that row alone has fewer fields than the header
    (`Table.cut_short`: a logger that lost power mid-line), counted as ``truncated``: its last
    field may be a number cut short, and ``...,812.4,64`` (DNI 645.3) had been read as a DNI of
    64 W/m², the missing fields as NaN, and nothing said."""
    if not table.cut_short:
        return table
    line = int(table.lines[-1])
    report["truncated"] = {"count": 1, "lines": [line],
                           "why": f"the last line is cut short ({table.cut_short} of {len(table.headers)} fields)"}
    return dataclasses.replace(table, rows=table.rows[:-1], lines=table.lines[:-1])


def _short_rows(table: Table, mapping: dict, report: dict) -> None:
    """Count as ``short_rows`` the rows before the last with fewer fields than the header that
    miss a column read (`Table.short`): their missing cells are read as NaN, and their last field
    may be a number cut short (a logger that lost power mid-line and wrote on in a new line:
    ``...,06:00,64`` read as a GHI of 64 W/m²). They had been padded with NaN without a word
    ('changes: none'); a row missing only columns not read is left alone."""
    read = [table.headers.index(header) for name, header in mapping.items() if header in table.headers]
    if not table.short or not read:
        return
    needed = max(read) + 1
    lines = [line for line, fields in table.short.items() if fields < needed]
    if lines:
        report["short_rows"] = {"count": len(lines), "lines": lines[:5],
                                "why": f"fewer fields than the header's {len(table.headers)}; the missing cells "
                                       "read as NaN, the last one kept as written (a line cut short?)"}


def _without_empty_columns(table: Table, report: dict) -> Table:
    """`table` without its columns that have no name and no value in any row: Excel's "Save as
    CSV" pads rows to the sheet's used range (``time;ghi;dni;dhi;;``), and the two unnamed columns
    had been refused as one name twice. They hold nothing, so nothing is changed; the report
    counts them."""
    empty = [i for i, header in enumerate(table.headers)
             if not header.strip() and all(i >= len(row) or not row[i].strip() for row in table.rows)]
    if not empty or len(empty) == len(table.headers):
        return table
    keep = [i for i in range(len(table.headers)) if i not in empty]
    report["empty_columns"] = len(empty)
    return dataclasses.replace(table, headers=[table.headers[i] for i in keep],
                               rows=[[row[i] for i in keep if i < len(row)] for row in table.rows])


#: Numbers loggers write for a reading they do not have (Campbell's 7999 and -7999 for over range,
#: -9999 and -999 in SCADA and BSRN exports): no weather column can hold them, so they are missing.
MISSING_MARKERS = (-99999.0, -9999.0, -999.0, -7999.0, 7999.0, 9999.0)
#: The columns markers are read in (a photocurrent or a pointing signal is the user's own record).
_MARKED = ("ghi", "dni", "dhi", "wind_speed", "temp_air")


def _missing_markers(table: Table, name: str, values: np.ndarray, report: dict) -> np.ndarray:
    """`values` with `MISSING_MARKERS` as NaN, counted: a temperature sensor unplugged (-9999 in
    every row) had refused the whole file as a wrong unit."""
    if name not in _MARKED:
        return values
    marked = np.isin(values, MISSING_MARKERS)
    if not marked.any():
        return values
    report.setdefault("missing_markers", {})[name] = {
        "count": int(marked.sum()), "lines": [int(v) for v in table.lines[marked][:5]],
        "first": float(values[marked][0]), "action": "set to NaN"}
    return np.where(marked, np.nan, values)


def _zone_in_name(header: str) -> str | None:
    """The UTC offset a time or clock column's name gives (`CLOCK_ZONES`: MIDC's ``MST``,
    ``time_utc``, ``Time (UTC)``): a time column so named had been read as the site's local time.
    An offset written after UTC or GMT (``Time UTC-5``, ``Time (UTC+8)``, HOBO's ``Date Time,
    GMT+08:00``) is that offset: ``Time UTC-5`` had been read as UTC, and the others' offsets
    ignored."""
    written = offset_in_name(header)
    if written is not None:
        return written
    name, _, note = split_header(header)
    words = [name, *re.split(r"[\s_/-]+", name), *(word.lower() for word in re.split(r"[\s;]+", note or ""))]
    return next((CLOCK_ZONES[word] for word in words if word in CLOCK_ZONES), None)


def _refuse_unknown_unit(path: Path, header: str, name: str, note: str) -> None:
    """Refuse a column whose header gives a unit the reader does not convert: ``GHI (Wh/m2)`` had
    been read as W/m² (six times too low for 10-minute sums) and ``Wind (km h-1)`` as m/s, with
    the unit reported as a note and the file called clean."""
    unit = next((part.partition(",")[0] for part in note.split("; ") if looks_like_unit(part.partition(",")[0])),
                None)
    if unit is not None:
        raise HybridtrackError(f"{path}: column {header!r}: the unit {unit!r} is not one hybridtrack converts for "
                               f"{name} (it takes {', '.join(spellings(name))}); convert the column, or "
                               f"give its unit with --units {name}=UNIT if it is one of those")


def _read_csv(path: Path, text: str, columns, tz, units, site, dayfirst, strict, report) -> tuple[pd.DataFrame, dict]:
    """The table's frame, and the site an NSRDB or SAM CSV file's site lines give (else {})."""
    table = _without_empty_columns(locate_table(path, text), report)
    position = {h: i for i, h in enumerate(table.headers)}
    repeated = sorted({h for h in table.headers if table.headers.count(h) > 1})
    if repeated:
        raise HybridtrackError(f"{path}: column {repeated[0]!r} appears more than once in the header; rename one")

    def cells(header):
        return [row[position[header]] for row in table.rows]

    mapping = resolve_columns(str(path), table.headers, columns)
    report.update(rows_read=len(table.rows), table=table.kind, separator=_SEPARATOR_NAMES[table.separator],
                  decimal=table.decimal,
                  skipped={k: v for k, v in table.skipped.items() if v},
                  columns={k: v for k, v in mapping.items() if k in WEATHER_COLUMNS})
    unread = not_read(table.headers, mapping)
    if unread:
        report["not_read"] = unread
    table = _without_cut_last(table, report)
    _short_rows(table, mapping, report)
    if not {"time", "date", "year"} & set(mapping):
        raise HybridtrackError(f"{path}: no time column found; name it with columns={{'time': ...}} "
                               f"(--map time=COLUMN, or --map time= for an unnamed first column); columns are "
                               f"{', '.join(name_shown(h) if not h or len(h) > LONGEST_NAME else h for h in table.headers)}")
    if not any(name in mapping for name in (*IRRADIANCE, "photocurrent")):
        raise HybridtrackError(f"{path}: no irradiance column found (ghi, dni, dhi); map one, e.g. --map "
                               f"dni=COLUMN; columns are "
                               f"{', '.join(name_shown(h) if len(h) > LONGEST_NAME else h for h in table.headers)}")
    meta = header_site(path, table) if table.site else {}
    index, keep = _stamps(path, table, mapping, cells, tz, site, dayfirst, report, meta.get("zone"))
    frame = pd.DataFrame(index=index)
    conversions, notes = {}, {}
    for name in WEATHER_COLUMNS:
        if name not in mapping:
            continue
        header = mapping[name]
        values = _missing_markers(table, name, _numbers(path, table, header, cells(header), table.decimal, strict,
                                                        report, name), report)
        _, header_unit, note = split_header(header)
        if note:
            notes[header] = note
        unit = (units or {}).get(name) or header_unit or table.units.get(header) or None
        if unit is None and note:
            _refuse_unknown_unit(path, header, name, note)
        where = "--units" if (units or {}).get(name) else f"{path}: column {header!r}"
        values, converted = to_frame_units(values, name, unit, where)
        if converted:
            conversions[name] = converted
        frame[name] = values
    if conversions:
        report["units_converted"] = conversions
    if notes:
        report["header_notes"] = notes
    label = label_header(table.headers)
    if label is not None:
        frame[LABEL_COLUMN] = _sky_labels(cells(label), np.asarray(table.lines), report)
    frame["_line"] = table.lines.astype(float)
    return frame[keep], meta


def _refuse_irregular(path: Path, frame: pd.DataFrame) -> None:
    """In strict mode, stamps off a regular grid (which `resample` would put on one, interpolating
    their values) are refused at the first line off it: they had been resampled unasked."""
    if len(frame) < 3:
        return
    native, regular = native_step(frame.index)
    if regular:
        return
    step = logger_step(native)  # a jittering logger's: 61 s of median is its minute
    stamps = frame.index.as_unit("ns").asi8
    lines = first_lines(frame, (stamps - stamps[0]) % step.value != 0)
    where = f"line {lines[0]}: " if lines else ""
    raise HybridtrackError(f"{path}: {where}a time stamp off the file's {span(step)} steps (irregular stamps, which "
                           "the reader would put on a grid) (strict)")


def _sky_labels(cells: list, lines: np.ndarray, report: dict) -> np.ndarray:
    """A file's true-sky labels as the runs read them, written in lower case without the spaces
    around them, a blank one missing; each change counted in `report` (``sky_rewritten``,
    ``sky_blank``), and labels that name no sky (`SKY_CODES`: kept, a run reads them as unknown
    and the hybrid-oracle policy refuses them) found (``sky_unknown``). They had been rewritten
    without a word ("changes: none")."""
    from ..control import SKY_CODES

    raw = pd.Series(cells, dtype=object)
    labels = raw.str.strip().str.lower()
    given = raw.notna().to_numpy()
    blank = given & (labels == "").to_numpy()
    rewritten = given & ~blank & (labels != raw).to_numpy()
    unknown = given & ~blank & ~labels.isin(SKY_CODES).to_numpy()
    for key, where, action in (("sky_rewritten", rewritten, "written in lower case without spaces"),
                               ("sky_blank", blank, "read as missing")):
        if where.any():
            report[key] = {"count": int(where.sum()), "lines": [int(v) for v in lines[where][:5]], "action": action}
    if unknown.any():
        first = int(np.argmax(unknown))
        report["sky_unknown"] = {"count": int(unknown.sum()), "first": f"{labels.iloc[first]!r:.40} (line {lines[first]})",
                                 "action": "kept (read as unknown; the hybrid-oracle policy refuses them)"}
    return labels.where(~blank, np.nan).to_numpy(object)


def _read_pvlib_as_told(path: Path, fmt: str, tz, report: dict, text: str, encoding: str):
    """`read_pvlib`, whose refusal of a file given a format its first lines are not (``--format
    epw`` on a CSV table) says so: pvlib's own word alone had been ``KeyError: 'altitude'``."""
    try:
        return read_pvlib(path, fmt, tz, report, text, encoding)
    except HybridtrackError as exc:
        detected = detect_format(text)
        if fmt not in RECOGNISED_FORMATS or detected == fmt:
            raise
        looks = "a table" if detected == "csv" else f"a {detected.upper()} file"
        raise HybridtrackError(f"{exc}; its first lines are {looks}'s, not those of the {fmt.upper()} format: "
                               "leave --format out (format=None) to read it as what it is") from None


def _site_from_meta(meta: dict):
    from ..sites import custom

    try:
        return custom(float(meta["latitude"]), float(meta["longitude"]), meta.get("site_tz", "UTC"),
                      float(meta.get("altitude", meta.get("elevation", 0.0)) or 0.0),
                      name=meta_name(meta, "the file's site"))
    except (HybridtrackError, TypeError, ValueError):
        return None


def _wind(frame: pd.DataFrame, attrs: dict, report: dict) -> pd.DataFrame:
    """Mark the wind measured or missing; a missing column is NaN, never a fabricated calm."""
    if "wind_speed" in frame and np.isfinite(frame["wind_speed"].to_numpy(float)).any():
        attrs["wind_data"] = "measured"
        return frame
    attrs["wind_data"] = "missing"
    why = "no wind column in the file" if "wind_speed" not in frame else "the wind column holds no readable value"
    report["wind_missing"] = f"{why}; wind_speed is NaN (attrs['wind_data'] = 'missing'), never taken as calm"
    frame = frame.copy()
    frame["wind_speed"] = np.nan
    return frame


def _clip_offsets(path: Path, frame: pd.DataFrame, report: dict, clear: np.ndarray | None, strict: bool) -> None:
    """`checks.clip_offsets` after the sun check, on the site's clear sky `clear` unless the sun
    check found the light off the site's clock (a warning, with ``lenient``): the sun's height at a
    stamp then says nothing of the light there. In `strict` mode a clipped offset is refused."""
    trusted = clear is not None and not str(report.get("sun_check", "")).startswith("WARNING")
    clip_offsets(path, frame, report, clear if trusted else None)
    if strict:
        refuse_repairs(path, report)


def _check_switches(*, dayfirst, **switches) -> None:
    """Refuse a switch of `read_weather` that is not True or False (`dayfirst` may be None): ``strict="no"``
    had been read as True, ``lenient="no"`` and ``dayfirst="no"`` taken as they came."""
    given = {**switches, **({} if dayfirst is None else {"dayfirst": dayfirst})}
    for name, value in given.items():
        if not isinstance(value, (bool, np.bool_)):
            raise HybridtrackError(f"read_weather: {name} must be True or False"
                                   f"{' (or None)' if name == 'dayfirst' else ''}, got {value!r:.40}")


def read_weather(path, *, columns: Mapping[str, str] | None = None, tz: str | None = None, format: str | None = None,
                 site=None, units: Mapping[str, str] | None = None, freq: str | None = None,
                 decomposition: str = "erbs", strict: bool = False, dayfirst: bool | None = None,
                 lenient: bool = False) -> pd.DataFrame:
    """A recorded weather file as a checked weather frame.

    Parameters
    ----------
    path : str or Path
        CSV-like text (any separator, header block, comments, TOA5), or a pvlib format; packed
        with gzip or zip, in UTF-8, UTF-16 or Latin-1.
    columns : mapping, optional
        Quantity to the file's column, e.g. ``{"dni": "Direct Normal", "time": ""}`` (``""``: the
        unnamed first column pandas writes); names not given are found by `ALIASES`.
    tz : str, optional
        The file's time zone (IANA): naive stamps are in it, stamps with offsets are converted
        to it. Separate from the site's zone.
    format : str, optional
        ``"csv"`` or one of pvlib's formats (epw, tmy3, tmy2, midc, srml, bsrn, surfrad, crn,
        solrad); by default recognised from the content.
    site : Site or str, optional
        Used to derive missing components, for the sun and magnitude checks, and as the zone
        of naive stamps when `tz` is not given.
    units : mapping, optional
        Quantity to unit, e.g. ``{"ghi": "kW/m2", "wind_speed": "km/h"}``.
    freq : str, optional
        Resample to this step (any step, e.g. ``"7min"``); irregular data is resampled to its
        median step.
    decomposition : {"erbs", "dirint"}
        How DNI and DHI are split from GHI alone.
    strict : bool
        Refuse, rather than repair and report, anything the checks would repair.
    dayfirst : bool, optional
        Whether ``a/b/yyyy`` dates are day-first; None decides from the whole column.
    lenient : bool
        Warn, rather than refuse, when the light does not follow the site's sun.

    Returns
    -------
    pandas.DataFrame
        Columns among ``ghi dni dhi wind_speed temp_air photocurrent`` (``wind_speed`` always,
        NaN when the file has none) on a tz-aware index; ``attrs`` holds ``validation`` (see
        `validation_report`), ``wind_data`` (``"measured"`` or ``"missing"``), the source of
        each irradiance column and the resampling method.
    """
    from ..sites import get
    from ..times import check_tz
    from .files import input_path

    path = input_path(path, "weather file")
    if tz is not None:
        check_tz(tz)
    check_names({} if units is None else units, "--units")
    if columns is not None:
        check_names(columns, "--map")
    _check_switches(strict=strict, lenient=lenient, dayfirst=dayfirst)
    site = get(site) if site is not None else None
    report: dict = {"source": str(path)}
    text, report["read_as"] = file_text(path, report=report)
    encoding = report["read_as"]
    fmt = str(format).lower() if format is not None else detect_format(text)
    if fmt == "csv":
        frame, meta = _read_csv(path, text, columns, tz, units, site, dayfirst, strict, report)
    elif fmt in PVLIB_FORMATS:
        if columns or units:
            raise HybridtrackError(f"{path}: --map and --units apply to tables; a {fmt.upper()} file names its own "
                                   "columns and units")
        frame, meta = _read_pvlib_as_told(path, fmt, tz, report, text, encoding)
        report["rows_read"] = int(len(frame))
    else:
        raise HybridtrackError(f"unknown format {format!r}; choose csv, {', '.join(PVLIB_FORMATS)}")
    if site is None and {"latitude", "longitude"} <= set(meta):
        site = _site_from_meta(meta)
        if site is not None:
            report["site"] = (f"{site.name} ({site.latitude:.3f}°, {site.longitude:.3f}°, {site.altitude:g} m, "
                              f"{site.tz}), from the file's header")
    elif site is not None:
        from .suncheck import place_check

        place_check(path, meta, site, report, lenient=lenient)
    frame = check_frame(path, frame, report)
    if strict:
        refuse_repairs(path, report)
    clear = None
    if site is not None:
        from .suncheck import sun_check

        zenith, clear = site_clear_sky(frame.index, site)
        check_magnitude(path, frame, report, clear)
        check_magnitude_by_day(path, frame, report, clear, site.tz)
        sun_check(path, frame, site, report, lenient=lenient)
    else:
        check_magnitude(path, frame, report, None)
    _clip_offsets(path, frame, report, clear, strict)
    if site is not None:
        closure_check(path, frame, zenith.to_numpy(float), report, strict=strict)
    attrs: dict = {}
    frame = fill_components(path, frame, site, decomposition, attrs, report)
    if strict and freq is None:
        _refuse_irregular(path, frame)
    frame = resample(frame, freq, report, attrs)
    frame = _wind(frame, attrs, report)
    frame = frame[[c for c in (*WEATHER_COLUMNS, LABEL_COLUMN) if c in frame.columns]]
    report["rows_out"] = int(len(frame))
    report["date_range"] = f"{frame.index[0]} to {frame.index[-1]}"
    attrs.update(source=str(path), validation=report)
    if site is not None:
        attrs["site"] = site.name
    frame.attrs = attrs
    return frame
