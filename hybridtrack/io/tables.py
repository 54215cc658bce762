"""Tables and headers: where a file's table starts, its separator, header, units row and rows.

A weather table is found in text that may carry, before or inside it:

* a block of notes before the header (station, logger, anything);
* comment lines starting with ``#``, anywhere, skipped with their line numbers kept;
* a Campbell Scientific TOA5 header: an environment line (``"TOA5",station,logger,...``),
  the field names, a units row and a processing row (``Smp``, ``Avg``);
* an NSRDB (PSM3, PSM4) or SAM CSV header: a line of names from ``Source`` to ``Latitude``,
  ``Longitude``, ``Time Zone``, ``Elevation`` (and ``GHI Units`` ...) and a line of their values,
  above the table's own header (`Table.site`);
* a units row under the header in other loggers' files;
* a comma, semicolon, tab or bar separator (sniffed on the data's own lines), and decimal
  commas with semicolons anywhere in the table.

Line numbers in every message are the file's own, 1-based, as an editor shows them.
"""

from __future__ import annotations

import contextlib
import csv
import io
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .files import file_text

__all__ = ["Table", "locate_table", "read_table", "numeric_columns", "table_row", "MISSING", "UNITS_ROW_ZONE"]

#: Cell texts that mean "no value" (Campbell writes NAN, spreadsheets #N/A).
MISSING = ("", "nan", "na", "n/a", "#n/a", "-", "null", "none", "--")

_SEPARATORS = {",": "comma", ";": "semicolon", "\t": "tab", "|": "bar"}
_NUMBER = re.compile(r"[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?|[-+]?inf(inity)?", re.I)
#: A number written with a decimal comma (``812,5``), and one with a decimal point (``812.5``).
_COMMA_DECIMAL = re.compile(r"[-+]?\d*,\d+")
_POINT_DECIMAL = re.compile(r"[-+]?\d*\.\d+([eE][-+]?\d+)?")
#: A number whose thousands are grouped with commas beside a decimal point: ``1,060.2``, ``12,000``
#: (never ``0,812``: a group starts with a digit other than 0).
COMMA_GROUPED = re.compile(r"[-+]?[1-9]\d{0,2}(,\d{3})+(\.\d*)?")
#: An ISO 8601 stamp, whose ``T`` is no letter of a column's name.
_ISO_STAMP = re.compile(r"\s*\d{4}-\d{2}-\d{2}T\d")


@dataclass
class Table:
    """A located table: its header, rows (as text) and the file line of each row."""

    headers: list[str]
    rows: list[list[str]]
    lines: np.ndarray
    separator: str
    decimal: str
    units: dict[str, str] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)
    skipped: dict[str, list[int]] = field(default_factory=dict)
    kind: str = "table"
    #: An NSRDB or SAM CSV file's site lines: each name of the first with its value in the second,
    #: and that second line's number.
    site: dict[str, str] = field(default_factory=dict)
    site_line: int = 0
    #: The last row, when it alone has fewer fields than the header (a logger that lost power
    #: mid-line): how many fields it has. Its last field may be a number cut short (``645.3``
    #: written as ``64``), so it is not read (`hybridtrack.io.weather`).
    cut_short: int = 0
    #: The other rows with fewer fields than the header, padded with empty cells: each's file line
    #: and how many fields it has (`hybridtrack.io.weather` reports those missing a column it reads).
    short: dict[int, int] = field(default_factory=dict)


#: The longest field the csv module is let read: Python's default, 131,072 characters, had
#: stopped a file with one long note line or one corrupted cell with a traceback. The text is
#: in memory already, so no field can be longer than it; 2**31 - 1 fits a C long everywhere.
_FIELD_LIMIT = 2**31 - 1


@contextlib.contextmanager
def _long_fields() -> Iterator[None]:
    """Let the csv module read fields of any length while a table is read (then as before)."""
    previous = csv.field_size_limit(_FIELD_LIMIT)
    try:
        yield
    finally:
        csv.field_size_limit(previous)


def _split(line: str, sep: str) -> list[str]:
    return next(csv.reader([line], delimiter=sep))


def _kept_lines(text: str) -> tuple[list[tuple[int, str]], list[int]]:
    """(line number, text) of every line that is not blank or a ``#`` comment, and the comment lines."""
    kept, comments = [], []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            comments.append(number)
            continue
        kept.append((number, line))
    return kept, comments


def _is_number(cell: str) -> bool:
    return bool(_NUMBER.fullmatch(cell.strip()))


#: A units row's cell for the time column that is a UTC offset (``UTC+8``, ``[GMT-05:00]``): its
#: digits are no stamp's.
UNITS_ROW_ZONE = re.compile(r"[\[(]?\s*(?:UTC|GMT)\s*(?:[+-]\d{1,2}(?::?\d{2})?)?\s*[\])]?", re.I)


def _meta_row(fields: list[str]) -> bool:
    """A units or processing row: no cell is a number and the first cell has no digit (no stamp)
    unless it is a UTC offset (`UNITS_ROW_ZONE`: such a row had been refused as a time stamp)."""
    cells = [f.strip() for f in fields]
    first = cells[0] if cells and not UNITS_ROW_ZONE.fullmatch(cells[0]) else ""
    return not any(_is_number(c) for c in cells if c) and not re.search(r"\d", first)


def _named(field: str) -> bool:
    """Whether a field may be a column's name: it has letters, and is no ISO stamp (``...T12:00``)."""
    return bool(re.search(r"[A-Za-z]", field)) and not _ISO_STAMP.match(field)


def _choose_separator(path: Path, kept: list[tuple[int, str]]) -> tuple[int, str]:
    """Index (into `kept`) of the header and the separator.

    For each separator the data's usual field count is read off the last lines; the header is
    the first line with that many fields of which one is a name (`_named`). The separator that
    splits the rows below its header most consistently (then widest, then with the earlier
    header) wins: ``2021-06-21T12:00:00;812,5;...`` split at its commas had been taken for a
    header, its ``T`` for a name.
    """
    tail = [line for _, line in kept[-30:]]
    best = None
    for sep in _SEPARATORS:
        counts = [len(_split(line, sep)) for line in tail]
        width = max(set(counts), key=counts.count)
        if width < 2:
            continue
        for position, (_, line) in enumerate(kept):
            fields = _split(line, sep)
            if len(fields) == width and any(_named(f) for f in fields):
                rest = kept[position + 1:]
                sample = rest[::max(1, len(rest) // 500)]  # enough lines to judge, in big files too
                below = [len(_split(x, sep)) for _, x in sample]
                share = below.count(width) / max(len(below), 1)
                if best is None or (share, width, -position) > best[0]:
                    best = ((share, width, -position), position, sep)
                break
    if best is None:
        raise HybridtrackError(f"{path}: no table found: no header row of named columns separated by comma, "
                               "semicolon, tab or bar")
    return best[1], best[2]


def _header_after_hint(path: Path, kept: list[tuple[int, str]], sep: str) -> tuple[int, str, str]:
    if len(kept) < 2:
        raise HybridtrackError(f"{path}: no table found after the 'sep={sep}' line")
    return 0, sep, f"table with Excel's 'sep={sep}' line"


def _without_repeated_header(rows: list[list[str]], numbers: list[int], preamble: list[list[str]],
                             skipped: dict) -> tuple[list[list[str]], list[int]]:
    """`rows` without the lines that repeat the header or a line above or below it (`preamble`: a
    TOA5 file's environment line, units and processing rows; a logger restarted, daily files
    joined with ``cat``), which are skipped and listed: such a header had been refused as a time
    stamp, and a TOA5 environment line as a row longer than the header."""
    again = [i for i, fields in enumerate(rows) if [f.strip() for f in fields] in preamble]
    if not again:
        return rows, numbers
    skipped["repeated header lines"] = [numbers[i] for i in again]
    drop = set(again)
    keep = [i for i in range(len(rows)) if i not in drop]
    return [rows[i] for i in keep], [numbers[i] for i in keep]


def _rows(path: Path, body: list[tuple[int, str]], sep: str, headers: list[str], header_line: int,
          skipped: dict, preamble: list[list[str]]) -> tuple[list[list[str]], list[int], int, dict[int, int]]:
    """The rows' fields, each as long as `headers`, and their file lines; empty rows and lines
    repeating the `preamble` (the header and the lines about it, each as stripped fields) skipped,
    long rows refused; the field count of a last row cut short (`Table.cut_short`, else 0); and
    the other short rows' lines and field counts (`Table.short`)."""
    width = len(headers)
    empty = [not line.strip(sep + ' \t"') for _, line in body]  # ';;;;': a row the logger left empty
    if any(empty):
        skipped["empty rows"] = [number for (number, _), blank in zip(body, empty) if blank]
        body = [entry for entry, blank in zip(body, empty) if not blank]
    rows = list(csv.reader([line for _, line in body], delimiter=sep))
    numbers = [number for number, _ in body]
    if len(rows) != len(numbers):
        _refuse_open_quote(path, body)
    rows, numbers = _without_repeated_header(rows, numbers, preamble, skipped)
    short = [len(fields) < width for fields in rows]
    cut_short = len(rows[-1]) if len(rows) > 2 and short[-1] and not any(short[:-1]) else 0
    padded = {numbers[i]: len(fields) for i, fields in enumerate(rows) if short[i]}
    if cut_short:
        padded.pop(numbers[-1])
    for i, fields in enumerate(rows):
        if len(fields) == width:
            continue
        if len(fields) > width and any(f.strip() for f in fields[width:]):
            raise HybridtrackError(f"{path}: line {numbers[i]}: {len(fields)} fields, but the header on line "
                                   f"{header_line} names {width}")
        rows[i] = fields[:width] + [""] * (width - len(fields))
    return rows, numbers, cut_short, padded


def _refuse_open_quote(path: Path, body: list[tuple[int, str]]) -> None:
    """Refuse the first line whose quote is never closed: the csv module would read every line
    after it into that one field, and the rows would no longer match their lines."""
    for number, line in body:
        if line.count('"') % 2:
            raise HybridtrackError(f"{path}: line {number}: a quote (\") opens a field and is never closed")
    raise HybridtrackError(f"{path}: the rows cannot be told apart (a field spans lines)")


def rows_with_values(body: list[tuple[int, str]], sep: str) -> bool:
    return any(any(f.strip() for f in _split(line, sep)) for _, line in body)


def _header(path: Path, kept: list[tuple[int, str]]) -> tuple[list, int, str, str, dict[str, str]]:
    """The lines from Excel's ``sep=`` line on, the header's index in them, the separator, the
    table's kind and an NSRDB or SAM CSV file's site (see the module's notes)."""
    first = _split(kept[0][1], ",")
    hint = re.fullmatch(r"\s*sep=(.)\s*", kept[0][1])  # Excel's separator line
    if hint and hint.group(1) in _SEPARATORS:
        return kept[1:], *_header_after_hint(path, kept[1:], hint.group(1)), {}
    if first and first[0].strip().upper() == "TOA5":
        if len(kept) < 5:
            raise HybridtrackError(f"{path}: a TOA5 file needs its four header lines and data")
        return kept, 1, ",", f"Campbell TOA5 ({', '.join(c for c in first[1:3] if c)})", {}
    if _site_header(first):
        if len(kept) < 4:
            raise HybridtrackError(f"{path}: an NSRDB or SAM CSV file needs its site lines, a header and data")
        if not any(_is_number(cell) for cell in _split(kept[1][1], ",")):
            raise HybridtrackError(f"{path}: line {kept[1][0]}: no number under line {kept[0][0]}'s names (Latitude, "
                                   "Longitude, ...): an NSRDB or SAM CSV file's second line holds the site's values")
        return kept, 2, ",", "NSRDB / SAM CSV (the site on lines 1-2)", _site_values(first, kept)
    return kept, *_choose_separator(path, kept), "table", {}


@_long_fields()
def locate_table(path: Path, text: str) -> Table:
    """The weather table in `text` (see the module's notes)."""
    kept, comments = _kept_lines(text)
    if len(kept) < 2:
        raise HybridtrackError(f"{path}: no table found (fewer than two lines of data)")
    kept, position, sep, kind, site = _header(path, kept)
    headers = [h.strip() for h in _split(kept[position][1], sep)]
    skipped = {"notes before the header": [] if site else [n for n, _ in kept[:position]], "comments": comments}
    body = kept[position + 1:]
    meta = []
    while body and len(meta) < 2 and _meta_row(_split(body[0][1], sep)):
        meta.append(_split(body[0][1], sep))
        skipped.setdefault("units and processing rows", []).append(body[0][0])
        body = body[1:]
    if not body or not rows_with_values(body, sep):
        raise HybridtrackError(f"{path}: the table has a header but no rows")
    preamble = [[f.strip() for f in fields] for fields in (*(_split(line, sep) for _, line in kept[:position]),
                                                          headers, *meta)]
    rows, numbers, cut_short, padded = _rows(path, body, sep, headers, kept[position][0], skipped, preamble)
    units = {h: u.strip() for h, u in zip(headers, meta[0])} if meta else {}
    units.update({h: site[f"{h} Units"] for h in headers if site.get(f"{h} Units")})  # NSRDB: 'GHI Units'
    decimal = _decimal(sep, rows)
    return Table(headers, rows, np.asarray(numbers), sep, decimal, units=units, skipped=skipped, kind=kind,
                 site=site, site_line=kept[1][0] if site else 0, cut_short=cut_short, short=padded)


def _site_header(first: list[str]) -> bool:
    """Whether a file's first line names an NSRDB or SAM CSV file's site: ``Source``, ...,
    ``Latitude``, ``Longitude``, ``Time Zone`` (a mobile logger's header ``Source,Latitude,
    Longitude,Timestamp,...`` is no such line)."""
    names = [name.strip() for name in first]
    return bool(names) and names[0] == "Source" and {"Latitude", "Longitude", "Time Zone"} <= set(names)


def _site_values(first: list[str], kept: list[tuple[int, str]]) -> dict[str, str]:
    """Each name of an NSRDB or SAM CSV file's first line with its value in the second."""
    return {name.strip(): value.strip() for name, value in zip(first, _split(kept[1][1], ",")) if name.strip()}


def _decimal(sep: str, rows: list[list[str]]) -> str:
    """The table's decimal mark: ``','`` where a cell is a number written with a decimal comma, in
    a semicolon-separated table any (``0,5``, ``1,060``); in a tab-, bar- or comma-separated one
    (the cell quoted) one that is no group of thousands (``812,5``, ``0,812``, not ``1,060``), where
    no number has a decimal point. Such tables had been refused, every number unreadable."""
    commas = (cell for cell in (f.strip() for row in rows for f in row if "," in f) if _COMMA_DECIMAL.fullmatch(cell))
    if sep == ";":
        return "," if next(commas, None) is not None else "."
    if all(COMMA_GROUPED.fullmatch(cell) for cell in commas):  # stops at the first that is no group
        return "."
    points = (f.strip() for row in rows for f in row if "." in f)
    return "." if any(_POINT_DECIMAL.fullmatch(cell) for cell in points) else ","


@_long_fields()
def read_table(path) -> pd.DataFrame:
    """A small table from CSV (comma, semicolon or tab) or TOML (``[[case]]`` rows).

    Lines starting with ``#`` in a CSV are comments. Column names are stripped and lowered.
    """
    from .files import _tomllib, input_path

    path = input_path(path, "table")
    text = file_text(path)[0]
    if path.suffix.lower() == ".toml":
        tomllib = _tomllib()
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise HybridtrackError(f"{path}: not valid TOML: {exc}") from None
        rows = data.get("case", data.get("cases"))
        if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
            raise HybridtrackError(f"{path}: expected an array of [[case]] tables")
        for number, row in enumerate(rows, 1):
            _refuse_repeated_names(path, [str(key).strip().lower() for key in row], f"case {number}")
        frame = pd.DataFrame(rows)
    else:
        kept = _kept_lines(text)[0]
        sep = _table_separator(path, kept)
        options = dict(sep=sep, engine="python", comment="#", skipinitialspace=True, index_col=False)
        with _as_csv_error(path):  # the header as pandas reads it (quotes, spaces, a '#'), before it renames repeats
            names = pd.read_csv(io.StringIO(text), header=None, nrows=1, dtype=str, **options).iloc[0] if kept else []
        _refuse_repeated_names(path, [str(n).strip().lower() for n in names], f"line {kept[0][0]}" if kept else "")
        _refuse_long_rows(path, kept, sep, len(names))
        with _as_csv_error(path):
            frame = pd.read_csv(io.StringIO(text), **options)
    frame.columns = [str(c).strip().lower() for c in frame.columns]
    if frame.empty:
        raise HybridtrackError(f"{path}: the table has no rows")
    frame.attrs["source"] = str(path)
    if path.suffix.lower() != ".toml":
        lines = [number for number, _ in _kept_lines(text)[0][1:]]  # the rows' own lines, comments skipped
        if len(lines) == len(frame):
            frame.attrs["lines"] = lines
    return frame


def _table_separator(path: Path, kept: list[tuple[int, str]]) -> str:
    """A small table's separator, chosen as for a weather file (`_choose_separator`: comma,
    semicolon, tab or bar); a comma for a table of one column, which any separator reads."""
    if len(kept) < 2:
        return ","
    try:
        return _choose_separator(path, kept)[1]
    except HybridtrackError:
        return ","


@contextlib.contextmanager
def _as_csv_error(path: Path) -> Iterator[None]:
    """pandas' and csv's refusals of a table as one `HybridtrackError` naming the file."""
    try:
        yield
    except HybridtrackError:
        raise
    except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError, csv.Error) as exc:
        raise HybridtrackError(f"{path}: cannot read as CSV: {str(exc).splitlines()[0]}") from None


def _refuse_repeated_names(path: Path, names: list[str], where: str) -> None:
    """Refuse a header naming a column twice (column names are read stripped and lowered, so
    ``east`` and ``EAST`` are one name): pandas would keep one and rename or drop the other."""
    seen = set()
    for name in names:
        if name and name in seen:
            raise HybridtrackError(f"{path}: {where}: column {name!r} appears more than once in the header; "
                                   "rename one")
        seen.add(name)


def _refuse_long_rows(path: Path, kept: list[tuple[int, str]], sep: str, width: int) -> None:
    """Refuse a row with more fields than its header names (`width`, as pandas reads the header:
    a ``#`` ends it): pandas would take the first column for an index and shift every value one
    column left (or, told not to, drop the last ones)."""
    for number, line in kept[1:]:
        fields = _split(line, sep)
        if len(fields) > width and any(f.strip() for f in fields[width:]):
            raise HybridtrackError(f"{path}: line {number}: {len(fields)} fields, but the header on line "
                                   f"{kept[0][0]} names {width}")


def table_row(frame: pd.DataFrame, position: int) -> int:
    """The file's row of a table's row at `position`, as a spreadsheet shows it: `read_table`
    keeps each row's line past comment and blank lines; else the header counts as row 1."""
    lines = frame.attrs.get("lines")
    label = frame.index[position]
    if lines is not None and isinstance(label, (int, np.integer)) and 0 <= label < len(lines):
        return int(lines[label])
    return position + 2


def numeric_columns(frame: pd.DataFrame, columns, where: str, *, required=()) -> pd.DataFrame:
    """`frame` with `columns` (those present) as floats; text in one names its row and column.

    An infinite cell (``inf``, ``1e400``) is refused: no reading is infinite. An empty cell is
    NaN, or refused in a column of `required`. Row numbers are the file's, as a spreadsheet
    shows them (`read_table` keeps them past comment lines); else the header counts as row 1.
    """
    frame = frame.copy()
    for column in columns:
        if column not in frame.columns:
            continue
        cells = frame[column]
        truth = cells.map(lambda v: isinstance(v, (bool, np.bool_))).to_numpy(bool)  # pandas reads True as 1
        values = pd.to_numeric(cells.mask(truth), errors="coerce")
        bad = (values.isna() & cells.notna()).to_numpy()
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            cell = repr(str(cells.iloc[row])) if truth[row] else repr(cells.iloc[row])  # 'True', as the file has it
            raise HybridtrackError(f"{where}: row {table_row(frame, row)}, column {column!r}: {cell} is not a number")
        values = values.astype(float)
        refused = np.isinf(values.to_numpy()) | (values.isna().to_numpy() if column in required else False)
        if refused.any():
            row = int(np.flatnonzero(refused)[0])
            what = "empty or NaN" if np.isnan(values.iloc[row]) else f"{values.iloc[row]} is not a finite number"
            raise HybridtrackError(f"{where}: row {table_row(frame, row)}, column {column!r}: {what}")
        frame[column] = values
    return frame
