"""The validation report: what was read, from where, and every change made to the data.

`validation_report` prints ``frame.attrs["validation"]`` as short lines: the source, rows in
and out, the date range, how the table and its stamps were read, the columns, findings (gaps,
NaN, light at night, the sun check) and then each change with its count and the first file
lines it touched: renamed, converted, sorted, dropped, set to NaN, clipped, filled,
interpolated, resampled.
"""

from __future__ import annotations

import pandas as pd

from .checks import span
from .resample import native_step

__all__ = ["validation_report", "ISSUES"]

#: Report keys that make the verdict "usable, with issues" rather than "clean".
ISSUES = ("unreadable", "missing_markers", "truncated", "short_rows", "dst_dropped", "unsorted", "duplicates", "gaps", "nan", "negative_in_sun", "negative_clipped", "calm_clipped",
          "impossible", "light_at_night", "wind_missing", "empty_dropped", "sky_unknown")

_FINDINGS = {"gaps": "gaps (kept as gaps)", "nan": "NaN kept", "dst_repeated": "DST: repeated hour",
             "light_at_night": "light while the sun is down (kept)", "wind_missing": "wind: MISSING",
             "nights_left_out": "nights left out", "sky_unknown": "sky labels that name no sky"}

_CHANGES = {
    "padding": "dropped (NUL bytes after the text: a logger card's unwritten tail)",
    "units_converted": "converted", "unreadable": "set to NaN (unreadable text)",
    "truncated": "dropped (a last line cut short)",
    "short_rows": "padded with NaN (lines short of fields)",
    "missing_markers": "set to NaN (a logger's missing-value marker: -9999, 7999, ...)",
    "dst_dropped": "dropped (DST: stamps that do not exist, or repeated ones their order could not place)",
    "unsorted": "sorted (stamps out of order)",
    "duplicates": "dropped (repeated stamps, the first kept)", "impossible": "set to NaN (physically impossible)",
    "negative_in_sun": "set to NaN (negative irradiance with the sun well up: no night offset)",
    "negative_clipped": "clipped to 0 (negative irradiance)", "calm_clipped": "clipped to 0 (anemometer zero offset)",
    "empty_dropped": "dropped (irradiance column without a readable value)", "filled": "filled",
    "nights_filled": "put back (the nights the logger left out, --fill-nights)",
    "sky_rewritten": "rewritten (sky labels in lower case, without spaces)",
    "sky_blank": "set to missing (blank sky labels)",
}


def _describe(value) -> str:
    if isinstance(value, dict):
        return ", ".join(f"{k} {_describe(v)}" for k, v in value.items() if k != "action")
    if isinstance(value, list):
        return ", ".join(map(str, value))
    return str(value)


def _steps(report: dict, frame: pd.DataFrame) -> str:
    """The file's step and, where the frame's differs (resampled), the frame's: the header had
    named the file's step alone beside the rows put on another."""
    read = report.get("step", "?")
    if len(frame) < 2:
        return f"step {read}"
    out = span(native_step(frame.index)[0])
    return f"step {read}" if out == read else f"step {read} read, {out} out"


def _head(report: dict, frame: pd.DataFrame) -> list[str]:
    lines = [f"{report.get('source', 'frame')}: {report.get('rows_read', len(frame))} rows read, "
             f"{report.get('rows_out', len(frame))} rows out, {_steps(report, frame)}",
             f"  dates: {report.get('date_range', '?')}"]
    if "format" in report:
        lines.append(f"  format: {report['format'].upper()} (through pvlib), read as {report.get('read_as', '?')}")
    else:
        kind = "" if report.get("table", "table") == "table" else f"{report['table']}, "
        thousands = f", thousands grouped by {report['thousands']}" if "thousands" in report else ""
        lines.append(f"  table: {kind}{report.get('separator', '?')}-separated, decimal "
                     f"'{report.get('decimal', '.')}'{thousands}, read as {report.get('read_as', '?')}")
        for what, numbers in report.get("skipped", {}).items():
            lines.append(f"  skipped {what}: {len(numbers)} line{'s' if len(numbers) > 1 else ''} "
                         f"({_describe(numbers[:5])}{', ...' if len(numbers) > 5 else ''})")
    lines.append("  columns: " + ", ".join(f"{k} <- {v!r}" for k, v in report.get("columns", {}).items()))
    if report.get("not_read"):
        lines.append(f"  not read: {_describe(report['not_read'])}")
    if report.get("empty_columns"):
        lines.append(f"  skipped {report['empty_columns']} empty column(s) without a name (a spreadsheet's padding)")
    if "header_notes" in report:
        lines.append(f"  header notes (not units, ignored): {_describe(report['header_notes'])}")
    lines.append(f"  time: {report.get('time', '?')}" + "".join(f"; {prefix}{report[key]}" for key, prefix in
                                                            (("offset_written", ""), ("date_order", "dates "),
                                                             ("end_of_day", ""))
                                                            if key in report))
    if "site" in report:
        lines.append(f"  site: {report['site']}")
    if "place" in report:
        lines.append(f"  place: {report['place']}")
    if "sun_check" in report:
        lines.append(f"  sun check: {report['sun_check']}")
    if "closure" in report:
        lines.append(f"  closure: {report['closure']}")
    return lines


def _changes(report: dict) -> list[str]:
    lines = []
    renamed = {k: v for k, v in report.get("columns", {}).items() if v != k}
    if renamed:
        lines.append("    renamed: " + ", ".join(f"{v!r} -> {k}" for k, v in renamed.items()))
    for key, label in _CHANGES.items():
        if key in report:
            lines.append(f"    {label}: {_describe(report[key])}")
    if "resampled" in report:
        entry = report["resampled"]
        counts = ", ".join(f"{k} {v}" for k, v in entry.items() if k not in ("method", "empty_by_column"))
        by_column = f": {_describe(entry['empty_by_column'])}" if entry.get("empty_by_column") else ""
        lines.append(f"    resampled: {entry['method']} ({counts}{by_column})")
    return lines


def validation_report(frame: pd.DataFrame) -> str:
    """The validation summary of a frame from `read_weather`, as short readable lines."""
    report = frame.attrs.get("validation", {})
    lines = _head(report, frame)
    for key, label in _FINDINGS.items():
        if key in report:
            lines.append(f"  {label}: {_describe(report[key])}")
    if frame.attrs.get("wind_data") == "missing" and "wind_missing" not in report:
        lines.append("  wind: MISSING")
    changes = _changes(report)
    lines.append("  changes: " + ("none" if not changes else f"{len(changes)}"))
    lines.extend(changes)
    issues = [k for k in ISSUES if k in report]
    warning = sum(str(report.get(key, "")).startswith("WARNING") for key in ("place", "sun_check", "closure"))
    kinds = f"{len(issues) + warning} kind{'s' if len(issues) + warning > 1 else ''}"
    lines.append("  verdict: " + ("clean" if not issues and not warning else f"usable, with {kinds} of issue noted "
                                                                              "above"))
    return "\n".join(lines)
