"""Long runs in bounded memory: day-long segments, the log streamed to Parquet, running metrics.

`simulate` holds a run's whole weather frame, world arrays and log in memory, about 2 kB a step
(`hybridtrack.budget`): a year at 1-second steps (31.5 M steps) would need some 60 GB. `stream`
runs the same span as consecutive segments of one local day each, cut at the site's midnight,
when the collector is asleep at night stow. Each segment is an ordinary `simulate` call on that
day's weather; what the controller has learnt is carried from one to the next (`Result.memory`:
its mount fit, calibration offsets, the clock watch's readings and alarms, a commissioned
mount). Each segment's log is appended to one Parquet file as one row group, its events to
``events.csv``, and its metrics to a `hybridtrack.metrics.RunningSummary`; then it is dropped.
Memory is that of one day's run (about 0.6 GB at 1 s) plus the histogram (1.4 MB), whatever the
span.

What a restart at midnight does not carry (and so where a streamed run differs from one
`simulate` over the same weather): the controller's moment-to-moment state (mode, Kalman
filters, sky-watch windows, wind hold, encoder monitor, the sensor/model disagreement
checkpoint and its distrust), and the sensor-only tracker's park, which goes back to the east
each morning. At midnight these are at rest (night stow, no readings), so the difference is
small; ``docs/long-runs.md`` gives the measured figures. The world's sensor noise of each
segment after the first is seeded from ``(seed, day)`` (`day_seed`), the first segment's from
the seed itself, so the first day is exactly `simulate` on that day.

Weather comes from a source that yields one local day at a time:

* `synthetic_days`: `hybridtrack.sky.synthetic` one day at a time, each day seeded from
  ``(seed, day)`` (`day_seed`). `synthetic` over a whole span draws every day from one random
  stream, so a span made at once is not the same weather as the same span made by the day (it
  is the same kind of weather); the streamed source is deterministic and independent of where
  the span starts or ends: a day's weather depends only on the seed and the date.
* `recorded_days`: a weather frame on disk, read in pieces: Parquet by record batches, CSV in
  chunks of rows. The file must be in the weather-frame layout (a tz-aware time index or a
  ``time`` column, a ``dni`` column, as `hybridtrack.io.read_weather` returns and
  ``frame.to_parquet`` writes): `read_weather`'s checks and repairs (units, gaps, resampling)
  need the whole file and are not run on the pieces. Convert a raw record once with
  `read_weather` and ``to_parquet``.
* `frame_days`: a frame already in memory, cut at local midnight.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as dt
import itertools
import os
import shutil
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import params, sites
from .collectors import Collector, as_collector
from .errors import HybridtrackError
from .io.checks import (CLIPPED_AT_ZERO, LIMITS, check_magnitude, check_magnitude_by_day, kilowatts_without_site,
                        site_clear_sky)
from .io.files import input_path
from .io.stamps import has_offset, shown
from .io.units import FRAME_UNITS
from .metrics import HISTOGRAM_RESOLUTION, RunningSummary
from .outputs import claim, held, output_folder, removing_empty_folders, strict_json, write, write_in_place
from .times import check_tz, local_midnight, local_steps, parse_date, parse_freq

__all__ = ["stream", "StreamResult", "DaySource", "synthetic_days", "recorded_days", "frame_days", "day_seed",
           "read_log", "stream_files", "partial_files", "AwakeAtMidnightWarning"]


class AwakeAtMidnightWarning(UserWarning):
    """A streamed run cut its span at a midnight with the tracker awake (the sun up at midnight: a
    polar summer): each such segment restarts the tracker from stow, as no real night did."""


#: Modes a tracker rests in at a streamed run's cut, as it should: asleep at night, or stowed.
RESTING = ("stow_night", "stow_wind")

#: Rows read from a recorded file at a time (a day at 1 s is 86,400).
CHUNK_ROWS = 200_000


def day_seed(seed: int, day: dt.date) -> int:
    """The seed of one day of a streamed run: from ``(seed, day)`` through numpy's `SeedSequence`,
    so each day's draws are independent of every other day's and of where the span starts."""
    state = np.random.SeedSequence([params.seed(seed), day.toordinal()]).generate_state(2, np.uint32)
    return int(state[0]) << 31 | int(state[1]) >> 1


@dataclass
class DaySource:
    """Weather one local day at a time: iterating yields ``(date, frame)`` in order.

    Attributes
    ----------
    site : Site
        The site whose midnight cuts the days.
    describe : str
        What the weather is, for headings.
    steps : int or None
        The steps over the whole span, when known beforehand (a progress bar's total).
    days : int or None
        The days, when known beforehand.
    """

    site: sites.Site
    describe: str
    steps: int | None
    days: int | None
    _days: Callable[[], Iterator[tuple[dt.date, pd.DataFrame]]] = field(repr=False)
    #: Whether the weather holds any wind reading (a recorded file without one is replayed tracking
    #: through, as `hybridtrack replay` does with a file in memory); None where not judged.
    wind_measured: bool | None = None

    #: Whether `check_span` found a whole local day.
    _spans_a_day: bool = field(default=False, repr=False)
    #: The check of the weather's true-sky labels (`check_true_sky`), a pass over them alone; None
    #: where there is nothing to check before the run (synthetic days make their own labels).
    _true_sky: Callable[[], None] | None = field(default=None, repr=False)

    def __iter__(self) -> Iterator[tuple[dt.date, pd.DataFrame]]:
        return self._days()

    def check_span(self) -> None:
        """Refuse a span with no whole local day before anything runs (`stream` calls it, and the
        command line before its progress bar): the weather is read up to its first whole day and
        let go, a day or two of a recorded file, once per source. Read ahead and held instead, the
        days of a logger that records only by day had been held in memory to the file's end."""
        if self._spans_a_day:
            return
        days = 0
        for day, frame in self:
            if _whole(day, frame, self.site):
                self._spans_a_day = True
                return
            days += 1
        raise HybridtrackError(f"{self.describe}: holds no time steps" if days == 0 else
                               f"a streamed run needs at least one whole local day at {self.site.name}; this span "
                               "has none (run it without --stream; hybridtrack.simulate from Python)")

    def check_true_sky(self) -> None:
        """Refuse, before anything runs, a weather without the true-sky labels the hybrid-oracle
        policy reads, or with one that names no sky (`stream` calls it for that policy, and the
        command line before its progress bar). Each day's run refuses them too, but only when
        that day comes: the days before a bad label had run and been written first."""
        if self._true_sky is not None:
            self._true_sky()
            self._true_sky = None  # checked once per source


def _dates(start, end) -> tuple[dt.date, dt.date]:
    first = parse_date(start)
    last = first if end is None else parse_date(end)
    if last < first:
        raise HybridtrackError(f"the span ends ({last}) before it starts ({first})")
    return first, last


def synthetic_days(site, start, end=None, *, weather: str = "climate", freq: str = "1s", seed: int = 0,
                   **options) -> DaySource:
    """Synthetic weather from `start` to `end` (local dates, both whole days), one day at a time.

    Parameters
    ----------
    site : Site or str
    start, end : date or str
        First and last local date; `end` defaults to `start`.
    weather : str
        One of `hybridtrack.sky.synthetic`'s weathers for every day (``"climate"``: each day
        drawn from the site's monthly climate). A per-day list is not taken.
    freq : str
        Step, e.g. ``"1s"``.
    seed : int
        Each day is ``synthetic(site, day, ..., seed=day_seed(seed, day))``.
    **options
        Passed to `hybridtrack.sky.synthetic` (``gusts_per_day``, ``wind_mean``, ``climate``).

    Returns
    -------
    DaySource
    """
    from .sky import WEATHERS, synthetic, weather_name

    site = sites.get(site)
    first, last = _dates(start, end)
    if not isinstance(weather, str) or weather_name(weather) not in WEATHERS:
        raise HybridtrackError(f"weather {weather!r}: a streamed run takes one of {', '.join(WEATHERS)} for every day")
    weather = weather_name(weather)
    step = parse_freq(freq)
    params.seed(seed)
    days = (last - first).days + 1
    _check_options(site, first, step, weather, freq, options)

    def each():
        for k in range(days):
            day = first + dt.timedelta(days=k)
            yield day, synthetic(site, day, weather=weather, freq=freq, seed=day_seed(seed, day), **options)

    return DaySource(site, f"{first} to {last}, {weather} (synthetic, each day seeded from ({seed}, date))",
                     days * int(pd.Timedelta(days=1) // step), days, each)


def _check_options(site, first: dt.date, step: pd.Timedelta, weather: str, freq: str, options: dict) -> None:
    """Refuse `synthetic_days`' options as `synthetic` would, on two steps of the first day: an
    unknown one was a TypeError out of the run's first day, after the run had claimed its folder."""
    import inspect

    from .sky import synthetic

    known = sorted(name for name, p in inspect.signature(synthetic).parameters.items()
                   if p.kind is p.KEYWORD_ONLY and name not in ("weather", "freq", "seed"))
    for name in options:
        if name not in known:
            raise HybridtrackError(f"synthetic_days: unknown option {name!r}; it takes {', '.join(known)}")
    start = pd.Timestamp(first)
    try:
        synthetic(site, start, start + step, weather=weather, freq=freq, seed=0, **options)
    except (TypeError, ValueError) as exc:  # a value of the wrong shape (gust_peak="strong")
        raise HybridtrackError(f"synthetic_days: options {options!r:.80}: {exc}") from None


def _by_day(pieces: Iterator[pd.DataFrame], site: sites.Site, where: str) -> Iterator[tuple[dt.date, pd.DataFrame]]:
    """Local days (`_cut_days`), a day of one stamp joined to a neighbour: a run needs two steps,
    and a logger's export that ends on the next midnight's stamp (00:00-24:00) is common. A lone
    stamp joins the day before it (the day after it, at the start of the span); no step is lost."""
    held = None  # the day before, kept until the next shows whether a lone stamp joins it
    for day, frame in _cut_days(pieces, site, where):
        if held is None:
            held = day, frame
        elif len(frame) == 1:
            held = held[0], pd.concat([held[1], frame])
        elif len(held[1]) == 1:
            held = day, pd.concat([held[1], frame])
        else:
            yield held
            held = day, frame
    if held is not None:
        yield held


def _cut_days(pieces: Iterator[pd.DataFrame], site: sites.Site, where: str) -> Iterator[tuple[dt.date, pd.DataFrame]]:
    """Regroup consecutive pieces of a frame into local days, each yielded once it is complete."""
    held: pd.DataFrame | None = None
    last = None
    for piece in pieces:
        if not len(piece):  # a file of a header alone
            continue
        if not isinstance(piece.index, pd.DatetimeIndex) or piece.index.tz is None:
            raise HybridtrackError(f"{where}: the time stamps have no UTC offset; give their zone (--tz; tz= from Python)")
        if last is not None and piece.index[0] <= last:
            raise HybridtrackError(f"{where}: time goes back or repeats at {piece.index[0]}; a streamed file must be "
                                   "sorted without repeats (write it from hybridtrack.io.read_weather)")
        last = piece.index[-1]
        held = piece if held is None else pd.concat([held, piece])
        day = _local_days(held.index, site.tz)
        complete = day < day[-1]
        if complete.any():
            done = held[complete]
            held = held[~complete]
            for number, frame in done.groupby(day[complete], sort=True):
                yield EPOCH + dt.timedelta(days=int(number)), frame
    if held is not None and len(held):
        yield EPOCH + dt.timedelta(days=int(_local_days(held.index[:1], site.tz)[0])), held


#: Day 0 of `_local_days`.
EPOCH = dt.date(1970, 1, 1)


def _local_days(index: pd.DatetimeIndex, tz: str) -> np.ndarray:
    """Each stamp's local date as a whole number of days since `EPOCH`, for the whole index at
    once (a Python date per stamp would be 31.5 million objects for a year at 1 s)."""
    return index.tz_convert(tz).tz_localize(None).as_unit("ns").asi8 // (86_400 * 10**9)


def frame_days(frame: pd.DataFrame, site) -> DaySource:
    """A weather frame already in memory, cut at the site's local midnight."""
    site = sites.get(site)
    if not isinstance(frame, pd.DataFrame) or not isinstance(frame.index, pd.DatetimeIndex) or frame.index.tz is None:
        raise HybridtrackError("the weather frame must be a DataFrame on a tz-aware DatetimeIndex")
    back = np.flatnonzero(np.diff(frame.index.as_unit("ns").asi8) <= 0)
    if len(back):  # judged before its span, which a frame backwards or its days swapped gets wrong
        row, stamp, before = int(back[0]) + 1, frame.index[back[0] + 1], frame.index[back[0]]
        what = "repeats" if stamp == before else "goes back"
        raise HybridtrackError(f"the weather frame's time {what} at row {row} ({stamp} after {before}); sort it "
                               "(frame.sort_index()) and drop repeated stamps")
    local = frame.index.tz_convert(site.tz)
    days = len(np.unique(_local_days(frame.index, site.tz)))
    covered = (frame.index[-1] - frame.index[0]) + (frame.index[1] - frame.index[0]) if len(frame) > 1 else None
    if covered is not None and covered < pd.Timedelta(hours=23):
        raise HybridtrackError(f"the frame spans {local[0]} to {local[-1]}: a streamed run needs at least one whole "
                               "local day (run a shorter span without --stream; hybridtrack.simulate from Python)")
    return DaySource(site, "a weather frame", len(frame), days, lambda: _by_day(iter([frame]), site, "the frame"),
                     _true_sky=lambda: _check_true_sky(frame))


def _check_true_sky(frame: pd.DataFrame) -> None:
    """`DaySource.check_true_sky` of a frame in memory: `hybridtrack.simulate`'s own check."""
    from .simulation import check_true_sky

    check_true_sky(frame)


def _refuse_unknown_sky_in_file(path: Path, separator: str | None) -> None:
    """`DaySource.check_true_sky` of a file on disk: its ``sky`` column alone read a chunk at a
    time (`_column_chunks`, as the run reads it, so that the verdict is the run's), the first label
    that names no sky refused by its line (a CSV's; a Parquet file's row) and column, with their
    count. A file pandas or pyarrow cannot read is left to the run's own read, which names what is
    wrong."""
    from .simulation import ORACLE_READS, unknown_sky

    try:
        names, chunks, first_row, _ = _column_chunks(path, separator, lambda header: ["sky"] if "sky" in header else [])
        rows, count, first = 0, 0, None
        for chunk in chunks if "sky" in names else ():
            unknown = np.flatnonzero(unknown_sky(chunk["sky"]))
            if len(unknown) and first is None:
                first = (first_row + rows + int(unknown[0]), chunk["sky"].iloc[unknown[0]])
            rows, count = rows + len(chunk), count + len(unknown)
    except (OSError, ValueError):  # pandas' and pyarrow's read errors
        return
    if "sky" not in names:
        raise HybridtrackError(f"{path}: no column 'sky': {ORACLE_READS} from a weather frame's true sky "
                               "(hybridtrack check FILE --out clean.parquet keeps a record's sky column)")
    if first is not None:
        where = "line" if separator is not None else "row"
        raise HybridtrackError(f"{path}: {where} {first[0]}, column 'sky': {first[1]!r:.40} is no sky label ({count} "
                               f"such in the file); {ORACLE_READS} (a streamed file is read as written)")


def _column_chunks(path: Path, separator: str | None, pick: Callable[[list], list]
                   ) -> tuple[list, Iterator[pd.DataFrame], int, int | None]:
    """A CSV (`separator`) or Parquet file's column names; the columns `pick` chooses from them,
    read alone a chunk at a time (none if it chooses none); the file row of a chunk's first row (a
    CSV's line: 2); and the file's row count where its metadata gives it (Parquet), else None."""
    if separator is not None:
        names = list(pd.read_csv(path, sep=separator, nrows=0).columns)
        kept = pick(names)
        chunks = pd.read_csv(path, sep=separator, usecols=kept, chunksize=CHUNK_ROWS,
                             low_memory=False) if kept else iter(())  # each chunk typed whole: no DtypeWarning
        return names, chunks, 2, None
    import pyarrow.parquet as pq

    handle = pq.ParquetFile(path)
    names = list(handle.schema_arrow.names)
    kept = pick(names)
    chunks = (batch.to_pandas() for batch in handle.iter_batches(CHUNK_ROWS, columns=kept)) if kept else iter(())
    return names, chunks, 1, handle.metadata.num_rows


def recorded_days(path, site, *, tz=None, chunk_rows: int = CHUNK_ROWS) -> DaySource:
    """A weather frame on disk (Parquet or CSV), read `chunk_rows` rows at a time, by local day.

    Parameters
    ----------
    path : str or Path
        ``.parquet`` (record batches; a pandas-written index or a ``time`` column) or ``.csv``
        (a first column or a ``time`` column of time stamps).
    site : Site or str
    tz : str, optional
        The zone of naive time stamps; tz-aware stamps are kept.
    chunk_rows : int

    Returns
    -------
    DaySource
    """
    site = sites.get(site)
    if tz is not None:  # a zone that is none had escaped as zoneinfo's KeyError once the stream started
        tz = check_tz(tz, "recorded_days: tz: ")
    path = input_path(path, "weather file")
    if path.is_dir():
        raise HybridtrackError(f"{path}: is a folder, not a weather file")
    if not path.is_file():  # /dev/null had been "no such file"
        raise HybridtrackError(f"{path}: is not a regular file (a device or a pipe, which a streamed run, reading the "
                               f"file twice, cannot take)" if path.exists() else f"{path}: no such file")
    chunk_rows = params.whole(chunk_rows, "chunk_rows", 1, 10**9)
    suffix = path.suffix.lower()
    if suffix not in (".parquet", ".pq", ".csv"):
        raise HybridtrackError(f"{path}: a streamed run reads .parquet or .csv weather frames, not {suffix or 'this'}")

    offsets: list = []  # whether the first piece's stamps carried their UTC offsets, and its zone

    def stamped(piece: pd.DataFrame, first_row: int) -> pd.DataFrame:
        name = "time"
        if not isinstance(piece.index, pd.DatetimeIndex):
            name = "time" if "time" in piece.columns else piece.columns[0]
            piece = piece.set_index(_parsed_stamps(piece.pop(name), path, first_row))
        _numeric(piece, path, first_row)
        _physical(piece, path, first_row)
        _same_kind_of_stamps(offsets, piece.index, path, first_row, name)
        if piece.index.tz is None and tz is not None:
            piece.index = _localised(piece.index, tz, path, first_row, name)
        elif piece.index.tz is not None:  # one zone for every piece, the first's: a daylight-saving change
            piece.index = piece.index.tz_convert(tz or offsets[1])  # between two had joined +01:00 and +02:00 into none
        piece.index.name = None
        _in_order(piece, path, first_row)
        return piece

    separator = csv_separator(path) if suffix == ".csv" else None
    _refuse_repeated_columns(path, separator)
    measured, dni = _measured(path, separator, ("dni", "wind_speed"))
    if "dni" not in measured:
        raise HybridtrackError(_without_dni(path, separator))
    _refuse_dni_in_kilowatts(path, dni)
    steps = None
    if suffix == ".csv":

        first_row = 2  # the file's line: the header is line 1

        def pieces():
            try:
                with pd.read_csv(path, sep=separator, chunksize=chunk_rows, low_memory=False) as reader:
                    for k, piece in enumerate(reader):
                        yield stamped(piece, first_row + k * chunk_rows)
            except HybridtrackError:
                raise
            except (ValueError, pd.errors.ParserError) as exc:
                raise HybridtrackError(f"{path}: cannot read as CSV ({' '.join(str(exc).split())})") from None
    else:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            handle = pq.ParquetFile(path)
        except (OSError, pa.ArrowException) as exc:
            raise HybridtrackError(f"{path}: cannot read as Parquet ({exc})") from None
        steps = handle.metadata.num_rows
        first_row = 1

        def pieces():
            schema = handle.schema_arrow
            for k, batch in enumerate(handle.iter_batches(batch_size=chunk_rows)):
                yield stamped(pa.Table.from_batches([batch], schema=schema).to_pandas(), first_row + k * chunk_rows)

    rows = lambda: itertools.count(first_row, chunk_rows)  # noqa: E731 - each piece's first row
    return DaySource(site, f"{path}", steps, None,
                     lambda: _by_day(_magnitude_checked(pieces(), path, rows(), site), site, str(path)),
                     wind_measured="wind_speed" in measured,
                     _true_sky=lambda: _refuse_unknown_sky_in_file(path, separator))


#: The separators a streamed CSV may use: the one its header line holds most of is used.
SEPARATORS = (",", ";", "\t")
#: What a streamed file's stamp trouble is refused with: the way to a file that streams.
CONVERT_ONCE = ("a streamed file is read as written: convert a record once with hybridtrack check FILE --out "
                "clean.parquet (hybridtrack.io.read_weather(...).to_parquet(...) from Python)")


def _without_dni(path: Path, separator: str | None) -> str:
    """Why a streamed file has no DNI to run on, in its own words: no column named ``dni`` (a
    header with a unit, ``dni [kW/m2]``, names none), or one whose first value is not a number
    (a decimal comma), or one with no value at all. The one reason given for each ("missing or
    holds no number ... which derives it from GHI and DHI") had sent a file of decimal commas to
    derive a DNI it had."""
    try:
        if separator is None:
            import pyarrow.parquet as pq

            head = pq.ParquetFile(path).schema_arrow.names
            first = None
        else:
            table = pd.read_csv(path, sep=separator, nrows=CHUNK_ROWS, dtype=str, keep_default_na=False)
            head = list(table.columns)
            given = table["dni"][~table["dni"].map(_reads_as_number)] if "dni" in table.columns else table.iloc[:0, 0]
            first = (int(given.index[0]) + 2, given.iloc[0]) if len(given) else None
    except Exception:  # the run's own read says what is wrong, by row
        head, first = [], None
    if "dni" not in head:
        shown = ", ".join(repr(name) for name in head[:8]) + (", ..." if len(head) > 8 else "")
        return (f"{path}: no column 'dni' (the columns are {shown or 'unreadable'}): a streamed file names its columns "
                f"as a weather frame does, in its units (W/m², no unit in the name); {CONVERT_ONCE}")
    if first is not None:
        return (f"{path}: row {first[0]}, column 'dni': {first[1]!r:.40} is not a number (a decimal comma, or a "
                f"unit in the cell?); {CONVERT_ONCE}")
    return f"{path}: column 'dni' holds no number; {CONVERT_ONCE}, which derives it from GHI and DHI"


def _reads_as_number(cell: str) -> bool:
    """Whether a CSV cell is a number to pandas, or empty: ``NaN`` and ``inf`` are numbers, if no
    reading; ``0,5`` is not."""
    try:
        float(cell.strip() or "nan")
    except ValueError:
        return False
    return True


def csv_separator(path: Path) -> str:
    """The separator of a CSV file, judged from its header line: a logger on a European locale
    writes ``;`` (with a decimal comma, refused by row as not a number) and some write tabs."""
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        header = handle.readline()
    return max(SEPARATORS, key=header.count)


def _parsed_stamps(stamps: pd.Series, path: Path, first_row: int) -> pd.DatetimeIndex:
    """A CSV's time column parsed as ISO 8601, or refused by its first bad row. Stamps whose UTC
    offset changes (a logger on local time with daylight saving) are instants: kept as UTC, as
    `hybridtrack.io.read_weather` keeps them."""
    try:
        parsed = pd.to_datetime(stamps, format="ISO8601", errors="coerce", utc=False)
    except ValueError:  # offsets that differ from row to row, or stamps with and without one
        naive = np.flatnonzero((~has_offset(stamps.astype(str)) & stamps.notna()).to_numpy())
        if len(naive):  # read as UTC by pandas: a record shifted by its zone's offset without a word
            raise HybridtrackError(f"{path}: row {first_row + int(naive[0])}, column {stamps.name!r}: "
                                   f"{stamps.iloc[naive[0]]!r} has no UTC offset, but other stamps in the column have "
                                   f"one ({CONVERT_ONCE})") from None
        parsed = pd.to_datetime(stamps, format="ISO8601", errors="coerce", utc=True)
    bad = np.flatnonzero(parsed.isna().to_numpy())
    if len(bad):
        row, cell = first_row + int(bad[0]), stamps.iloc[bad[0]]
        what = "'' is an empty time stamp" if pd.isna(cell) else f"{shown(cell)} is not an ISO 8601 time stamp"
        raise HybridtrackError(f"{path}: row {row}, column {stamps.name!r}: {what} ({CONVERT_ONCE})")
    return pd.DatetimeIndex(parsed)


def _same_kind_of_stamps(offsets: list, index: pd.DatetimeIndex, path: Path, first_row: int, name: str) -> None:
    """Refuse a piece of stamps without UTC offsets after pieces with them, or the other way round,
    by its first row, as stamps of both kinds in one piece are (`_parsed_stamps`): whether a file
    was refused had turned on the size of the pieces it was read in."""
    aware = index.tz is not None
    if not offsets:
        offsets.extend([aware, index.tz])
    elif aware != offsets[0] and len(index):
        kind = "has a UTC offset, but the stamps before it have none" if aware else \
            "has no UTC offset, but the stamps before it have one"
        raise HybridtrackError(f"{path}: row {first_row}, column {name!r}: {index[0]} {kind} ({CONVERT_ONCE})")


def _localised(index: pd.DatetimeIndex, tz: str, path: Path, first_row: int, name: str) -> pd.DatetimeIndex:
    """Naive stamps put in `tz`, or refused by the first row that the zone's daylight-saving change
    skips or repeats (the reader drops or resolves those; a stream does not repair)."""
    try:
        return index.tz_localize(tz)
    except ValueError:  # pandas' NonExistentTimeError and AmbiguousTimeError
        unresolved = np.flatnonzero(index.tz_localize(tz, nonexistent="NaT", ambiguous="NaT").isna())
        row = first_row + int(unresolved[0])
        raise HybridtrackError(f"{path}: row {row}, column {name!r}: {index[unresolved[0]]} does not exist or is "
                               f"ambiguous in {tz} (a daylight-saving change); give the stamps a UTC offset or "
                               f"tz=UTC ({CONVERT_ONCE})") from None


#: Columns of a weather frame that hold text (the true sky's label); every other column is a number.
TEXT_COLUMNS = ("sky",)


def _measured(path: Path, separator: str | None, names: tuple[str, ...]) -> tuple[set[str], tuple | None]:
    """Which of the columns `names` hold at least one finite number, read alone a chunk at a time,
    and, in a file of DNI without GHI or DHI, the DNI's top with its row and the file's first and
    last stamps (`_refuse_dni_in_kilowatts`). A file without rows, or one pandas or pyarrow cannot
    read, counts as holding them all: the run's own read then says what is wrong, by row."""
    def pick(header: list) -> list:  # a CSV's first column is its stamps; a Parquet file's, its index
        kept = [name for name in names if name in header]
        if separator is not None:
            return [header[0], *kept]
        time = next((n for n in header if n == "time" or n.startswith("__index_level_")), None)
        return kept + [time] * (time is not None) if kept else []

    try:
        header, chunks, first_row, total = _column_chunks(path, separator, pick)
        if total == 0:
            return set(names), None
        dni_alone = "dni" in names and not {"ghi", "dhi"} & set(header)
        found: set[str] = set()
        rows, top, stamps = 0, (-np.inf, 0), []
        for chunk in chunks:
            found |= {name for name in names if name in chunk.columns
                      and np.isfinite(pd.to_numeric(chunk[name], errors="coerce").to_numpy(float)).any()}
            if dni_alone and "dni" in chunk.columns and len(chunk):
                values = pd.to_numeric(chunk["dni"], errors="coerce").to_numpy(float)
                if np.isfinite(values).any() and np.nanmax(values) > top[0]:
                    top = (float(np.nanmax(values)), first_row + rows + int(np.nanargmax(values)))
                stamps = [*stamps[:1], *_ends(chunk, next((c for c in chunk.columns if c not in names), None))]
            rows += len(chunk)
        if not rows and separator is not None:
            return set(names), None
        return found, (top, stamps[0], stamps[-1]) if dni_alone and np.isfinite(top[0]) and stamps else None
    except (OSError, ValueError):  # pandas' and pyarrow's read errors
        return set(names), None


def _ends(chunk: pd.DataFrame, time: str | None) -> list:
    """A chunk's first and last stamps, read alone (an unreadable one is left to the run's read)."""
    values = chunk.index if time is None or time not in chunk.columns else chunk[time]
    try:
        return [pd.Timestamp(values[0]), pd.Timestamp(values[-1])] if isinstance(values, pd.Index) else \
            [pd.Timestamp(values.iloc[0]), pd.Timestamp(values.iloc[-1])]
    except (ValueError, TypeError):
        return []


def _refuse_dni_in_kilowatts(path: Path, dni: tuple | None) -> None:
    """The record reader's judgement of a file of DNI alone, on the whole file (`dni`: its top and
    row, and its first and last stamps, from `_measured`), before the first day runs: DNI of at
    most 1.5 over six hours or more is kW/m² (`kilowatts_without_site`). Judged on each span of
    the stream instead, the verdict had turned on the pieces' size: a day in kW/m² streamed at one
    size and was refused at another, and an overcast day's noise was refused at small sizes."""
    if dni is None:
        return
    (top, row), first, last = dni
    try:
        hours = (last - first) / pd.Timedelta(hours=1)
    except (TypeError, ValueError):  # stamps naive and aware: left to the run's read, which names them
        return
    if kilowatts_without_site(top, hours):
        raise HybridtrackError(f"{path}: row {row}, column 'dni': dni is at most {top:g} over {hours:.0f} hours; "
                               "the values look like kW/m² read as W/m²: convert the file once with hybridtrack "
                               "check FILE --units dni=kW/m2 --out clean.parquet")


def _refuse_repeated_columns(path: Path, separator: str | None) -> None:
    """Refuse a column name the file's header holds twice, as the record reader does: a CSV's second
    ``dni`` had been read as ``dni.1`` and dropped without a word (the first, perhaps all zeros,
    run), and a Parquet file's had ended in pandas' TypeError. A header that cannot be read is
    left to the run's own read, which names what is wrong."""
    try:
        if separator is not None:
            names = [str(name) for name in pd.read_csv(path, sep=separator, nrows=1, header=None, dtype=str).iloc[0]]
        else:
            import pyarrow.parquet as pq

            names = list(pq.ParquetFile(path).schema_arrow.names)
    except (OSError, ValueError, IndexError):  # pandas' and pyarrow's read errors; a file of no line
        return
    named = pd.Index([name for name in names if name not in ("", "nan")])  # a spreadsheet's empty padding columns
    repeated = named[named.duplicated()]
    if len(repeated):
        raise HybridtrackError(f"{path}: column {repeated[0]!r} appears more than once in the header; rename one")


def _numeric(piece: pd.DataFrame, path: Path, first_row: int) -> None:
    """Refuse a cell that is not a number, naming its row (`first_row` is the piece's first) and
    column: a streamed frame is read as it was written, without the reader's repairs."""
    for column in piece.columns:
        if column in TEXT_COLUMNS or pd.api.types.is_numeric_dtype(piece[column].dtype):
            continue
        values = pd.to_numeric(piece[column], errors="coerce")
        bad = np.flatnonzero(values.isna().to_numpy() & piece[column].notna().to_numpy())
        if len(bad):
            raise HybridtrackError(f"{path}: row {first_row + int(bad[0])}, column {column!r}: "
                                   f"{piece[column].iloc[bad[0]]!r} is not a number")
        piece[column] = values


def _in_order(piece: pd.DataFrame, path: Path, first_row: int) -> None:
    """Refuse a stamp that repeats or goes back from the row before it (the reader would sort and
    drop it), naming its row."""
    back = np.flatnonzero(np.diff(piece.index.as_unit("ns").asi8) <= 0)
    if len(back):
        row = first_row + int(back[0]) + 1
        raise HybridtrackError(f"{path}: row {row}: time {piece.index[back[0] + 1]} repeats or goes back from the row "
                               "before; a streamed file must be sorted without repeats (write it from "
                               "hybridtrack.io.read_weather)")


def _physical(piece: pd.DataFrame, path: Path, first_row: int) -> None:
    """Refuse what the reader's checks would repair (`hybridtrack.io.checks`): a value outside
    its column's physical range, or a negative irradiance or wind (a night offset the reader
    clips); each by its row (`first_row` is the piece's first) and column. Irradiance in kW/m² is
    judged over a day of pieces (`_magnitude_checked`)."""
    for column, (low, high) in LIMITS.items():
        if column not in piece:
            continue
        values = piece[column].to_numpy(float)
        floor = 0.0 if column in CLIPPED_AT_ZERO else low
        bad = np.flatnonzero(~np.isnan(values) & ~((values >= floor) & (values <= high)))
        if len(bad):
            raise HybridtrackError(
                f"{path}: row {first_row + int(bad[0])}, column {column!r}: {values[bad[0]]:g} is outside "
                f"{floor:g}..{high:g} {FRAME_UNITS[column]} (a streamed file is read as written, without the "
                f"reader's repairs: convert it once with hybridtrack check FILE --out clean.parquet)")


#: The span of rows a streamed file's irradiance magnitude is judged over (`_magnitude_checked`):
#: a day holds the sun's light, where a few hours of night hold none to judge.
MAGNITUDE_SPAN = pd.Timedelta(days=1)
#: The irradiance columns the magnitude check reads (`hybridtrack.io.checks.check_magnitude`).
_IRRADIANCE = ("ghi", "dhi", "dni")


def _magnitude_checked(pieces: Iterator[pd.DataFrame], path: Path, first_rows: Iterator[int],
                       site: sites.Site) -> Iterator[pd.DataFrame]:
    """`pieces` (each starting at the file's row from `first_rows`) passed on unchanged, with
    irradiance in kW/m² refused (`check_magnitude`) over spans of at least `MAGNITUDE_SPAN` (or
    the whole file, if shorter), each judged before its last piece is passed on. Judged a piece at
    a time, a file read in small chunks (``chunk_rows`` of six hours or less) had never been.
    Each whole local day is judged as the record reader judges it too (`_days_checked`)."""
    window: list[pd.DataFrame] = []
    held: list[pd.DataFrame] = []  # the span's last local day, whole only with the next span

    def judge(last: bool):
        lines = pd.concat(window)
        if len(lines) >= 2:  # DNI alone is judged on the whole file (`_refuse_dni_in_kilowatts`), not a span
            check_magnitude(path, lines, {}, None, whole_file=False,
                            remedy="convert the file once with hybridtrack check FILE --units {name}=kW/m2 --out "
                                   "clean.parquet")
        held[:] = [_days_checked(path, pd.concat([*held, lines]), site, last)]

    for piece, first_row in zip(pieces, first_rows):
        if len(piece):  # an empty piece (a header alone) has no span
            columns = [name for name in _IRRADIANCE if name in piece]
            window.append(piece[columns].assign(_line=np.arange(first_row, first_row + len(piece), dtype=float)))
            if window[-1].index[-1] - window[0].index[0] >= MAGNITUDE_SPAN:
                judge(last=False)
                window = []
        yield piece
    if window or held:
        window = window or [held[0].iloc[:0]]
        judge(last=True)


def _days_checked(path: Path, lines: pd.DataFrame, site: sites.Site, last: bool) -> pd.DataFrame:
    """Judge the whole local days of `lines` (all of them if `last`) as the record reader judges a
    file's days (`hybridtrack.io.checks.check_magnitude_by_day`, on the site's clear sky): a day in
    kW/m² beside days in W/m², or hours of a day in kW/m² beside its hours in W/m² (a logger whose
    unit changed within the day, which a streamed replay had run as a dark morning). Return the
    rows of the day still open, for the next span."""
    if not len(lines) or lines.index.tz is None or not any(name in lines for name in ("ghi", "dhi")):
        return lines.iloc[:0]  # naive stamps are refused by the day cutter; DNI alone is judged above
    days = _local_days(lines.index, site.tz)
    whole = np.ones(len(lines), bool) if last else days < days[-1]
    if whole.any():
        judged = lines[whole]
        check_magnitude_by_day(path, judged, {}, site_clear_sky(judged.index, site)[1], site.tz,
                               part=True)  # the file's span passed whole: a day in kW/m² is among days in W/m²
    return lines[~whole]


# -- the run -------------------------------------------------------------------------------------


@dataclass
class StreamResult:
    """A finished streamed run: its summary and where its log and events are on disk.

    Attributes
    ----------
    summary : dict
        ``summary.json``: `summarize`'s keys from running metrics (the p95 from a histogram of
        ``streamed.p95_resolution_deg`` bins), with the streamed run's own ``streamed`` entry.
    files : dict of Path
        ``log`` (Parquet, one row group a day), ``events`` (CSV), ``summary`` (JSON).
    memory : dict
        What the controller carries out of the last segment (`hybridtrack.simulation.Result`).
    config : SimulationConfig
        The run's config (each segment's differs only in its noise seed and the clock's age).
    kept_as_read : KeptAsRead
        The weather's missing readings and gaps, which the run kept as they were
        (``streamed.kept_as_read`` in the summary).

    A run that stops part way (an error, an interrupt) leaves the log and events of the days it
    finished, and no ``summary.json``.
    """

    summary: dict
    files: dict
    site: sites.Site
    collector: Collector
    config: object
    memory: dict | None = field(default=None, repr=False)
    kept_as_read: KeptAsRead | None = field(default=None, repr=False)

    def log(self, columns=None, *, day=None) -> pd.DataFrame:
        """The log read back (all of it, or one local `day`), `columns` only if given."""
        return read_log(self.files["log"], columns=columns, day=day, tz=self.site.tz)

    def days(self, columns=None) -> Iterator[pd.DataFrame]:
        """The log one segment (a local day) at a time, without holding more than one."""
        import pyarrow.parquet as pq

        handle = pq.ParquetFile(self.files["log"])
        for group in range(handle.num_row_groups):
            yield _categorised(handle.read_row_group(group, columns=_with_index(handle, columns)).to_pandas())

    def events(self) -> pd.DataFrame:
        """Every mode change and alarm of the run (``events.csv``)."""
        events = pd.read_csv(self.files["events"])
        events["time"] = pd.to_datetime(events["time"], format="ISO8601")
        return events

    def __repr__(self) -> str:
        from .report import _headline, _shares

        s = self.summary
        lines = [f"hybridtrack streamed run: {s['site']} · {s['collector']} · {s['strategy']} · "
                 f"{s['start'][:10]} to {s['end'][:10]}",
                 f"  {s['steps']:,} steps in {s['streamed']['segments']} day-long segments; log in {self.files['log']}"]
        lines += [f"  {label}: {value}" for label, value in _headline(s)]
        lines += [f"  modes: {_shares(s['mode_share'])}", f"  sky: {_shares(s['sky_share'])} (every step)"]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        from html import escape

        from .report import _headline, _shares

        s = self.summary
        rows = [("run", f"{s['site']} · {s['collector']} · {s['strategy']} · {s['start'][:10]} to {s['end'][:10]}"),
                ("steps", f"{s['steps']:,} in {s['streamed']['segments']} day-long segments"), *_headline(s),
                ("mode shares", _shares(s["mode_share"])), ("sky shares (every step)", _shares(s["sky_share"])),
                *((role, str(path)) for role, path in self.files.items())]
        table = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th><td style='text-align:left'>{escape(v)}"
                        f"</td></tr>" for k, v in rows)
        return f"<div><strong>hybridtrack streamed run</strong><table>{table}</table></div>"


def _with_index(handle, columns):
    if columns is None:
        return None
    index = [c for c in (handle.schema_arrow.pandas_metadata or {}).get("index_columns", []) if isinstance(c, str)]
    return [*columns, *index]


def _categorised(log: pd.DataFrame) -> pd.DataFrame:
    """The log's categorical columns with every category of their kind, as `simulate` makes them."""
    from .control import MODES, SENSOR_STATUS, SKY_CODES

    for column, categories in (("mode", MODES), ("sky", SKY_CODES), ("sensor_status", SENSOR_STATUS)):
        if column in log.columns:
            log[column] = pd.Categorical(log[column].astype(object), categories=list(categories))
    return log


def read_log(path, *, columns=None, day=None, tz=None) -> pd.DataFrame:
    """A streamed run's ``log.parquet`` read back: all of it, or the local `day` (a date) only.

    Parameters
    ----------
    path : str or Path
    columns : list of str, optional
    day : date or str, optional
        One local day (the site's zone `tz`): only its row group is read.
    tz : str, optional
        The site's zone, to find `day`.
    """
    import pyarrow
    import pyarrow.parquet as pq

    if not isinstance(path, (str, os.PathLike)):
        raise HybridtrackError(f"read_log: path must be a file's path, got {path!r:.60}")
    if isinstance(columns, str) or not (columns is None or all(isinstance(c, str) for c in columns)):
        raise HybridtrackError(f"read_log: columns must be a list of names, got {columns!r:.60}")
    try:
        handle = _Segments(Path(path)) if Path(path).is_dir() else pq.ParquetFile(path)
    except (OSError, pyarrow.ArrowInvalid) as exc:  # missing, not Parquet, cut short (no footer), no segment
        raise HybridtrackError(f"{path}: cannot read as a streamed log ({str(exc).splitlines()[0]})") from None
    index = set(_with_index(handle, []))
    names = [name for name in handle.schema_arrow.names if name not in index]
    unknown = sorted(set(columns or ()) - set(names))
    if unknown:
        raise HybridtrackError(f"{path}: no column {unknown[0]!r} in the log; it has {', '.join(names)}")
    if day is None:
        return _categorised(handle.read(columns=_with_index(handle, columns)).to_pandas())
    return _day_of(handle, path, columns, day, tz)


class _Segments:
    """A stopped streamed run's ``log.partial.parquet`` folder, read as its joined log would be:
    the segments are its row groups (the part of ``pyarrow.parquet.ParquetFile`` `read_log` uses)."""

    def __init__(self, folder: Path):
        import pyarrow.parquet as pq

        self.parts = _segment_files(folder)
        if not self.parts:
            raise OSError(f"{folder} holds no segment of a streamed log")
        self.schema_arrow = pq.read_schema(self.parts[0])
        self.num_row_groups = len(self.parts)

    def read_row_group(self, group: int, columns=None):
        import pyarrow.parquet as pq

        return pq.read_table(self.parts[group], columns=columns)

    def read(self, columns=None):
        import pyarrow as pa

        return pa.concat_tables([self.read_row_group(group, columns) for group in range(self.num_row_groups)])


def _day_of(handle, path, columns, day, tz) -> pd.DataFrame:
    """`read_log`'s one local `day` (a date, in the zone `tz` or the log's own)."""
    from .times import check_tz

    try:
        stamp = pd.Timestamp(day)
    except (ValueError, TypeError):
        stamp = pd.NaT
    if pd.isna(stamp) or stamp != stamp.normalize():
        raise HybridtrackError(f"read_log: day {day!r} is not a date") from None
    wanted = stamp.date()
    if tz is not None and not isinstance(tz, str):
        raise HybridtrackError(f"read_log: tz must be a time zone's name, got {tz!r:.60}")
    tz = check_tz(tz, "read_log: ") if tz is not None else None
    for group in range(handle.num_row_groups):
        log = _categorised(handle.read_row_group(group, columns=_with_index(handle, columns)).to_pandas())
        if len(log) and log.index[0].tz_convert(tz or log.index.tz).date() == wanted:
            return log
    raise HybridtrackError(f"{path}: no segment on {wanted}")


class _PartialRun:
    """A streamed run's log and events under partial names (`partial_files`) until it finishes.

    Each segment's log is a Parquet file of its own in the folder ``log.partial.parquet``, written
    whole and then moved into place, so whatever stops the run (an error, Ctrl-C, a full disk,
    the process killed outright) leaves every finished segment whole and readable (`read_log`
    reads the folder): one Parquet file appended to lost them all when its footer was never
    written. The events go to one CSV file, cut back to its last whole segment when a write
    fails. `finish` joins the segments into ``log.parquet``, one row group a segment.
    """

    def __init__(self, files: dict):
        self.files, self.partial = files, partial_files(files)
        self.schema, self.segments = None, 0

    def _start(self) -> None:
        """Make the segments' folder (a forced rerun's claim took an earlier stopped run's) and the
        events' header."""
        parts = self.partial["log"]
        if parts.is_dir() and not parts.is_symlink():
            shutil.rmtree(parts, ignore_errors=True)
        else:  # a stopped run of an earlier version left one file
            with contextlib.suppress(OSError):
                parts.unlink()
        write_in_place(parts, lambda path: path.mkdir())
        write_in_place(self.partial["events"], lambda path: path.write_text("time,from,to,reason\n"))

    def append(self, result) -> None:
        """Add one finished segment's events and log; a failed write leaves the segments before."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(result.log, preserve_index=True)
        if self.schema is None:
            self._start()
            self.schema = table.schema
        elif not table.schema.equals(self.schema, check_metadata=False):
            raise HybridtrackError(f"{self.files['log']}: a segment's log has other columns or types than the first's")
        events = self.partial["events"]
        whole = events.stat().st_size
        try:
            if len(result.events):
                write_in_place(events, lambda path: result.events.to_csv(path, mode="a", header=False, index=False))
            write(self.partial["log"] / f"{self.segments:05d}.parquet",
                  lambda path: pq.write_table(table, path, row_group_size=len(table)))
        except BaseException:
            with contextlib.suppress(OSError):
                os.truncate(events, whole)  # the events of the segments whose log is there, no more
            raise
        self.segments += 1

    def finish(self) -> None:
        """Join the segments into the log and give it and the events their names; an earlier run's
        summary goes first, so that no summary is ever beside a log it does not describe (a
        finished run writes it last)."""
        import pyarrow.parquet as pq

        parts = _segment_files(self.partial["log"])

        def join(path: Path) -> None:
            with pq.ParquetWriter(path, pq.read_schema(parts[0])) as writer:  # as the segments read back
                for part in parts:  # one segment in memory at a time
                    table = pq.read_table(part)
                    writer.write_table(table, row_group_size=max(len(table), 1))

        self.files["summary"].unlink(missing_ok=True)
        write(self.files["log"], join)
        write_in_place(self.files["events"], lambda target: os.replace(self.partial["events"], target))
        shutil.rmtree(self.partial["log"], ignore_errors=True)

    def abandon(self) -> None:
        """After a failure: keep the segments done (whole, readable with `read_log`) under their
        partial names; remove the partial files if there are none."""
        if not self.segments:
            shutil.rmtree(self.partial["log"], ignore_errors=True)
            self.partial["events"].unlink(missing_ok=True)


def _segment_files(folder: Path) -> list[Path]:
    """A stopped or running streamed run's segment logs, in order."""
    return sorted(folder.glob("[0-9]" * 5 + ".parquet"))


def stream_files(folder) -> dict[str, Path]:
    """The files `stream` writes into `folder`, by role."""
    folder = output_folder(folder)
    return {"log": folder / "log.parquet", "events": folder / "events.csv", "summary": folder / "summary.json"}


def partial_files(files: dict) -> dict[str, Path]:
    """Where `stream` writes the log and the events (`stream_files`) until the run finishes:
    ``log.partial.parquet``, a folder of one Parquet file a segment (`read_log` reads it), and
    ``events.partial.csv``."""
    return {role: files[role].with_name(f"{files[role].stem}.partial{files[role].suffix}") for role in ("log", "events")}


@removing_empty_folders()
def stream(source: DaySource, out, *, collector: str | Collector = "trough-ns", strategy: str | None = None,
           config=None, classifier=None, warm_start: bool = True, progress=None,
           on_segment: Callable | None = None, resolution: float = HISTOGRAM_RESOLUTION) -> StreamResult:
    """Run a tracking controller over a long span one local day at a time, streaming to `out`.

    Parameters
    ----------
    source : DaySource
        The weather, a day at a time (`synthetic_days`, `recorded_days`, `frame_days`). The span
        must hold at least one whole local day (`DaySource.check_span`, before anything runs);
        a part day at either end runs as a short segment.
    out : str or Path
        Folder for ``log.parquet``, ``events.csv`` and ``summary.json``, claimed before the run
        (`hybridtrack.outputs.claim`: no symbolic links; existing files only under ``replacing``).
        The log and the events are written as ``log.partial.parquet`` and ``events.partial.csv``
        (`partial_files`) and take their names when the run finishes, so an earlier run's files
        are kept whole until then. A run that stops keeps its finished days under those partial
        names (unless no day finished, or a write failed: then they are removed).
    collector, strategy, config, classifier
        As `hybridtrack.simulate` takes them. The config's ``engine = "auto"`` is decided on the
        whole span's steps (where the source knows them), not on one day's: a year at 1 s pays
        for compiling the kernel (`hybridtrack.kernel.COMPILE_PAYS_AT`).
    warm_start : bool
        The first segment's warm start (`hybridtrack.simulate`); later segments go on from the
        one before (its `Result.memory`).
    progress : callable or bool, optional
        Called with the steps done since its last call; True shows a bar on stderr
        (`progress_bar`), False or None nothing (`hybridtrack.simulation.progress_updates`).
    on_segment : callable, optional
        Called with each segment's `Result` before it is dropped (tests, custom tallies).
    resolution : float
        Degrees, the bin width of the error histogram the p95 comes from.

    Returns
    -------
    StreamResult

    Notes
    -----
    Memory is bounded by one segment: a day at 1 s is 86,400 steps, about 0.6 GB peak with the
    compiled kernel (``docs/long-runs.md``). Nothing is kept that grows with the span but the
    clock watch's readings (one per axis per five clear minutes, about 2 MB a year) and the
    summary's ``day_cycle`` (two entries a day).

    References
    ----------
    Apache Parquet file format: row groups, https://parquet.apache.org/docs/file-format/
    """
    from .kernel import decided
    from .simulation import check_progress, checked_config, progress_updates

    if not isinstance(source, DaySource):
        raise HybridtrackError("source must be a DaySource (synthetic_days, recorded_days or frame_days)")
    site = source.site
    config = checked_config(config)
    check_progress(progress)
    if on_segment is not None and not callable(on_segment):
        raise HybridtrackError(f"on_segment must be a callable or None, got {on_segment!r:.60}")
    if strategy is not None:
        config = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy=strategy))
    collector = as_collector(collector)
    if source.steps:  # whether the kernel pays is a question of the whole span, not of one day's segment
        config = decided(config, source.steps)
    running = RunningSummary(site=site.name, collector=collector.kind, strategy=config.controller.strategy,
                             resolution=resolution)  # checks `resolution` before anything is written
    if config.controller.strategy == "hybrid-oracle":
        source.check_true_sky()
    source.check_span()
    files = stream_files(out)
    partial = partial_files(files)
    claim([*files.values(), partial["events"]], folders=[partial["log"]])  # the log's segments: a folder
    with held(files["log"].parent), progress_updates(progress, lambda: progress_bar(source)) as update:
        result = _stream_segments(source, files, site, collector, config, classifier, warm_start, update,
                                  on_segment, running)  # no other run may append to this folder's log meanwhile
    if "awake_at_midnight" in result.summary["streamed"]:
        awake = result.summary["streamed"]["awake_at_midnight"]
        warnings.warn(f"{awake['count']} streamed day(s) began with the tracker awake at midnight (the first "
                      f"{awake['first']}): {awake['why']}", AwakeAtMidnightWarning, stacklevel=2)
    return result


def _stream_segments(source: DaySource, files: dict, site, collector: Collector, config, classifier,
                     warm_start: bool, progress, on_segment: Callable | None, running: RunningSummary) -> StreamResult:
    """`stream`'s segments, run and written into the folder it holds."""
    from .simulation import simulate

    run = _PartialRun(files)
    memory: bool | dict = warm_start
    start = None
    wind, cycle, last, awake_at_cut = set(), [], None, []
    kept = KeptAsRead()
    try:
        for day, frame in source:
            kept.add(frame)
            begin = frame.index[0]
            start = begin if start is None else start
            age = (begin - start) / pd.Timedelta(days=1)
            setup = dataclasses.replace(config, imperfections=dataclasses.replace(
                config.imperfections, commissioned_days_ago=config.imperfections.commissioned_days_ago + age),
                seed=config.seed if run.segments == 0 else day_seed(config.seed, day))
            result = simulate(frame, site, collector=collector, config=setup, classifier=classifier,
                              progress=progress, warm_start=memory)
            if run.segments and result.log["mode"].iloc[0] not in RESTING:
                awake_at_cut.append(day)
            run.append(result)
            running.add(result.log, events=result.events, **result.scoring)
            wind.add(result.summary["wind_data"])
            cycle += result.summary["day_cycle"]
            if on_segment is not None:
                on_segment(result)
            memory = result.memory
            last = {"calibration": result.summary["calibration"], "clock": result.summary["clock"]}
            del result, frame  # nothing of a segment outlives it but its memory and the running sums
    except BaseException:
        run.abandon()
        raise
    run.finish()
    summary = running.summary()
    summary["calibration"] = last["calibration"]
    summary["clock"] = last["clock"]
    summary["wind_data"] = wind.pop() if len(wind) == 1 else "partly missing"
    summary["day_cycle"] = cycle
    summary["streamed"] = {"segments": run.segments, "segment": "one local day, cut at midnight",
                           "p95_resolution_deg": running.resolution, "weather": source.describe,
                           "kept_as_read": kept.report()}
    if awake_at_cut:
        summary["streamed"]["awake_at_midnight"] = _awake_at_cut(awake_at_cut)
    write(files["summary"], lambda path: path.write_text(strict_json(summary, indent=2) + "\n"))
    return StreamResult(summary, files, site, collector, config, memory, kept)


def _awake_at_cut(days: list[dt.date]) -> dict:
    """The summary's note of the days a streamed run began with the tracker awake (`stream` warns of
    them: `AwakeAtMidnightWarning`): the controller's state and the collector restart at each cut,
    which a midnight at night stow hides and a midnight sun does not (the collector slews from stow)."""
    return {"count": len(days), "first": str(days[0]),
            "why": "the tracker was awake at midnight (its computed sun up, or about to be): each such day "
                   "restarted it from stow; run these days in memory (simulate) for an unbroken run"}


#: The columns whose missing readings a streamed run counts (`KeptAsRead`).
COUNTED_COLUMNS = ("dni", "dhi", "ghi", "wind_speed", "photocurrent")
#: Columns the run takes as a missing reading at every step when the file has none: the world's
#: sky then gives no diffuse light, as for a NaN reading (a file without DHI had run with its
#: missing counts empty, where 21 NaN DHI rows of another were counted).
ABSENT_AS_MISSING = ("dhi",)
#: A step longer than this many times the weather's typical step is a gap, as the record reader
#: counts them (`hybridtrack.io.checks`).
GAP_STEPS = 1.5


@dataclass
class KeptAsRead:
    """What a streamed run's weather holds that the run keeps as it is, counted as its days pass
    (`stream` repairs nothing; `hybridtrack.io.read_weather` counts the same in its report): the
    missing readings of each column (each a sensor's fault the controller must survive) and the
    gaps, steps longer than `GAP_STEPS` times their local step (`hybridtrack.times.local_steps`, as
    the nights a logger left out are found; a day missing from the file among them, and a
    15-minute day after a 1-minute day no gap at each step, as the first day's step had made it);
    each with the time of its first."""

    missing: dict = field(default_factory=dict)
    gaps: int = 0
    longest: pd.Timedelta = pd.Timedelta(0)
    first_gap_after: pd.Timestamp | None = None
    last: pd.Timestamp | None = None

    def add(self, frame: pd.DataFrame) -> None:
        """Count a day's frame, the day after the one counted before it."""
        for column in COUNTED_COLUMNS:
            if column in frame or column in ABSENT_AS_MISSING:
                missing = frame[column].isna().to_numpy() if column in frame else np.ones(len(frame), bool)
                if missing.any():
                    count, first = self.missing.get(column, (0, frame.index[int(np.argmax(missing))]))
                    self.missing[column] = (count + int(missing.sum()), first)
        index = frame.index if self.last is None else frame.index.insert(0, self.last)
        steps = np.diff(index.as_unit("ns").asi8)
        at = np.flatnonzero(steps > GAP_STEPS * local_steps(steps, GAP_STEPS))
        if len(at) and self.first_gap_after is None:
            self.first_gap_after = index[at[0]]
        if len(at):
            self.gaps += len(at)
            self.longest = max(self.longest, pd.Timedelta(int(steps[at].max()), "ns"))
        self.last = frame.index[-1]

    def report(self) -> dict:
        """As the summary holds it: ``missing`` by column (count, first) and, if any, ``gaps``
        (count, longest, the stamp before the first)."""
        from .io.checks import span

        out = {"missing": {column: {"count": count, "first": str(first)}
                           for column, (count, first) in self.missing.items()}}
        if self.gaps:
            out["gaps"] = {"count": self.gaps, "longest": span(self.longest), "first_after": str(self.first_gap_after)}
        return out

    def lines(self) -> list[str]:
        """A line of text for each finding, as the command line prints them."""
        said = [f"kept as read: {count:,} missing {column} reading{'s' * (count > 1)} (the first at {first})"
                for column, (count, first) in self.missing.items()]
        if self.gaps:
            said.append(f"kept as read: {self.gaps:,} gap{'s' * (self.gaps > 1)} in the time steps, the longest "
                        f"{self.report()['gaps']['longest']} (the first after {self.first_gap_after})")
        return said


def _whole(day: dt.date, frame: pd.DataFrame, site) -> bool:
    """Whether `frame` covers the whole local `day` at `site`, its last step running to midnight."""
    begin = frame.index[0]
    midnight, next_midnight = (local_midnight(d, site.tz) for d in (day, day + dt.timedelta(days=1)))
    step = frame.index[1] - begin if len(frame) > 1 else pd.Timedelta(0)
    return begin <= midnight and frame.index[-1] + step >= next_midnight


def progress_bar(source: DaySource, *, label: str = ""):
    """A tqdm bar over the steps (or the segments, when the steps are not known) on stderr
    (`hybridtrack.progress.bar`)."""
    from .progress import bar

    return bar(source.steps, unit="step", unit_scale=True, desc=label or "streaming", mininterval=1.0)
