"""Reading user files: weather records and small tables, with errors that say where.

`read_weather` turns a recorded irradiance file into a weather frame (``domain.md``,
``design.md``): pvlib's column names on a tz-aware index, checked, and with a validation
summary in ``frame.attrs["validation"]`` (`validation_report` prints it).

What it accepts and how it decides:

* **CSV under any names**: a header block before the table is skipped. The separator
  (comma, semicolon, tab, bar) is sniffed, and a decimal comma is accepted with semicolons.
  Columns are found by their usual names (``GHI``, ``Global``, ``Direct Normal``,
  ``Diffuse``, ``Wind speed``, ``Temperature`` ...), or by the mapping you give
  (``columns={"dni": "Direct Normal"}``). Units in brackets in a header (``GHI [kW/m2]``)
  or given in `units` are converted.
* **pvlib's formats**: EPW, TMY3, MIDC, SRML, BSRN, SURFRAD, CRN, SOLRAD go through
  ``pvlib.iotools`` as they are. Typical-year files (EPW, TMY3) take one year, 2019, since
  their months come from different years.
* **Time**: stamps with offsets keep them: converted to `tz` when given, else kept at their
  one fixed offset, else UTC. Naive stamps are localised with `tz` and refused without it.
  Repeated stamps in a DST fall-back are resolved by their order. Stamps that fall in a
  spring-forward gap cannot exist; they are dropped and reported.
* **Unreadable values**: text in a few rows of a numeric column (a bad stretch of a logger
  file) becomes NaN, counted with its lines, and the rest is read; text in half or more of a
  column is refused.
* **Checks**, each counted in the summary with the first offending file lines: unsorted
  stamps (sorted), duplicated stamps (the first kept), gaps (left as gaps), NaN (kept),
  small negative values (above -50 W/m², sensor offsets at night: clipped to 0).
  Physically impossible values are flagged, set to NaN, and counted: irradiance below
  -50 W/m², GHI above 1500, DNI above 1400, DHI above 1000, wind below 0 or above 75 m/s,
  temperature outside -90..65 °C. A column where most values are impossible is refused as
  a unit mistake. With ``strict=True`` each of these repairs is an error instead.
* **Missing components**: DNI from GHI and DHI by closure, or from GHI alone by a pvlib
  decomposition (Erbs by default, or DIRINT); DHI or GHI by closure. Each needs the sun's
  position, so a site. The choice is recorded in ``attrs["dni_source"]`` (and
  ``dhi_source``, ``ghi_source``).
* **Resampling**: irregular data, or data at a step other than `freq`, is resampled. A
  coarser step is interpolated in time, without bridging gaps longer than three steps; a
  finer one is averaged over each step. The method is recorded in ``attrs["resampling"]``.
"""

from __future__ import annotations

import csv
import datetime as dt
import io
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import HybridtrackError

__all__ = ["read_weather", "read_table", "read_toml", "write_toml", "read_text", "numeric_columns", "validation_report", "WEATHER_COLUMNS",
           "PVLIB_FORMATS", "LIMITS"]

#: The columns of a weather frame, in order.
WEATHER_COLUMNS = ("ghi", "dni", "dhi", "wind_speed", "temp_air", "photocurrent")
IRRADIANCE = ("ghi", "dni", "dhi")

#: A column of true sky labels (e.g. in synthetic records), kept as text for scoring.
LABEL_COLUMN = "sky"

#: Usual header names of each column (compared lower-cased, units in brackets removed).
ALIASES = {
    "time": ("time", "timestamp", "datetime", "date_time", "date time", "date/time", "time stamp", "utc",
             "local time", "date"),
    "ghi": ("ghi", "global", "global horizontal", "global_horizontal", "global horizontal irradiance",
            "global irradiance", "glo", "gh", "ghi_wm2"),
    "dni": ("dni", "direct normal", "direct_normal", "direct normal irradiance", "direct", "beam", "dn", "dni_wm2"),
    "dhi": ("dhi", "diffuse", "diffuse horizontal", "diffuse_horizontal", "diffuse horizontal irradiance", "dif",
            "dhi_wm2"),
    "wind_speed": ("wind_speed", "wind speed", "windspeed", "wind", "ws", "wspd"),
    "temp_air": ("temp_air", "air temperature", "temperature", "temp", "tair", "t_air", "ta"),
    "photocurrent": ("photocurrent", "photocurrent_ma", "intensity", "intensity_ma", "sensor current"),
}

#: Unit conversions to the frame's units (W/m², m/s, °C, mA), by lower-cased unit text.
UNITS = {
    "irradiance": {"w/m2": 1.0, "w/m²": 1.0, "w m-2": 1.0, "wm-2": 1.0, "kw/m2": 1000.0, "kw/m²": 1000.0},
    "wind_speed": {"m/s": 1.0, "km/h": 1 / 3.6, "kmh": 1 / 3.6, "kn": 0.514444, "knots": 0.514444, "mph": 0.44704},
    "temp_air": {"c": None, "°c": None, "degc": None, "k": None, "f": None, "°f": None},
    "photocurrent": {"ma": 1.0, "a": 1000.0, "ua": 0.001, "µa": 0.001},
}

#: Physically possible range of each column; outside it a value is flagged (NaN).
LIMITS = {"ghi": (-50.0, 1500.0), "dni": (-50.0, 1400.0), "dhi": (-50.0, 1000.0), "wind_speed": (0.0, 75.0),
          "temp_air": (-90.0, 65.0), "photocurrent": (0.0, 10_000.0)}

#: Formats read through pvlib.iotools.
PVLIB_FORMATS = {"epw": "read_epw", "tmy3": "read_tmy3", "midc": "read_midc", "srml": "read_srml",
                 "bsrn": "read_bsrn", "surfrad": "read_surfrad", "crn": "read_crn", "solrad": "read_solrad"}
#: Typical-year formats: their months come from different years, so pvlib coerces one year.
TYPICAL_YEAR_FORMATS = ("epw", "tmy3")
TYPICAL_YEAR = 2019  # any year that is not a leap year


# --- small tables ---------------------------------------------------------------------------


def read_text(path) -> str:
    """A text file's contents, or one clear error: missing, a folder, binary, not UTF-8, empty."""
    path = Path(path)
    return _text(path)


def numeric_columns(frame: pd.DataFrame, columns, where: str) -> pd.DataFrame:
    """`frame` with `columns` (those present) as floats; text in one names its row and column.

    Row numbers count the header as row 1, as a spreadsheet shows them.
    """
    frame = frame.copy()
    for column in columns:
        if column not in frame.columns:
            continue
        values = pd.to_numeric(frame[column], errors="coerce")
        bad = (values.isna() & frame[column].notna()).to_numpy()
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise HybridtrackError(f"{where}: row {row + 2}, column {column!r}: {frame[column].iloc[row]!r} "
                                   "is not a number")
        frame[column] = values.astype(float)
    return frame


def _text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise HybridtrackError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise HybridtrackError(f"{path}: is a folder, not a file") from None
    except PermissionError:
        raise HybridtrackError(f"{path}: not readable (permission denied)") from None
    if b"\x00" in raw[:4096]:
        raise HybridtrackError(f"{path}: looks binary, not a text table")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise HybridtrackError(f"{path}: line {line}: not UTF-8 text (byte {exc.start}); save the file as UTF-8") from None
    if not text.strip():
        raise HybridtrackError(f"{path}: the file is empty")
    return text


def read_table(path) -> pd.DataFrame:
    """A small table from CSV (comma, semicolon or tab) or TOML (``[[case]]`` rows).

    Lines starting with ``#`` in a CSV are comments. Column names are stripped and lowered.
    """
    path = Path(path)
    text = _text(path)
    if path.suffix.lower() == ".toml":
        try:
            import tomllib
        except ModuleNotFoundError:  # pragma: no cover - Python 3.10
            import tomli as tomllib
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise HybridtrackError(f"{path}: not valid TOML: {exc}") from None
        rows = data.get("case", data.get("cases"))
        if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
            raise HybridtrackError(f"{path}: expected an array of [[case]] tables")
        frame = pd.DataFrame(rows)
    else:
        try:
            frame = pd.read_csv(io.StringIO(text), sep=None, engine="python", comment="#", skipinitialspace=True)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError, csv.Error) as exc:
            raise HybridtrackError(f"{path}: cannot read as CSV: {str(exc).splitlines()[0]}") from None
    frame.columns = [str(c).strip().lower() for c in frame.columns]
    if frame.empty:
        raise HybridtrackError(f"{path}: the table has no rows")
    frame.attrs["source"] = str(path)
    return frame


def read_toml(path, what: str = "config") -> dict:
    """A TOML file as a dict, or one clear error naming the file (missing, not UTF-8, bad TOML)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise HybridtrackError(f"{path}: no such {what} file") from None
    except IsADirectoryError:
        raise HybridtrackError(f"{path}: is a folder, not a {what} file") from None
    except UnicodeDecodeError as exc:
        raise HybridtrackError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise HybridtrackError(f"{path}: not valid TOML: {exc}") from None


def write_toml(data: dict, path) -> Path:
    """Write a dict as TOML, creating folders; `read_toml` reads it back equal."""
    import tomli_w

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    return path


# --- weather files --------------------------------------------------------------------------


_BRACKETS = re.compile(r"\s*[\[(]([^\])]*)[\])]\s*")


def _split_header(name: str) -> tuple[str, str | None]:
    """``'GHI [kW/m2]'`` -> (``'ghi'``, ``'kw/m2'``)."""
    match = _BRACKETS.search(name)
    unit = match.group(1).strip().lower() if match else None
    return _BRACKETS.sub(" ", name).strip().lower(), unit


def _locate_table(path: Path, text: str) -> tuple[list[str], int, str]:
    """The file's lines, the index of the table's header line, and the separator.

    For each candidate separator the data's usual field count is read off the last lines,
    and the header is the first line with that many fields of which one has letters. The
    separator that finds a header and splits the data most consistently (then widest) wins,
    so a block of notes before the table, or decimal commas, do not mislead it.
    """
    lines = text.splitlines()
    data = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    if len(data) < 2:
        raise HybridtrackError(f"{path}: no table found (fewer than two lines of data)")
    tail = data[-min(len(data), 30):]
    best = None
    for sep in (",", ";", "\t", "|"):
        counts = [len(next(csv.reader([line], delimiter=sep))) for line in tail]
        width = max(set(counts), key=counts.count)
        if width < 2:
            continue
        for number, line in enumerate(lines):
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            fields = next(csv.reader([line], delimiter=sep))
            if len(fields) == width and any(re.search(r"[A-Za-z]", f) for f in fields):
                below = [len(next(csv.reader([x], delimiter=sep))) for x in lines[number + 1:] if x.strip()]
                share = below.count(width) / max(len(below), 1)
                if best is None or (share, width) > best[0]:
                    best = ((share, width), number, sep)
                break
    if best is None:
        raise HybridtrackError(f"{path}: no table found: no header row of named columns separated by comma, "
                               "semicolon, tab or bar")
    return lines, best[1], best[2]


def _resolve_columns(path: Path, headers: list[str], columns: Mapping[str, str] | None) -> dict[str, str]:
    """Project name -> file header, from the user's mapping first, then the usual names."""
    mapping: dict[str, str] = {}
    for name, header in (columns or {}).items():
        if name not in ("time", *WEATHER_COLUMNS):
            raise HybridtrackError(f"unknown column name {name!r} in the mapping; use time, {', '.join(WEATHER_COLUMNS)}")
        if header not in headers:
            raise HybridtrackError(f"{path}: no column {header!r} (mapped to {name}); columns are {', '.join(headers)}")
        mapping[name] = header
    taken = set(mapping.values())
    for name, aliases in ALIASES.items():
        if name in mapping:
            continue
        for header in headers:
            if header not in taken and _split_header(header)[0] in aliases:
                mapping[name] = header
                taken.add(header)
                break
    return mapping


def _line_numbers(offset: int, rows: np.ndarray) -> list[int]:
    return [int(offset + r) for r in rows[:5]]


def _fixed_zone(offset: str) -> dt.timezone:
    """``'+08:00'`` or ``'+0800'`` -> a fixed-offset time zone."""
    sign = -1 if offset.startswith("-") else 1
    digits = offset[1:].replace(":", "")
    hours, minutes = int(digits[:2]), int(digits[2:4] or 0)
    if hours > 14 or minutes >= 60:
        raise HybridtrackError(f"UTC offset {offset!r} is not a real one (beyond ±14:00)")
    return dt.timezone(sign * dt.timedelta(hours=hours, minutes=minutes))


def _parse_time(path: Path, values: pd.Series, header: str, tz: str | None, first_line: int, report: dict):
    text = values.astype(str).str.strip()
    has_offset = text.str.contains(r"\d(?:[+-]\d{2}:?\d{2}|Z)$", regex=True)  # an offset follows the time
    try:
        parsed = pd.to_datetime(text, utc=bool(has_offset.any()), format="mixed")
    except (ValueError, TypeError, OverflowError) as exc:
        bad = next((i for i, v in enumerate(text) if pd.isna(pd.to_datetime(v, errors="coerce", format="mixed"))), 0)
        raise HybridtrackError(f"{path}: line {first_line + bad}, column {header!r}: {text.iloc[bad]!r} is not a "
                               f"time stamp ({str(exc).splitlines()[0]})") from None
    if parsed.isna().any():
        bad = int(np.flatnonzero(parsed.isna().to_numpy())[0])
        raise HybridtrackError(f"{path}: line {first_line + bad}, column {header!r}: {text.iloc[bad]!r} is not a time stamp")
    index = pd.DatetimeIndex(parsed)
    years = np.asarray(index.year)
    odd = np.flatnonzero((years < 1900) | (years > 2200))
    if len(odd):  # '-0.5' or '1,5' parse as dates in year 0; no logger recorded then
        bad = int(odd[0])
        raise HybridtrackError(f"{path}: line {first_line + bad}, column {header!r}: {text.iloc[bad]!r} is not a "
                               "plausible time stamp (outside 1900-2200)")
    if has_offset.any():
        if not has_offset.all():
            bad = int(np.flatnonzero(~has_offset.to_numpy())[0])
            raise HybridtrackError(f"{path}: line {first_line + bad}, column {header!r}: stamps mix UTC offsets "
                                   f"and none ({text.iloc[bad]!r})")
        offsets = text.str.extract(r"([+-]\d{2}:?\d{2}|Z)$")[0].str.replace("Z", "+00:00")
        if tz is not None:
            report["time"] = f"stamps with UTC offsets, converted to {tz}"
            return index.tz_convert(tz), np.ones(len(index), bool)
        if offsets.nunique() == 1:
            try:
                zone = _fixed_zone(offsets.iloc[0])
            except HybridtrackError as exc:
                raise HybridtrackError(f"{path}: line {first_line}, column {header!r}: {exc}") from None
            report["time"] = f"stamps with UTC offset {offsets.iloc[0]}, kept"
            return index.tz_convert(zone), np.ones(len(index), bool)
        report["time"] = f"stamps with {offsets.nunique()} different UTC offsets, kept as UTC (give a time zone to convert)"
        return index, np.ones(len(index), bool)
    if tz is None:
        raise HybridtrackError(f"{path}: column {header!r} has naive time stamps (no UTC offset); give the time zone "
                               "they were logged in (tz=..., --tz Asia/Shanghai)")
    try:
        local = index.tz_localize(tz, ambiguous="infer", nonexistent="NaT")
        resolved = "repeated DST stamps resolved by their order"
    except (ValueError, TypeError):  # the order cannot tell the repeated hour apart
        local = index.tz_localize(tz, ambiguous="NaT", nonexistent="NaT")
        resolved = "ambiguous DST stamps dropped (their order did not resolve them)"
    keep = ~local.isna()
    report["time"] = f"naive stamps localised to {tz}"
    dropped = np.flatnonzero(~keep)
    if len(dropped):
        report["dst_dropped"] = {"count": int(len(dropped)), "lines": _line_numbers(first_line, dropped),
                                 "why": "stamps that do not exist in the time zone (spring-forward gap) "
                                        "or could not be resolved"}
    ambiguous_count = int(index.tz_localize(tz, ambiguous="NaT", nonexistent="shift_forward").isna().sum())
    if ambiguous_count:
        report["dst_repeated"] = {"count": ambiguous_count, "resolution": resolved}
    return local, keep


def _convert_units(path: Path, name: str, values: pd.Series, unit: str | None) -> tuple[pd.Series, str | None]:
    if unit is None:
        return values, None
    key = unit.strip().lower().replace(" ", "")
    table = UNITS["irradiance"] if name in IRRADIANCE else UNITS.get(name, {})
    if key not in {k.replace(" ", "") for k in table}:
        allowed = ", ".join(sorted(table)) or "none"
        raise HybridtrackError(f"{path}: column {name!r}: unknown unit {unit!r}; known: {allowed}")
    if name == "temp_air":
        if key == "k":
            return values - 273.15, "K -> °C"
        if key in ("f", "°f"):
            return (values - 32.0) * 5.0 / 9.0, "°F -> °C"
        return values, None
    factor = {k.replace(" ", ""): v for k, v in table.items()}[key]
    return values * factor, (None if factor == 1.0 else f"{unit} x {factor:g}")


def _read_csv_weather(path: Path, columns, tz, units, report, strict: bool) -> tuple[pd.DataFrame, dict]:
    text = _text(path)
    lines, header_at, sep = _locate_table(path, text)
    body = "\n".join(lines[header_at:])
    headers = [h.strip() for h in next(csv.reader([lines[header_at]], delimiter=sep))]
    sample = [f for line in lines[header_at + 1: header_at + 20] for f in line.split(sep)]
    decimal = "," if sep == ";" and any(re.fullmatch(r"-?\d+,\d+", f.strip()) for f in sample) else "."
    try:
        raw = pd.read_csv(io.StringIO(body), sep=sep, dtype=str, decimal=decimal, comment=None, skip_blank_lines=True,
                          keep_default_na=False)
    except (pd.errors.ParserError, ValueError) as exc:
        raise HybridtrackError(f"{path}: cannot read the table: {str(exc).splitlines()[0]}") from None
    raw.columns = headers if len(headers) == len(raw.columns) else raw.columns
    repeated = sorted({h for h in raw.columns if list(raw.columns).count(h) > 1})
    if repeated:
        raise HybridtrackError(f"{path}: line {header_at + 1}: column {repeated[0]!r} appears more than once in the "
                               "header; rename one")
    if raw.empty:
        raise HybridtrackError(f"{path}: the table has a header but no rows")
    first_line = header_at + 2  # 1-based file line of the first data row
    report["rows_read"] = int(len(raw))
    mapping = _resolve_columns(path, list(raw.columns), columns)
    report.update(header_lines_skipped=header_at, separator={",": "comma", ";": "semicolon", "\t": "tab",
                                                            "|": "bar"}[sep], decimal=decimal,
                  columns={k: v for k, v in mapping.items()})
    if "time" not in mapping:
        raise HybridtrackError(f"{path}: no time column found; name it with columns={{'time': ...}} "
                               f"(--map time=COLUMN); columns are {', '.join(raw.columns)}")
    if not any(name in mapping for name in (*IRRADIANCE, "photocurrent")):
        raise HybridtrackError(f"{path}: no irradiance column found (ghi, dni, dhi); map one, e.g. --map "
                               f"dni=COLUMN; columns are {', '.join(raw.columns)}")
    index, keep = _parse_time(path, raw[mapping["time"]], mapping["time"], tz, first_line, report)
    frame = pd.DataFrame(index=index)
    conversions = {}
    for name in WEATHER_COLUMNS:
        if name not in mapping:
            continue
        header = mapping[name]
        strings = raw[header].astype(str).str.strip()
        if decimal == ",":
            strings = strings.str.replace(",", ".", regex=False)
        values = pd.to_numeric(strings.replace({"": np.nan, "nan": np.nan, "NaN": np.nan, "NA": np.nan, "-": np.nan}),
                               errors="coerce")
        bad = (values.isna() & ~strings.isin(["", "nan", "NaN", "NA", "-"])).to_numpy()
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            where = f"{path}: line {first_line + row}, column {header!r}: {raw[header].iloc[row]!r} is not a number"
            filled = int((~strings.isin(["", "nan", "NaN", "NA", "-"])).sum())
            if strict or bad.sum() * 2 >= max(filled, 1):
                raise HybridtrackError(where if strict else f"{where} (nor are {bad.sum()} of its {filled} values)")
            report.setdefault("unreadable", {})[name] = {"count": int(bad.sum()), "lines": _line_numbers(first_line,
                                                                                                          np.flatnonzero(bad)),
                                                         "first": str(raw[header].iloc[row]), "action": "set to NaN"}
        unit = (units or {}).get(name) or _split_header(header)[1]
        values, note = _convert_units(path, name, values, unit)
        if note:
            conversions[name] = note
        frame[name] = values.to_numpy(float)
    if conversions:
        report["units_converted"] = conversions
    label = next((h for h in raw.columns if _split_header(h)[0] == LABEL_COLUMN), None)
    if label is not None:
        frame[LABEL_COLUMN] = raw[label].astype(str).str.strip().str.lower().replace({"": np.nan}).to_numpy()
    frame["_line"] = np.arange(first_line, first_line + len(frame))
    return frame[keep], {}


def _read_pvlib(path: Path, fmt: str, tz, report) -> tuple[pd.DataFrame, dict]:
    import pvlib

    if not path.exists():
        raise HybridtrackError(f"{path}: no such file")
    reader = getattr(pvlib.iotools, PVLIB_FORMATS[fmt])
    options = {"coerce_year": TYPICAL_YEAR} if fmt in TYPICAL_YEAR_FORMATS else {}
    try:
        result = reader(str(path), **options)
    except Exception as exc:  # pvlib raises many kinds; the user needs one line
        raise HybridtrackError(f"{path}: pvlib could not read it as {fmt.upper()}: "
                               f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}") from None
    data, meta = (result if isinstance(result, tuple) else (result, {}))
    data = data.copy()
    frame = pd.DataFrame(index=pd.DatetimeIndex(data.index))
    for name in WEATHER_COLUMNS:
        if name in data.columns:
            frame[name] = pd.to_numeric(data[name], errors="coerce").to_numpy(float)
    if frame.index.tz is None:
        if tz is None:
            raise HybridtrackError(f"{path}: the {fmt.upper()} stamps carry no time zone; give one (tz=..., --tz)")
        frame.index = frame.index.tz_localize(tz, ambiguous="infer", nonexistent="shift_forward")
    elif tz is not None:
        frame.index = frame.index.tz_convert(tz)
    report.update(format=fmt, columns={name: name for name in frame.columns},
                  time=f"from the {fmt.upper()} file ({frame.index.tz})"
                       + (f", one year ({TYPICAL_YEAR}) for a typical-year file" if options else ""))
    frame["_line"] = np.arange(1, len(frame) + 1)
    return frame, dict(meta) if isinstance(meta, Mapping) else {}


def _span(delta) -> str:
    """A duration in its largest whole unit: ``5min``, ``1h``, ``30s``, ``2d``."""
    delta = pd.Timedelta(delta)
    for unit, size in (("d", pd.Timedelta(days=1)), ("h", pd.Timedelta(hours=1)), ("min", pd.Timedelta(minutes=1)),
                       ("s", pd.Timedelta(seconds=1))):
        if delta >= size and delta % size == pd.Timedelta(0):
            return f"{delta // size}{unit}"
    return str(delta)


def _first_lines(frame: pd.DataFrame, mask) -> list[int]:
    return [int(v) for v in frame["_line"].to_numpy()[np.asarray(mask)][:5]]


def _check(path: Path, frame: pd.DataFrame, report: dict) -> pd.DataFrame:
    if not frame.index.is_monotonic_increasing:
        disorder = np.flatnonzero(np.diff(frame.index.as_unit("ns").asi8) < 0) + 1
        report["unsorted"] = {"count": int(len(disorder)), "lines": _first_lines(frame, np.isin(np.arange(len(frame)),
                                                                                                disorder)),
                              "action": "sorted by time"}
        frame = frame.sort_index(kind="stable")
    duplicated = frame.index.duplicated(keep="first")
    if duplicated.any():
        report["duplicates"] = {"count": int(duplicated.sum()), "lines": _first_lines(frame, duplicated),
                                "action": "first of each kept"}
        frame = frame[~duplicated]
    if len(frame) < 2:
        raise HybridtrackError(f"{path}: fewer than two distinct time stamps; nothing to replay")
    steps = np.diff(frame.index.as_unit("ns").asi8)
    step = int(np.median(steps))
    gap_at = np.flatnonzero(steps > 1.5 * step)
    report["step"] = _span(pd.Timedelta(step, "ns"))
    if len(gap_at):
        longest = int(steps[gap_at].max())
        report["gaps"] = {"count": int(len(gap_at)), "longest": _span(pd.Timedelta(longest, "ns")),
                          "first_after_lines": _first_lines(frame, np.isin(np.arange(len(frame)), gap_at))}
    nan = {name: int(frame[name].isna().sum()) for name in WEATHER_COLUMNS if name in frame and frame[name].isna().any()}
    if nan:
        report["nan"] = nan
    clipped, impossible = {}, {}
    for name, (low, high) in LIMITS.items():
        if name not in frame:
            continue
        values = frame[name].to_numpy(float)
        finite = np.isfinite(values)
        bad = finite & ((values < low) | (values > high))
        if finite.sum() and bad.sum() > 0.5 * finite.sum():
            raise HybridtrackError(
                f"{path}: column {report.get('columns', {}).get(name, name)!r}: {bad.sum() / finite.sum():.0%} of values "
                f"are outside {low:g}..{high:g} ({_unit(name)}); wrong unit? give it, e.g. --units {name}={_HINT[name]}")
        if bad.any():
            impossible[name] = {"count": int(bad.sum()), "lines": _first_lines(frame, bad),
                                "first": float(values[bad][0]), "action": "set to NaN"}
            values = np.where(bad, np.nan, values)
        if name in IRRADIANCE:
            negative = np.isfinite(values) & (values < 0)
            if negative.any():
                clipped[name] = {"count": int(negative.sum()), "lines": _first_lines(frame, negative)}
                values = np.where(negative, 0.0, values)
        frame[name] = values
    if clipped:
        report["negative_clipped"] = clipped
    if impossible:
        report["impossible"] = impossible
    return frame


_HINT = {"ghi": "kW/m2", "dni": "kW/m2", "dhi": "kW/m2", "wind_speed": "km/h", "temp_air": "K", "photocurrent": "A"}


_REPAIRS = {
    "unreadable": "text in a numeric column", "dst_dropped": "a time stamp that does not exist in the time zone",
    "unsorted": "time stamps out of order", "duplicates": "a repeated time stamp",
    "impossible": "a physically impossible value", "negative_clipped": "a negative irradiance",
}


def _refuse_repairs(path: Path, report: dict) -> None:
    """In strict mode, the first thing the checks would have repaired is an error."""
    for key, what in _REPAIRS.items():
        if key not in report:
            continue
        entry = report[key]
        if "lines" in entry:
            raise HybridtrackError(f"{path}: line {entry['lines'][0]}: {what} (strict)")
        column, detail = next(iter(entry.items()))
        raise HybridtrackError(f"{path}: line {detail['lines'][0]}, column {column!r}: {what} (strict)")


def _unit(name: str) -> str:
    return {"wind_speed": "m/s", "temp_air": "°C", "photocurrent": "mA"}.get(name, "W/m²")


def _complete(path: Path, frame: pd.DataFrame, site, decomposition: str, attrs: dict) -> pd.DataFrame:
    present = {name for name in IRRADIANCE if name in frame}
    for name in present:
        attrs[f"{name}_source"] = "measured"
    if present == set(IRRADIANCE) or not present:
        return frame
    if site is None:
        missing = ", ".join(sorted(set(IRRADIANCE) - present))
        raise HybridtrackError(f"{path}: {missing} missing; deriving it needs the sun's position, so give a site "
                               "(site=..., --site or --lat/--lon)")
    import pvlib

    from .sun import solar_position

    position = solar_position(frame.index, site)
    zenith = position["apparent_zenith"].to_numpy(float)
    cos_z = np.cos(np.radians(zenith))
    usable = zenith < 87.0  # closure divides by cos z; near the horizon it only amplifies noise
    if present == {"ghi", "dhi"}:
        frame["dni"] = np.where(usable, np.clip((frame["ghi"] - frame["dhi"]) / np.where(usable, cos_z, 1.0), 0.0, 1400.0),
                                0.0)
        attrs["dni_source"] = "closure: (ghi - dhi) / cos(zenith), 0 with the sun within 3° of the horizon"
    elif present == {"ghi", "dni"}:
        frame["dhi"] = np.clip(frame["ghi"] - frame["dni"] * np.clip(cos_z, 0.0, None), 0.0, None)
        attrs["dhi_source"] = "closure: ghi - dni cos(zenith)"
    elif present == {"dni", "dhi"}:
        frame["ghi"] = frame["dni"] * np.clip(cos_z, 0.0, None) + frame["dhi"]
        attrs["ghi_source"] = "closure: dni cos(zenith) + dhi"
    elif present == {"ghi"}:
        if decomposition == "erbs":
            parts = pvlib.irradiance.erbs(frame["ghi"], zenith, frame.index)
        elif decomposition == "dirint":
            dni = pvlib.irradiance.dirint(frame["ghi"], zenith, frame.index).fillna(0.0)
            parts = {"dni": dni, "dhi": frame["ghi"] - dni * np.clip(cos_z, 0.0, None)}
        else:
            raise HybridtrackError(f"unknown decomposition {decomposition!r}; choose 'erbs' or 'dirint'")
        frame["dni"] = np.asarray(parts["dni"], float)
        frame["dhi"] = np.clip(np.asarray(parts["dhi"], float), 0.0, None)
        attrs["dni_source"] = f"{decomposition} decomposition of GHI (pvlib)"
        attrs["dhi_source"] = f"{decomposition} decomposition of GHI (pvlib)"
    else:  # only DNI or only DHI: not enough to rebuild the rest
        raise HybridtrackError(f"{path}: only {', '.join(sorted(present))} given; need GHI, or two of GHI, DNI, DHI")
    return frame


def _segments(index: pd.DatetimeIndex, longest: pd.Timedelta) -> list[tuple[pd.Timestamp, pd.Timestamp]]:
    """(first, last) stamp of each stretch of data without a gap longer than `longest`."""
    steps = np.diff(index.as_unit("ns").asi8)
    breaks = np.flatnonzero(steps > longest.value)
    starts = np.concatenate([[0], breaks + 1])
    ends = np.concatenate([breaks, [len(index) - 1]])
    return [(index[a], index[b]) for a, b in zip(starts, ends)]


def _resample(frame: pd.DataFrame, freq: str | None, report: dict, attrs: dict) -> pd.DataFrame:
    from .times import parse_freq

    steps = np.diff(frame.index.as_unit("ns").asi8)
    native = pd.Timedelta(int(np.median(steps)), "ns")
    regular = bool(np.all(steps % native.value == 0))  # whole steps, gaps allowed
    target = parse_freq(freq) if freq is not None else native
    if regular and target == native:
        attrs["resampling"] = f"none (regular {_span(native)} steps)"
        return frame
    columns = [c for c in frame.columns if c not in ("_line", LABEL_COLUMN)]
    # resample each stretch of data on its own, so that a gap stays a gap
    ranges = [pd.date_range(first.floor(target) if target <= pd.Timedelta(days=1) else first, last, freq=target)
              for first, last in _segments(frame.index, 3 * native)]
    grid = ranges[0].append(ranges[1:]) if len(ranges) > 1 else ranges[0]
    if target >= native:  # finer data: mean over each step (labelled at its start)
        binned = frame[columns].resample(target, label="left", closed="left").mean()
        out = binned.reindex(grid)
        method = f"mean over each {_span(target)} step"
    else:  # coarser or irregular data: time interpolation, not across long gaps
        union = frame[columns].reindex(frame.index.union(grid))
        limit = max(int(3 * native / target), 1)
        out = union.interpolate(method="time", limit=limit, limit_area="inside").reindex(grid)
        method = f"linear in time from {_span(native)} to {_span(target)}, gaps over {_span(3 * native)} left empty"
    if not regular:
        method = f"irregular stamps (median step {_span(native)}): " + method
    if LABEL_COLUMN in frame.columns:
        out[LABEL_COLUMN] = frame[LABEL_COLUMN].reindex(out.index, method="ffill")
    attrs["resampling"] = method
    report["resampled"] = method
    out["_line"] = np.nan
    return out


def read_weather(path, *, columns: Mapping[str, str] | None = None, tz: str | None = None, format: str = "csv",
                 site=None, units: Mapping[str, str] | None = None, freq: str | None = None,
                 decomposition: str = "erbs", strict: bool = False) -> pd.DataFrame:
    """A recorded weather file as a checked weather frame.

    Parameters
    ----------
    path : str or Path
    columns : mapping, optional
        Project name to the file's column, e.g. ``{"dni": "Direct Normal", "time": "Stamp"}``;
        names not given are found by their usual headers.
    tz : str, optional
        IANA time zone: localises naive stamps (required for them), converts aware ones.
    format : str
        ``"csv"`` or one of pvlib's formats: epw, tmy3, tmy2, midc, srml, bsrn, surfrad, crn, solrad.
    site : Site or str, optional
        Needed to derive a missing irradiance component from the sun's position.
    units : mapping, optional
        Column name to unit, e.g. ``{"ghi": "kW/m2", "wind_speed": "km/h"}``.
    freq : str, optional
        Resample to this step (e.g. ``"1min"``); irregular data is resampled to its median step.
    decomposition : {"erbs", "dirint"}
        How DNI and DHI are split from GHI alone.
    strict : bool
        Refuse, rather than repair and report, anything the checks find: text in a numeric
        column, unsorted or duplicated stamps, impossible or negative values, DST stamps that
        do not exist. The error names the first offending line.

    Returns
    -------
    pandas.DataFrame
        Columns among ``ghi dni dhi wind_speed temp_air photocurrent``; ``attrs`` holds
        ``validation`` (see `validation_report`), the source of each irradiance column and
        the resampling method.
    """
    from .sites import get

    from .times import check_tz

    path = Path(path)
    fmt = str(format).lower()
    if tz is not None:
        check_tz(tz)
    report: dict = {"source": str(path)}
    if fmt == "csv":
        frame, meta = _read_csv_weather(path, columns, tz, units, report, strict)
    elif fmt in PVLIB_FORMATS:
        frame, meta = _read_pvlib(path, fmt, tz, report)
    else:
        raise HybridtrackError(f"unknown format {format!r}; choose csv, {', '.join(PVLIB_FORMATS)}")
    report.setdefault("rows_read", int(len(frame)))
    if site is None and {"latitude", "longitude"} <= set(meta):
        from .sites import custom

        site = custom(float(meta["latitude"]), float(meta["longitude"]), "UTC",
                      float(meta.get("altitude", 0.0) or 0.0), name=str(meta.get("Name", meta.get("city", "file"))))
    elif site is not None:
        site = get(site)
    frame = _check(path, frame, report)
    if strict:
        _refuse_repairs(path, report)
    attrs: dict = {}
    frame = _complete(path, frame, site, decomposition, attrs)
    frame = _resample(frame, freq, report, attrs)
    frame = frame[[c for c in (*WEATHER_COLUMNS, LABEL_COLUMN) if c in frame.columns]]
    report["rows_out"] = int(len(frame))
    attrs.update(source=str(path), validation=report)
    if site is not None:
        attrs["site"] = site.name
    frame.attrs = attrs
    return frame


def validation_report(frame: pd.DataFrame) -> str:
    """The validation summary of a frame from `read_weather`, as short readable lines."""
    report = frame.attrs.get("validation", {})
    lines = [f"{report.get('source', 'frame')}: {report.get('rows_read', len(frame))} rows read, "
             f"{report.get('rows_out', len(frame))} rows out, step {report.get('step', '?')}"]
    if "format" in report:
        lines.append(f"  format: {report['format'].upper()} (through pvlib)")
    else:
        lines.append(f"  table: {report.get('separator', '?')}-separated, decimal '{report.get('decimal', '.')}', "
                     f"{report.get('header_lines_skipped', 0)} header lines skipped")
    lines.append("  columns: " + ", ".join(f"{k} <- {v!r}" for k, v in report.get("columns", {}).items()))
    lines.append(f"  time: {report.get('time', '?')}")
    labels = {"unreadable": "unreadable values (NaN)", "dst_dropped": "DST: dropped", "dst_repeated": "DST: repeated hour", "unsorted": "unsorted",
              "duplicates": "duplicated stamps", "gaps": "gaps", "nan": "NaN kept", "negative_clipped":
              "negative values clipped to 0", "impossible": "impossible values flagged (NaN)",
              "units_converted": "units converted", "resampled": "resampled"}
    for key, label in labels.items():
        if key in report:
            lines.append(f"  {label}: {_describe(report[key])}")
    for name in IRRADIANCE:
        source = frame.attrs.get(f"{name}_source")
        if source and source != "measured":
            lines.append(f"  {name}: {source}")
    issues = [k for k in ("unreadable", "dst_dropped", "unsorted", "duplicates", "gaps", "nan", "negative_clipped",
                          "impossible") if k in report]
    kinds = f"{len(issues)} kind{'s' if len(issues) > 1 else ''}"
    lines.append("  verdict: " + ("clean" if not issues else f"usable, with {kinds} of issue noted above"))
    return "\n".join(lines)


def _describe(value) -> str:
    if isinstance(value, dict):
        return ", ".join(f"{k} {_describe(v)}" for k, v in value.items())
    if isinstance(value, list):
        return ", ".join(map(str, value))
    return str(value)
