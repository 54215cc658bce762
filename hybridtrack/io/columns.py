"""Column names: which of a file's columns holds each quantity.

A header is split into its name and a bracketed part (``'GHI [kW/m2]'``); the bracketed part
is a unit when it spells one (`units.any_known_unit`), else a note (``'(vent/cor)'``) that is
reported and otherwise ignored. The name is compared, lower-cased, with `ALIASES` after a
logger's averaging suffix (``_Avg``, ``_Smp``, ``_S_WVT`` ...) is removed, so ``GHI_Avg`` and
``WS_ms_S_WVT`` are found; a statistic's (``_Std``, ``_Max`` ...) is not, so ``WS_ms_Std`` is not
the wind. Two columns that match one quantity are refused. The user's mapping (``--map NAME=COLUMN``) comes first and may name
any column; it is refused when it names an unknown quantity, a missing column, or one column
for two quantities. docs/records.md lists the aliases.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from ..errors import HybridtrackError, quoted_cut
from .units import any_known_unit

__all__ = ["WEATHER_COLUMNS", "IRRADIANCE", "LABEL_COLUMN", "ALIASES", "UNNAMED", "STAMP_PARTS", "split_header",
           "resolve_columns", "check_names", "not_read", "label_header"]

#: The columns of a weather frame, in order.
WEATHER_COLUMNS = ("ghi", "dni", "dhi", "wind_speed", "temp_air", "photocurrent", "pointing", "pointing_2")
IRRADIANCE = ("ghi", "dni", "dhi")

#: A column of true sky labels (e.g. in synthetic records), kept as text for scoring.
LABEL_COLUMN = "sky"

#: The name of a column without a header (pandas writes its index so); ``--map time=`` names it.
UNNAMED = ""

#: Usual header names of each column, lower-cased, after brackets and statistics suffixes are removed.
ALIASES = {
    "time": ("time", "timestamp", "datetime", "date_time", "date time", "date/time", "time stamp", "tmstamp",
             "utc", "local time", "time_utc", "epoch", "unix time", "unixtime", UNNAMED, "unnamed: 0", "index",
             "zeit", "zeitstempel", "datum/zeit", "horodatage", "date heure", "date et heure", "fecha hora",
             "fecha y hora"),
    "date": ("date", "day", "date (mm/dd/yyyy)", "yyyy-mm-dd", "datum", "fecha"),
    "clock": ("time", "hour", "clock", "hh:mm", "time (hh:mm)", "mst", "pst", "lst", "est", "cst", "uhrzeit", "hora",
              "heure"),
    "ghi": ("ghi", "global", "global horizontal", "global_horizontal", "global horizontal irradiance",
            "global irradiance", "glo", "gh", "ghi_wm2", "slrw", "sw_in", "swdown", "global_irradiance",
            "global_horiz", "ghi_pyr", "g_h", "dw_solar", "rayonnement global"),
    "dni": ("dni", "direct normal", "direct_normal", "direct normal irradiance", "direct", "beam", "dn", "dni_wm2",
            "direct_normal_irradiance", "dni_pyr", "b_n", "direct_n", "rayonnement direct"),
    "dhi": ("dhi", "diffuse", "diffuse horizontal", "diffuse_horizontal", "diffuse horizontal irradiance", "dif",
            "dhi_wm2", "diffuse_horizontal_irradiance", "d_h", "rayonnement diffus"),
    "wind_speed": ("wind_speed", "wind speed", "windspeed", "windgeschwindigkeit", "vitesse du vent",
                   "wind", "ws", "wspd", "ws_ms", "wind_ms", "avg wind speed", "wind speed avg", "wsp"),
    "temp_air": ("temp_air", "air temperature", "temperature", "temp", "tair", "t_air", "ta", "airtc", "airtk",
                 "air_temp", "tamb", "t_amb", "ambient temperature", "dry bulb", "drybulb", "temp_c", "t2m",
                 "dry bulb temp", "tower dry bulb temp", "tdry", "temperatur", "température", "temperatura",
                 "lufttemperatur"),
    "photocurrent": ("photocurrent", "photocurrent_ma", "intensity", "intensity_ma", "sensor current"),
    # the sun sensor's pointing signal: the sun's offset from its axis, on each axis it serves
    "pointing": ("pointing", "pointing_deg", "sensor_offset", "sensor offset", "sun sensor offset", "pointing_1",
                 "sensor_offset_1"),
    "pointing_2": ("pointing_2", "sensor_offset_2"),
}

#: A stamp written in columns of its own, as NSRDB and SAM CSV files write it: year, month, day,
#: hour and (optionally) minute. Read as a date column and a clock column, it had been the day of
#: the month and the hour alone.
STAMP_PARTS = ("year", "month", "day", "hour", "minute")

#: Suffixes loggers append to a measurement's name that keep it the quantity (Campbell: _Avg,
#: _Smp, _S_WVT ...). A statistic of it (_Std, _Tot, _Max, _Min, _Count ...) keeps its suffix, so
#: it is never taken for the quantity: ``WS_ms_Std`` listed first had been read as the wind.
_SUFFIX = re.compile(r"(_(avg|mean|smp|sample|s_wvt|wvt|wvc))+$")
_BRACKETS = re.compile(r"\s*[\[(]([^\])]*)[\])]\s*")


def split_header(header: str) -> tuple[str, str | None, str | None]:
    """``'GHI [kW/m2]'`` -> (``'ghi'``, ``'kW/m2'``, None); ``'DNI (vent/cor)'`` -> (``'dni'``, None, ``'vent/cor'``).

    The part of a bracket before a comma is its unit when it spells one (``'Wind (km/h, 10-min
    mean)'`` -> ``'km/h'``, note ``'10-min mean'``). The name is lower-cased, stripped of brackets
    and of a logger's averaging suffix.
    """
    unit, notes = None, []
    for match in _BRACKETS.finditer(header):
        inner = match.group(1).strip()
        candidate, _, rest = inner.partition(",")  # '(km/h, 10-min mean)': a unit, then a note
        if unit is None and any_known_unit(candidate):
            unit = candidate.strip()
            notes.append(rest.strip())
        else:
            notes.append(inner)
    note = "; ".join(part for part in notes if part) or None
    name = re.sub(r"\s*@.*$", "", _BRACKETS.sub(" ", header)).strip().lower()  # 'Wind Speed @ 6ft'
    name = re.sub(r"\s+", " ", name)
    if name == UNNAMED or name.startswith("unnamed:"):
        return (UNNAMED if header.strip().lower() in (UNNAMED, "unnamed: 0") else name), unit, note
    return _SUFFIX.sub("", name), unit, note


def check_names(mapping: Mapping[str, str], flag: str) -> None:
    """Refuse a mapping that names an unknown quantity (``--units beam=...``), or is no mapping of
    quantities to text (from Python: ``units="kW/m2"`` had been read letter by letter, a list or a
    number raised Python's own errors)."""
    example = "{'ghi': 'Global'}" if flag == "--map" else "{'ghi': 'kW/m2'}"
    if not isinstance(mapping, Mapping):
        shown = " ".join(repr(mapping).split())  # one line, whatever its repr spans
        raise HybridtrackError(f"{flag} must map quantities to text, e.g. {example}; got {type(mapping).__name__} "
                               f"{shown:.40}")
    allowed = ("time", *WEATHER_COLUMNS) if flag == "--map" else WEATHER_COLUMNS
    for name, value in mapping.items():
        if not isinstance(name, str) or name not in allowed:  # pd.NA had raised TypeError
            raise HybridtrackError(f"unknown column name {name!r:.40} in {flag}; use {', '.join(allowed)}")
        if not isinstance(value, str):
            raise HybridtrackError(f"{flag} {name}: give text, e.g. {example}; got {value!r:.40}")
        if flag == "--units" and not value.strip():  # had been taken as no unit given, without a word
            raise HybridtrackError(f"{flag} {name}: the unit is empty; give one, e.g. {example}, or leave {name} out "
                                   "to read the header's")


#: The longest column name read as a quantity's: the longest aliases with a unit and a note
#: (``Direct Normal Irradiance (W/m^2) [CHP1 s/n 123456]``) are under 100 characters. A header
#: cell of a million characters (a corrupted first line) had taken 3 seconds to match per
#: million, and was printed whole in the report's ``not read`` line.
LONGEST_NAME = 256


def name_shown(header: str) -> str:
    """A column's name as a message or the report quotes it: a long one cut, with its length."""
    return quoted_cut(header, LONGEST_NAME)


def _matches(header: str, name: str) -> bool:
    if len(header) > LONGEST_NAME:
        return False
    base = split_header(header)[0]
    return base in ALIASES[name] or (name == "time" and header.strip().lower() in ALIASES["time"])


def resolve_columns(where: str, headers: list[str], columns: Mapping[str, str] | None) -> dict[str, str]:
    """Quantity -> file header, from the user's mapping first, then `ALIASES`.

    The result may hold ``date`` and ``clock`` instead of ``time`` when the file keeps them in
    two columns, or `STAMP_PARTS` when it keeps the stamp in columns of its own.
    """
    columns = dict(columns or {})
    check_names(columns, "--map")
    mapping: dict[str, str] = {}
    for name, header in columns.items():
        found = _find(headers, header)
        if found is None:
            shown = ", ".join(name_shown(h) if not h.strip() or len(h) > LONGEST_NAME else h for h in headers)
            raise HybridtrackError(f"{where}: no column {header!r} (mapped to {name}); columns are {shown}")
        twice = next((other for other, taken in mapping.items() if taken == found), None)
        if twice is not None:
            raise HybridtrackError(f"{where}: column {found!r} is mapped to both {twice} and {name}; "
                                   "one column holds one quantity")
        mapping[name] = found
    taken = set(mapping.values())
    # pandas' index written out ('', 'Unnamed: 0', 'index' after reset_index) is the time only when
    # no column is named for it: a counter 0, 1, 2 had been taken over a 'time' column beside it
    unnamed_last = sorted(headers, key=lambda h: h.strip().lower() in (UNNAMED, "unnamed: 0", "index"))
    for name in ("time", *WEATHER_COLUMNS):
        if name in mapping:
            continue
        found = [h for h in unnamed_last if h not in taken and _matches(h, name)]
        if len(found) > 1 and name != "time":
            raise HybridtrackError(f"{where}: columns {found[0]!r} and {found[1]!r} both look like {name}; say "
                                   f"which holds it with --map {name}=COLUMN (columns={{{name!r}: ...}})")
        if found:
            mapping[name] = found[0]
            taken.add(found[0])
    if "time" not in mapping and _stamp_parts(headers, taken, mapping):
        return mapping
    if "time" not in mapping or split_header(mapping["time"])[0] in ALIASES["clock"] and "time" not in columns:
        _date_and_clock(headers, taken, mapping)
    return mapping


def not_read(headers: list[str], mapping: Mapping[str, str]) -> list[str]:
    """The named columns no quantity was read from, each with the quantity its name looks like
    when it has one (``'ghi' (looks like ghi)``: a ``--map ghi=OTHER`` left the file's own ghi
    unread), for the report: a column the reading passes over is said, not dropped unseen."""
    taken = {*mapping.values(), label_header(headers)}  # a second sky column had been passed over unsaid
    shown = []
    for header in headers:
        if header in taken or not header.strip():
            continue
        like = next((name for name in WEATHER_COLUMNS if _matches(header, name)), None)
        if like is None and split_header(header)[0] == LABEL_COLUMN:
            like = f"{LABEL_COLUMN}; the first, {name_shown(label_header(headers))}, is read"
        shown.append(name_shown(header) + (f" (looks like {like})" if like else ""))
    return shown


def label_header(headers: list[str]) -> str | None:
    """The header of the true-sky labels: the first named `LABEL_COLUMN` (``'Sky'``, ``'sky [label]'``)."""
    return next((h for h in headers if split_header(h)[0] == LABEL_COLUMN), None)


def _stamp_parts(headers: list[str], taken: set, mapping: dict[str, str]) -> bool:
    """Whether the stamp is in columns of its own (`STAMP_PARTS`: a minute column is optional);
    they are then put in `mapping`."""
    found = {split_header(h)[0]: h for h in reversed(headers) if h not in taken}
    if not all(part in found for part in STAMP_PARTS[:4]):
        return False
    mapping.update({part: found[part] for part in STAMP_PARTS if part in found})
    return True


def _find(headers: list[str], wanted: str) -> str | None:
    """The header the user meant: exact, then stripped and case-insensitive; '' or 'Unnamed: 0' is the unnamed one."""
    if wanted in headers:
        return wanted
    key = wanted.strip().lower()
    if key in (UNNAMED, "unnamed: 0"):
        return next((h for h in headers if h.strip().lower() in (UNNAMED, "unnamed: 0")), None)
    return next((h for h in headers if h.strip().lower() == key), None)


def _date_and_clock(headers: list[str], taken: set, mapping: dict[str, str]) -> None:
    """Separate ``date`` and ``time`` columns: both are kept for the stamps to combine."""
    date = next((h for h in headers if h not in taken and split_header(h)[0] in ALIASES["date"]), None)
    if date is None:
        return
    clock = mapping.get("time") or next((h for h in headers if h not in taken
                                         and split_header(h)[0] in ALIASES["clock"]), None)
    mapping.pop("time", None)
    if clock is None:
        mapping["time"] = date  # one column named 'date' may hold whole stamps
    else:
        mapping["date"], mapping["clock"] = date, clock
