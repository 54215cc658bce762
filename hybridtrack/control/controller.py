"""The controller: what a PLC does each scan, from its own readings, config and state.

Each scan it takes an `Observation` (encoder, sensor, photocurrent, anemometer) and its plan
(`plan.make_plan`: the computed sun and the working day from its own clock), and returns how far
to move each axis. The pieces, each in its own module: the encoder monitor, the wind guard, the
sky watch, the sensor gate with its Kalman filter, the calibrator; here they are put together
with the day cycle, the mode choice, the target and the drive command. It never sees the world.
"""

from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass

import numpy as np

from ..drive import Drive
from .calibration import Calibrator
from .clockwatch import ClockWatch
from .config import ControllerConfig
from .disagreement import DisagreementMonitor
from .encoder import AXIS_NAMES, EncoderMonitor
from .mountfit import MountEstimator, ordered_dot, pull_spread
from .modes import (ASTRONOMICAL, FAULT, FAULTY, IMPLAUSIBLE, INVALID, MODES, NOT_READ, OK, OUT_OF_VIEW, OUTLIER,
                    SEARCH, SENSOR, SENSOR_STATUS, SKY_CODES, STOW_NIGHT, STOW_WIND, STUCK, SUNNY, UNKNOWN)
from .observation import Observation
from .plan import ControllerPlan
from .sensing import SensorGate, axis_offset, reading_scale
from .skywatch import ClassifierTable, SkyWatch
from .wind import WindGuard, unreadable, unreadable_reason

__all__ = ["Controller", "ControllerOutputs"]

log = logging.getLogger("hybridtrack.control")

#: Minutes of darkness after which the sensor-only tracker sleeps.
DUSK_MINUTES = 30.0
#: Minutes between the readings the mount fit takes: readings a minute apart are correlated
#: through the filter and the sun has hardly moved, so more would add time, not information.
FIT_EVERY = 5.0
#: Fit readings (an hour at one every five minutes) before the sensor is judged against the fit.
SETTLE_UPDATES = 12
#: Minutes a sensor may read beyond the plausibility bound of the calibrated model, with no
#: plausible reading between, before it is an alarm (`Controller._held_off`): the sun turns 15° in
#: an hour, so a reading that stays off that long is no cloud's passing pull (which the gate's
#: reacquire rides out in minutes) but a faulty sensor or a collector that is not where its
#: encoder says (a coupling slipping by degrees an hour, a mount that moved).
HELD_OFF_MINUTES = 60.0
#: W/m² of light in view at which the sensor's datasheet noise (`ControllerConfig.sensor_noise`) is stated.
REFERENCE_LIGHT = 1000.0
#: The policies that decide on the fuzzy classifier's sky.
CLASSIFYING = ("hybrid", "hybrid-nocal")


@dataclass
class ControllerOutputs:
    """Per scan: mode, sensor status, sky class and score, the photocurrent read and its variation
    (NaN while asleep), and per axis the target, the encoder reading used, the calibration (the
    correction made to the computed target) and the filtered sun angle where a reading was
    taken; per mount parameter its fitted value and 1σ (N, parameters; empty without a fit);
    moves and travel per axis; events as (scan, from mode, to mode, reason)."""

    mode: np.ndarray
    sensor_status: np.ndarray
    sky: np.ndarray
    sky_score: np.ndarray
    intensity: np.ndarray
    variation: np.ndarray
    target: np.ndarray
    reading: np.ndarray
    calibration: np.ndarray
    sun: np.ndarray
    fit: np.ndarray
    fit_std: np.ndarray
    moves: np.ndarray
    travel: np.ndarray
    events: list


def _lead(rate: float, period: float, deadband: float) -> float:
    """How far ahead of the sun to aim, degrees: half the sun's motion until the next move.

    With the sun moving `rate` °/min and a scan every `period` minutes, the drive moves every
    k = ceil(deadband / (|rate| · period)) scans; aiming rate · period · (k - 1) / 2 ahead centres
    the error the scans see on the sun. Bounded by half the deadband; no lead when the drive moves
    every scan anyway.
    """
    step = abs(rate) * period
    if not step > 0:
        return 0.0
    scans = math.ceil(deadband / step - 1e-9)
    return math.copysign(min(step * (scans - 1) / 2.0, deadband / 2.0), rate)


class Controller:
    """A tracking controller for one collector of one or two axes.

    Parameters
    ----------
    config : ControllerConfig
    drives : list of Drive
        The datasheet of each axis's drive and encoder (deadband, speeds, limits, stow).
    plan : ControllerPlan
    classifier : FuzzyWeatherClassifier
        The sky classifier, run as a table (`skywatch.ClassifierTable`).
    sky_inputs : SkyInputConfig
        How the photocurrent becomes the classifier's inputs (`hybridtrack.skyinputs`).
    dark_current : float
        mA: the sensor's datasheet dark current.
    park : list of float
        Where the sensor-only tracker waits before its first morning (toward the eastern
        horizon, as installers set such trackers); after that, where it first found the sun.
    memory : dict, optional
        What a controller that has been running carries over (`Controller.memory`): its mount
        fit and calibration offsets.
    responsivity, sun_threshold : float, optional
        The sensor's datasheet responsivity (mA per W/m²) and the light (W/m²) below which it
        does not see the sun: how the light in view is read from the photocurrent, and its floor,
        for the noise of a fit reading (`_reading_variance`). Without them a fit reading has the
        datasheet noise as stated.
    """

    def __init__(self, config: ControllerConfig, drives: list[Drive], plan: ControllerPlan, classifier,
                 sky_inputs, dark_current: float, park: list[float], memory: dict | None = None,
                 responsivity: float | None = None, sun_threshold: float = 0.0):
        self.config = config
        self.responsivity, self.sun_threshold = responsivity, sun_threshold
        self.drives = drives
        self.axes = len(drives)
        self.plan = plan
        self.plan_alarms = plan.alarms
        resolution = [d.resolution for d in drives]
        self.circular = [d.limits[1] - d.limits[0] >= 360.0 for d in drives]
        self.encoders = [EncoderMonitor(r, config.encoder_confirm, name)
                         for r, name in zip(resolution, AXIS_NAMES[self.axes])]
        self.wind = WindGuard(config.wind_stow, config.wind_release, config.minutes("wind_hold"), config.wind_missing)
        self.sky = SkyWatch(ClassifierTable(classifier), sky_inputs, dark_current)
        variance = [config.sensor_noise**2 + r * r / 12.0 for r in resolution]
        self.gates = [SensorGate(config.kalman, config.process_noise, v, config.stuck_scans, config.gate,
                                 config.reacquire, config.sensor_noise) for v in variance]
        self.calibrators = [Calibrator(config.minutes("calibration_tau"), config.calibration_max_rate)
                            for _ in drives]
        self.jacobian, self.weight = plan.jacobian, plan.weight
        self.fit = MountEstimator(self.axes, config.sensor_noise, parameters=plan.jacobian.shape[2]) \
            if plan.jacobian is not None else None
        self.clock = ClockWatch(plan.jacobian.shape[2], config.sensor_noise, constant_seen=self.axes == 2) \
            if self.fit is not None else None
        self.theta = np.zeros(self.fit.n if self.fit is not None else 2 + self.axes)
        self.fit_since = 0.0
        self.fitted_at = [-math.inf] * self.axes
        self.recorded_updates = -1
        self.mount_at: tuple = (-1, -1)
        self.mount: list = []
        self.fit_row = ([], [])
        self.disagreement = DisagreementMonitor()
        self.checkpoint: dict | None = None
        self.distrusted_until = -math.inf  # the sensor disagreed with the calibrated model: not trusted till then
        self.held_off_since, self.held_off_raised = math.nan, False  # `_held_off`'s spell
        self.held_miss = math.nan  # this scan's implausible reading furthest from the model
        if memory:
            self._recall(memory)
            if self.fit is not None:  # the clear sky's level is the sky's, not the fit's: no checkpoint restores it
                self.fit.level = memory.get("light_level", self.fit.level)
            if self.clock is not None and "clock" in memory:  # a run carried on (`carry`), timers rebased
                self.clock.restore(memory["clock"])
            if "anemometer_stuck_at" in memory:  # the anemometer an earlier run judged stuck (`carry`)
                self.wind.stuck, self.wind.flat_value = True, float(memory["anemometer_stuck_at"])
        self.dwell, self.loss = config.minutes("dwell"), config.minutes("sensor_loss")
        self.coast_for = config.minutes("coast")
        self.mode, self.mode_since = STOW_NIGHT, -math.inf
        self.invalid_since = math.nan
        self.previous_t = math.nan
        self.resting = False
        self.park = list(park)
        # a run that starts in the dark has been dark long: a sensor-only tracker started at midnight had
        # taken its first dark scan for dusk, woken and driven off stow for half an hour
        self.dark_since = -math.inf
        self.was_awake = False
        self.blind_stow: list[float] | None = None  # what is left of a timed stow move, per axis
        self.found_today = False
        self.events: list = []
        self.moves = [0] * self.axes
        self.travel = [0.0] * self.axes

    # -- the plan as lists, and the record, for the scan-by-scan step -----------------------------
    # Built on first use: a Python list gives a float about three times faster than an array does,
    # and the compiled kernel (`hybridtrack.kernel`), which reads the plan's arrays, never pays for them.

    @functools.cached_property
    def model(self) -> list:
        return [self.plan.model[:, a].tolist() for a in range(self.axes)]

    @functools.cached_property
    def awake(self) -> list:
        return self.plan.awake.tolist()

    @functools.cached_property
    def slept(self) -> list:
        return self.plan.slept.tolist()

    @functools.cached_property
    def clock_steps(self) -> list:
        return self.plan.clock_steps.tolist()

    @functools.cached_property
    def clear_light(self) -> list:
        return _listed_or_nan(self.plan.clear_light, len(self.plan.awake))

    @functools.cached_property
    def altitude(self) -> list:
        return _listed_or_nan(self.plan.apparent_altitude, len(self.plan.awake))

    @functools.cached_property
    def out(self) -> dict:
        n = len(self.plan.awake)
        out = {name: [0] * n for name in ("mode", "status", "sky")}
        out.update({name: [math.nan] * n for name in ("score", "variation", "intensity")})
        return out

    @functools.cached_property
    def out_axes(self) -> dict:
        n = len(self.plan.awake)
        return {name: [[math.nan] * n for _ in range(self.axes)] for name in ("target", "reading", "calibration", "sun")}

    @functools.cached_property
    def out_fit(self) -> dict:
        n, fitted = len(self.plan.awake), len(self.theta) if self.fit is not None else 0
        return {name: [[math.nan] * n for _ in range(fitted)] for name in ("value", "std")}

    # -- bookkeeping -----------------------------------------------------------------------------

    def _switch(self, i: int, new: int, reason: str, t: float) -> None:
        self.events.append((i, MODES[self.mode], MODES[new], reason))
        log.debug("scan %d: %s -> %s (%s)", i, MODES[self.mode], MODES[new], reason)
        self.mode, self.mode_since = new, t

    def _alarm(self, i: int, reason: str) -> None:
        self.events.append((i, MODES[self.mode], MODES[self.mode], reason))
        log.info("scan %d: %s", i, reason)

    def _turn(self, a: int, difference: float) -> float:
        """A difference of angles on axis `a`: the short way round on a circular axis."""
        return (difference + 180.0) % 360.0 - 180.0 if self.circular[a] else difference

    def _record(self, i: int, status: int, targets: list, reading: list) -> None:
        out, per_axis = self.out, self.out_axes
        out["mode"][i] = self.mode
        out["status"][i] = status
        for a in range(self.axes):
            per_axis["target"][a][i] = targets[a]
            per_axis["reading"][a][i] = reading[a]
            per_axis["calibration"][a][i] = self._correction(i, a)
        if self.fit is not None:
            if self.fit.updates != self.recorded_updates:
                self.recorded_updates = self.fit.updates
                self.fit_row = (self.fit.theta.tolist(), self.fit.std())
            for k in range(len(self.theta)):
                self.out_fit["value"][k][i] = self.fit_row[0][k]
                self.out_fit["std"][k][i] = self.fit_row[1][k]

    def sleeps_until(self, i: int) -> int:
        """The first scan from `i` at which the controller wakes (len of the plan if never)."""
        awake = self.awake
        j = i
        while j < len(awake) and not awake[j]:
            j += 1
        return j

    def rest(self, i: int, j: int, last_t: float) -> None:
        """Scans `i` to `j` - 1 asleep at stow with nothing happening (the last at timer `last_t`):
        recorded in bulk, as stepping through them would."""
        count = j - i
        reading = [monitor.believed for monitor in self.encoders]
        self.previous_t = last_t
        out, per_axis = self.out, self.out_axes
        out["mode"][i:j] = [STOW_NIGHT] * count
        out["status"][i:j] = [NOT_READ] * count
        out["sky"][i:j] = [UNKNOWN] * count
        for a in range(self.axes):
            per_axis["target"][a][i:j] = [self._night_target(a)] * count
            per_axis["reading"][a][i:j] = [reading[a]] * count
            offset = self.calibrators[a].offset
            per_axis["calibration"][a][i:j] = [offset] * count if self.fit is None else \
                (self._mount_corrections(i, j)[:, a] + offset).tolist()
            per_axis["sun"][a][i:j] = [math.nan] * count
        if self.fit is not None:
            for k, (value, std) in enumerate(zip(self.fit.theta, self.fit.std())):
                self.out_fit["value"][k][i:j] = [value] * count
                self.out_fit["std"][k][i:j] = [std] * count

    # -- one scan --------------------------------------------------------------------------------

    def step(self, obs: Observation) -> list[float]:
        """Take one scan's readings; return the move to make on each axis, degrees."""
        i, t = obs.i, obs.t
        dt = t - self.previous_t if not math.isnan(self.previous_t) else 1.0
        self.previous_t = t
        awake = self.awake[i] and (not self.config.sensor_only or self._daylight(t, obs.intensity))
        if i in self.plan_alarms:
            self._alarm(i, self.plan_alarms[i])
        if self.clock_steps[i]:
            self._alarm(i, f"controller clock stepped by {self.clock_steps[i]:+.0f} s against the scan timer; "
                           "clock re-based")
        reading = self._read_encoders(i, t, obs)
        stuck = self.wind.watch(t, obs.wind, awake)
        if stuck:
            self._alarm(i, stuck)
        wind = self.wind.heard(obs.wind)
        gusty = self.wind.update(t, wind)
        if self.resting and not awake and not gusty:
            self.was_awake = False
            self.out["sky"][i] = UNKNOWN
            self._record(i, NOT_READ, [self._night_target(a) for a in range(self.axes)], reading)
            return [0.0] * self.axes
        if self.slept[i]:
            self._night_in_gap(i, t, dt)
        self._day_and_wind(i, t, awake, gusty, wind, obs.wind)
        if self.was_awake and not awake:  # the day's end
            self._judge_clock(i)
        if awake and not self.was_awake:  # a new day: the residual offsets were the evening sky's
            for calibrator in self.calibrators:
                calibrator.start_day()
        self.was_awake = awake
        sky = self._watch_sky(i, t, obs)
        status, valid = self._sense(i, t, dt, obs, reading, awake, sky)
        self._choose_mode(i, t, status, valid, sky, obs)
        targets, moves = self._command(i, t, dt, reading, valid, obs)
        self._record(i, status, targets, reading)
        if self.mode == STOW_NIGHT:
            for gate in self.gates:
                gate.forget()
        return moves

    def _night_in_gap(self, i: int, t: float, minutes: float) -> None:
        """The night slept in the gap before scan `i` (`ControllerPlan.slept`: a frame without its
        nights), as an evening ends a day: the stow, the clock's verdict, the filters forgotten.
        `_day_and_wind` then wakes the controller at this scan."""
        if self.mode not in (STOW_WIND, FAULT, STOW_NIGHT):
            self._switch(i, STOW_NIGHT, f"no scans for {minutes / 60.0:.1f} h across the night: asleep through it", t)
            self.found_today = False
        if self.was_awake:
            self._judge_clock(i)
        for gate in self.gates:
            gate.forget()
        self.was_awake = False

    def _judge_clock(self, i: int) -> None:
        """At a day's end, the clock watch's verdict on the day's readings, as alarms."""
        if self.clock is not None:
            for alarm in self.clock.verdict():
                self._alarm(i, alarm)

    def _daylight(self, t: float, intensity: float) -> bool:
        """The sensor-only tracker's day: light above dusk, or dark for less than 30 minutes."""
        if intensity >= self.config.dusk_current:
            self.dark_since = math.nan
            return True
        if math.isnan(self.dark_since):
            self.dark_since = t
        return t - self.dark_since < DUSK_MINUTES

    def _read_encoders(self, i: int, t: float, obs: Observation) -> list[float]:
        reading = []
        reckoned = self.mode == FAULT or self.blind_stow is not None
        for a, monitor in enumerate(self.encoders):
            value, note, frozen = monitor.read(obs.encoder[a], reckoned)
            if frozen and self.mode != FAULT:
                self._switch(i, FAULT, note, t)
            elif note:
                self._alarm(i, note)
            reading.append(value)
        return reading

    def _day_and_wind(self, i: int, t: float, awake: bool, gusty: bool, wind: float, read: float) -> None:
        """The wind guard's stow and release, then the day's; `wind` as the guard counts the
        anemometer's reading `read`."""
        mode, config = self.mode, self.config
        resume = SENSOR if config.sensor_only else ASTRONOMICAL
        if gusty and mode != STOW_WIND:  # wind first, from every mode
            if unreadable(read):
                reason = unreadable_reason(read)
            else:
                reason = "wind reading missing" if math.isnan(wind) else f"wind {wind:.1f} m/s > {config.wind_stow}"
            if mode == FAULT:  # the encoder is not believed: a timed move from the reckoned position
                self.blind_stow = [d.stow - m.believed for d, m in zip(self.drives, self.encoders)]
                reason += "; encoder judged frozen: timed stow move from the position reckoned from the moves commanded"
            self._switch(i, STOW_WIND, reason, t)
        elif mode == STOW_WIND and not gusty and self.wind.released(t):
            released = f"wind at or below {config.wind_release} m/s for {config.wind_hold}"
            if self.blind_stow is not None:
                self.blind_stow = None
                self._switch(i, FAULT, released + "; encoder still judged frozen: drive halted", t)
            else:
                self._switch(i, resume, released, t)
        mode = self.mode
        if mode == FAULT:
            if awake and not self.was_awake:
                self._switch(i, resume, "a new day: probing the encoder again", t)
        elif mode != STOW_WIND:
            if not awake and mode != STOW_NIGHT:
                self._switch(i, STOW_NIGHT, "dark for 30 minutes" if config.sensor_only
                             else "outside working hours or sun down", t)
                self.found_today = False
            elif awake and mode == STOW_NIGHT:
                self._switch(i, resume, "awake and sun up" if config.uses_model else "daylight", t)

    def _watch_sky(self, i: int, t: float, obs: Observation) -> int:
        """Read the photocurrent; the policies that use the classifier also classify the sky."""
        self.out["intensity"][i] = obs.intensity
        if self.config.strategy not in CLASSIFYING:
            return UNKNOWN
        code, score, variation = self.sky.update(t, obs.intensity, self.clear_light[i], self.altitude[i])
        self.out["sky"][i] = code
        self.out["score"][i] = score
        self.out["variation"][i] = variation
        return code

    def _trusts_sensor(self, sky: int, obs: Observation) -> bool:
        """Whether the policy wants the sensor now (and so lets it calibrate the model)."""
        strategy = self.config.strategy
        if strategy == "hybrid-always" or strategy == "sensor":
            return True
        if strategy == "hybrid-oracle":
            return obs.true_sky == SUNNY
        return sky == SUNNY

    def _sense(self, i: int, t: float, dt: float, obs: Observation, reading: list, awake: bool,
               sky: int) -> tuple[int, list]:
        config = self.config
        valid = [False] * self.axes
        if not (config.uses_sensor and awake and self.mode not in (STOW_WIND, FAULT)):
            return NOT_READ, valid
        status = OK
        trusted = config.calibrates and self._trusts_sensor(sky, obs)
        self.held_miss = math.nan
        predicted = [False] * self.axes  # a gate that judged an outlier has predicted across this scan
        for a, gate in enumerate(self.gates):
            verdict = gate.judge(obs.offset[a], obs.valid, obs.coarse[a],
                                 self._turn(a, self._expected_sun(i, a, t) - reading[a]))
            if verdict == OK and obs.t < self.distrusted_until:
                verdict = IMPLAUSIBLE
            if verdict == OK:
                offset, measures = axis_offset(obs.offset, a, reading)
                if not measures and config.uses_model and not math.isnan(self.model[a][i]):
                    verdict = INVALID  # no measure of the azimuth near the zenith: the calibrated model steers
                else:
                    verdict = self._offer(i, a, dt, reading[a] + offset, trusted and measures,
                                          reading_scale(obs.offset, a, reading))
            valid[a], predicted[a] = verdict == OK, verdict == OUTLIER
            if valid[a]:
                self.out_axes["sun"][a][i] = gate.filter.angle
            if verdict != OK and status == OK:
                status = verdict
        for a, gate in enumerate(self.gates):
            if not (valid[a] or predicted[a]):
                gate.coast(dt)
        self._held_off(i, t, all(valid))
        if all(valid):
            self.invalid_since = math.nan
            if config.sensor_only and not self.found_today:
                self.park = [g.filter.angle for g in self.gates]
                self.found_today = True
        elif math.isnan(self.invalid_since):
            self.invalid_since = t
        return status, valid

    def _held_off(self, i: int, t: float, plausible: bool) -> None:
        """Watch for a sensor held beyond the plausibility bound: a spell starts at a reading the
        gate finds implausible against the calibrated model (`held_miss`) and ends at a scan whose
        readings are all taken; scans between (clouds, the night, a distrusted sensor) neither end
        nor extend it. After `HELD_OFF_MINUTES` an alarm, once a spell: the sensor is no longer
        used, and if the collector is what slipped, the computed target it now follows is off too
        (a coupling creeping by a degree an hour had left a trough 8° off by evening with no word
        after the first "sensor lost")."""
        if plausible:
            self.held_off_since, self.held_off_raised = math.nan, False
            return
        if math.isnan(self.held_miss):
            return
        if math.isnan(self.held_off_since):
            self.held_off_since = t
        if not self.held_off_raised and t - self.held_off_since >= HELD_OFF_MINUTES:
            self.held_off_raised = True
            self._alarm(i, f"sensor {self.held_miss:+.2f}° from the calibrated model, held beyond the plausibility "
                           f"bound for {t - self.held_off_since:.0f} min: a faulty sensor, or a collector off its "
                           "encoder (a slipping coupling, a moved mount); the computed target is followed")

    def _expected_sun(self, i: int, a: int, t: float) -> float:
        """Where the sun should be on axis `a` for the stuck check: the computed sun, or for the
        sensor-only tracker the filter's rate carried forward."""
        if self.config.uses_model:
            return self.model[a][i] + self._correction(i, a)
        gate = self.gates[a]
        return gate.filter.rate * t if gate.ready else math.nan

    def _plausibility_bound(self, i: int, a: int) -> float:
        limit = self.config.sensor_plausibility
        if self.axes == 2 and a == 0:  # in pointing terms a heliostat's azimuth axis turns 1/cos(elevation) faster
            return limit / max(math.cos(math.radians(self.model[1][i])), 0.05)
        return limit

    def _correction(self, i: int, a: int) -> float:
        """What calibration adds to the computed target of axis `a`: the fitted mount, then the offset."""
        offset = self.calibrators[a].offset
        if self.fit is None:
            return offset
        if self.mount_at != (i, self.fit.updates):
            self.mount_at = (i, self.fit.updates)
            self.mount = self._mount_corrections(i, i + 1)[0].tolist()
        return self.mount[a] + offset

    def _mount_corrections(self, i: int, j: int) -> np.ndarray:
        """The fitted mount's correction of scans `i` to `j` - 1, (j - i, axes)."""
        return ordered_dot(self.jacobian[i:j], self.theta)

    def _offer(self, i: int, a: int, dt: float, z: float, trusted: bool, scale: float) -> int:
        """Offer the sensor's sun angle on axis `a` to the gate (its variance the filter's R times
        `scale`, `reading_scale`), and let a trusted one calibrate."""
        config, gate = self.config, self.gates[a]
        m0 = self.model[a][i]
        m1 = self.model[a][i - 1] if i else math.nan
        bound = self._plausibility_bound(i, a)
        has_model = config.uses_model and not math.isnan(m0)
        miss = self._turn(a, z - m0 - self._correction(i, a)) if has_model else math.nan
        if has_model and dt > 0 and not math.isnan(m1):
            rate = self._turn(a, m0 - m1) / dt
        else:  # no computed sun: the filter's own rate, once it has one
            rate = gate.filter.rate if gate.ready else 0.0
        verdict = gate.take(z, dt, miss, bound, rate, scale)
        if verdict == IMPLAUSIBLE and not abs(miss) <= abs(self.held_miss):  # the first, or further off
            self.held_miss = miss
        if verdict == OK and trusted and has_model:
            self._learn(i, a, dt, z, m0, m1, bound)
        return verdict

    def _learn(self, i: int, a: int, dt: float, z: float, m0: float, m1: float, bound: float) -> None:
        """A trusted reading: the mount fit learns from it, then the residual offset on top."""
        t = self.previous_t
        if self.fit is not None and t - self.fitted_at[a] >= FIT_EVERY:
            self.fitted_at[a] = t
            self.fit.forget(t - self.fit_since)
            self.fit_since = t
            w = self.weight[i, a]
            miss, spread = self._against_checkpoint(i, a, z, m0, w)
            pull = w * pull_spread(self.config.pull_gain, self.fit.excess_light(self._light_ratio(i)),
                                   self.altitude[i])
            self.fit.update(self.jacobian[i, a] * w, self._turn(a, z - m0) * w,
                            self._reading_variance(i) + pull * pull)
            self.theta = self.fit.theta
            if self._disagrees(i, miss, spread):
                return
            rate = self._turn(a, m0 - m1) / dt if dt > 0 else math.nan
            if math.isfinite(rate):
                self.clock.add(t, a, self.jacobian[i, a], rate, self._turn(a, z - m0), w)
        mount = self._correction(i, a) - self.calibrators[a].offset
        residual = self._turn(a, self.gates[a].filter.angle - m0 - mount)
        self.calibrators[a].learn(dt, residual, self._turn(a, m0 - m1), bound)

    def _light_ratio(self, i: int) -> float:
        """The photocurrent above dark over the clear-sky photocurrent expected at scan `i` (NaN
        where none is expected)."""
        expected = self.clear_light[i]
        return (self.out["intensity"][i] - self.sky.dark) / expected if expected > 0 else math.nan

    def _against_checkpoint(self, i: int, a: int, z: float, m0: float, w: float) -> tuple[float, float]:
        """The sensor's sun angle less the mount as fitted at the last checkpoint, and the spread that
        difference should have: the sensor's noise and the checkpoint's own uncertainty, both in
        pointing terms as the fit takes them (axis degrees times the axis's weight `w`: a heliostat's
        azimuth degree near the zenith is a small pointing error). A calibration that follows a
        drifting sensor must not hide the drift; the residual offset is left out, as it follows the
        time of day and a checkpoint's offset belongs to another hour."""
        fit = self.checkpoint if self.checkpoint is not None else {"theta": self.theta, "p": self.fit.p}
        row = self.jacobian[i, a]
        miss = self._turn(a, z - m0 - float(ordered_dot(row, fit["theta"]))) * w
        spread = float(ordered_dot(row, ordered_dot(fit["p"], row)))
        return miss, math.sqrt(self._reading_variance(i) + w * w * spread)

    def _reading_variance(self, i: int) -> float:
        """deg²: the variance of a sensor reading at scan `i`: the datasheet noise, stated at
        `REFERENCE_LIGHT` in view, grown as the light falls, (σ · 1000 / L)², as the sensor's
        amplifier noise does against a smaller signal (`hybridtrack.sensor`). L is the light the
        cells see, from the photocurrent above dark over the `responsivity`, at least the sensor's
        sun threshold (below it the sensor reports no sun), and the threshold where the photocurrent
        has no number (a recorded one with a gap): the sensor said it saw the sun, so its reading
        is taken as no better than at the least light it sees it in. A NaN here had made the mount
        fit's matrix NaN, and LAPACK's SVD failed mid-run. Without a responsivity, σ² as stated."""
        if self.responsivity is None:
            return self.fit.r
        light = (self.out["intensity"][i] - self.sky.dark) / self.responsivity
        if not light >= self.sun_threshold:  # NaN too
            light = self.sun_threshold
        ratio = REFERENCE_LIGHT / light
        return self.fit.r * ratio * ratio  # not ** 2: libm's pow and a product may differ in the last bit

    def _disagrees(self, i: int, miss: float, spread: float) -> bool:
        """Watch the sensor against the checkpointed calibration (`miss`, degrees, with its expected
        `spread`); on a persistent disagreement act as `ControllerConfig.on_disagreement` says: roll
        the calibration back and distrust the sensor (and return True), or keep both and go on."""
        if self.fit.updates < SETTLE_UPDATES:  # a fit still finding its feet is not evidence against the sensor
            return False
        if self.disagreement.calm:
            self.checkpoint = self.memory()
        if not self.disagreement.add(miss / spread, miss, self.config.disagreement):
            return False
        mean, count = self.disagreement.mean_residual(), self.disagreement.run
        self.disagreement.reset()
        found = f"sensor and calibrated model disagree: mean residual {mean:+.3f}° over {count} readings; "
        if self.config.on_disagreement == "sensor":  # the mount moved: the fit follows the sensor
            self.checkpoint = self.memory()
            self._alarm(i, found + "sensor trusted, calibration follows it (on_disagreement = 'sensor')")
            return False
        if self.checkpoint is not None:
            self._recall(self.checkpoint)
        distrust = self.config.minutes("distrust")
        self.distrusted_until = self.previous_t + distrust
        self._alarm(i, found + f"calibration rolled back, sensor not trusted for {distrust:.0f} min")
        return True

    def memory(self) -> dict:
        """What this controller would carry into a next run: its mount fit (with the clear sky's
        light level its readings are judged against) and offsets."""
        fit = self.fit
        state = {"offsets": [c.offset for c in self.calibrators]}
        if fit is not None:
            state.update(theta=fit.theta.tolist(), p=fit.p.copy(), information=fit.information.copy(),
                         evidence=fit.evidence.copy(), frozen=fit.axis_frozen, updates=fit.updates,
                         light_level=fit.level)
        return state

    def carry(self, start) -> dict:
        """`memory` and the clock watch's readings (`ClockWatch.save`; `start` is the instant the
        scan timer counts from): what the next run of a long one starts from, so the clock's drift
        is judged over the whole span (`hybridtrack.streaming`)."""
        state = self.memory()
        if self.clock is not None:
            state["clock"] = self.clock.save(start)
        if self.wind.stuck:  # judged over three hours of daylight: not again each morning of a long run
            state["anemometer_stuck_at"] = self.wind.flat_value
        return state

    def _recall(self, memory: dict) -> None:
        for calibrator, offset in zip(self.calibrators, memory.get("offsets", [])):
            calibrator.carry(offset)
        if self.fit is not None and "theta" in memory:
            fit = self.fit
            fit.theta, fit.p = np.array(memory["theta"], float), np.array(memory["p"], float)
            fit.information, fit.axis_frozen = memory["information"].copy(), memory["frozen"]
            # a memory saved before the fit carried its information vector: the one its θ solves
            fit.evidence = np.array(memory["evidence"], float) if "evidence" in memory else fit.information @ fit.theta
            fit.updates = memory["updates"]
            self.theta = np.array(fit.theta)

    def fitted_mount(self) -> dict | None:
        """The fitted parameters, their 1σ, and whether the pedestal terms are frozen."""
        return None if self.fit is None else {"theta": self.fit.theta.tolist(), "std": self.fit.std(),
                                              "frozen": self.fit.axis_frozen, "condition": self.fit.condition}

    def _choose_mode(self, i: int, t: float, status: int, valid: list, sky: int, obs: Observation) -> None:
        mode = self.mode
        if mode not in (ASTRONOMICAL, SENSOR, SEARCH):
            return
        sensor_ok = self.config.uses_sensor and all(valid)
        lost_for = t - self.invalid_since
        if self.config.sensor_only:  # no sun model: a sensor faulty for `sensor_loss` hands over to the cells
            if mode == SEARCH and sensor_ok:
                self._switch(i, SENSOR, "sun back in the sensor's view", t)
            elif mode == SENSOR and status in (STUCK, IMPLAUSIBLE) and lost_for >= self.loss:
                self._switch(i, SEARCH, f"sensor lost ({SENSOR_STATUS[status]})", t)
            elif mode == SENSOR and status == OUT_OF_VIEW:
                self._switch(i, SEARCH, "the acquisition cells see the sun outside the fine view", t)
            return
        want = self.config.uses_sensor and self._trusts_sensor(sky, obs)
        if mode == SENSOR and not sensor_ok and (status in FAULTY or lost_for >= self.loss):
            self._switch(i, ASTRONOMICAL, f"sensor lost ({SENSOR_STATUS[status]})", t)
        elif mode == SENSOR and not want and t - self.mode_since >= self.dwell:
            reason = "true sky not sunny" if self.config.strategy == "hybrid-oracle" else f"sky {SKY_CODES[sky]}"
            self._switch(i, ASTRONOMICAL, reason, t)
        elif mode == ASTRONOMICAL and want and sensor_ok and t - self.mode_since >= self.dwell:
            self._switch(i, SENSOR, "sensor valid and trusted" if self.config.strategy == "hybrid-always"
                         else "sky sunny and sensor valid", t)

    # -- targets and the drive ---------------------------------------------------------------------

    def _night_target(self, a: int) -> float:
        return self.park[a] if self.config.sensor_only else self.drives[a].stow

    def _target(self, i: int, a: int, t: float, dt: float, reading: float, valid: bool, rough: float) -> float:
        """The angle to drive axis `a` to; `rough` is the acquisition cells' offset in its degrees."""
        mode, gate, drive = self.mode, self.gates[a], self.drives[a]
        lead = self.config.lead
        if mode == STOW_WIND:
            return drive.stow
        if mode == STOW_NIGHT:
            return self._night_target(a)
        if mode == SENSOR:
            coasting = not valid and t - self.invalid_since <= self.coast_for
            if not (gate.ready and (valid or not self.config.sensor_only or coasting)):
                return reading  # hold
            if valid or not self._strayed(i, a, gate.filter.angle):
                return gate.filter.angle + (_lead(gate.filter.rate, dt, drive.deadband) if lead else 0.0)
            # a filter coasted beyond the plausibility bound of the calibrated model: the computed target
        if mode == SEARCH:
            # the drive's speed limits the step; a scan later the cells look again
            return reading if math.isnan(rough) else reading + rough
        m = self.model[a][i]
        if math.isnan(m):
            return drive.stow
        target = m + self._correction(i, a)
        previous = self.model[a][i - 1] if i else math.nan
        if lead and not math.isnan(previous) and dt > 0:
            target += _lead(self._turn(a, m - previous) / dt, dt, drive.deadband)
        if self.circular[a]:  # the nearest way to the same direction, within the limits
            target = reading + self._turn(a, target - reading)
            low, high = drive.limits
            if not low <= target <= high:
                target += 360.0 if target < low else -360.0
        return target

    def _strayed(self, i: int, a: int, angle: float) -> bool:
        """Whether a filtered angle on axis `a` lies further from the calibrated model than the
        plausibility bound: a filter that coasted there (a rate learned across a gap) is no target
        while the model is at hand (never without one)."""
        m = self.model[a][i]
        if not self.config.uses_model or math.isnan(m):
            return False
        return abs(self._turn(a, angle - m - self._correction(i, a))) > self._plausibility_bound(i, a)

    def _command(self, i: int, t: float, dt: float, reading: list, valid: list,
                 obs: Observation) -> tuple[list, list]:
        targets, moves = [], []
        mode = self.mode
        stowing = mode == STOW_NIGHT or mode == STOW_WIND
        self.resting = mode == STOW_NIGHT and not self.awake[i]
        for a, drive in enumerate(self.drives):
            monitor = self.encoders[a]
            monitor.commanded = 0.0
            if mode == FAULT:  # position unknown: never move
                targets.append(reading[a])
                moves.append(0.0)
                continue
            if self.blind_stow is not None:  # a timed stow move: run at stow speed for the distance, then stop
                left = self.blind_stow[a]
                step = max(-drive.stow_speed * dt, min(drive.stow_speed * dt, left))
                self.blind_stow[a] = left - step
                monitor.commanded = step  # the encoder is not believed: the position is reckoned from it
                self.travel[a] += abs(step)
                self.moves[a] += 1 if step else 0
                targets.append(drive.stow)
                moves.append(step)
                continue
            low, high = drive.limits
            rough, _ = axis_offset(obs.coarse, a, reading)
            target = min(max(self._target(i, a, t, dt, reading[a], valid[a], rough), low), high)
            error = target - reading[a]
            held = mode == STOW_WIND and abs(reading[a] - drive.stow) <= drive.deadband  # stowed: never move
            threshold = drive.resolution if stowing or mode == SEARCH else drive.deadband
            step = 0.0
            if not held and abs(error) > threshold:
                speed = drive.stow_speed if stowing else drive.speed
                step = max(-speed * dt, min(speed * dt, error))
                monitor.commanded = step
                self.moves[a] += 1
                self.travel[a] += abs(step)
                self.resting = False
            targets.append(target)
            moves.append(step)
        return targets, moves

    def outputs(self) -> ControllerOutputs:
        """Everything recorded, as arrays."""
        out, per_axis = self.out, self.out_axes

        def columns(name):
            return np.array(per_axis[name], float).T.reshape(-1, self.axes)

        def fit(name):
            return np.array(self.out_fit[name], float).T.reshape(len(self.awake), -1)

        return ControllerOutputs(np.array(out["mode"], np.int8), np.array(out["status"], np.int8),
                                 np.array(out["sky"], np.int8), np.array(out["score"], float),
                                 np.array(out["intensity"], float), np.array(out["variation"], float),
                                 columns("target"), columns("reading"), columns("calibration"), columns("sun"),
                                 fit("value"), fit("std"),
                                 np.array(self.moves), np.array(self.travel), self.events)


def _listed_or_nan(values: np.ndarray | None, n: int) -> list:
    """`values` as a list, or NaN at every scan without them."""
    return values.tolist() if values is not None else [math.nan] * n
