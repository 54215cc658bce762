"""The clock against the sun the sensor shows: a drift on any collector, an error where it can be seen."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack import sites
from hybridtrack.collectors import Collector
from hybridtrack.control.mountfit import jacobian
from hybridtrack.control.plan import MountEstimate
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.sky import synthetic
from hybridtrack.sun import solar_position
from hybridtrack.world import Imperfections

#: Seconds of clock error a degree of site longitude makes (the sun's 15° an hour).
SECONDS_PER_DEGREE = 240.0


def _run(site, start, end, collector, weather="sunny", seed=1, **imperfections):
    frame = synthetic(site, start, end, weather=weather, seed=seed)
    config = SimulationConfig(imperfections=Imperfections(**imperfections), seed=seed)
    return simulate(frame, site, collector=collector, config=config)


def _clock_alarms(result):
    return [r for r in result.events["reason"] if "against the sun the sensor shows" in r]


def test_a_clock_gaining_a_minute_a_day_is_alarmed_with_its_drift_on_a_trough():
    result = _run("lanzhou", "2021-06-21", "2021-06-23", "trough-ns", clock_drift=60.0, clock_error=0.0,
                  commissioned_days_ago=0.0)
    assert any("clock drifting" in r for r in _clock_alarms(result))
    clock = result.summary["clock"]
    assert clock["drift_s_per_day"] == pytest.approx(60.0, abs=6.0)  # within 10 % of the world's drift
    assert clock["drift_s_per_day"] == pytest.approx(60.0, abs=4 * clock["drift_std_s_per_day"])


@pytest.mark.xfail(strict=True, reason="one day tells a 5-min clock from the sensor's collimation error at 3.8σ, "
                                       "not 4σ: 303 ± 80 s (truth 302 s); the next test alarms it in two days")
def test_a_heliostat_shows_a_clock_set_five_minutes_wrong_in_one_sunny_day():
    """Before the sensor read in its own frame and the mount had a collimation term, 352 ± 66 s
    (5.3σ). A bias across the mirror's face is bias / cos(e) of azimuth, and over one day cos(e)
    moves with the sun's azimuth rate enough to leave the clock's 1σ a fifth wider (80 s), so the
    estimate, nearer the truth than it was, is 3.8σ from zero and not alarmed until a second day."""
    imperfections = Imperfections(clock_error=300.0, clock_drift=0.0)
    result = _run("delingha", "2018-06-21", "2018-06-21", "heliostat", clock_error=300.0, clock_drift=0.0)
    truth = imperfections.clock_error + imperfections.longitude_error * SECONDS_PER_DEGREE
    assert any("clock off by" in r for r in _clock_alarms(result))
    clock = result.summary["clock"]
    assert clock["error_s"] == pytest.approx(truth, abs=4 * clock["error_std_s"])


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_heliostat_shows_a_clock_set_five_minutes_wrong_in_two_sunny_days(seed):
    """The collimation term's price: a second day. Measured 312-376 s, 1σ 59-82 s, truth 302 s."""
    imperfections = Imperfections(clock_error=300.0, clock_drift=0.0)
    result = _run("delingha", "2018-06-21", "2018-06-22", "heliostat", seed=seed, clock_error=300.0, clock_drift=0.0)
    truth = imperfections.clock_error + imperfections.longitude_error * SECONDS_PER_DEGREE
    assert any("clock off by" in r for r in _clock_alarms(result))
    clock = result.summary["clock"]
    assert clock["error_s"] == pytest.approx(truth, abs=4 * clock["error_std_s"])


def test_a_troughs_sensor_cannot_tell_a_clock_error_from_its_mount():
    """A clock error turns the sky about the polar axis: for a north-south trough, to first order an
    encoder zero of ω·τ·cos(latitude) and an axis azimuth error of ω·τ·sin(latitude) in size. Only
    the refraction of a low sun, which does not turn with the sky, tells them apart a little: a
    day's 1σ of 266 s (the prior's 600 s; 373 s with the geometric sun as the truth), so no
    alarm, and a minute's error is not told."""
    site, collector, tau = sites.get("lanzhou"), Collector("trough-ns"), 60.0
    index = pd.date_range("2021-06-21 07:00", "2021-06-21 19:00", freq="10min", tz=site.tz)
    sun, later = (solar_position(index + pd.Timedelta(seconds=s), site, "spa") for s in (0.0, tau))
    nominal = MountEstimate()
    shift = (nominal.targets(later["altitude"], later["azimuth"], collector)
             - nominal.targets(sun["altitude"], sun["azimuth"], collector))[:, 0]
    rows = jacobian(sun["altitude"].to_numpy(), sun["azimuth"].to_numpy(), collector)[:, 0, :]
    fit, *_ = np.linalg.lstsq(rows, shift, rcond=None)
    turn = 15.0 * tau / 3600.0
    assert np.abs(rows @ fit - shift).max() < 0.01 * np.abs(shift).max()  # the mount mimics the clock
    latitude = np.radians(site.latitude)
    assert abs(fit[0]) == pytest.approx(turn * np.sin(latitude), rel=0.05)  # axis azimuth error
    assert abs(fit[2]) == pytest.approx(turn * np.cos(latitude), rel=0.05)  # encoder zero
    result = _run("lanzhou", "2021-06-21", "2021-06-21", "trough-ns", clock_error=60.0, clock_drift=0.0)
    assert not _clock_alarms(result)
    assert result.summary["clock"]["error_std_s"] > 200.0  # 4σ is over 13 minutes: a minute's error is not told


@pytest.mark.parametrize("collector,site,start,end", [("trough-ns", "nanjing", "2013-06-21", "2013-06-23"),
                                                      ("fresnel", "lanzhou", "2021-12-21", "2021-12-23"),
                                                      ("heliostat", "delingha", "2018-06-21", "2018-06-23")])
@pytest.mark.parametrize("weather", ["sunny", "mixed"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_no_clock_alarm_on_a_healthy_clock(collector, site, start, end, weather, seed):
    """Default imperfections: a clock 15 s behind and gaining a second a day, as a PLC's does."""
    result = _run(site, start, end, collector, weather=weather, seed=seed)
    assert not _clock_alarms(result)


def test_a_parameter_the_readings_cannot_tell_keeps_its_priors_one_sigma():
    """Readings with no rate say nothing of the clock: its 1σ is the prior's 600 s, however
    scattered the readings are. Scaling the whole covariance by the scatter (here about 100 times
    the datasheet variance) had reported it at 600 s times that scatter's root; a trough's
    streamed year had said 1,884 s. The mount's offset, which the readings do tell, takes the
    scatter: by hand, the residuals' standard deviation over the root of their count."""
    from hybridtrack.control.clockwatch import PRIOR, ClockWatch

    watch = ClockWatch(1, 0.05)
    residuals = 0.5 * np.random.default_rng(1).standard_normal(40)
    for k, residual in enumerate(residuals):
        watch.add(5.0 * k, 0, [1.0], 0.0, residual, 1.0)  # rate 0: a clock error moves nothing
    estimate, std = watch.solve()
    assert std[1] == pytest.approx(PRIOR["clock"], rel=1e-12) and estimate[1] == 0.0
    by_hand = residuals.std(ddof=1) / np.sqrt(len(residuals))
    assert std[0] == pytest.approx(by_hand, rel=0.1)  # the residuals' serial correlation is clipped at 0
    assert estimate[0] == pytest.approx(residuals.mean(), rel=1e-3)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_a_single_axis_never_alarms_a_constant_clock_error_it_cannot_see(engine):
    """Madrid (40.4° N, 3.7° W on Central European time), one sunny late-October day, a healthy
    clock (15 s behind): the trough's estimate read +1,420 s ± 331 s, 4.3σ, and was alarmed
    (helper-44). A single axis tells a constant error from its mount only through the low sun's
    refraction, which the controller's sun model leaves out, so the estimate is its model's error.
    It is still reported; only a drift, which the mount cannot mimic, is alarmed."""
    import dataclasses

    madrid = sites.custom(40.4, -3.7, "Europe/Madrid", name="madrid")
    config = SimulationConfig(seed=0)
    config = dataclasses.replace(config, engine=engine)
    result = simulate(synthetic(madrid, "2024-10-26", weather="sunny", seed=0), madrid, collector="trough-ns",
                      config=config)
    clock = result.summary["clock"]
    assert abs(clock["error_s"]) >= 4 * clock["error_std_s"]  # what had been alarmed, still reported
    assert not _clock_alarms(result)
