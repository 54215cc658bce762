"""Resampling to the control step, for any step (also one that does not divide a day).

The grid starts at local midnight of the first day and runs in whole steps from there, so a
7-minute grid continues across midnight instead of restarting. Each stretch of data without a
gap longer than three native steps is resampled on its own, so a gap stays a gap:

* a step at least as long as the data's: the mean of the readings in each step, labelled at
  its start;
* a shorter step (or irregular data): linear interpolation in time between two neighbouring
  readings that both have a value, never across a gap or beside a NaN reading; a stamp the
  data has keeps its value, NaN included (a flagged value is never filled).

The report counts the rows made, the new rows given a value (``interpolated``) or the steps with
a reading (``averaged``), and the values left empty (``empty``, a step empty in two columns
counting twice, and ``empty_by_column``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..budget import check_steps
from ..errors import HybridtrackError
from .checks import span
from .columns import LABEL_COLUMN, WEATHER_COLUMNS

__all__ = ["resample", "native_step", "logger_step", "LOGGER_STEPS"]


def _segments(index: pd.DatetimeIndex, longest: pd.Timedelta) -> list[tuple[pd.Timestamp, pd.Timestamp]]:
    """(first, last) stamp of each stretch of data without a gap longer than `longest`."""
    steps = np.diff(index.as_unit("ns").asi8)
    breaks = np.flatnonzero(steps > longest.value)
    starts = np.concatenate([[0], breaks + 1])
    ends = np.concatenate([breaks, [len(index) - 1]])
    return [(index[a], index[b]) for a, b in zip(starts, ends)]


def _grid(index: pd.DatetimeIndex, native: pd.Timedelta, target: pd.Timedelta) -> tuple[pd.DatetimeIndex, pd.Timestamp]:
    origin = index[0].normalize() if index.tz is None else index[0].tz_convert(index.tz).normalize()
    parts = []
    for first, last in _segments(index, 3 * native):
        start = origin + ((first - origin) // target) * target
        parts.append(pd.date_range(start, last, freq=target))
    grid = parts[0].append(parts[1:]) if len(parts) > 1 else parts[0]
    return grid[~grid.duplicated()], origin


def _interpolated(series: pd.Series, grid: pd.DatetimeIndex, longest: pd.Timedelta) -> np.ndarray:
    """`series` linear in time at `grid`, only between two neighbouring readings that both have a
    value and are at most `longest` apart; a stamp the data has keeps its value, NaN included.

    pandas' ``interpolate(limit=...)`` had filled the first points of every NaN stretch from the
    readings around it (an afternoon missing from an hourly file got 12:01 = 889 W/m²).
    """
    stamps, grid_ns, values = series.index.as_unit("ns").asi8, grid.as_unit("ns").asi8, series.to_numpy(float)
    after = np.searchsorted(stamps, grid_ns, side="right")
    before, after = np.clip(after - 1, 0, len(stamps) - 1), np.clip(after, 0, len(stamps) - 1)
    span_ns = stamps[after] - stamps[before]
    inside = (stamps[before] <= grid_ns) & (grid_ns < stamps[after]) & (span_ns <= longest.value)
    weight = (grid_ns - stamps[before]) / np.where(span_ns > 0, span_ns, 1)
    out = np.where(inside, values[before] + weight * (values[after] - values[before]), np.nan)  # NaN beside a NaN
    exact = stamps[before] == grid_ns
    out[exact] = values[before][exact]
    return out


def _left_empty(out: pd.DataFrame) -> dict:
    """The values the resampled columns were left without: ``empty`` in all, and
    ``empty_by_column`` for each column that has any."""
    by_column = {column: int(count) for column, count in out.isna().sum().items() if count}
    return {"empty": sum(by_column.values()), "empty_by_column": by_column}


#: The steps loggers record at. Stamps that jitter about one of them (a logger's clock stamping a
#: second late now and then) have a median step beside it (61 s): they are put on its grid, not on
#: one of their median (a 1-minute file had been averaged onto 61-second steps, 300 rows to 295).
LOGGER_STEPS = tuple(pd.Timedelta(step) for step in (
    "1s", "2s", "5s", "10s", "15s", "20s", "30s", "1min", "2min", "3min", "5min", "10min", "15min", "20min",
    "30min", "1h", "2h", "3h", "6h", "12h", "1D"))
#: How far a median step may lie from a logger's step and be taken for it: a twentieth of it.
LOGGER_STEP_TOLERANCE = 0.05


def native_step(index: pd.DatetimeIndex) -> tuple[pd.Timedelta, bool]:
    """The median step of `index` and whether every step is a whole number of it (gaps allowed)."""
    steps = np.diff(index.as_unit("ns").asi8)
    native = pd.Timedelta(int(np.median(steps)), "ns")
    return native, bool(np.all(steps % native.value == 0))


def logger_step(native: pd.Timedelta) -> pd.Timedelta:
    """The logger's step (`LOGGER_STEPS`) within `LOGGER_STEP_TOLERANCE` of a median step, or the median."""
    near = [step for step in LOGGER_STEPS if abs(native - step) <= LOGGER_STEP_TOLERANCE * step]
    return near[0] if near else native


def resample(frame: pd.DataFrame, freq: str | None, report: dict, attrs: dict) -> pd.DataFrame:
    """`frame` on a regular grid of step `freq` (its own median step if None); see the module's notes."""
    from ..times import parse_freq

    native, regular = native_step(frame.index)
    target = parse_freq(freq) if freq is not None else (native if regular else logger_step(native))
    if pd.isna(target):
        raise HybridtrackError(f"step {freq!r} is not a duration such as '1min' or '10s'")
    if regular and target == native:
        attrs["resampling"] = f"none (regular {span(native)} steps)"
        return frame
    check_steps(frame.index[0], frame.index[-1], target,
                what=f"resampling {span(frame.index[-1] - frame.index[0])} of data to {span(target)}")
    columns = [c for c in frame.columns if c in WEATHER_COLUMNS]
    grid, origin = _grid(frame.index, native, target)
    if target >= native:
        binned = frame[columns].resample(target, label="left", closed="left", origin=origin).mean()
        out = binned.reindex(grid)
        method = f"mean over each {span(target)} step"
        made = out[columns].notna().any(axis=1)
        counts = {"rows": int(len(out)), "averaged": int(made.sum())}
    else:
        out = pd.DataFrame({c: _interpolated(frame[c], grid, 3 * native) for c in columns}, index=grid)
        method = f"linear in time from {span(native)} to {span(target)}, gaps over {span(3 * native)} left empty"
        new = ~grid.isin(frame.index)
        counts = {"rows": int(len(out)), "interpolated": int((new & out[columns].notna().any(axis=1)).sum())}
    if not regular:
        method = f"irregular stamps (median step {span(native)}): " + method
        if freq is None and target != native:
            method = method.replace("): ", f", a logger's {span(target)} step): ", 1)
    if out[columns].isna().all(axis=None):
        raise HybridtrackError(f"resampling to {span(target)} left no values; check the step (--freq/--step)")
    counts.update(_left_empty(out[columns]))
    if LABEL_COLUMN in frame.columns:
        out[LABEL_COLUMN] = frame[LABEL_COLUMN].reindex(out.index, method="ffill")
    attrs["resampling"] = method
    report["resampled"] = {"method": method, **counts}
    out["_line"] = np.nan
    return out
