"""Run the hybrid controller over a weather frame and score it against the true sun.

Data flows one way (``design.md``). Everything that does not depend on the controller's own
state is computed for the whole frame at once: the true sun (SPA) and the true targets of
the misaligned mounting, the controller's sun (its model, clock and site), the sensor's
photocurrent and variation, and the fuzzy sky class. Then the controller steps through
time (`hybridtrack.control.run_controller`), and the log is scored (`hybridtrack.metrics`).
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import sites
from .collectors import Collector
from .control import MODES, SENSOR_STATUS, SKY_CODES, ControllerConfig, ControllerInputs, run_controller
from .drive import Drive
from .errors import HybridtrackError
from .fuzzy import FuzzyConfig, FuzzyWeatherClassifier
from .metrics import summarize
from .sensor import SensorModel
from .sun import solar_position
from .world import Imperfections, incidence_cosine, mounting_rotation, true_targets

__all__ = ["SimulationConfig", "Result", "simulate", "LOG_COLUMNS", "FAULTS", "CLOCK_STEP_SECONDS"]

#: A jump of the controller's clock against its scan timer larger than this is a clock step.
CLOCK_STEP_SECONDS = 5.0
#: The faults `simulate` can inject, with what each array holds.
FAULTS = {
    "sensor": "(N,) or (N, axes): the reading the sensor gives (degrees); NaN where it works",
    "sensor_dropout": "(N,) bool: the sensor gives no reading",
    "sensor_drift": "(N,): degrees added to every sensor reading (a drifting bias)",
    "encoder": "(N,) or (N, axes): degrees added to the encoder reading (a wild count)",
    "encoder_frozen": "(N,) bool: the encoder repeats its last reading",
    "clock": "(N,): seconds added to the controller's clock",
}

LOG_COLUMNS = ("target_true", "target", "angle", "error", "mode", "sky", "sky_score", "sensor_valid",
               "sensor_status", "intensity_ma", "variation_ma", "wind_speed", "dni", "calibration")


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
        The drive of a single-axis collector. A heliostat uses it for its elevation axis
        (limits 0-90°, stow 90°) and for its azimuth axis, which turns all the way round:
        limits -180° to 540° (a cable wrap of one turn either way), stow at 180°.
    seed : int
        Seeds the sensor noise.
    """

    controller: ControllerConfig = field(default_factory=ControllerConfig)
    imperfections: Imperfections = field(default_factory=Imperfections)
    sensor: SensorModel = field(default_factory=SensorModel)
    drive: Drive = field(default_factory=Drive)
    seed: int = 0

    def to_dict(self) -> dict:
        """A plain dict in the TOML layout."""
        def plain(value):
            if dataclasses.is_dataclass(value):
                return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
            return list(value) if isinstance(value, tuple) else value

        return plain(self)

    @classmethod
    def from_dict(cls, data, *, source: str = "config") -> SimulationConfig:
        """Build from the TOML layout; unknown keys and wrong types are refused with their key."""
        def build(kind, values, where):
            if not isinstance(values, dict):
                raise HybridtrackError(f"{source}: {where or 'config'} must be a table")
            known = {f.name: f for f in dataclasses.fields(kind)}
            unknown = sorted(set(values) - set(known))
            if unknown:
                raise HybridtrackError(f"{source}: {where + '.' if where else ''}{unknown[0]}: unknown key; "
                                       f"known: {', '.join(known)}")
            default = kind()
            changes = {}
            for name, value in values.items():
                key = f"{where}.{name}" if where else name
                current = getattr(default, name)
                if dataclasses.is_dataclass(current):
                    changes[name] = build(type(current), value, key)
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
                        raise HybridtrackError(f"{source}: {key}: must be a number, got {value!r}")
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
                raise HybridtrackError(f"{source}: {where}: {exc}" if where else f"{source}: {exc}") from None

        return build(cls, dict(data), "")

    @classmethod
    def from_toml(cls, path) -> SimulationConfig:
        """Load from a TOML file; keys left out keep their defaults."""
        from .io import read_toml

        return cls.from_dict(read_toml(path), source=str(path))

    def to_toml(self, path) -> Path:
        """Write as TOML; `from_toml` reads it back equal."""
        from .io import write_toml

        return write_toml(self.to_dict(), path)


@dataclass
class Result:
    """A finished run.

    Attributes
    ----------
    log : pandas.DataFrame
        One row per step, indexed like the frame (see `LOG_COLUMNS`; a heliostat adds the
        ``*_azimuth`` columns of its second axis).
    summary : dict
        The metrics written to ``summary.json`` (`hybridtrack.metrics`).
    events : pandas.DataFrame
        Every mode change: ``time``, ``from``, ``to``, ``reason``.
    """

    log: pd.DataFrame
    summary: dict
    events: pd.DataFrame
    site: sites.Site
    collector: Collector
    config: SimulationConfig

    def save(self, folder, *, plot: bool = True, log_format: str = "auto") -> dict[str, Path]:
        """Write ``log.parquet`` (or ``log.csv``), ``events.csv``, ``summary.json`` and ``report.png``."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        written = {}
        use_parquet = log_format == "parquet" or (log_format == "auto" and _has_parquet())
        if use_parquet:
            written["log"] = folder / "log.parquet"
            self.log.to_parquet(written["log"])
        else:
            written["log"] = folder / "log.csv"
            self.log.to_csv(written["log"], float_format="%.5f", index_label="time")
        written["events"] = folder / "events.csv"
        self.events.to_csv(written["events"], index=False)
        written["summary"] = folder / "summary.json"
        written["summary"].write_text(json.dumps(self.summary, indent=2) + "\n")
        if plot:
            from .report import plot_run, save_figure

            written["report"] = save_figure(plot_run(self), folder / "report.png")
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


def _has_parquet() -> bool:
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def _drives(collector: Collector, drive: Drive) -> list[Drive]:
    if collector.kind != "heliostat":
        return [drive]
    return [dataclasses.replace(drive, limits=(-180.0, 540.0), stow=180.0),
            dataclasses.replace(drive, limits=(0.0, 90.0), stow=90.0)]


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
    if "dni" not in frame.columns:
        raise HybridtrackError(f"the weather frame has no 'dni' column; it has {', '.join(map(str, frame.columns))}")
    return frame


def _working(local: pd.DatetimeIndex, hours: tuple[str, str]) -> np.ndarray:
    from .times import clock_hours, parse_clock

    start, end = (parse_clock(h) for h in hours)
    clock = clock_hours(local)
    return (clock >= start.hour + start.minute / 60.0) & (clock <= end.hour + end.minute / 60.0)


def simulate(frame: pd.DataFrame, site, *, collector: str | Collector = "trough-ns", strategy: str | None = None,
             config: SimulationConfig | None = None, classifier: FuzzyWeatherClassifier | None = None,
             faults: dict | None = None, progress=None) -> Result:
    """Run the hybrid controller over a weather frame.

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame (``dni``; ``dhi``, ``wind_speed`` and a recorded ``photocurrent``
        when there are) on a tz-aware, increasing index.
    site : Site or str
    collector : str or Collector
        ``trough-ns``, ``trough-ew``, ``fresnel`` or ``heliostat``, or a `Collector` with
        its geometry.
    strategy : str, optional
        ``hybrid`` (default), ``hybrid-nocal``, ``astronomical`` or ``sensor``; overrides
        the config's.
    config : SimulationConfig, optional
    classifier : FuzzyWeatherClassifier, optional
        The sky classifier; the published one by default.
    faults : dict, optional
        Injected faults for testing, one array value per step; see `FAULTS`.
    progress : callable, optional
        Called with the number of steps done since its last call (e.g. a tqdm bar's update).

    Returns
    -------
    Result
    """
    config = config or SimulationConfig()
    if strategy is not None:
        config = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy=strategy))
    site = sites.get(site)
    collector = Collector(collector) if isinstance(collector, str) else collector
    frame = _check_frame(frame)
    index = frame.index
    n = len(index)
    faults = faults or {}
    unknown = sorted(set(faults) - set(FAULTS))
    if unknown:
        raise HybridtrackError(f"unknown fault {unknown[0]!r}; known: {', '.join(FAULTS)}")
    imp = config.imperfections
    drives = _drives(collector, config.drive)
    axes = len(drives)

    # the controller's view: its clock, its site, its sun model, the nominal geometry. Its
    # scan timer runs on its own, so a step of the clock against it is seen and taken out;
    # a slow drift is not.
    clock = imp.clock_error + _fault(faults, "clock", n, 0.0)
    jumps = np.diff(clock, prepend=clock[0])
    stepped = np.abs(jumps) > CLOCK_STEP_SECONDS
    clock = clock - np.cumsum(np.where(stepped, jumps, 0.0))
    controller_times = index + pd.to_timedelta(clock, unit="s")
    controller_site = sites.Site(site.name, float(np.clip(site.latitude + imp.latitude_error, -90, 90)),
                                 float((site.longitude + imp.longitude_error + 180) % 360 - 180), site.altitude, site.tz)
    believed = solar_position(controller_times, controller_site, config.controller.sun_model)
    model = true_targets(believed["altitude"].to_numpy(), believed["azimuth"].to_numpy(), collector, night=True)
    # awake from 30 minutes before its sunrise (to pre-position) to its sunset, within working hours
    soon = solar_position(controller_times + pd.Timedelta(minutes=30), controller_site, config.controller.sun_model)
    sun_up = believed["altitude"].to_numpy() > config.controller.min_altitude
    rising = (soon["altitude"].to_numpy() > config.controller.min_altitude) & ~sun_up \
        & (soon["altitude"].to_numpy() > believed["altitude"].to_numpy())
    awake = _working(controller_times.tz_convert(site.tz), config.controller.working_hours) & (sun_up | rising)

    # the true world: SPA where the sun can be up, the misaligned mounting
    candidate = believed["altitude"].to_numpy() > -3.0
    true_alt = np.full(n, -90.0)
    true_az = np.zeros(n)
    if candidate.any():
        truth_sun = solar_position(index[candidate], site, "spa")
        true_alt[candidate] = truth_sun["altitude"].to_numpy()
        true_az[candidate] = truth_sun["azimuth"].to_numpy()
    truth = true_targets(true_alt, true_az, collector, mounting_rotation(imp, collector.axis))

    # the sensor and the sky class, for the whole frame at once
    sensor = dataclasses.replace(config.sensor, bias=imp.sensor_bias, noise=imp.sensor_noise)
    rng = np.random.default_rng(config.seed)
    weather = frame if "dhi" in frame.columns else frame.assign(dhi=0.0)
    intensity = sensor.photocurrent(weather, rng=rng)
    variation = sensor.variation(intensity)
    clf = classifier or FuzzyWeatherClassifier(FuzzyConfig.default())
    sky_score = clf.score(intensity.to_numpy(), variation.to_numpy())
    sky_label = clf.label(sky_score)
    sky_code = np.array([SKY_CODES.index(v) if v in SKY_CODES else 3 for v in sky_label], np.int8)
    wind = frame["wind_speed"].to_numpy(float) if "wind_speed" in frame.columns else np.zeros(n)
    dni = frame["dni"].to_numpy(float)

    inputs = ControllerInputs(
        minutes=np.asarray((index - index[0]) / pd.Timedelta(minutes=1), float), awake=awake, wind=wind,
        sky=sky_code, dni=dni, model=model, truth=np.nan_to_num(truth, nan=0.0) if axes else truth,
        noise=rng.standard_normal((n, axes)),
        sensor_fault=_axes_fault(faults, "sensor", n, axes, np.nan),
        encoder_fault=_axes_fault(faults, "encoder", n, axes, 0.0),
        encoder_frozen=_mask(faults, "encoder_frozen", n),
        sensor_dropout=_mask(faults, "sensor_dropout", n),
        sensor_drift=_fault(faults, "sensor_drift", n, 0.0) if "sensor_drift" in faults else None,
        clock_step=np.where(stepped, jumps, 0.0) if stepped.any() else None,
    )
    out = run_controller(inputs, config.controller, drives, encoder_offset=imp.encoder_offset,
                         sensor_bias=imp.sensor_bias, sensor_noise=imp.sensor_noise,
                         field_of_view=sensor.field_of_view, direct_threshold=sensor.direct_threshold,
                         progress=progress)

    log = _log(index, collector, truth, out, sky_label, sky_score, intensity, variation, wind, dni)
    events = pd.DataFrame([(index[i], a, b, why) for i, a, b, why in out.events],
                          columns=["time", "from", "to", "reason"])
    summary = summarize(log, site=site.name, collector=collector.kind, strategy=config.controller.strategy,
                        moves=int(out.moves.sum()), travel=float(out.travel.sum()), events=events,
                        sun_up=true_alt > 0, incidence=incidence_cosine(true_alt, true_az, collector))
    return Result(log, summary, events, site, collector, config)


def _mask(faults: dict, name: str, n: int) -> np.ndarray | None:
    if name not in faults:
        return None
    values = np.asarray(faults[name], bool)
    if values.shape != (n,):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}), got shape {values.shape}")
    return values


def _fault(faults: dict, name: str, n: int, default: float) -> np.ndarray:
    if name not in faults:
        return np.full(n, default)
    values = np.asarray(faults[name], float)
    if values.shape != (n,):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}), got shape {values.shape}")
    return np.nan_to_num(values, nan=default)


def _axes_fault(faults: dict, name: str, n: int, axes: int, default: float) -> np.ndarray | None:
    if name not in faults:
        return None
    values = np.asarray(faults[name], float)
    if values.ndim == 1:
        values = np.repeat(values[:, None], axes, axis=1)
    if values.shape != (n, axes):
        raise HybridtrackError(f"fault {name!r} needs one value per step ({n}) and axis ({axes}), got {values.shape}")
    return np.where(np.isnan(values), default, values) if not np.isnan(default) else values


def _log(index, collector: Collector, truth, out, sky_label, sky_score, intensity, variation, wind, dni) -> pd.DataFrame:
    from .collectors import sun_vector

    main = 0 if collector.single_axis else 1  # a heliostat's main columns are its elevation axis
    if collector.single_axis:
        error = out.angle[:, 0] - truth[:, 0]
    else:  # the angle between the actual and the required mirror normal
        actual = sun_vector(out.angle[:, 1], out.angle[:, 0])
        wanted = sun_vector(truth[:, 1], truth[:, 0])
        error = np.degrees(np.arccos(np.clip(np.sum(actual * wanted, axis=1), -1.0, 1.0)))
    log = pd.DataFrame({
        "target_true": truth[:, main], "target": out.target[:, main], "angle": out.angle[:, main], "error": error,
        "mode": pd.Categorical(np.asarray(MODES)[out.mode], categories=list(MODES)),
        "sky": pd.Categorical(np.asarray(sky_label, dtype=object), categories=[*SKY_CODES]),
        "sky_score": sky_score, "sensor_valid": out.sensor_status == 0,
        "sensor_status": pd.Categorical(np.asarray(SENSOR_STATUS)[out.sensor_status], categories=list(SENSOR_STATUS)),
        "intensity_ma": intensity.to_numpy(), "variation_ma": variation.to_numpy(), "wind_speed": wind, "dni": dni,
        "calibration": out.calibration[:, main],
    }, index=index)
    if not collector.single_axis:
        log["target_true_azimuth"] = truth[:, 0]
        log["target_azimuth"] = out.target[:, 0] % 360.0  # the axis may have wound past a turn
        log["angle_azimuth"] = out.angle[:, 0] % 360.0
        log["calibration_azimuth"] = out.calibration[:, 0]
    return log
