"""What the controller works out from its own clock alone: the computed sun and its working day.

None of it depends on the controller's state, so it is computed for the whole run at once.
Each value at a scan uses only that scan's clock reading and the clock's history, as the PLC's
own per-scan computation would:

* the controller's clock is compared with its scan timer; a jump of more than
  `CLOCK_STEP_SECONDS` between two scans is a clock step, logged and taken out (the clock is
  re-based on the timer). A clock that creeps, gaining or losing more than `CREEP_LIMIT` seconds
  an hour over the last hour (a healthy one drifts a second or two a day), is logged with its
  rate and re-based on the timer from then on;
* the computed sun at the (re-based) clock, the believed site and the controller's sun model;
* the computed target of each axis on the mount as the controller believes it to be (nominal,
  or corrected by a commissioning fit), in encoder coordinates;
* awake: with the computed sun up, or rising within 30 minutes (to pre-position), or set less
  than 15 minutes ago (to catch the last light), within the working hours, which by default span
  the whole day: the day is set by the sun, and clock hours are an optional limit. The
  sensor-only tracker has no sun model and no working hours: it wakes and sleeps by the light
  its sensor reads (`Controller`), so its plan is awake throughout;
* slept: the scans awake after a gap in the scans, from a scan awake, within which the
  controller would have been asleep: a frame with its nights left out (a logger that records
  only by day). The controller sleeps that night at the scan after the gap (`Controller.step`).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..collectors import Collector
from ..mounting import angles_on_mount, geometry_key, heliostat_sun, mounting_rotation, pointing_vectors
from ..sites import Site
from ..sun import solar_position
from ..reuse import Content, Same, shared
from ..times import clock_hours, parse_clock, plus_seconds
from .config import ControllerConfig
from .mountfit import vector_jacobian

__all__ = ["MountEstimate", "ControllerPlan", "make_plan", "east_park", "CLOCK_STEP_SECONDS"]

#: A jump of the controller's clock against its scan timer larger than this is a clock step.
CLOCK_STEP_SECONDS = 5.0
#: Seconds an hour: a clock creeping faster than this against the scan timer is faulty (a PLC's
#: crystal drifts about 0.1 s an hour at worst; sixty times that is no temperature effect).
CREEP_LIMIT = 5.0
#: How long before its computed sunrise the controller wakes to pre-position.
PRE_POSITION = pd.Timedelta(minutes=30)
#: How long after its computed sunset the controller goes on before it stows.
AFTER_SUNSET = pd.Timedelta(minutes=15)


@dataclass(frozen=True)
class MountEstimate:
    """The controller's belief about its own mount, in the world's `Imperfections` terms.

    Parameters
    ----------
    axis_azimuth_error, axis_tilt_error, axis_roll_error : float
        Degrees (see `hybridtrack.mounting.mounting_rotation`).
    encoder_offset : tuple of float
        Degrees, per axis: the encoder reads the true angle plus this.
    collimation_error : float
        Degrees across a heliostat's mirror face at which its sun sensor centres the sun (its
        mounting bias, the world's ``sensor_bias``): ``collimation_error / cos(elevation)`` of
        azimuth (`hybridtrack.control.mountfit.collimation_secant`), the pointing model's
        collimation term. Not used by a single axis.
    """

    axis_azimuth_error: float = 0.0
    axis_tilt_error: float = 0.0
    axis_roll_error: float = 0.0
    encoder_offset: tuple[float, ...] = field(default=(0.0,))
    collimation_error: float = 0.0

    @classmethod
    def from_parameters(cls, names: list[str], values) -> MountEstimate:
        """From fitted parameters named as in `hybridtrack.control.mountfit.parameter_names`."""
        given = dict(zip(names, (float(v) for v in values)))
        encoders = (given.get("encoder_offset_azimuth", 0.0), given["encoder_offset"]) \
            if "encoder_offset_azimuth" in given else (given["encoder_offset"],)
        return cls(given.get("axis_azimuth_error", 0.0), given.get("axis_tilt_error", 0.0),
                   given.get("axis_roll_error", 0.0), encoders, given.get("collimation_error", 0.0))

    def rotation(self, collector: Collector) -> np.ndarray:
        """The mount's rotation (`hybridtrack.mounting.mounting_rotation`)."""
        return mounting_rotation(self.axis_azimuth_error, self.axis_tilt_error, collector.axis, self.axis_roll_error)

    def targets(self, altitude, azimuth, collector: Collector) -> np.ndarray:
        """Computed targets in encoder coordinates, (N, axes); the geometry is followed below the horizon."""
        return self.vector_targets(pointing_vectors(altitude, azimuth, collector, night=True), collector)

    def vector_targets(self, vectors: np.ndarray, collector: Collector) -> np.ndarray:
        """`targets` from the pointing vectors (`hybridtrack.mounting.pointing_vectors`, ``night=True``)."""
        targets = angles_on_mount(vectors, collector, self.rotation(collector))
        targets = targets + np.resize(np.asarray(self.encoder_offset, float), targets.shape[1])
        if self.collimation_error and targets.shape[-1] == 2:
            from .mountfit import vector_collimation_secant

            targets[..., 0] += self.collimation_error * vector_collimation_secant(vectors)
        return targets


@dataclass
class ControllerPlan:
    """Per scan: timer (minutes), computed targets (N, axes), awake, clock steps (seconds, 0 if
    none), and for a controller that fits its mount the targets' derivatives by the mount's
    parameters (N, axes, parameters) with each axis's weight in pointing terms (N, axes), and for
    the sky watch its computed sun's apparent altitude (degrees) and the photocurrent above dark
    it expects under a clear sky (mA; set from that altitude by the run)."""

    minutes: np.ndarray
    model: np.ndarray
    awake: np.ndarray
    clock_steps: np.ndarray
    jacobian: np.ndarray | None = None
    weight: np.ndarray | None = None
    alarms: dict = field(default_factory=dict)
    clear_light: np.ndarray | None = None
    apparent_altitude: np.ndarray | None = None
    slept: np.ndarray | None = None

    def __post_init__(self):
        if self.slept is None:  # no night in a gap between scans
            self.slept = np.zeros(len(self.awake), bool)


def _rebased(clock: pd.DatetimeIndex, minutes: np.ndarray) -> tuple[pd.DatetimeIndex, np.ndarray, dict]:
    """The clock with its steps and creep against the scan timer taken out, the steps in seconds,
    and the alarms by scan."""
    elapsed = np.asarray((clock - clock[0]) / pd.Timedelta(seconds=1), float)
    drift = elapsed - 60.0 * minutes
    jumps = np.diff(drift, prepend=drift[0])
    steps = np.where(np.abs(jumps) > CLOCK_STEP_SECONDS, jumps, 0.0)
    drift = drift - np.cumsum(steps)
    alarms = {}
    hour_ago = np.searchsorted(minutes, minutes - 60.0)
    span = minutes - minutes[hour_ago]
    rate = np.divide(drift - drift[hour_ago], span / 60.0, out=np.zeros_like(drift), where=span >= 59.0)
    creeping = np.flatnonzero(np.abs(rate) > CREEP_LIMIT)
    if len(creeping):
        i = int(creeping[0])
        latest = (drift[i] - drift[i - 1]) / max(minutes[i] - minutes[i - 1], 1e-9) * 60.0 if i else rate[i]
        alarms[i] = (f"controller clock creeping {latest:+.0f} s an hour against the scan timer "
                     f"({drift[i] - drift[hour_ago[i]]:+.0f} s in the last hour); "
                     "clock re-based on the timer from here")
        drift[i:] = drift[i]  # from here the clock runs with the timer
    rebased = plus_seconds(clock[:1], 60.0 * minutes + drift)
    return rebased, steps, alarms


def _working(local: pd.DatetimeIndex, hours: tuple[str, str]) -> np.ndarray:
    """Scans whose local clock reads within `hours`, both ends included; an end of ``24:00`` is
    the day's end, every reading before the next midnight (its seconds had been dropped, so the
    clock's last minute of each day was outside)."""
    start, end = (parse_clock(h) for h in hours)
    clock = clock_hours(local)
    return (clock >= _hours_of(start)) & (clock <= (24.0 if end == dt.time.max else _hours_of(end)))


def _hours_of(time: dt.time) -> float:
    return time.hour + time.minute / 60.0 + (time.second + time.microsecond / 1e6) / 3600.0


def make_plan(clock: pd.DatetimeIndex, minutes: np.ndarray, site: Site, collector: Collector,
              config: ControllerConfig, mount: MountEstimate | None = None) -> ControllerPlan:
    """The controller's plan from what its clock shows at each scan and its scan timer.

    Parameters
    ----------
    clock : pandas.DatetimeIndex
        The controller clock's reading at each scan (tz-aware).
    minutes : numpy.ndarray
        The scan timer, minutes since the run began.
    site : Site
        The site as the controller was told it.
    collector : Collector
    config : ControllerConfig
    mount : MountEstimate, optional
        The controller's belief about its mount; nominal by default.
    """
    sun_key = ("plan's sun", Same(clock), Content(minutes), site, config)
    clock, steps, alarms, altitude, azimuth, apparent, awake, slept = shared(
        sun_key, lambda: _plan_sun(clock, minutes, site, config))
    aimed = apparent if config.refraction else altitude  # the sun as it appears, or the model's geometric sun
    vectors = shared(geometry_key(sun_key, "pointing", collector),
                     lambda: pointing_vectors(aimed, azimuth, collector, night=True,
                                              sun=heliostat_sun(sun_key, aimed, azimuth, collector, night=True)))
    model = (mount or MountEstimate()).vector_targets(vectors, collector)
    plan = ControllerPlan(np.asarray(minutes, float), model, awake, steps, alarms=alarms, apparent_altitude=apparent,
                          slept=slept)
    if config.calibrates:
        lit = np.isfinite(model).all(axis=1)
        plan.jacobian = shared(geometry_key((*sun_key, Content(lit)), "derivatives", collector),
                               lambda: vector_jacobian(vectors, collector, lit=lit))
        plan.weight = np.ones(model.shape)
        if not collector.single_axis:  # an azimuth error counts cos(elevation) in pointing terms
            plan.weight[:, 0] = np.cos(np.radians(np.clip(model[:, 1], 0.0, 90.0)))
    return plan


def _plan_sun(clock: pd.DatetimeIndex, minutes: np.ndarray, site: Site, config: ControllerConfig) -> tuple:
    """What the plan computes from the clock alone, the same for every collector a field controller
    drives: the re-based clock, its steps and alarms, the computed sun (altitude, azimuth, apparent
    altitude), the scans awake and those after a gap the controller slept through."""
    clock, steps, alarms = _rebased(clock, minutes)
    sun = solar_position(clock, site, config.sun_model)
    altitude, azimuth = sun["altitude"].to_numpy(), sun["azimuth"].to_numpy()
    if config.sensor_only:
        awake, slept = np.ones(len(clock), bool), np.zeros(len(clock), bool)
    else:
        awake = _awake(clock, altitude, site, config)
        slept = _slept_in_gaps(clock, awake, site, config)
    return clock, steps, alarms, altitude, azimuth, sun["apparent_altitude"].to_numpy(), awake, slept


def _awake(clock: pd.DatetimeIndex, altitude: np.ndarray, site: Site, config: ControllerConfig) -> np.ndarray:
    """Scans within the working hours and the sun's day (`_sun_day`)."""
    working = _working(clock.tz_convert(site.tz), config.working_hours)
    return np.asarray(working & _sun_day(clock, altitude, site, config), bool)


#: Minutes between the instants at which a gap in the scans is looked into for a night.
GAP_LOOK_MINUTES = 5.0


def _slept_in_gaps(clock: pd.DatetimeIndex, awake: np.ndarray, site: Site, config: ControllerConfig) -> np.ndarray:
    """Scans awake after a gap from a scan awake, within which the controller would have been
    asleep at one of the instants `GAP_LOOK_MINUTES` apart (its clock run on evenly between the
    two scans): the night of a frame that leaves its nights out."""
    slept = np.zeros(len(clock), bool)
    minutes = np.asarray((clock[1:] - clock[:-1]) / pd.Timedelta(minutes=1), float)
    gaps = np.flatnonzero((minutes > GAP_LOOK_MINUTES) & awake[:-1] & awake[1:])
    if not len(gaps):
        return slept
    looks = np.ceil(minutes[gaps] / GAP_LOOK_MINUTES).astype(int) - 1  # instants strictly inside each gap
    owner = np.repeat(np.arange(len(gaps)), looks)
    within = np.arange(len(owner)) - np.repeat(np.cumsum(looks) - looks, looks) + 1
    instants = clock[gaps[owner]] + pd.to_timedelta(within * GAP_LOOK_MINUTES, unit="min")
    altitude = solar_position(instants, site, config.sun_model)["altitude"].to_numpy()
    asleep = ~_awake(instants, altitude, site, config)
    slept[gaps[np.unique(owner[asleep])] + 1] = True
    return slept


#: Degrees a minute the sun's altitude can change at most (the earth turns 0.25° a minute), with
#: room for refraction's change near the horizon: bounds where `_sun_day` must look ahead or back.
ALTITUDE_RATE = 0.3


def _sun_day(clock: pd.DatetimeIndex, altitude: np.ndarray, site: Site, config: ControllerConfig) -> np.ndarray:
    """Scans with the computed sun up, rising within `PRE_POSITION` or set within `AFTER_SUNSET`.

    The sun `PRE_POSITION` ahead and `AFTER_SUNSET` back is computed only where it could be
    above `min_altitude` while the sun now is not (within `ALTITUDE_RATE` a minute of it): the
    same answer as computing it at every scan, for a fraction of the sun passes."""
    up = altitude > config.min_altitude
    awake = up.copy()
    for shift, direction in ((PRE_POSITION, 1), (AFTER_SUNSET, -1)):
        reach = ALTITUDE_RATE * shift / pd.Timedelta(minutes=1)
        near = np.flatnonzero(~up & (altitude > config.min_altitude - reach))
        if len(near):
            other = solar_position(clock[near] + direction * shift, site, config.sun_model)["altitude"].to_numpy()
            awake[near] |= (other > config.min_altitude) & (other > altitude[near])
    return awake


def east_park(collector: Collector) -> list[float]:
    """Where an installer parks a sensor-only tracker before its first morning: toward a sun 5°
    above the eastern horizon, on the nominal mount."""
    return MountEstimate(encoder_offset=(0.0, 0.0)).targets([5.0], [90.0], collector)[0].tolist()
