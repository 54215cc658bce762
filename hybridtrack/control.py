"""The tracking controller: strategy state machine, Kalman-filtered sensor, calibration, drive.

Modes, and why the controller is in each:

``stow_night``
    outside working hours (05:00-20:00 by its clock) or with its computed sun below
    `min_altitude`: drive to stow and wait;
``stow_wind``
    wind above 17.2 m/s (or an invalid wind reading) seen in this scan: drive to stow at
    once, from any mode, and stay. Tracking resumes only after the wind has stayed at or
    below `wind_release` for `wind_hold`;
``astronomical``
    follow the computed sun (PLC model or SPA at the controller's clock and site), plus the
    calibration offset learned from the sensor;
``sensor``
    follow the sun sensor: its pointing offset added to the encoder reading is the sun's
    angle in encoder coordinates, smoothed by a Kalman filter whose state is that angle and
    its rate;
``search``
    the sensor-only strategy's way back to a sun that left the fine sensor's field of view:
    the coarse cells tell the side, and the drive sweeps toward it at `search_speed`;
``fault``
    the encoder stopped answering a commanded move: the position is unknown, so the drive
    halts (no move at all) until the next morning, when the controller probes again.

Faults the controller guards against, each logged in the events:

* a sensor reading repeated exactly for `stuck_scans` scans (a real one always has noise)
  is judged stuck. One further from the model than `sensor_plausibility` is judged
  implausible. The comparison is with the uncorrected model, so a drifting sensor cannot
  drag the calibration along with it, and the calibration is bounded by the same amount.
  Neither kind of reading is ever tracked.
* an encoder reading that jumps away from where the last commanded move should have left
  it is a glitch: it is ignored for that scan, and accepted only if it persists for
  `encoder_confirm` scans. A reading that does not move when the drive was commanded to is
  a frozen encoder, and puts the controller in ``fault``.
* an anemometer reading that is not a number counts as a gust: stow.

The sky class picks between sensor and astronomical: sunny means sensor, anything else
astronomical. A minimum dwell keeps a flickering sky from flipping the mode every minute.
In sensor mode, a sensor invalid for longer than `sensor_loss` hands over to astronomical
at once, so the hybrid never loses the sun and needs no search mode.

Calibration is continuous rather than every 30 minutes. Whenever the filter takes a valid
reading, the offset between the filtered sun and the model's target moves toward their
difference: a running mean over the first 30 minutes of readings, then a 30-minute time
constant. That follows the slow, time-of-day-dependent
errors of a misaligned axis and a wrong clock as a periodic snapshot cannot, while still
averaging out sensor noise. The offset is kept overnight.

Every invalid sensor reading skips the filter update and is recorded: low light, sun out of
view, a reading that is not a number, or an outlier rejected by the innovation gate.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .drive import encoder_reading
from .errors import HybridtrackError

__all__ = ["ControllerConfig", "STRATEGIES", "MODES", "SENSOR_STATUS", "FastKalman", "FilterpyKalman",
           "run_controller", "ControllerInputs", "ControllerOutputs"]

log = logging.getLogger("hybridtrack.control")

STRATEGIES = ("hybrid", "hybrid-nocal", "astronomical", "sensor")
MODES = ("stow_night", "stow_wind", "astronomical", "sensor", "search", "fault")
STOW_NIGHT, STOW_WIND, ASTRONOMICAL, SENSOR, SEARCH, FAULT = range(len(MODES))
SENSOR_STATUS = ("ok", "low light", "out of view", "invalid reading", "outlier", "not read", "stuck", "implausible")
OK, LOW_LIGHT, OUT_OF_VIEW, INVALID, OUTLIER, NOT_READ, STUCK, IMPLAUSIBLE = range(len(SENSOR_STATUS))
SKY_CODES = ("sunny", "cloudy", "overcast", "unknown")


@dataclass(frozen=True)
class ControllerConfig:
    """How the controller behaves.

    Parameters
    ----------
    strategy : {"hybrid", "hybrid-nocal", "astronomical", "sensor"}
        ``hybrid``: sensor under a sunny sky, astronomical otherwise, with calibration;
        ``hybrid-nocal``: the same without calibration; ``astronomical``: open loop only
        (the trough paper's design); ``sensor``: closed loop only.
    sun_model : {"plc", "spa"}
        The controller's sun model.
    dwell : str
        Minimum time between switches of sensor and astronomical mode.
    wind_stow, wind_release : float
        m/s: stow above `wind_stow`; resume once at or below `wind_release` for `wind_hold`.
    wind_hold : str
    working_hours : tuple of str
        Local clock times the controller works between.
    min_altitude : float
        Degrees: the computed sun must be above this to track.
    calibration_tau : str
        Time constant of the continuous calibration.
    sensor_loss : str
        How long an invalid sensor is tolerated in sensor mode.
    process_noise : float
        Kalman white-noise acceleration intensity, deg²/min³ (loose enough for an east-west
        trough's fast-changing rate after sunrise).
    gate : float
        Innovation gate, in standard deviations. After `reacquire` readings in a row fail it,
        the filter restarts from the latest reading: a filter that drifted away from the sun
        must not go on rejecting it.
    reacquire : int
    sensor_plausibility : float
        Degrees: a sensor reading further from the (calibrated) model is implausible, and
        the calibration never exceeds it.
    stuck_scans : int
        Identical sensor readings in a row that mark the sensor stuck.
    encoder_confirm : int
        Scans a jumped encoder reading must persist before it is believed.
    calibration_max_rate : float
        Degrees per minute: calibration learns only while the model's target moves no faster.
        The offset it learns is meant to be a slow bias; where the geometry turns fast (an
        east-west trough just after sunrise), a clock error shows as a large passing offset.
    search_speed : float
        Degrees per minute of the sensor-only sun search.
    lead : bool
        Aim half a deadband ahead of the sun, in its direction of motion, so the intermittent
        drive's sawtooth is centred on the sun instead of trailing it. ``False`` is the
        published field practice (aim at the sun): the error then trails by up to a deadband.
    kalman : {"fast", "filterpy"}
        ``filterpy`` runs filterpy's KalmanFilter, the reference; ``fast`` the same
        equations in plain floats (a test keeps them equal).
    """

    strategy: str = "hybrid"
    sun_model: str = "plc"
    dwell: str = "5min"
    wind_stow: float = 17.2
    wind_release: float = 12.0
    wind_hold: str = "10min"
    working_hours: tuple[str, str] = ("05:00", "20:00")
    min_altitude: float = 0.0
    calibration_tau: str = "30min"
    sensor_loss: str = "3min"
    process_noise: float = 1e-3
    gate: float = 4.0
    reacquire: int = 3
    calibration_max_rate: float = 1.0
    sensor_plausibility: float = 2.0
    stuck_scans: int = 3
    encoder_confirm: int = 3
    search_speed: float = 5.0
    lead: bool = True
    kalman: str = "fast"

    def __post_init__(self) -> None:
        from .times import parse_clock

        object.__setattr__(self, "working_hours", tuple(self.working_hours))
        if self.strategy not in STRATEGIES:
            raise HybridtrackError(f"unknown strategy {self.strategy!r}; choose from {', '.join(STRATEGIES)}")
        if self.sun_model not in ("plc", "spa"):
            raise HybridtrackError(f"unknown sun model {self.sun_model!r}; choose 'plc' or 'spa'")
        if self.kalman not in ("fast", "filterpy"):
            raise HybridtrackError(f"unknown Kalman engine {self.kalman!r}; choose 'fast' or 'filterpy'")
        for name in ("dwell", "wind_hold", "calibration_tau", "sensor_loss"):
            try:
                if pd.Timedelta(getattr(self, name)) <= pd.Timedelta(0):
                    raise ValueError
            except ValueError:
                raise HybridtrackError(f"controller: {name} {getattr(self, name)!r} is not a positive duration") from None
        if not 0 < self.wind_release <= self.wind_stow:
            raise HybridtrackError(f"controller: wind_release {self.wind_release} must be positive and at most "
                                   f"wind_stow {self.wind_stow}")
        if len(self.working_hours) != 2:
            raise HybridtrackError("controller: working_hours needs a start and an end")
        for clock in self.working_hours:
            parse_clock(clock)
        if not (self.process_noise > 0 and self.gate > 0 and self.search_speed > 0 and self.calibration_max_rate > 0):
            raise HybridtrackError("controller: process_noise, gate, search_speed and calibration_max_rate must be "
                                   "positive")
        for name in ("reacquire", "stuck_scans", "encoder_confirm"):
            value = getattr(self, name)
            if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
                raise HybridtrackError(f"controller: {name} must be a whole number of at least 1, got {value!r}")
        if not self.sensor_plausibility > 0:
            raise HybridtrackError("controller: sensor_plausibility must be positive")

    @property
    def uses_sensor(self) -> bool:
        """Whether the strategy ever tracks the sensor."""
        return self.strategy in ("hybrid", "hybrid-nocal", "sensor")

    @property
    def uses_model(self) -> bool:
        """Whether the strategy ever follows the computed sun."""
        return self.strategy != "sensor"

    @property
    def calibrates(self) -> bool:
        """Whether the model is corrected from the sensor."""
        return self.strategy == "hybrid"

    def minutes(self, name: str) -> float:
        """A duration field in minutes."""
        return pd.Timedelta(getattr(self, name)) / pd.Timedelta(minutes=1)


class FastKalman:
    """Constant-rate Kalman filter on (angle, rate) in plain floats; matches `FilterpyKalman`."""

    def __init__(self, q: float, r: float):
        self.q, self.r = q, r
        self.x0 = self.x1 = 0.0
        self.p00, self.p01, self.p11 = 1.0, 0.0, 0.1

    def reset(self, angle: float, rate: float) -> None:
        """Start again at `angle` (degrees) moving at `rate` (degrees per minute)."""
        self.x0, self.x1 = angle, rate
        self.p00, self.p01, self.p11 = 1.0, 0.0, 0.1

    def predict(self, dt: float) -> None:
        """Advance the state `dt` minutes (white-noise acceleration model)."""
        q = self.q
        self.x0 += dt * self.x1
        p00, p01, p11 = self.p00, self.p01, self.p11
        self.p00 = p00 + 2.0 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0
        self.p01 = p01 + dt * p11 + q * dt * dt / 2.0
        self.p11 = p11 + q * dt

    def innovation(self, z: float) -> tuple[float, float]:
        """The residual of a measurement `z` and its variance."""
        return z - self.x0, self.p00 + self.r

    def update(self, z: float) -> None:
        """Take in a measurement of the angle, degrees."""
        y, s = z - self.x0, self.p00 + self.r
        k0, k1 = self.p00 / s, self.p01 / s
        self.x0 += k0 * y
        self.x1 += k1 * y
        p00, p01, p11 = self.p00, self.p01, self.p11
        self.p00 = (1.0 - k0) * p00
        self.p01 = (1.0 - k0) * p01
        self.p11 = p11 - k1 * p01

    @property
    def angle(self) -> float:
        """Filtered angle, degrees."""
        return self.x0

    @property
    def rate(self) -> float:
        """Filtered rate, degrees per minute."""
        return self.x1


class FilterpyKalman:
    """The same filter through filterpy's ``KalmanFilter`` (the reference)."""

    def __init__(self, q: float, r: float):
        from filterpy.kalman import KalmanFilter

        self.q = q
        self.kf = KalmanFilter(dim_x=2, dim_z=1)
        self.kf.H = np.array([[1.0, 0.0]])
        self.kf.R = np.array([[r]])
        self.reset(0.0, 0.0)

    def reset(self, angle: float, rate: float) -> None:
        """Start again at `angle` (degrees) moving at `rate` (degrees per minute)."""
        self.kf.x = np.array([[angle], [rate]])
        self.kf.P = np.array([[1.0, 0.0], [0.0, 0.1]])

    def predict(self, dt: float) -> None:
        """Advance the state `dt` minutes (white-noise acceleration model)."""
        q = self.q
        self.kf.F = np.array([[1.0, dt], [0.0, 1.0]])
        self.kf.Q = q * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
        self.kf.predict()

    def innovation(self, z: float) -> tuple[float, float]:
        """The residual of a measurement `z` and its variance."""
        return z - float(self.kf.x[0, 0]), float(self.kf.P[0, 0] + self.kf.R[0, 0])

    def update(self, z: float) -> None:
        """Take in a measurement of the angle, degrees."""
        self.kf.update(np.array([[z]]))

    @property
    def angle(self) -> float:
        """Filtered angle, degrees."""
        return float(self.kf.x[0, 0])

    @property
    def rate(self) -> float:
        """Filtered rate, degrees per minute."""
        return float(self.kf.x[1, 0])


@dataclass
class ControllerInputs:
    """Everything the loop reads, per step, as flat arrays of length N (axes as columns).

    `model` is the controller's computed target per axis (its clock, site and sun model;
    NaN when its sun is down); `truth` the true target per axis, used only to simulate
    what the sensor sees. `awake` is the controller's own working-hours-and-sun-up flag.
    """

    minutes: np.ndarray
    awake: np.ndarray
    wind: np.ndarray
    sky: np.ndarray  # codes into SKY_CODES
    dni: np.ndarray
    model: np.ndarray  # (N, axes)
    truth: np.ndarray  # (N, axes)
    noise: np.ndarray  # (N, axes) standard normal draws for the sensor
    sensor_fault: np.ndarray | None = None  # (N, axes): NaN none, else the reading the sensor gives
    sensor_dropout: np.ndarray | None = None  # (N,) bool: the sensor gives no reading at all
    sensor_drift: np.ndarray | None = None  # (N,) degrees added to every sensor reading
    clock_step: np.ndarray | None = None  # (N,) seconds the controller clock jumped at this scan (detected)
    encoder_fault: np.ndarray | None = None  # (N, axes): added to the reading (a wild count)
    encoder_frozen: np.ndarray | None = None  # (N,) bool: the encoder repeats its last reading


@dataclass
class ControllerOutputs:
    """Per step: mode, sensor status, and per axis the command, the true angle and the reading."""

    mode: np.ndarray
    sensor_status: np.ndarray
    target: np.ndarray
    angle: np.ndarray
    reading: np.ndarray
    calibration: np.ndarray
    moves: np.ndarray  # per axis
    travel: np.ndarray  # per axis, degrees
    events: list  # (step, from mode, to mode, reason)


def run_controller(inputs: ControllerInputs, config: ControllerConfig, drives, *, encoder_offset: float,
                   sensor_bias: float, sensor_noise: float, field_of_view: float, direct_threshold: float,
                   bulk_nights: bool = True, progress=None) -> ControllerOutputs:
    """Step the controller through time; the only sequential part of a simulation.

    With `bulk_nights`, a stretch of steps in which the controller sleeps at stow with no gust
    and no injected fault is filled in one go instead of step by step; the result is the same
    (a test keeps it so), only faster. `progress`, if given, is called now and then with the
    number of steps done since its last call.
    """
    n, axes = inputs.model.shape
    make = FilterpyKalman if config.kalman == "filterpy" else FastKalman
    resolution = [d.resolution for d in drives]
    filters = [make(config.process_noise, sensor_noise**2 + r * r / 12.0 + 1e-6) for r in resolution]
    dwell, hold = config.minutes("dwell"), config.minutes("wind_hold")
    loss, tau = config.minutes("sensor_loss"), config.minutes("calibration_tau")
    gate2 = config.gate**2
    stow = [d.stow for d in drives]
    circular = [d.limits[1] - d.limits[0] >= 360.0 for d in drives]  # an axis that turns all the way round

    def turn(a: int, difference: float) -> float:
        """A difference of angles on axis `a`: the short way round on a circular axis."""
        return (difference + 180.0) % 360.0 - 180.0 if circular[a] else difference

    low = [d.limits[0] for d in drives]
    high = [d.limits[1] for d in drives]
    actual = [stow[a] - encoder_offset for a in range(axes)]  # parked where the controller believes stow is
    last_reading = [math.nan] * axes
    calibration = [0.0] * axes
    calibrated = [0.0] * axes  # minutes of readings the calibration has averaged
    filter_ready = [False] * axes
    rejected = [0] * axes  # gated readings in a row
    last_measured = [math.nan] * axes
    repeats = [0] * axes  # identical sensor readings in a row
    commanded = [0.0] * axes  # the move commanded at the last scan
    believed = [math.nan] * axes  # the reading the controller uses
    jumped = [0] * axes  # scans a jumped encoder reading has persisted
    limit = config.sensor_plausibility
    mode, mode_since = STOW_NIGHT, -math.inf
    calm_since = -math.inf
    invalid_since = math.nan
    uses_sensor, uses_model, calibrates = config.uses_sensor, config.uses_model, config.calibrates
    lead = config.lead
    half_band = [d.deadband / 2.0 for d in drives]
    sensor_only = config.strategy == "sensor"
    wind_stow, wind_release = config.wind_stow, config.wind_release

    minutes = inputs.minutes.tolist()
    awake = inputs.awake.tolist()
    wind = inputs.wind.tolist()
    sky = inputs.sky.tolist()
    dni = inputs.dni.tolist()
    model = [inputs.model[:, a].tolist() for a in range(axes)]
    truth = [inputs.truth[:, a].tolist() for a in range(axes)]
    noise = [inputs.noise[:, a].tolist() for a in range(axes)]
    sensor_fault = [inputs.sensor_fault[:, a].tolist() for a in range(axes)] if inputs.sensor_fault is not None else None
    encoder_fault = [inputs.encoder_fault[:, a].tolist() for a in range(axes)] \
        if inputs.encoder_fault is not None else None
    frozen = inputs.encoder_frozen.tolist() if inputs.encoder_frozen is not None else None
    dropout = inputs.sensor_dropout.tolist() if inputs.sensor_dropout is not None else None
    drift = inputs.sensor_drift.tolist() if inputs.sensor_drift is not None else None
    clock_step = inputs.clock_step.tolist() if inputs.clock_step is not None else None

    # where each sleeping stretch ends, and whether a gust falls in it
    asleep = ~np.asarray(inputs.awake, bool)
    next_wake = np.full(n + 1, n, np.int64)
    wake_at = np.flatnonzero(~asleep)
    if n:
        next_wake[:n] = wake_at[np.minimum(np.searchsorted(wake_at, np.arange(n)), len(wake_at) - 1)] \
            if len(wake_at) else n
        next_wake[:n] = np.where(np.arange(n) > (wake_at[-1] if len(wake_at) else -1), n, next_wake[:n])
    gusts = np.concatenate([[0], np.cumsum(~(np.asarray(inputs.wind, float) <= wind_stow))])
    can_skip = bulk_nights and encoder_fault is None and frozen is None and clock_step is None
    next_wake, gusts = next_wake.tolist(), gusts.tolist()

    out_mode: list = []
    out_status: list = []
    out_target = [[] for _ in range(axes)]
    out_angle = [[] for _ in range(axes)]
    out_reading = [[] for _ in range(axes)]
    out_cal = [[] for _ in range(axes)]
    moves = [0] * axes
    travel = [0.0] * axes
    events: list = []
    resting = False  # asleep at stow: nothing to do until the controller wakes

    def switch(i: int, new: int, reason: str) -> None:
        nonlocal mode, mode_since
        events.append((i, MODES[mode], MODES[new], reason))
        log.debug("step %d: %s -> %s (%s)", i, MODES[mode], MODES[new], reason)
        mode, mode_since = new, minutes[i]

    def alarm(i: int, reason: str) -> None:
        events.append((i, MODES[mode], MODES[mode], reason))
        log.info("step %d: %s", i, reason)

    i = 0
    reported = 0
    previous_t = minutes[0] if n else 0.0
    while i < n:
        if progress is not None and i - reported >= 8192:
            progress(i - reported)
            reported = i
        t = minutes[i]
        dt = t - previous_t if i else 1.0
        previous_t = t
        # -- asleep at stow: fill the whole night at once ------------------------------------
        if resting and not awake[i]:
            j = next_wake[i] if can_skip else i + 1
            if j > i + 1 and gusts[j] - gusts[i] == 0:
                count = j - i
                out_mode.extend([STOW_NIGHT] * count)
                out_status.extend([NOT_READ] * count)
                for a in range(axes):
                    out_target[a].extend([stow[a]] * count)
                    out_angle[a].extend([actual[a]] * count)
                    out_reading[a].extend([last_reading[a]] * count)
                    out_cal[a].extend([calibration[a]] * count)
                previous_t = minutes[j - 1]
                i = j
                continue
        # -- what the encoder says, and whether to believe it ---------------------------------
        if clock_step is not None and clock_step[i]:
            alarm(i, f"controller clock stepped by {clock_step[i]:+.0f} s against the scan timer; clock re-based")
        reading = []
        for a in range(axes):
            if frozen is not None and frozen[i] and not math.isnan(last_reading[a]):
                value = last_reading[a]
            else:
                value = encoder_reading(actual[a] + encoder_offset, resolution[a])
                if encoder_fault is not None:
                    value += encoder_fault[a][i]
            previous = last_reading[a]
            last_reading[a] = value
            if math.isnan(believed[a]) or mode == FAULT:
                believed[a] = value
                reading.append(value)
                continue
            expected = believed[a] + commanded[a]
            tolerance = 2.0 * resolution[a] + 1e-9
            if commanded[a] and abs(value - previous) < 0.5 * resolution[a] \
                    and abs(commanded[a]) > tolerance and mode != FAULT:
                switch(i, FAULT, f"encoder frozen: commanded {commanded[a]:+.2f}°, reading unchanged; drive halted")
                believed[a] = value
            elif abs(value - expected) > tolerance:
                jumped[a] += 1
                if jumped[a] >= config.encoder_confirm:
                    alarm(i, f"encoder reading {value:.3f}° held for {jumped[a]} scans; believed")
                    believed[a] = value
                    jumped[a] = 0
                else:
                    if jumped[a] == 1:
                        alarm(i, f"encoder glitch: read {value:.3f}°, expected {expected:.3f}°; ignored")
                    believed[a] = expected
            else:
                jumped[a] = 0
                believed[a] = value
            reading.append(believed[a])
        w = wind[i]
        gusty = not (w <= wind_stow)  # NaN counts as gusty: the safe reading
        if resting and not awake[i] and not gusty:
            out_mode.append(STOW_NIGHT)
            out_status.append(NOT_READ)
            for a in range(axes):
                out_target[a].append(stow[a])
                out_angle[a].append(actual[a])
                out_reading[a].append(reading[a])
                out_cal[a].append(calibration[a])
            i += 1
            continue
        # -- wind -----------------------------------------------------------------------------
        if gusty:
            calm_since = math.inf
            if mode != STOW_WIND and mode != FAULT:
                switch(i, STOW_WIND, "wind reading invalid" if math.isnan(w) else f"wind {w:.1f} m/s > {wind_stow}")
        elif w <= wind_release:
            if calm_since == math.inf or calm_since == -math.inf:
                calm_since = t
        else:
            calm_since = math.inf
        if mode == STOW_WIND and not gusty and calm_since != math.inf and t - calm_since >= hold:
            switch(i, ASTRONOMICAL if uses_model else SENSOR,
                   f"wind at or below {wind_release} m/s for {config.wind_hold}")
        # -- day cycle ------------------------------------------------------------------------
        if mode == FAULT:
            if awake[i] and i and not awake[i - 1]:
                switch(i, ASTRONOMICAL if uses_model else SENSOR, "a new day: probing the encoder again")
        elif mode != STOW_WIND:
            if not awake[i]:
                if mode != STOW_NIGHT:
                    switch(i, STOW_NIGHT, "outside working hours or sun down")
            elif mode == STOW_NIGHT:
                switch(i, ASTRONOMICAL if uses_model else SENSOR, "awake and sun up")
        # -- the sensor -----------------------------------------------------------------------
        status = NOT_READ
        valid = [False] * axes
        if uses_sensor and awake[i] and mode != STOW_WIND and mode != FAULT:
            status = OK
            for a in range(axes):
                offset = turn(a, truth[a][i] - actual[a])
                fault = sensor_fault[a][i] if sensor_fault is not None else math.nan
                measured = fault if not math.isnan(fault) else offset + sensor_bias + sensor_noise * noise[a][i]
                if drift is not None:
                    measured += drift[i]
                if dropout is not None and dropout[i]:
                    measured = math.nan
                if measured == last_measured[a]:
                    repeats[a] += 1
                else:
                    repeats[a] = 0
                last_measured[a] = measured
                if repeats[a] >= config.stuck_scans - 1:
                    status = status if status != OK else STUCK
                    continue
                if not dni[i] >= direct_threshold:
                    status = status if status != OK else LOW_LIGHT
                    continue
                if not abs(offset) <= field_of_view:
                    status = status if status != OK else OUT_OF_VIEW
                    continue
                if math.isnan(measured) or abs(measured) > 90.0:
                    status = status if status != OK else INVALID
                    continue
                z = reading[a] + measured
                m0 = model[a][i]
                # in pointing terms: a heliostat's azimuth axis turns 1/cos(elevation) times faster
                bound = limit / max(math.cos(math.radians(model[1][i])), 0.05) if axes == 2 and a == 0 else limit
                if uses_model and not math.isnan(m0) and abs(turn(a, z - m0)) > bound:
                    status = status if status != OK else IMPLAUSIBLE
                    continue
                kf = filters[a]
                if not filter_ready[a]:
                    m1 = model[a][i - 1] if i else math.nan
                    rate = turn(a, m0 - m1) / dt if uses_model and dt > 0 and not math.isnan(m0 - m1) else 0.0
                    kf.reset(z, rate)
                    filter_ready[a] = True
                    valid[a] = True
                    continue
                kf.predict(dt)
                y, s = kf.innovation(z)
                if y * y > gate2 * s:
                    rejected[a] += 1
                    if rejected[a] < config.reacquire:
                        status = status if status != OK else OUTLIER
                        continue
                    log.debug("step %d: axis %d filter restarted after %d rejected readings", i, a, rejected[a])
                    kf.reset(z, kf.rate)
                else:
                    kf.update(z)
                rejected[a] = 0
                valid[a] = True
                m1 = model[a][i - 1] if i else math.nan
                steady = abs(turn(a, m0 - m1)) <= config.calibration_max_rate * dt
                if calibrates and steady:
                    # a running mean of the first readings, then forgetting with time constant tau
                    calibrated[a] += dt
                    alpha = max(1.0 - math.exp(-dt / tau), dt / calibrated[a] if calibrated[a] < tau else 0.0)
                    calibration[a] += alpha * turn(a, kf.angle - m0 - calibration[a])
                    calibration[a] = max(-bound, min(bound, calibration[a]))
            for a in range(axes):
                if filter_ready[a] and not valid[a]:
                    filters[a].predict(dt)  # no update: the filter coasts
        sensor_ok = uses_sensor and all(valid)
        if sensor_ok:
            invalid_since = math.nan
        elif math.isnan(invalid_since):
            invalid_since = t
        # -- strategy -------------------------------------------------------------------------
        if mode in (ASTRONOMICAL, SENSOR, SEARCH):
            if sensor_only:
                if mode == SEARCH and sensor_ok:
                    switch(i, SENSOR, "sun back in view")
                elif mode == SENSOR and status == OUT_OF_VIEW:
                    switch(i, SEARCH, "sun out of the sensor's view")
            else:
                want_sensor = uses_sensor and sky[i] == 0
                faulty = status in (STUCK, IMPLAUSIBLE, INVALID)  # judged wrong, not merely clouded
                if mode == SENSOR and not sensor_ok and (faulty or t - invalid_since >= loss):
                    switch(i, ASTRONOMICAL, f"sensor lost ({SENSOR_STATUS[status]})")
                elif mode == SENSOR and not want_sensor and t - mode_since >= dwell:
                    switch(i, ASTRONOMICAL, f"sky {SKY_CODES[sky[i]]}")
                elif mode == ASTRONOMICAL and want_sensor and sensor_ok and t - mode_since >= dwell:
                    switch(i, SENSOR, "sky sunny and sensor valid")
        # -- targets and the drive ------------------------------------------------------------
        stowing = mode == STOW_NIGHT or mode == STOW_WIND
        resting = mode == STOW_NIGHT and not awake[i]
        for a in range(axes):
            drive = drives[a]
            speed = drive.speed
            commanded[a] = 0.0
            if mode == FAULT:  # position unknown: never move
                out_target[a].append(reading[a])
                out_angle[a].append(actual[a])
                out_reading[a].append(reading[a])
                out_cal[a].append(calibration[a])
                continue
            if stowing:
                target = stow[a]  # in encoder terms: the controller does not know its encoder's offset
                speed = drive.stow_speed
            elif mode == SENSOR:
                if filter_ready[a] and (valid[a] or not sensor_only):
                    target = filters[a].angle
                    if lead:
                        target += math.copysign(half_band[a], filters[a].rate)
                else:
                    target = reading[a]
            elif mode == SEARCH:
                target = reading[a] + math.copysign(config.search_speed * dt, turn(a, truth[a][i] - actual[a]))
            else:
                m = model[a][i]
                target = (m + calibration[a]) if not math.isnan(m) else stow[a]
                if lead and i and not math.isnan(m):
                    previous = model[a][i - 1]
                    if not math.isnan(previous) and m != previous:
                        target += math.copysign(half_band[a], turn(a, m - previous))
                if circular[a]:  # the nearest way to the same direction, within the limits
                    target = reading[a] + turn(a, target - reading[a])
                    if not low[a] <= target <= high[a]:
                        target += 360.0 if target < low[a] else -360.0
            target = min(max(target, low[a]), high[a])
            error = target - reading[a]
            held = mode == STOW_WIND and abs(reading[a] - stow[a]) <= drive.deadband  # stowed: never move
            threshold = resolution[a] if stowing or mode == SEARCH else drive.deadband
            if not held and abs(error) > threshold:
                step = max(-speed * dt, min(speed * dt, error))
                new = min(max(actual[a] + step, low[a]), high[a])
                commanded[a] = new - actual[a]
                travel[a] += abs(new - actual[a])
                moves[a] += 1
                actual[a] = new
                resting = False
            out_target[a].append(target)
            out_angle[a].append(actual[a])
            out_reading[a].append(reading[a])
            out_cal[a].append(calibration[a])
        out_mode.append(mode)
        out_status.append(status)
        if mode == STOW_NIGHT:
            filter_ready = [False] * axes
        i += 1

    if progress is not None and n > reported:
        progress(n - reported)

    def columns(per_axis):
        return np.array(per_axis, float).T.reshape(n, axes)

    return ControllerOutputs(np.array(out_mode, np.int8), np.array(out_status, np.int8), columns(out_target),
                             columns(out_angle), columns(out_reading), columns(out_cal), np.array(moves),
                             np.array(travel), events)
