"""What the controller is told: its strategy and the datasheet constants of its own parts."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from ..params import duration, number, whole

__all__ = ["ControllerConfig", "STRATEGIES"]

#: The tracking policies. The last two are references that measure the classifier:
#: ``hybrid-always`` trusts the sensor whenever it reads valid, ``hybrid-oracle`` knows the true sky.
STRATEGIES = ("hybrid", "hybrid-nocal", "astronomical", "astronomical-commissioned", "sensor",
              "hybrid-always", "hybrid-oracle")


#: (field, low, high, low excluded): m/s, degrees, deg²/min³, standard deviations, degrees per
#: minute, mA. A sensor's noise is at least 1e-4° (0.36″, a thousandth of the < 0.1° accuracy of
#: commercial fine sun sensors): the mount fit weighs a reading by its square, and 1e-200°
#: underflowed it to zero (LAPACK's SVD then failed mid-run).
_RANGES = (("wind_stow", 0, 60, True), ("wind_release", 0, 60, True), ("min_altitude", -10, 30, False),
           ("process_noise", 0, 10, True), ("gate", 0, 100, True), ("calibration_max_rate", 0, 100, True),
           ("sensor_plausibility", 0, 45, True), ("sensor_noise", 1e-4, 5, False), ("dusk_current", 0, 1000, True),
           ("disagreement", 0, 45, True), ("pull_gain", 0, 100, False))


def _check_working_hours(hours) -> None:
    """Refuse working hours that are not a start and a later end on the same day (there is no
    overnight shift: the controller works by day)."""
    from ..times import parse_clock

    if len(hours) != 2:
        raise HybridtrackError("controller: working_hours needs a start and an end")
    start, end = (parse_clock(clock) for clock in hours)
    if not start < end:
        raise HybridtrackError(f"controller: working_hours {list(hours)} must end after they start on the same day "
                               "(a controller works by day; there is no overnight shift)")


@dataclass(frozen=True)
class ControllerConfig:
    """How the controller behaves, and what it knows of its own parts.

    Parameters
    ----------
    strategy : str
        One of `STRATEGIES`. ``hybrid``: sensor under a sky the fuzzy classifier calls sunny,
        computed sun otherwise, calibrated from the sensor; ``hybrid-nocal``: the same without
        calibration; ``hybrid-always``: the sensor whenever it reads valid (no classifier);
        ``hybrid-oracle``: the sensor whenever the *true* sky is sunny (a reference, needs the
        frame's ``sky`` column); ``astronomical``: open loop as installed;
        ``astronomical-commissioned``: open loop after a one-time commissioning fit of the
        mounting from a clear day of sensor readings; ``sensor``: closed loop only, as sold.
    sun_model : {"plc", "spa"}
        The controller's sun model.
    refraction : bool
        Whether the controller points at the sun as it appears, its model's altitude raised by
        atmospheric refraction (`hybridtrack.sun.refraction`, SPA's formula at the site's
        pressure and 12 °C), as a tracker built on SPA does; False for a controller whose sun
        model leaves it out (the published PLC model is geometric), which points below the true
        sun near the horizon: at sea level 0.28° at 2°, 0.09° at 10°, 0.02° at 45° (Meeus 1998,
        ch. 16; docs/world.md, "Refraction").
    dwell : str
        Minimum time between switches of sensor and astronomical mode.
    wind_stow, wind_release : float
        m/s: stow above `wind_stow`; resume once at or below `wind_release` for `wind_hold`.
    wind_hold : str
    wind_missing : {"stow", "track"}
        What a missing anemometer reading means. ``stow`` (the default, a live controller's
        safe choice) treats it as a gust; ``track`` goes on tracking, for replaying a recorded
        file that has no wind at all (``hybridtrack replay`` chooses it then, and says so). In
        both cases the run reports the wind as missing, never as calm.
    working_hours : tuple of str
        Local clock times the controller may work between, the end included: an optional limit
        on a day that the computed sun sets. The default spans the whole day, to ``24:00`` (the
        day's end).
    min_altitude : float
        Degrees: the computed sun must be above this to track.
    calibration_tau : str
        Time constant of the continuous calibration.
    sensor_loss : str
        How long an invalid sensor is tolerated in sensor mode.
    process_noise : float
        Kalman white-noise acceleration intensity, deg²/min³.
    gate : float
        Innovation gate, in standard deviations. After `reacquire` readings in a row fail it,
        the filter restarts from the latest reading.
    reacquire : int
    sensor_plausibility : float
        Degrees: a sensor reading further from the (calibrated) model is implausible.
    stuck_scans : int
        Scans over which a sun angle from the sensor that stays within a third of its datasheet
        noise (`sensor_noise`), while the sun moved ten times that, marks the sensor stuck.
    encoder_confirm : int
        Scans a jumped encoder reading must persist before it is believed.
    calibration_max_rate : float
        Degrees per minute: calibration learns only while the model's target moves no faster.
    coast : str
        Sensor-only strategy: how long to keep moving at the filtered rate through a gap in
        the sensor's signal before holding still. Passing clouds last minutes to tens of minutes;
        commercial trackers' cloud modes coast through such spells and hold under overcast.
    dusk_current : float
        mA: the sensor-only tracker sleeps once its photocurrent has stayed below this for
        30 minutes, and wakes when it rises above it (5 mA over the 30 mA dark current, about
        20 W/m² of light: civil twilight).
    lead : bool
        Aim ahead of the sun by its rate times half the expected time to the next move, at most
        half the deadband (`hybridtrack.control.controller._lead`), so the intermittent drive's
        sawtooth is centred on the sun. ``False`` is the published field practice (aim at it).
    sensor_noise : float
        Degrees, 1σ: the sensor's datasheet accuracy at full sun, the Kalman filter's R. The
        default is half the < 0.1° accuracy quoted for commercial fine sun sensors.
    disagreement : float
        Degrees: a persistent residual between the sensor and the calibrated model at least this
        large is a sensor (or mount) fault; a smaller one is the model's own misfit. Half the
        0.5° whole-system error that trough fields are built to.
    on_disagreement : {"model", "sensor"}
        Whom to trust when they disagree so. ``model`` (default): the sensor is suspect (a bias,
        a drift, a knock to its bracket); the calibration goes back to the checkpoint taken while
        the two agreed and the sensor is not trusted for `distrust`, then judged again. ``sensor``:
        the mount is suspect (a shifted pedestal, a slipped coupling); the calibration keeps what
        it learned and the sensor stays trusted. Either way the alarm is logged with its size.
        ``model`` is the safe default: a sensor fault is the likelier one, and with ``sensor``
        a biased sensor drags the calibration with it.
    distrust : str
        How long a sensor judged against the model is not trusted (``on_disagreement = "model"``):
        an hour, long enough for the sun to move about 15° and show a bias again from another angle.
    pull_gain : float
        Degrees: how far a reading in a clear gap may be pulled toward the cloud light near the
        sun, per unit of light above the clear sky's level, at the zenith (1/sin of the sun's
        altitude lower down). The mount fit weighs each reading by it
        (`hybridtrack.control.mountfit.pull_spread`, which derives the default from the
        circumsolar share of cloud light and a cloud edge's distance); 0 weighs every reading by
        the sensor's noise alone.
    kalman : {"fast", "filterpy"}
        ``filterpy`` runs filterpy's KalmanFilter, the reference; ``fast`` the same
        equations in plain floats (a test keeps them equal).
    """

    strategy: str = "hybrid"
    sun_model: str = "plc"
    refraction: bool = True
    dwell: str = "5min"
    wind_stow: float = 17.2
    wind_release: float = 12.0
    wind_hold: str = "10min"
    wind_missing: str = "stow"
    working_hours: tuple[str, str] = ("00:00", "24:00")
    min_altitude: float = 0.0
    calibration_tau: str = "30min"
    sensor_loss: str = "3min"
    process_noise: float = 1e-3
    gate: float = 4.0
    reacquire: int = 3
    calibration_max_rate: float = 1.0
    sensor_plausibility: float = 2.0
    stuck_scans: int = 4
    encoder_confirm: int = 3
    coast: str = "30min"
    dusk_current: float = 35.0
    lead: bool = True
    sensor_noise: float = 0.05
    disagreement: float = 0.25
    on_disagreement: str = "model"
    distrust: str = "60min"
    kalman: str = "fast"
    pull_gain: float = 1.4

    def __post_init__(self) -> None:
        object.__setattr__(self, "working_hours", tuple(self.working_hours))
        if self.strategy not in STRATEGIES:
            raise HybridtrackError(f"unknown strategy {self.strategy!r}; choose from {', '.join(STRATEGIES)}")
        if self.sun_model not in ("plc", "spa"):
            raise HybridtrackError(f"unknown sun model {self.sun_model!r}; choose 'plc' or 'spa'")
        for name in ("refraction", "lead"):  # "no" had been taken as True; numpy's booleans are taken, as bools
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise HybridtrackError(f"controller: {name} must be true or false, got {getattr(self, name)!r:.40}")
            object.__setattr__(self, name, bool(getattr(self, name)))
        if self.wind_missing not in ("stow", "track"):
            raise HybridtrackError(f"controller: wind_missing {self.wind_missing!r}; choose 'stow' or 'track'")
        if self.kalman not in ("fast", "filterpy"):
            raise HybridtrackError(f"unknown Kalman engine {self.kalman!r}; choose 'fast' or 'filterpy'")
        if self.on_disagreement not in ("model", "sensor"):
            raise HybridtrackError(f"controller: on_disagreement {self.on_disagreement!r}; choose 'model' or 'sensor'")
        for name in ("dwell", "wind_hold", "calibration_tau", "sensor_loss", "coast", "distrust"):
            duration(getattr(self, name), f"controller: {name}")
        for name, low, high, above in _RANGES:
            number(getattr(self, name), f"controller: {name}", low, high, above=above)
        if not self.wind_release <= self.wind_stow:
            raise HybridtrackError(f"controller: wind_release {self.wind_release} must be at most "
                                   f"wind_stow {self.wind_stow}")
        _check_working_hours(self.working_hours)
        for name, least in (("reacquire", 1), ("stuck_scans", 3), ("encoder_confirm", 1)):
            whole(getattr(self, name), f"controller: {name}", least, 10_000)
        if not self.disagreement <= self.sensor_plausibility:
            raise HybridtrackError(f"controller: disagreement {self.disagreement} must be at most "
                                   f"sensor_plausibility {self.sensor_plausibility}")

    @property
    def uses_sensor(self) -> bool:
        """Whether the strategy ever tracks the sensor."""
        return self.strategy not in ("astronomical", "astronomical-commissioned")

    @property
    def uses_model(self) -> bool:
        """Whether the strategy ever follows the computed sun."""
        return self.strategy != "sensor"

    @property
    def calibrates(self) -> bool:
        """Whether the model is corrected from the sensor while it runs."""
        return self.strategy in ("hybrid", "hybrid-always", "hybrid-oracle")

    @property
    def sensor_only(self) -> bool:
        """The closed-loop-only strategy, with its acquisition, coasting and parking."""
        return self.strategy == "sensor"

    def minutes(self, name: str) -> float:
        """A duration field in minutes."""
        return pd.Timedelta(getattr(self, name)) / pd.Timedelta(minutes=1)
