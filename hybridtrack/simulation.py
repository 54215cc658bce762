"""Run a tracking controller over a weather frame and score it against the true sun.

The world (`hybridtrack.world.World`: the true sun, mount, sensor physics, encoder and actuator)
and the controller (`hybridtrack.control.Controller`: what a PLC has) are built apart (for a long
run on two threads, side by side). What does not depend on anyone's state is computed for the whole
frame at once: the world's true sun and sensor scene, the controller's plan from its own clock.
Then each scan the world
observes, the controller decides and the world moves; the log is scored (`hybridtrack.metrics`).
"""

from __future__ import annotations

import contextvars
import dataclasses
import functools
import numbers
import threading
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import mountpass, params, sites
from .collectors import GEOMETRY_KINDS, Collector, as_collector, within_turn
from .control import (MODES, SENSOR_STATUS, SKY_CODES, Controller, ControllerConfig, MountEstimate, Observation,
                      make_plan)
from .control.clockwatch import ClockWatch
from .control.modes import sky_code
from .control.mountfit import parameter_names
from .control.plan import east_park
from .control.wind import READABLE
from .drive import Drive
from .budget import check_steps
from .errors import HybridtrackError
from .outputs import claim, output_folder, remove_earlier, removing_empty_folders, strict_json, together, write
from .reuse import Same, same_object, shared
from .fuzzy import FuzzyWeatherClassifier
from .fuzzy.classifier import READING_LIMIT
from .io.checks import span
from .kernel import ENGINES, run_compiled, uses_kernel
from .metrics import score, summarize
from .mountreport import FIT_PREFIX
from .sensor import RECORDED_POINTING, SensorModel
from .sky import LIGHT_AT_NIGHT
from .skyinputs import (SkyInputConfig, clear_sky, clear_sky_photocurrent, fuzzy_config, photocurrent_range,
                        sky_inputs)
from .world import Imperfections, World, controller_clock, installed_site, scan_timer
from .times import check_dates

__all__ = ["SimulationConfig", "Result", "simulate", "LOG_COLUMNS", "FAULTS", "NightsLeftOutWarning",
           "AnotherSiteWarning"]
#: The faults `simulate` can inject, with what each array holds.
FAULTS = {
    "sensor": "(N,) or (N, axes): the reading the sensor gives (degrees); NaN where it works",
    "sensor_dropout": "(N,) bool: the sensor gives no reading",
    "sensor_drift": "(N,): degrees added to every sensor reading (a drifting bias)",
    "encoder": "(N,) or (N, axes): degrees added to the encoder reading (a wild count)",
    "encoder_frozen": "(N,) bool: the encoder repeats its last reading",
    "clock": "(N,): seconds added to the controller's clock",
}

#: The largest size of each numeric fault: a turn of degrees, a year of seconds (a larger clock
#: offset is no fault a tracker could meet, and beyond it pandas' time arithmetic overflows).
FAULT_LIMITS = {"sensor": 360.0, "sensor_drift": 360.0, "encoder": 360.0, "clock": 365.0 * 86_400.0}

#: The fields of a run config's parts that a run does not read, with what it reads instead: they
#: must stay at their defaults (`_refuse_unread`).
UNREAD = {
    ("sensor", "bias"): "imperfections.sensor_bias, the installed sensor's bias",
    ("sensor", "noise"): "imperfections.sensor_noise, the installed sensor's noise",
    ("sensor", "window"): "sky.window, the controller's variation window",
    ("heliostat_drive", "limits"): "nothing: a heliostat's azimuth axis turns from -180 to 540 degrees and stows "
                                   "at 180, its elevation axis from 0 to 90, stowed at 90",
    ("heliostat_drive", "stow"): "nothing: a heliostat stows its azimuth axis at 180 degrees and its elevation "
                                 "axis at 90",
}


def _refuse_unread(config) -> None:
    """Refuse a field of `UNREAD` set to other than its default: a user who set ``[sensor] bias``
    or ``[heliostat_drive] stow`` (or swept ``sensor.window``) got the default's results without a
    word. The message says what the run reads instead."""
    for (part, name), instead in UNREAD.items():
        value = getattr(getattr(config, part), name)
        if value != _unread_default(part, name):
            raise HybridtrackError(f"config: {part}.{name} = {value!r} is not read by a run; it reads {instead}")


#: ``intensity_ma`` and ``variation_ma`` are the photocurrent read and its trailing range, mA;
#: ``intensity_input`` and ``variation_input`` are what the classifier scored (``sky_score``), on the
#: mA scale of its config: the same in absolute mode, the clear-sky ratio and its range put on that
#: scale in relative mode (`hybridtrack.skyinputs.sky_inputs`).
LOG_COLUMNS = ("target_true", "target", "angle", "error", "mode", "sky", "sky_score", "sensor_valid",
               "sensor_status", "intensity_ma", "variation_ma", "intensity_input", "variation_input", "wind_speed",
               "dni", "calibration")


@dataclass(frozen=True)
class SimulationConfig:
    """Everything about a run but the weather, the site, the collector and the strategy.

    Parameters
    ----------
    controller : ControllerConfig
    imperfections : Imperfections
        The world's errors; `Imperfections.none()` for a perfect installation.
    sensor : SensorModel
    drive : Drive
        The drive of a single-axis collector.
    heliostat_drive : Drive
        A heliostat's drive: fine steps and a deadband of about a milliradian, as heliostat
        practice uses (0.05° deadband, a 16-bit encoder of 0.0055°), not a trough's 0.4°. It
        serves the elevation axis (limits 0-90°, stow 90°) and the azimuth axis, which turns all
        the way round: limits -180° to 540° (a cable wrap of one turn either way), stow at 180°.
    seed : int
        Seeds the sensor noise.
    sky : SkyInputConfig
        How the controller turns its sensor's photocurrent into the classifier's inputs
        (`hybridtrack.skyinputs`): by default the light relative to the clear sky it expects,
        measured best on real records; ``SkyInputConfig.published()`` is the published system.
    truth : {"spa-fast", "spa"}
        How the world computes the true sun: SPA with its slow series interpolated from hourly
        knots (within 1e-5° of SPA, a tenth of its cost; ``hybridtrack.sun``) or SPA itself.
    engine : {"auto", "compiled", "reference"}
        How the scans are stepped: ``reference`` the readable Python controller and world,
        ``compiled`` the numba kernel that restates them (`hybridtrack.kernel`, held equal by
        tests), ``auto`` the kernel where it supports the run, numba is installed and the kernel
        is compiled already (its disk cache) or the run is long enough to pay for compiling it
        (`hybridtrack.kernel.COMPILE_PAYS_AT` scans), else the reference: the same results.
    """

    controller: ControllerConfig = field(default_factory=ControllerConfig)
    imperfections: Imperfections = field(default_factory=Imperfections)
    sensor: SensorModel = field(default_factory=SensorModel)
    drive: Drive = field(default_factory=Drive)
    heliostat_drive: Drive = field(default_factory=lambda: Drive(deadband=0.05, encoder_bits=16))
    sky: SkyInputConfig = field(default_factory=SkyInputConfig)
    seed: int = 0
    truth: str = "spa-fast"
    engine: str = "auto"

    def __post_init__(self) -> None:
        for part in dataclasses.fields(self):  # a str or a dict had been taken, to fail deep in the run
            kind = _PART_KINDS.get(part.name)
            if kind is not None and not isinstance(getattr(self, part.name), kind):
                raise HybridtrackError(f"config: {part.name} must be a {kind.__name__}, got "
                                       f"{type(getattr(self, part.name)).__name__}")
        if self.truth not in ("spa-fast", "spa"):
            raise HybridtrackError(f"truth {self.truth!r}: choose 'spa-fast' or 'spa'")
        object.__setattr__(self, "seed", params.seed(self.seed, "seed"))  # numpy's int too; TOML writes int
        if self.engine not in ENGINES:
            raise HybridtrackError(f"engine {self.engine!r}: choose {', '.join(map(repr, ENGINES))}")
        _refuse_unread(self)

    def to_dict(self) -> dict:
        """A plain dict in the TOML layout."""
        def plain(value):
            if dataclasses.is_dataclass(value):
                return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
            if value is None:
                return "none"  # TOML has no null (the sky inputs' smoothing)
            return list(value) if isinstance(value, tuple) else value

        return plain(self)

    @classmethod
    def from_dict(cls, data, *, source: str = "config") -> SimulationConfig:
        """Build from the TOML layout; unknown keys and wrong types are refused with their key."""
        if not isinstance(data, Mapping):
            raise HybridtrackError(f"{source}: a run config must be a table (a dict), got {type(data).__name__}")
        def build(default, values, where):
            kind = type(default)
            if not isinstance(values, dict):
                raise HybridtrackError(f"{source}: {where or 'config'} must be a table")
            known = {f.name: f for f in dataclasses.fields(kind)}
            unknown = sorted(set(values) - set(known))
            if unknown:
                raise HybridtrackError(f"{source}: {where + '.' if where else ''}{unknown[0]}: unknown key; "
                                       f"known: {', '.join(known)}")
            changes = {}
            for name, value in values.items():
                key = f"{where}.{name}" if where else name
                current = getattr(default, name)
                if isinstance(value, np.generic):  # numpy's scalars as Python's: np.int64 had been no whole number
                    value = value.item()
                if dataclasses.is_dataclass(current):
                    changes[name] = build(current, value, key)
                elif isinstance(current, tuple):
                    if not isinstance(value, list) or len(value) != len(current):
                        raise HybridtrackError(f"{source}: {key}: must be a list of {len(current)}, got {value!r}")
                    changes[name] = tuple(value)
                elif isinstance(current, bool) or isinstance(value, bool):
                    if type(value) is not type(current):
                        raise HybridtrackError(f"{source}: {key}: must be {type(current).__name__}, got {value!r}")
                    changes[name] = value
                elif isinstance(current, (int, float)) and not isinstance(current, bool):
                    if not isinstance(value, (int, float)) or (isinstance(current, int) and not isinstance(value, int)):
                        kind = "a whole number" if isinstance(current, int) else "a number"
                        raise HybridtrackError(f"{source}: {key}: must be {kind}, got {value!r}")
                    changes[name] = value
                elif isinstance(current, str):
                    if not isinstance(value, str):
                        raise HybridtrackError(f"{source}: {key}: must be text, got {value!r}")
                    changes[name] = value
                else:  # pragma: no cover - every field is one of the above
                    changes[name] = value
            try:
                return dataclasses.replace(default, **changes)
            except HybridtrackError as exc:
                said = str(exc)
                if where and not said.startswith(f"{where}: "):
                    said = f"{where}: {said}"
                raise HybridtrackError(f"{source}: {said}") from None

        return build(cls(), dict(data), "")

    @classmethod
    def from_toml(cls, path) -> SimulationConfig:
        """Load from a TOML file; keys left out keep their defaults."""
        from .io import read_toml

        return cls.from_dict(read_toml(path), source=str(path))

    def to_toml(self, path) -> Path:
        """Write as TOML; `from_toml` reads it back equal."""
        from .io import write_toml

        return write_toml(self.to_dict(), path)


#: The kind each part of a `SimulationConfig` must be.
_PART_KINDS = {"controller": ControllerConfig, "imperfections": Imperfections, "sensor": SensorModel, "drive": Drive,
               "heliostat_drive": Drive, "sky": SkyInputConfig}
#: Each part's default, by the part's name.
_DEFAULT_PARTS = {f.name: f.default_factory for f in dataclasses.fields(SimulationConfig)
                  if f.default_factory is not dataclasses.MISSING}


@functools.cache
def _unread_default(part: str, name: str):
    """The default of an `UNREAD` field, made once (a config is made for every collector of a field
    and every day of a stream)."""
    return getattr(_DEFAULT_PARTS[part](), name)


@dataclass
class Result:
    """A finished run.

    Attributes
    ----------
    log : pandas.DataFrame
        One row per step, indexed like the frame (see `LOG_COLUMNS`; a heliostat adds the
        ``*_azimuth`` columns of its second axis; a controller that fits its mount adds each
        fitted parameter and its 1σ, ``fit_<name>`` and ``fit_<name>_std``, degrees).
    summary : dict
        The metrics written to ``summary.json`` (`hybridtrack.metrics`).
    events : pandas.DataFrame
        Every mode change: ``time``, ``from``, ``to``, ``reason``.
    memory : dict
        What the controller would carry into a next run (its mount fit and offsets, the clock
        watch's readings, a commissioned mount): `simulate`'s ``warm_start`` takes it.
    scoring : dict
        The inputs of the summary that are not in the log (per step ``sun_up`` and ``incidence``;
        ``moves`` and unrounded ``travel``), for scoring a run in parts
        (`hybridtrack.metrics.RunningSummary`).
    """

    log: pd.DataFrame
    summary: dict
    events: pd.DataFrame
    site: sites.Site
    collector: Collector
    config: SimulationConfig
    memory: dict | None = None
    scoring: dict | None = field(default=None, repr=False)

    @staticmethod
    def files(folder, *, plot: bool = True, log_format: str = "parquet") -> dict[str, Path]:
        """The files `save` writes into `folder`, by role."""
        if log_format not in ("parquet", "csv"):
            raise HybridtrackError(f"log_format {log_format!r}: choose 'parquet' or 'csv'")
        folder = output_folder(folder)
        files = {"log": folder / f"log.{log_format}", "events": folder / "events.csv",
                 "summary": folder / "summary.json"}
        return {**files, "report": folder / "report.png"} if plot else files

    @removing_empty_folders()
    def save(self, folder, *, plot: bool = True, log_format: str = "parquet") -> dict[str, Path]:
        """Write ``log.parquet`` (``log_format="csv"``: ``log.csv``), ``events.csv``, ``summary.json``
        (strict JSON: ``null`` for a missing number) and ``report.png``; see `hybridtrack.outputs`
        for what is refused. An earlier save's file that this one does not write (the log in the
        other format, the report when `plot` is False) is removed, as a file to replace is: left
        there, it would be read as this run's."""
        written = self.files(folder, plot=plot, log_format=log_format)
        every = {*self.files(folder, log_format="csv").values(), *self.files(folder).values()}
        earlier = sorted(every - set(written.values()))
        claim(written.values(), earlier=earlier)
        with together():  # all of this run's files, or none
            if log_format == "parquet":
                write(written["log"], self.log.to_parquet)
            else:
                write(written["log"], lambda path: self.log.to_csv(path, float_format="%.5f", index_label="time"))
            write(written["events"], lambda path: self.events.to_csv(path, index=False))
            write(written["summary"], lambda path: path.write_text(strict_json(self.summary, indent=2) + "\n"))
            if plot:
                from .report import plot_run, save_figure

                save_figure(plot_run(self), written["report"])
        remove_earlier(earlier)
        return written

    # -- for people (hybridtrack.report): a short repr, an HTML repr, pictures, a daily table --

    def __repr__(self) -> str:
        from .report import describe

        return describe(self)

    def _repr_html_(self) -> str:
        from .report import describe_html

        return describe_html(self)

    def plot(self, *, day=None):
        """The run as a `matplotlib.figure.Figure` (a timeline, or an overview of a long run)."""
        from .report import plot_run

        return plot_run(self, day=day)

    def daily(self) -> pd.DataFrame:
        """One row per local day: energy capture, RMS, p95, moves, stow minutes, sky shares."""
        from .report import daily

        return daily(self)

    def explain(self, time):
        """Why the controller was in its mode at `time`, with the fuzzy rules for that step."""
        from .report import explain_step

        return explain_step(self, time)


def _drives(collector: Collector, config: SimulationConfig) -> list[Drive]:
    if collector.kind != "heliostat":
        return [config.drive]
    drive = config.heliostat_drive
    return [dataclasses.replace(drive, limits=(-180.0, 540.0), stow=180.0),
            dataclasses.replace(drive, limits=(0.0, 90.0), stow=90.0)]


#: The longest typical (median) step a run takes: hourly records (a TMY or EPW file) are the coarsest
#: a tracking controller is replayed over; a longer step, in which the sun turns more than 15°, is
#: not a scan (a 13-hour step made a day of two scans and a meaningless score).
LONGEST_STEP = pd.Timedelta(hours=1)
#: The shortest step a run is replayed at: a PLC's scan of a tracking drive, which turns about
#: 0.004° a second with the sun (the year at 1-second steps is the finest this project runs).
SHORTEST_STEP = pd.Timedelta(seconds=1)


def run_step(freq) -> pd.Timedelta:
    """`freq` (``"1min"``, ``"10s"``) as the step of a run's synthetic weather, refused beyond
    `LONGEST_STEP`: ``"2h"`` or ``"1D"`` had made a frame that every run then refused as a
    frame ("resample the frame"), which a user who gave a step and no frame cannot do."""
    from .times import parse_freq

    step = parse_freq(freq)
    if step > LONGEST_STEP:
        raise HybridtrackError(f"step {freq!r} is longer than a run's longest, {LONGEST_STEP / pd.Timedelta(hours=1):g} h "
                               "(a tracking controller is replayed at steps of an hour or finer)")
    return step


def _check_frame(frame: pd.DataFrame) -> pd.DataFrame:
    if not isinstance(frame, pd.DataFrame) or not isinstance(frame.index, pd.DatetimeIndex):
        raise HybridtrackError("the weather frame must be a DataFrame on a DatetimeIndex")
    if frame.index.tz is None:
        raise HybridtrackError("the weather frame's index is naive; localise it (index.tz_localize(...))")
    if len(frame) < 2:
        raise HybridtrackError("the weather frame needs at least two steps")
    if not frame.index.is_monotonic_increasing or frame.index.has_duplicates:
        raise HybridtrackError("the weather frame's index must be increasing without repeats "
                               "(read files with hybridtrack.io.read_weather, which sorts and de-duplicates)")
    check_dates(frame.index[0].date(), frame.index[-1].date(), f"the weather frame ({frame.index[0]} to "
                f"{frame.index[-1]})")
    if isinstance(frame.columns, pd.MultiIndex):  # pandas gave a frame for each column: an AttributeError
        raise HybridtrackError("the weather frame's columns must be plain names (dni, dhi, …), not a MultiIndex; "
                               "flatten them first")
    if "dni" not in frame.columns:
        raise HybridtrackError(f"the weather frame has no 'dni' column; it has {', '.join(map(str, frame.columns))}")
    repeated = frame.columns[frame.columns.duplicated()]
    if len(repeated):  # which of the two would be the weather?
        raise HybridtrackError(f"the weather frame has the column {repeated[0]!r} more than once; keep one")
    for column in ("dni", "dhi", "ghi", "wind_speed", "temp_air", "photocurrent", *RECORDED_POINTING):
        if column in frame.columns:
            _physical_column(frame, column)
    first, last = frame.index[0], frame.index[-1]
    check_steps(first, last, (last - first) / (len(frame) - 1), what="the weather frame")
    typical = pd.Timedelta(int(np.median(np.diff(frame.index.as_unit("ns").asi8))), "ns")
    if typical < SHORTEST_STEP:
        raise HybridtrackError(f"the weather frame's stamps are {span(typical)} apart (median): a tracking "
                               f"controller is replayed at steps of {span(SHORTEST_STEP)} or longer; were epoch "
                               "seconds read as nanoseconds? (pandas.to_datetime(values, unit='s'))")
    if typical > LONGEST_STEP:
        hours = typical / pd.Timedelta(hours=1)
        raise HybridtrackError(f"the weather frame's steps are {hours:g} h apart (median), in which the sun turns "
                               f"{15 * hours:.0f}°: a tracking controller is replayed at steps of "
                               f"{LONGEST_STEP / pd.Timedelta(hours=1):g} h or finer; resample the frame")
    return frame


def _refuse_unphysical_light(frame: pd.DataFrame, site: sites.Site, altitude: np.ndarray) -> None:
    """Refuse a frame's light no sky at `site` gives: direct light at night (`_refuse_light_at_night`)
    or irradiance in kW/m² where W/m² belong (`_refuse_kilowatts`)."""
    _refuse_light_at_night(frame, site, altitude)
    _refuse_kilowatts(frame, site, altitude)


#: W/m²: DHI below this is no sky's, in kW/m² or W/m² alike (a frame's "no diffuse light", 0 or
#: its rounding, 1e-13, beam-only DHI by closure); in kW/m² a day's DHI with the clear sky at
#: `JUDGED_FROM` is tens of W/m², 0.02 or more.
NO_DIFFUSE = 0.01


def _refuse_kilowatts(frame: pd.DataFrame, site: sites.Site, altitude: np.ndarray) -> None:
    """Refuse a frame made in memory whose irradiance is in kW/m², judged day by day (a frame of
    days in two units is refused by its first kW/m² day) where the site's clear sky (Haurwitz
    1945, on the true sun) reaches `JUDGED_FROM`: GHI, or DHI above `NO_DIFFUSE`, whose largest
    value is at most `KILOWATT_TOP`; or DNI of at most that beside a beam GHI shows
    (`hybridtrack.io.checks.horizontal_beam`: `BEAM_SEEN` W/m² or more). No sky is so dark with
    the sun so high. DNI alone is not judged: a DNI-only overcast day has none to show (a file's
    whole span is, `hybridtrack.io.checks.check_magnitude`), and a frame's DNI of 0 beside a
    sunny GHI is its maker's to mean."""
    import pvlib

    from .io.checks import BEAM_SEEN, JUDGED_FROM, KILOWATT_TOP, horizontal_beam

    clear = pvlib.clearsky.haurwitz(pd.Series(90.0 - altitude, index=frame.index))["ghi"].to_numpy(float)
    beam = horizontal_beam(frame, clear) if "ghi" in frame.columns else None
    columns = {"sky": clear, "seen": beam[0] if beam is not None else np.full(len(frame), np.nan),
               **{name: frame[name].to_numpy(float) for name in ("ghi", "dhi", "dni") if name in frame.columns}}
    days = frame.index.tz_convert(site.tz).normalize()  # local midnights: no Python date made per stamp
    tops = pd.DataFrame(columns, index=days).groupby(level=0).max()  # NaN where a day has no number
    tops = tops[tops["sky"] >= JUDGED_FROM]
    for name, low, beside_beam in (("ghi", 0.0, False), ("dhi", NO_DIFFUSE, False), ("dni", 0.0, True)):
        if name not in tops:
            continue
        beside = tops["seen"] >= BEAM_SEEN if beside_beam else True
        found = tops[(tops[name] > low) & (tops[name] <= KILOWATT_TOP) & beside]
        if len(found):
            day, top = found.index[0].date(), found.iloc[0]
            why = (f"{beam[1]} {top['seen']:.0f} W/m² (a direct beam)" if beside_beam else
                   f"the clear sky reaches {top['sky']:.0f} W/m²")
            raise HybridtrackError(f"the weather frame on {day}: column {name!r}: {name} is at most {top[name]:g} while "
                                   f"{why}; the values look like kW/m², where W/m² belong: multiply the frame's "
                                   f"{name} by 1000")


def _refuse_light_at_night(frame: pd.DataFrame, site: sites.Site, altitude: np.ndarray) -> None:
    """Refuse a frame whose direct light comes while the sun is down at `site`: another place's
    weather, or an index in another time zone (a Denver day run at Lanzhou scored 0.9999).

    The rule is the records' sun check (`hybridtrack.io.suncheck`: more than 3 steps, and more
    than 2 % of the lit ones, with DNI above `LIGHT_AT_NIGHT`) on the true sun the world has
    computed: down throughout the stamp's tolerance (45 minutes or the step) either side is an
    altitude below the most the sun climbs in that time, 15° an hour. The step is the median one:
    a frame of days apart (typical days, a gap of a week) has no longer steps for it.
    """
    dni = frame["dni"].to_numpy(float)
    lit = dni > LIGHT_AT_NIGHT
    step = pd.Timedelta(int(np.median(np.diff(frame.index.as_unit("ns").asi8))), "ns")  # a gap is not a step
    hours = max(pd.Timedelta(minutes=45), step) / pd.Timedelta(hours=1)
    night = lit & (altitude < -15.0 * hours)
    if night.sum() > max(3, 0.02 * lit.sum()):
        first = int(np.flatnonzero(night)[0])
        raise HybridtrackError(f"the weather frame's direct light comes while the sun is down at {site.name}: "
                               f"{int(night.sum())} of {int(lit.sum())} lit steps, the first {dni[first]:g} W/m² at "
                               f"{frame.index[first]}; is it another place's weather, or its index in another time "
                               "zone? (hybridtrack.io.read_weather with the site finds the offset that fits)")


def _first_not_number(values: pd.Series) -> str:
    """Where a column of text first holds a value that is no number (``; the first that is none, at
    <stamp>: 'warm'``); nothing for another dtype (dates, booleans), or text of numbers alone."""
    if values.dtype != object and not pd.api.types.is_string_dtype(values.dtype):
        return ""
    numbers = pd.to_numeric(values, errors="coerce")
    text = np.flatnonzero(numbers.isna().to_numpy() & values.notna().to_numpy())
    return f"; the first that is none, at {values.index[text[0]]}: {values.iloc[text[0]]!r:.40}" if len(text) else ""


#: Light no sky gives, by column: ten times the most there is (the solar constant, 1361 W/m², at
#: perihelion: 1408 W/m²; a photocurrent of 10 A where the reader's limit is 10,000 mA). A reading
#: past it is a unit mixed up (kW/m² read as W/m², ×1000) or garbage (1e200 W/m² failed deep in the
#: mount fit with numpy's LinAlgError); a spike below it is a sensor's fault to survive.
NOT_LIGHT = {"dni": 14_080.0, "dhi": 14_080.0, "ghi": 14_080.0, "photocurrent": READING_LIMIT}
_UNITS = {"dni": "W/m²", "dhi": "W/m²", "ghi": "W/m²", "photocurrent": "mA"}


def _physical_column(frame: pd.DataFrame, column: str) -> None:
    """Refuse a column that is not numbers, or light that is infinite or past `NOT_LIGHT` (no world
    has it), naming the first such row. A negative or missing reading is a sensor's fault the
    controller must survive (`hybridtrack.faults`), so it runs; `hybridtrack.io.read_weather`
    repairs files."""
    values = frame[column]
    if not params.real_numbers(values.dtype):
        raise HybridtrackError(f"the weather frame's column {column!r} must hold numbers, got dtype {values.dtype}"
                               f"{_first_not_number(values)}")
    if column in RECORDED_POINTING:
        _pointing_column(frame, column)
    if column == "temp_air":
        _air_temperature(frame)
    if column not in NOT_LIGHT:
        return
    first = _first_wrong(frame, column, lambda light: np.isinf(light) | (light > NOT_LIGHT[column]))
    if first is not None:
        stamp, value = first
        why = "no reading (infinite)" if value == -np.inf else \
            f"not light (over {NOT_LIGHT[column]:,.0f}: a unit mixed up?)"  # -inf had been called "over 14,080"
        raise HybridtrackError(f"the weather frame's column {column!r} at {stamp}: {value:g} {_UNITS[column]} is "
                               f"{why}; read files with hybridtrack.io.read_weather, which flags and counts such values")


def _first_wrong(frame: pd.DataFrame, column: str, wrong) -> tuple[pd.Timestamp, float] | None:
    """The stamp and value of `column`'s first row where `wrong` (of the column's values as floats,
    NaN for a missing one) holds, or None."""
    array = frame[column].to_numpy(float, na_value=np.nan)
    with np.errstate(invalid="ignore"):
        bad = np.flatnonzero(wrong(array))
    return (frame.index[bad[0]], array[bad[0]]) if len(bad) else None


def _air_temperature(frame: pd.DataFrame) -> None:
    """Refuse an air temperature no air has (`hybridtrack.io.checks.LIMITS`, -90 to 65 °C, the
    records on earth either side), or none (infinite), naming the first such row. No run reads it
    yet, but a frame's kelvins or a logger's -9999 beside its light says the frame was made wrong,
    and its inf and text had run without a word; a file's reader counts such cells instead."""
    from .io.checks import LIMITS

    low, high = LIMITS["temp_air"]
    first = _first_wrong(frame, "temp_air", lambda air: np.isinf(air) | (air < low) | (air > high))
    if first is not None:
        stamp, value = first
        why = "no reading (infinite)" if np.isinf(value) else f"no air's (outside [{low:g}, {high:g}] °C: kelvins?)"
        raise HybridtrackError(f"the weather frame's column 'temp_air' at {stamp}: {value:g} °C is {why}; "
                               "read files with hybridtrack.io.read_weather, which flags and counts such values")


#: Degrees: the largest offset a recorded pointing signal can give, the sun at the horizon of a
#: sensor facing the zenith; the fine cells see ±10° (`SensorModel.field_of_view`).
POINTING_LIMIT = 90.0


def _pointing_column(frame: pd.DataFrame, column: str) -> None:
    """Refuse a recorded pointing signal (degrees off the sun) that is infinite or past
    `POINTING_LIMIT`: inf and 500° had been taken as readings."""
    first = _first_wrong(frame, column, lambda offset: np.isinf(offset) | (np.abs(offset) > POINTING_LIMIT))
    if first is not None:
        raise HybridtrackError(f"the weather frame's column {column!r} at {first[0]}: {first[1]:g}° is no sun "
                               f"sensor's offset (beyond ±{POINTING_LIMIT:g}°: milliradians, or arcminutes?)")


def checked_config(config) -> SimulationConfig:
    """`config`, or the default for None; anything but a `SimulationConfig` (a dict, say) is refused."""
    if config is None:
        return SimulationConfig()
    if not isinstance(config, SimulationConfig):
        raise HybridtrackError(f"config must be a SimulationConfig (SimulationConfig.from_dict for a dict), "
                               f"got {type(config).__name__}")
    return config


def simulate(frame: pd.DataFrame, site, *, collector: str | Collector = "trough-ns", strategy: str | None = None,
             config: SimulationConfig | None = None, classifier: FuzzyWeatherClassifier | None = None,
             faults: dict | None = None, progress=None, bulk_nights: bool = True,
             warm_start: bool | dict = True, sky_seed: int | None = None) -> Result:
    """Run a tracking controller over a weather frame.

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame (``dni``; ``dhi``, ``wind_speed``, a recorded ``photocurrent`` and the
        true ``sky`` when there are) on a tz-aware, increasing index. Without ``dhi`` (or where it
        is NaN) the sky gives no diffuse light: no bright cloud patch in the sensor's view
        (`hybridtrack.io.read_weather` derives a file's DHI from its GHI and DNI, and counts it).
    site : Site or str
    collector : str or Collector
        ``trough-ns``, ``trough-ew``, ``fresnel`` or ``heliostat``, or a `Collector` with
        its geometry (``Collector("trough", axis_azimuth=45)`` for a trough on another axis).
    strategy : str, optional
        One of ``hybridtrack.control.STRATEGIES``; overrides the config's.
    config : SimulationConfig, optional
    classifier : FuzzyWeatherClassifier, optional
        The controller's sky classifier; the published one by default.
    faults : dict, optional
        Injected faults for testing, one array value per step; see `FAULTS`.
    progress : callable or bool, optional
        Called with the number of steps done since its last call (e.g. a tqdm bar's update),
        from the thread that runs the scan loop: for a long compiled run
        (`SIDE_BY_SIDE_FROM` scans or more) a second thread, so it must be safe to call from
        one (tqdm's is). True shows a bar of the steps on stderr; False or None nothing.
    bulk_nights : bool
        Record a night asleep at stow in one go (the same result, faster; a test keeps it so).
    warm_start : bool or dict
        Start as a controller that has been running: ``astronomical-commissioned`` is
        commissioned, and the calibrating strategies carry their calibration, from a clear day
        before the run (`hybridtrack.commissioning`). ``False`` starts from nothing. A dict is
        an earlier run's `Result.memory`: this run goes on from where that one ended (a long run
        in day-long parts, `hybridtrack.streaming`).
    sky_seed : int, optional
        Seeds the sky of that clear day before the run; by default the config's seed, which
        seeds the world's own draws (the sensor's noise) too. A field's collectors share one
        (`hybridtrack.simulate_field`'s seed): collector ``i`` of a field runs alone as
        ``simulate(..., config=replace(config, imperfections=drawn[i], seed=its_seed),
        sky_seed=field_seed)``.

    Returns
    -------
    Result
    """
    warn_of_nights_left_out(frame, site)
    warn_of_another_site(frame, site)
    with progress_updates(progress, lambda: _step_bar(frame)) as update:
        return _scored(track(frame, site, collector=collector, strategy=strategy, config=config, classifier=classifier,
                             faults=faults, progress=update, bulk_nights=bulk_nights, warm_start=warm_start,
                             sky_seed=sky_seed))


@contextmanager
def progress_updates(progress, bar: Callable) -> Iterator[Callable | None]:
    """What a run calls with each count of steps done, from its `progress` argument: a callable as
    given; True a tqdm bar made by `bar()` and closed after (as a field's ``progress=True``); False
    or None nothing (`check_progress`)."""
    check_progress(progress)
    if isinstance(progress, (bool, np.bool_)) and progress:
        with bar() as made:
            yield made.update
        return
    yield progress if callable(progress) else None


def check_progress(progress) -> None:
    """Refuse a `progress` that is neither a callable, True, False nor None, by name."""
    if progress is not None and not isinstance(progress, (bool, np.bool_)) and not callable(progress):
        raise HybridtrackError(f"progress must be a callable (a tqdm bar's update), True, False or None, got "
                               f"{progress!r:.60}")


def _step_bar(frame: pd.DataFrame):
    """A tqdm bar over a frame's steps, on stderr."""
    from .progress import bar

    return bar(len(frame), unit="step", unit_scale=True, mininterval=1.0)


class NightsLeftOutWarning(UserWarning):
    """A weather frame leaves nights out (a logger that records by day only): each morning's slew
    from stow is scored, as no PLC scanning all night would show (`hybridtrack.io.fill_nights`)."""


def warn_of_nights_left_out(frame: pd.DataFrame, site) -> None:
    """Warn (`NightsLeftOutWarning`) of the nights `frame` leaves out between its readings, unless
    its validation report names them already (``read_weather``'s, from the command line's reader).
    A day-only logger file had scored its hybrid tracker 0.70° RMS against 0.15° with its nights,
    without a word from the API. A frame the run will refuse is left to the run to refuse."""
    import warnings

    from .io.nights import night_gaps

    if not isinstance(frame, pd.DataFrame) or "nights_left_out" in frame.attrs.get("validation", {}):
        return
    try:
        left_out = night_gaps(_check_frame(frame), site)  # a frame of 1-ns steps: no night filled at them
    except HybridtrackError:  # a site, an index or stamps the run refuses with its own words
        return
    if left_out:
        warnings.warn(f"the frame leaves out {left_out} night{'s' if left_out > 1 else ''} (no rows from a night "
                      "into its morning): each such morning's slew from stow is scored, as no PLC scanning all "
                      "night would show; hybridtrack.io.fill_nights(frame, site) puts them back",
                      NightsLeftOutWarning, stacklevel=3)


class AnotherSiteWarning(UserWarning):
    """A weather frame made for one site (its ``attrs["site"]``) is run at another."""



def warn_of_another_site(frame: pd.DataFrame, site) -> None:
    """Warn (`AnotherSiteWarning`) when `frame` says it was made for another site than `site`:
    its ``attrs["site"]`` (set by `hybridtrack.sky.synthetic` and `hybridtrack.io.read_weather`)
    names another place. Lanzhou's weather run at Nanjing had run without a word: its sun, light
    and wind are Lanzhou's, and only another time zone's index is refused (light at night). A
    built-in site's name beside a `Site` at the same coordinates (`sites.builtin_here`) is the same
    place; a site the run refuses is left to the run to refuse."""
    import warnings

    made_for = frame.attrs.get("site") if isinstance(frame, pd.DataFrame) else None
    try:
        runs_at = sites.get(site)
    except HybridtrackError:
        return
    if not isinstance(made_for, str) or made_for.strip().lower() == runs_at.name.strip().lower():
        return
    if sites.builtin_here(made_for, runs_at) is not None:
        return
    warnings.warn(f"the weather frame was made for {made_for} (its attrs['site']) and runs at {runs_at.name}: "
                  f"its sun, light and wind are {made_for}'s; make or read the weather for {runs_at.name}",
                  AnotherSiteWarning, stacklevel=3)


@dataclass
class Tracked:
    """A run tracked but not yet scored: what `simulate` builds its `Result` from, and what a
    caller that needs less than a `Result` takes instead (a field's collector kept without its log:
    `scores`; a warm start's clear day: `memory`).

    Attributes
    ----------
    index : pandas.DatetimeIndex
        The frame's stamps.
    site : Site
    told : Site
        The site as the installer told the controller.
    collector : Collector
    config : SimulationConfig
        With the run's strategy.
    world : World
    controller : Controller
    out : ControllerOutputs
    incidence : numpy.ndarray
        The cosine of incidence on a perfectly tracking aperture, per step.
    mount : MountEstimate or None
        The commissioned mount (``astronomical-commissioned``).
    classifier : FuzzyWeatherClassifier
    clear : callable or None
        Gives the clear sky the controller expects at each scan (a frame, made when the log asks
        for it), or None where it expects none.
    frame : pandas.DataFrame
    """

    index: pd.DatetimeIndex
    site: sites.Site
    told: sites.Site
    collector: Collector
    config: SimulationConfig
    world: World
    controller: Controller
    out: object
    incidence: np.ndarray
    mount: MountEstimate | None
    classifier: FuzzyWeatherClassifier
    clear: Callable[[], pd.DataFrame] | None
    frame: pd.DataFrame = field(repr=False)

    def scoring(self) -> dict:
        """The summary's inputs that are not in the log (`Result.scoring`)."""
        return {"sun_up": self.world.altitude > 0, "incidence": self.incidence, "moves": int(self.out.moves.sum()),
                "travel": float(self.out.travel.sum())}

    def events(self) -> pd.DataFrame:
        """The controller's events, stamped by their scan's time."""
        return _events_frame(self.index, self.out.events)

    def memory(self) -> dict:
        """What the controller carries into a next run (`Result.memory`)."""
        memory = self.controller.carry(self.index[0])
        if self.config.controller.strategy == "astronomical-commissioned":
            memory["commissioned"] = self.mount
        memory["origin"] = {"collector": self.collector.kind, "geometry": collector_geometry(self.collector),
                            "site": self.site.name, "latitude": self.site.latitude, "longitude": self.site.longitude,
                            "end": self.index[-1]}
        return memory

    def scores(self, events: pd.DataFrame) -> dict:
        """The summary's scores (`hybridtrack.metrics.score`) without building the log: from the
        pointing error, the modes, the DNI and the angles alone."""
        log = pd.DataFrame(_scored_columns(self.collector, self.world, self.out), index=self.index, copy=False)
        return score(log, collector=self.collector.kind, events=events, **self.scoring())


def track(frame: pd.DataFrame, site, *, collector: str | Collector = "trough-ns", strategy: str | None = None,
          config: SimulationConfig | None = None, classifier: FuzzyWeatherClassifier | None = None,
          faults: dict | None = None, progress=None, bulk_nights: bool = True,
          warm_start: bool | dict = True, fit_columns: bool = True, sky_seed: int | None = None) -> Tracked:
    """`simulate`'s run without its scoring: the world and the controller stepped over the frame.
    Takes `simulate`'s arguments; returns a `Tracked`. Without `fit_columns` the compiled kernel
    keeps no mount fit at each scan: for a run scored by `Tracked.scores` alone, whose log is
    never made (`hybridtrack.kernel.bridge.run_compiled`). `sky_seed` seeds the sky of the clear
    day before the run (warm start, commissioning; `hybridtrack.commissioning.clear_day`): by
    default the config's seed; a field gives its collectors its own."""
    config = checked_config(config)
    if progress is not None and not callable(progress):  # it is called with each count of steps done
        raise HybridtrackError(f"progress must be a callable (a tqdm bar's update) or None, got {progress!r:.60}")
    _check_run_options(classifier, bulk_nights, warm_start)
    sky_seed = None if sky_seed is None else params.seed(sky_seed, "sky_seed")
    if strategy is not None:
        config = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy=strategy))
    site = sites.get(site)
    collector = as_collector(collector)
    # once for a field's collectors under one frame (`hybridtrack.reuse`; 8 ms a year's frame)
    frame = same_object(("weather frame checked", Same(frame)), lambda: _check_frame(frame))
    faults = _check_faults(faults or {}, len(frame), 2 if collector.kind == "heliostat" else 1)
    drives = _drives(collector, config)
    if config.controller.strategy == "hybrid-oracle":
        check_true_sky(frame)

    def build_world():
        world = World(frame, site, collector, config.imperfections, config.sensor, drives, config.seed, faults,
                      truth=config.truth)
        # once for a field's collectors under one frame (`hybridtrack.reuse`): a refusal is not kept;
        # on the world's side, beside the plan, which takes longer (a field's first run waits for both)
        shared(("light checked", Same(frame), site), lambda: _refuse_unphysical_light(frame, site, world.altitude))
        return world

    told = installed_site(site, config.imperfections)  # the site as the installer told the controller

    def plan_ahead():
        return _controller_side(frame.index, site, told, collector, config, classifier, faults, warm_start, sky_seed)

    world, (mount, memory, plan, clf, clear) = _side_by_side(build_world, plan_ahead, len(frame))
    controller = Controller(config.controller, drives, plan, clf, config.sky, config.sensor.dark_current,
                            east_park(collector), memory, config.sensor.responsivity, config.sensor.direct_threshold)
    compiled = uses_kernel(config, world.n)
    stop = threading.Event()

    def run_scans():
        if compiled:
            return run_compiled(world, controller, progress, bulk_nights and not faults, stop, fit_columns)
        _run(world, controller, progress, bulk_nights and not faults)
        return controller.outputs()

    def score_ahead():
        return world.incidence()

    # the compiled loop lets go of Python's lock, so the scoring's geometry is done beside it
    out, incidence = _side_by_side(run_scans, score_ahead, len(frame) if compiled else 0, cancel=stop.set)
    return Tracked(frame.index, site, told, collector, config, world, controller, out, incidence, mount, clf, clear,
                   frame)


def _scored(run: Tracked) -> Result:
    """The `Result` of a tracked run: its log, summary and events."""
    index, out, config, collector, controller = run.index, run.out, run.config, run.collector, run.controller
    sky = _sky_seen(out.intensity, index, run.classifier, config, run.clear and run.clear(), run.told)
    log = _log(index, collector, run.world, out, sky)
    events = run.events()
    scoring = run.scoring()
    summary = summarize(log, site=run.site.name, collector=collector.kind, strategy=config.controller.strategy,
                        events=events, **scoring)
    summary["calibration"] = _calibration_summary(run.mount, controller.fitted_mount(), out, collector)
    summary["clock"] = controller.clock.state() if controller.clock is not None else None
    summary["wind_data"] = _wind_data(run.frame)
    summary["day_cycle"] = _day_cycle(events, run.site)
    return Result(log, summary, events, run.site, collector, config, run.memory(), scoring)




#: What the hybrid-oracle policy reads from a weather's ``sky`` column, for its refusals.
ORACLE_READS = f"the hybrid-oracle policy reads {', '.join(map(repr, SKY_CODES))}"


def unknown_sky(labels: pd.Series) -> np.ndarray:
    """Where `labels` (a ``sky`` column as read) name no sky of `SKY_CODES`; a missing one is
    unknown, which the hybrid-oracle policy takes."""
    return (labels.notna() & ~labels.isin(SKY_CODES)).to_numpy()


def check_true_sky(frame: pd.DataFrame) -> None:
    """The hybrid-oracle policy's true sky: a ``sky`` column of `SKY_CODES` labels (or missing). Any
    other label ('Sunny', 'clear', 1) had been read as not sunny, and the day run open loop."""
    if "sky" not in frame.columns:
        raise HybridtrackError("the hybrid-oracle policy needs the frame's true 'sky' column (synthetic frames "
                               "have one)")
    unknown = np.flatnonzero(unknown_sky(frame["sky"]))
    if len(unknown):
        raise HybridtrackError(f"the frame's 'sky' column at {frame.index[unknown[0]]}: "
                               f"{frame['sky'].iloc[unknown[0]]!r} is no sky label; {ORACLE_READS}")


def _check_run_options(classifier, bulk_nights, warm_start) -> None:
    """Refuse `simulate`'s options of another kind: a string classifier raised an AttributeError
    deep in the sky watch, and warm_start="no" was read as True."""
    if classifier is not None and not isinstance(classifier, FuzzyWeatherClassifier):
        raise HybridtrackError(f"classifier must be a FuzzyWeatherClassifier or None, got {classifier!r:.60}")
    if not isinstance(bulk_nights, (bool, np.bool_)):
        raise HybridtrackError(f"bulk_nights must be True or False, got {bulk_nights!r:.60}")
    if not isinstance(warm_start, (bool, np.bool_, dict)):
        raise HybridtrackError(f"warm_start must be True, False or an earlier run's Result.memory, got "
                               f"{warm_start!r:.60}")


#: Scans from which `simulate` builds the world on a second thread while the controller plans: both
#: are numpy over every scan, which runs without Python's lock, so the two take little more than the
#: longer of them (a site-year: 0.32 s for both against 0.28 s and 0.31 s alone, measured); below
#: this a thread is not worth starting.
SIDE_BY_SIDE_FROM = 50_000
#: Whether runs in this context may take a second thread (`one_thread`).
_SECOND_THREAD: contextvars.ContextVar[bool] = contextvars.ContextVar("hybridtrack_second_thread", default=True)


@contextmanager
def one_thread() -> Iterator[None]:
    """Within this block, `simulate` runs on its caller's thread alone: for callers that spread
    runs over the cores themselves (a field's threads, a sweep's or a field's Dask workers)."""
    token = _SECOND_THREAD.set(False)
    try:
        yield
    finally:
        _SECOND_THREAD.reset(token)


def _side_by_side(first, second, scans: int, cancel=None):
    """``(first(), second())``, the first on a second thread for a long run. The results are the
    same either way (neither reads the other's); so is the error raised, the first's before the
    second's, as when they run in turn. On Ctrl-C (or another exit that is not an error) `cancel`
    is called, so that a first that can stop early does, before the first is waited for."""
    if scans < SIDE_BY_SIDE_FROM or not _SECOND_THREAD.get():
        return first(), second()
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1, thread_name_prefix="hybridtrack-world") as pool:
        started = pool.submit(contextvars.copy_context().run, first)
        try:
            done = second()
            return started.result(), done
        except BaseException as error:
            if cancel is not None and not isinstance(error, Exception):
                cancel()
            started.result()  # the first's error, if it had one, is the one a run in turn raises
            raise


def _controller_side(index: pd.DatetimeIndex, site: sites.Site, told: sites.Site, collector: Collector,
                     config: SimulationConfig, classifier, faults: dict, warm_start, sky_seed: int | None = None):
    """What the controller brings and plans before its first scan, from what it has (its clock, the
    site it was `told`, its memory; nothing of the world's, whose `site` only sets its warm-start
    day): the commissioned mount and warm memory, the plan, the classifier and the clear sky it
    expects (None where it expects none)."""
    mount, memory = _history(site, collector, config, index[0], classifier, warm_start, sky_seed)
    clock = controller_clock(index, config.imperfections, faults)
    plan = make_plan(clock, scan_timer(index), told, collector, config.controller, mount)
    clf = classifier or FuzzyWeatherClassifier(fuzzy_config(config.sky))
    clear = _expected_clear_sky(index, told, config, plan, clock)
    if clear is not None:
        plan.clear_light = shared(("expected clear light", *clear.key, config.sensor), lambda: (
            clear_sky_photocurrent(clear(), config.sensor) - config.sensor.dark_current).to_numpy())
    return mount, memory, plan, clf, clear


def _events_frame(index: pd.DatetimeIndex, events: list) -> pd.DataFrame:
    """The controller's events, ``(scan, from, to, reason)``, as a frame stamped by the scan's time."""
    scans = [event[0] for event in events]
    words = {name: pd.array([event[k] for event in events], dtype="str")
             for k, name in ((1, "from"), (2, "to"), (3, "reason"))}
    return pd.DataFrame({"time": index[scans], **words})


def _day_cycle(events: pd.DataFrame, site: sites.Site) -> list[dict]:
    """When the collector woke and stowed for the night each day (local time), and why."""
    woke = (events["from"] == "stow_night") & (events["to"] != "stow_night")
    slept = (events["to"] == "stow_night") & (events["from"] != "stow_night")
    both = events[woke | slept]  # in the events' order: a night slept in a gap stows and wakes at one scan
    if both.empty:
        return []
    local = pd.DatetimeIndex(both["time"]).tz_convert(site.tz)
    return [{"time": time.isoformat(), "event": "woke" if up else "stowed", "reason": reason}
            for time, up, reason in zip(local, woke[woke | slept], both["reason"])]


def _wind_data(frame: pd.DataFrame) -> str:
    """``measured``, ``partly missing`` or ``missing``: never calm by default. A reading no
    anemometer gives (outside `hybridtrack.control.wind.READABLE`: -5 m/s, 1e300) is missing, as
    the wind guard counts it: such a reading had left the summary saying "measured" beside the
    stows it caused."""
    if "wind_speed" not in frame.columns:
        return "missing"
    low, high = READABLE
    readings = frame["wind_speed"].to_numpy(float, na_value=np.nan)
    with np.errstate(invalid="ignore"):
        present = (readings >= low) & (readings <= high)  # NaN and ±inf fall outside
    return "measured" if present.all() else ("missing" if not present.any() else "partly missing")


def _history(site, collector, config, start, classifier, warm_start, sky_seed=None):
    """What the controller brings from before the run: a commissioned mount, a warm calibration
    (from a clear day whose sky `sky_seed` seeds)."""
    from .commissioning import commission, warm_memory

    if isinstance(warm_start, dict):  # an earlier run carried on
        _check_memory(warm_start, collector)
        _check_origin(warm_start.get("origin"), collector, site, start)
        memory = dict(warm_start)
        memory.pop("origin", None)
        mount = memory.pop("commissioned", None)
        if config.controller.strategy == "astronomical-commissioned" and mount is None:
            mount = commission(site, collector, config, start, classifier=classifier, sky_seed=sky_seed)
        if "clock" in memory:
            memory["clock"] = ClockWatch.rebase(memory["clock"], start)
        return mount, memory if config.controller.calibrates else None
    if config.controller.strategy == "astronomical-commissioned":  # an open loop is always commissioned
        return commission(site, collector, config, start, classifier=classifier, sky_seed=sky_seed), None
    if warm_start and config.controller.calibrates:
        return None, warm_memory(site, collector, config, start, classifier=classifier, sky_seed=sky_seed)
    return None, None


#: What an earlier run's memory (`Result.memory`) holds: the mount fit's state, its calibration
#: offsets, the light level, the clock watch's readings and a commissioned mount.
MEMORY_KEYS = ("offsets", "theta", "p", "information", "evidence", "frozen", "updates", "light_level", "clock",
               "commissioned", "origin", "anemometer_stuck_at")
#: Where and when a memory was left (`Tracked.memory`): the kind of collector and its geometry
#: (`collector_geometry`), the site and the run's last step.
_ORIGIN_KEYS = ("collector", "geometry", "site", "latitude", "longitude", "end")
#: The numbers a memory holds, each an array or a number.
_MEMORY_NUMBERS = ("offsets", "theta", "p", "information", "evidence", "light_level", "anemometer_stuck_at")
#: The clock watch's readings (`ClockWatch.save`).
_CLOCK_KEYS = ("start", "counted", "t", "axis", "x", "y", "spell_start", "spell_last", "raised")


def _check_memory_form(memory: dict) -> None:
    """Refuse a `warm_start` dict that is no earlier run's memory by its keys and kinds: a hand-made
    one raised a ValueError or TypeError deep in the controller."""
    def refuse(why: str):
        raise HybridtrackError(f"warm_start: {why}; pass an earlier run's Result.memory (or True or False)")

    unknown = sorted(set(map(str, memory)) - set(MEMORY_KEYS))
    if unknown:
        refuse(f"unknown key {unknown[0]!r}; a memory holds {', '.join(MEMORY_KEYS)}")
    for key in _MEMORY_NUMBERS:
        if key in memory:
            try:
                np.asarray(memory[key], float)
            except (TypeError, ValueError):
                refuse(f"{key} must be numbers, got {memory[key]!r:.40}")
    if "theta" in memory and not {"p", "information", "frozen", "updates"} <= set(memory):
        refuse("the mount fit's theta comes with its p, information, frozen and updates")
    if "anemometer_stuck_at" in memory and not _anemometer_reading(memory["anemometer_stuck_at"]):
        refuse(f"anemometer_stuck_at must be one anemometer reading ({READABLE[0]:g} to {READABLE[1]:g} m/s), got "
               f"{memory['anemometer_stuck_at']!r:.40}")
    clock = memory.get("clock")
    if clock is not None and (not isinstance(clock, dict) or set(clock) != set(_CLOCK_KEYS)):
        refuse("clock must be the clock watch's readings, as a run leaves them")
    if memory.get("commissioned") is not None and not isinstance(memory["commissioned"], MountEstimate):
        refuse("commissioned must be a commissioned mount (MountEstimate)")
    origin = memory.get("origin")
    if origin is not None and (not isinstance(origin, dict) or set(origin) != set(_ORIGIN_KEYS)
                               or not isinstance(origin["geometry"], dict)
                               or not isinstance(origin["end"], pd.Timestamp) or origin["end"].tz is None):
        refuse("origin must say where and when the memory was left, as a run leaves it")


def _anemometer_reading(value) -> bool:
    """Whether `value` is one reading an anemometer can give (`hybridtrack.control.wind.READABLE`):
    not a flag, text or None (None had raised a TypeError in the controller)."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)) \
        and READABLE[0] <= value <= READABLE[1]


def _check_origin(origin: dict | None, collector: Collector, site: sites.Site, start: pd.Timestamp) -> None:
    """Refuse a memory left by another kind of collector (a trough-ns fit carried into a trough-ew
    run, whose mount terms mean something else) or another collector of the kind (a trough on
    another axis, another Fresnel row, a heliostat with another aim: `collector_geometry`), at
    another site, or by a run that ended after this one starts (a June memory in January: the
    clock watch read -161.5 days). A memory of a release that did not record its origin is taken
    as it is."""
    if origin is None:
        return
    if origin["collector"] != collector.kind:
        raise HybridtrackError(f"warm_start: this memory was left by a {origin['collector']} run; this is a "
                               f"{collector.kind} run, whose mount terms mean something else")
    left, geometry = origin["geometry"], collector_geometry(collector)
    for name in sorted(set(left) | set(geometry)):
        if left.get(name) != geometry.get(name):
            raise HybridtrackError(f"warm_start: this memory was left by a {collector.kind} with {name} "
                                   f"{left.get(name)}; this run's has {geometry.get(name)}: its fit and offsets are "
                                   "another collector's")
    if (origin["latitude"], origin["longitude"]) != (site.latitude, site.longitude):
        raise HybridtrackError(f"warm_start: this memory was left at {origin['site']} ({origin['latitude']:g}, "
                               f"{origin['longitude']:g}); this run is at {site.name} ({site.latitude:g}, "
                               f"{site.longitude:g})")
    if origin["end"] >= start:
        raise HybridtrackError(f"warm_start: this memory was left by a run that ended at {origin['end']}, not before "
                               f"this run starts ({start}): carry a memory forward in time")


def collector_geometry(collector: Collector) -> dict:
    """What makes a collector of its kind the one it is, as its memory's origin records it: the
    axis in effect (degrees from north; a trough-ew on 90° turns the other way from one on 270°),
    a Fresnel row's distance and receiver height (m), a heliostat's aim (m)."""
    geometry = {name: getattr(collector, name) for name, kinds in GEOMETRY_KINDS.items() if collector.kind in kinds}
    if "axis_azimuth" in geometry:
        geometry["axis_azimuth"] = collector.axis  # the kind's own where none was given
    return {name: tuple(map(float, value)) if isinstance(value, tuple) else float(value)
            for name, value in geometry.items()}


def _check_memory(memory: dict, collector: Collector) -> None:
    """Refuse an earlier run's memory that another kind of collector left (its fit and offsets have
    another number of terms)."""
    _check_memory_form(memory)
    names, axes = parameter_names(collector), 1 if collector.single_axis else 2
    theta, offsets = memory.get("theta"), memory.get("offsets")
    if offsets is not None and len(offsets) != axes:
        raise HybridtrackError(f"warm_start: this memory was left by a run of another kind of collector "
                               f"({len(offsets)} offsets; a {collector.kind} has {axes}); pass the memory of a "
                               f"{collector.kind} run")
    if theta is not None and len(theta) != len(names):  # a heliostat's fit of 4 terms: before its collimation term
        raise HybridtrackError(f"warm_start: this memory's mount fit has {len(theta)} terms and a {collector.kind}'s "
                               f"has {len(names)} ({', '.join(names)}): it was left by a run of another kind of "
                               "collector, or by an earlier hybridtrack (a heliostat's fit gained collimation_error); "
                               f"pass the memory of a {collector.kind} run of this version")


def _calibration_summary(mount: MountEstimate | None, fitted: dict | None, out, collector: Collector) -> dict | None:
    """The mount the controller ends with, in degrees, named as the world's `Imperfections` fields
    it estimates, with each one's 1σ (a fit) and the residual offset on top; None without one."""
    names = parameter_names(collector)
    if fitted is not None:
        summary = {name: round(float(v), 5) for name, v in zip(names, fitted["theta"])}
        summary["std"] = {name: round(float(v), 5) for name, v in zip(names, fitted["std"])}
        summary["pedestal_frozen"] = bool(fitted["frozen"])
        return summary
    if mount is None:
        return None
    values = [mount.axis_azimuth_error, mount.axis_tilt_error] if collector.single_axis \
        else [mount.axis_tilt_error, mount.axis_roll_error]
    collimation = [] if collector.single_axis else [mount.collimation_error]
    return {name: round(float(v), 5) for name, v in zip(names, [*values, *mount.encoder_offset, *collimation])}


def _run(world: World, controller: Controller, progress, bulk_nights: bool) -> None:
    """Step world and controller together: the world observes, the controller decides, the world moves."""
    n = world.n
    obs = Observation(world.axes)
    guard = controller.wind
    wind_ok = np.concatenate([[0], np.cumsum(guard.gusts(world.wind))])  # the kernel's mask (`bridge`)
    i = reported = 0
    while i < n:
        if progress is not None and i - reported >= 8192:
            progress(i - reported)
            reported = i
        if bulk_nights and controller.resting and not guard.stuck and not controller.awake[i]:
            j = controller.sleeps_until(i)
            if j > i + 1 and wind_ok[j] == wind_ok[i]:
                controller.rest(i, j, world.minutes[j - 1])
                world.rest(i, j)
                i = j
                continue
        world.observe(i, obs)
        world.move(i, controller.step(obs))
        i += 1
    if progress is not None and n > reported:
        progress(n - reported)


def _check_faults(faults: dict, n: int, axes: int) -> dict:
    if not isinstance(faults, Mapping):
        raise HybridtrackError(f"faults must be a dict of fault name to values per step (see FAULTS), "
                               f"got {type(faults).__name__}")
    unknown = sorted(set(faults) - set(FAULTS))
    if unknown:
        raise HybridtrackError(f"unknown fault {unknown[0]!r}; known: {', '.join(FAULTS)}")
    checked = {}
    for name, values in faults.items():
        if name in ("sensor_dropout", "encoder_frozen"):
            checked[name] = _mask(faults, name, n)
        elif name in ("sensor", "encoder"):
            checked[name] = _axes_fault(faults, name, n, axes, np.nan if name == "sensor" else 0.0)
        else:
            checked[name] = _fault(faults, name, n, 0.0)
    return checked


def _fault_array(faults: dict, name: str, kind) -> np.ndarray:
    """A fault's values as an array of `kind`, refused unless they are real numbers (not text,
    complex numbers or durations) and, for a mask, True/False or 0/1 (not NaN or 0.5, which `bool`
    would read as True)."""
    values = np.asarray(faults[name])
    real = values.dtype == bool or (np.issubdtype(values.dtype, np.number)
                                    and not np.issubdtype(values.dtype, np.complexfloating)
                                    and not np.issubdtype(values.dtype, np.timedelta64))
    if kind is bool:
        if not real or (values.dtype != bool and not np.isin(values, (0, 1)).all()):
            nan = real and np.issubdtype(values.dtype, np.floating) and np.isnan(values).any()
            raise HybridtrackError(f"fault {name!r} needs True/False (or 1/0) per step, got dtype {values.dtype}"
                                   f"{' with NaN' if nan else ''}")
        return values.astype(bool)
    if not real:
        raise HybridtrackError(f"fault {name!r} needs real numbers, got dtype {values.dtype}")
    values = values.astype(float)
    beyond = np.argwhere(np.abs(values) > FAULT_LIMITS[name])  # inf too; NaN is "no fault here"
    if len(beyond):
        where = tuple(beyond[0])
        raise HybridtrackError(f"fault {name!r} at step {where[0]}: {values[where]:g} is beyond "
                               f"±{FAULT_LIMITS[name]:g}")
    return values


def _mask(faults: dict, name: str, n: int) -> np.ndarray | None:
    if name not in faults:
        return None
    values = _fault_array(faults, name, bool)
    if values.shape != (n,):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}), got shape {values.shape}")
    return values


def _fault(faults: dict, name: str, n: int, default: float) -> np.ndarray:
    if name not in faults:
        return np.full(n, default)
    values = _fault_array(faults, name, float)
    if values.shape != (n,):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}), got shape {values.shape}")
    return np.nan_to_num(values, nan=default)


def _axes_fault(faults: dict, name: str, n: int, axes: int, default: float) -> np.ndarray | None:
    if name not in faults:
        return None
    values = _fault_array(faults, name, float)
    if values.ndim == 1:
        values = np.repeat(values[:, None], axes, axis=1)
    if values.shape != (n, axes):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}) and axis ({axes}), got {values.shape}")
    return np.where(np.isnan(values), default, values) if not np.isnan(default) else values


def _expected_clear_sky(index: pd.DatetimeIndex, site: sites.Site, config: SimulationConfig, plan,
                        clock: pd.DatetimeIndex):
    """The clear sky the controller expects at each scan, from what a PLC has: its `clock`, the
    `site` it was told and the sun its plan computed; on the scans' `index`. Returned as a
    function that gives it, computed once a run (its ``key`` the piece's in `hybridtrack.reuse`),
    or None where the controller expects none: a field's run that keeps no log never asks for the
    frame, only for the clear light (`_controller_side`), where a copy of the shared frame and
    the light from it had cost 14 ms a Fresnel row-year."""
    if config.sky.mode != "relative" or config.controller.sensor_only:
        return None
    key = ("expected clear sky", Same(clock), Same(index), site, config.controller)

    @functools.cache  # once a run: its clear light and its log ask for the same
    def expected():  # the plan's sun follows from the clock, the scans, the site and the controller's config
        return shared(key, lambda: clear_sky(clock, site, pd.DataFrame({"apparent_altitude": plan.apparent_altitude}))
                      .set_axis(index))

    expected.key = key
    return expected


def _sky_seen(intensity: np.ndarray, index: pd.DatetimeIndex, classifier, config: SimulationConfig,
              clear: pd.DataFrame | None, site: sites.Site) -> pd.DataFrame:
    """The sky as the exact classifier calls the controller's own readings (the log's ``sky``): the
    photocurrent read (NaN while asleep) and its trailing range, the classifier's two inputs from it
    (`sky_inputs`, the reference of the controller's scan-by-scan sky watch), the score and the
    label. The ranges and inputs are NaN where nothing was read."""
    reading = pd.Series(intensity, index=index, name="intensity_ma")
    inputs = config.sky if clear is not None else dataclasses.replace(config.sky, mode="absolute")
    level, variation = sky_inputs(pd.DataFrame(index=index), site, config.sensor, inputs, intensity=reading,
                                  clear=clear)
    asleep = np.isnan(intensity)
    level, variation, swing = (np.where(asleep, np.nan, values.to_numpy())
                               for values in (level, variation, photocurrent_range(reading, inputs)[1]))
    score = np.asarray(classifier.score(level, variation), float)
    return pd.DataFrame({"intensity_ma": intensity, "variation_ma": swing, "intensity_input": level,
                         "variation_input": variation, "sky_score": score,
                         "sky": _sky_categorical(*classifier.label_codes(score))}, index=index)


def _sky_categorical(codes: np.ndarray, names: tuple[str, ...]) -> pd.Categorical:
    """Labels (codes into `names`) as a Categorical of `SKY_CODES`; a band named otherwise is NaN."""
    recode = np.array([sky_code(name) for name in names])
    return pd.Categorical.from_codes(recode[codes], categories=list(SKY_CODES))


def _pointing_error(collector: Collector, world: World, engine: str = "auto") -> np.ndarray:
    """The pointing error at each scan (degrees): a single axis' angle less its true target; a
    heliostat's angle between its actual and its required mirror normal (in one compiled pass
    where numba is installed, `hybridtrack.mountpass.normal_errors`, the same bits as the numpy
    path below, `engine="numpy"`)."""
    from .collectors import direction_vectors

    truth, angle = world.truth, world.angles.T
    if not collector.single_axis and engine == "auto":
        fast = mountpass.normal_errors(world.angles, truth)
        if fast is not None:
            return fast
    if collector.single_axis:  # within ±180°: an axis whose limits pass a turn stands a turn off its target
        error = angle[:, 0] - truth[:, 0]
        wound = np.abs(error) > 180.0  # rare: the remainder on the whole year took 0.07 s (its NaN nights)
        error[wound] = (error[wound] + 180.0) % 360.0 - 180.0
        return error
    error = np.full(len(truth), np.nan)  # no target while the sun is down
    up = ~np.isnan(truth).any(axis=1)  # only there: a year's NaN nights took numpy's slow path
    actual = direction_vectors(angle[up, 1], angle[up, 0])  # the axes may stand past the zenith
    wanted = direction_vectors(truth[up, 1], truth[up, 0])
    error[up] = np.degrees(np.arccos(np.clip(np.sum(actual * wanted, axis=1), -1.0, 1.0)))
    return error


def _scored_columns(collector: Collector, world: World, out) -> dict:
    """The log columns the metrics read (`hybridtrack.metrics.score`): ``dni``, ``error`` and
    ``mode``, each the run's own array; `_log` and `Tracked.scores` both take them from here."""
    return {"error": _pointing_error(collector, world),
            "mode": pd.Categorical.from_codes(out.mode, categories=list(MODES)), "dni": world.frame_dni.copy()}


def _log(index, collector: Collector, world: World, out, sky: pd.DataFrame) -> pd.DataFrame:
    """The run's log, one row a scan. Its columns are taken as they are, not copied into one
    block (a heliostat's 26 columns over a year took 0.06 s to copy): every array is the run's
    own, and those read from a frame (which pandas hands out read-only) are copied, so an edit of
    the log works and edits nothing else."""
    truth = world.truth
    main = 0 if collector.single_axis else 1  # a heliostat's main columns are its elevation axis
    scored = _scored_columns(collector, world, out)
    columns = {
        "target_true": truth[:, main].copy(), "target": out.target[:, main], "angle": world.angles[-1].copy(),
        "error": scored["error"], "mode": scored["mode"],
        "sky": sky["sky"].array, "sky_score": sky["sky_score"].to_numpy(copy=True),
        "sensor_valid": out.sensor_status == 0,
        "sensor_status": pd.Categorical.from_codes(out.sensor_status, categories=list(SENSOR_STATUS)),
        **{name: sky[name].to_numpy(copy=True) for name in ("variation_ma", "intensity_input", "variation_input")},
        "intensity_ma": out.intensity,
        "wind_speed": world.wind.copy(), "dni": scored["dni"], "calibration": out.calibration[:, main],
        "sensor_sun": out.sun[:, main],
    }
    for k, name in enumerate(parameter_names(collector)[:out.fit.shape[1]]):
        columns[f"{FIT_PREFIX}{name}"] = out.fit[:, k]
        columns[f"{FIT_PREFIX}{name}_std"] = out.fit_std[:, k]
    if not collector.single_axis:
        columns.update({
            "target_true_azimuth": truth[:, 0].copy(),
            "target_azimuth": within_turn(out.target[:, 0]),  # the axis may have wound past a turn
            "angle_azimuth": within_turn(world.angles[0]),  # the axis may have wound past a turn
            "calibration_azimuth": out.calibration[:, 0],
            "sensor_sun_azimuth": out.sun[:, 0]})
    return pd.DataFrame(columns, index=index, copy=False)
