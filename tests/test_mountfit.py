"""The mount fit (`hybridtrack.control.mountfit`): its noise model for pulled readings, each reading
weighed by the cloud pull the controller can see, checked against steps worked by hand and the
issue 10 days it was made for; and its derivatives, by the chain rule through the mount's
rotation, against central differences of the whole mount geometry (turn the mount, recompute
every target)."""

import math

import numpy as np
import pytest

from hybridtrack.collectors import Collector
from hybridtrack.control.config import ControllerConfig
from hybridtrack.control.mountfit import (LEVEL_READINGS, LIGHT_TOLERANCE, MountEstimator, jacobian, parameter_names,
                                          pull_spread)
from hybridtrack.control.plan import MountEstimate
from hybridtrack.errors import HybridtrackError
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.sky import synthetic
from hybridtrack.sun import solar_position
from hybridtrack.times import local_range
from hybridtrack.world import Imperfections


def test_the_pull_spread_is_the_gain_times_the_excess_over_the_sines_of_the_suns_altitude():
    assert pull_spread(1.4, 0.06, 30.0) == pytest.approx(1.4 * 0.06 / 0.5, rel=1e-12)
    assert pull_spread(1.4, 0.06, 90.0) == pytest.approx(0.084, rel=1e-12)
    # Perez's bound: below 5° of sun (and with no computed sun) the circumsolar share stops growing
    assert pull_spread(1.4, 0.06, 2.0) == pytest.approx(0.084 / 0.0871557427, rel=1e-9)
    assert pull_spread(1.4, 0.06, math.nan) == pull_spread(1.4, 0.06, -3.0) == pull_spread(1.4, 0.06, 4.0)
    assert pull_spread(1.4, 0.0, 10.0) == 0.0


def test_the_clear_sky_level_starts_at_the_first_reading_and_averages_the_last_hour():
    fit = MountEstimator(1, 0.05)
    assert fit.excess_light(math.nan) == 0.0 and math.isnan(fit.level)  # no clear sky expected: nothing learnt
    assert fit.excess_light(1.03) == 0.0 and fit.level == 1.03  # the first reading is the level
    assert fit.excess_light(1.035) == 0.0  # within the clear sky's own wander
    level = 1.03 + (1.035 - 1.03) / 12
    assert fit.level == pytest.approx(level, rel=1e-12)
    assert fit.excess_light(1.10) == pytest.approx(1.10 - level - 0.01, rel=1e-12)  # taken before the update
    assert fit.level == pytest.approx(level + (1.10 - level) / 12, rel=1e-12)
    assert fit.excess_light(0.5) == 0.0  # less light than the level is no cloud light near the sun
    assert (LEVEL_READINGS, LIGHT_TOLERANCE) == (12, 0.01)


def test_a_reading_with_light_above_the_clear_sky_steps_the_fit_as_rls_with_its_pull_variance():
    """One RLS step by hand: P = diag(0.01, 0.01, 0.0004) deg², row (0.5, -0.2, 1), residual 0.2°,
    the sensor's 0.05° noise, the light ratio 1.10 against a level of 1.03, the sun at 30°."""
    fit = MountEstimator(1, 0.05)
    fit.axis_frozen = False
    fit.p = np.diag([0.01, 0.01, 0.0004])
    fit.excess_light(1.03)
    pull = pull_spread(1.4, fit.excess_light(1.10), 30.0)
    assert pull == pytest.approx(1.4 * (1.10 - 1.03 - 0.01) / 0.5, rel=1e-12)  # 0.168°
    row = np.array([0.5, -0.2, 1.0])
    fit.update(row, 0.2, 0.05**2 + pull**2)
    s = 0.0025 + 0.168**2 + (0.01 * 0.25 + 0.01 * 0.04 + 0.0004)  # R + row·P·row = 0.034024
    p_row = np.array([0.005, -0.002, 0.0004])
    assert fit.theta == pytest.approx(p_row * 0.2 / s, rel=1e-9)  # 3σ of s is 0.55°: not clipped
    assert fit.p == pytest.approx(np.diag([0.01, 0.01, 0.0004]) - np.outer(p_row, p_row) / s, rel=1e-9, abs=1e-15)
    assert fit.information == pytest.approx(np.outer(row, row) / (0.0025 + 0.168**2), rel=1e-9)
    # the datasheet noise alone (s = 0.0058) would have taken a step nearly six times as long
    plain = MountEstimator(1, 0.05)
    plain.axis_frozen = False
    plain.p = np.diag([0.01, 0.01, 0.0004])
    plain.update(row, 0.2)
    assert plain.theta == pytest.approx(p_row * 0.2 / 0.0058, rel=1e-9)


def test_no_step_goes_further_than_the_clip_in_the_fits_own_metric():
    """Δθᵀ P⁻¹ Δθ = ν² · row·P·row / s ≤ clip²: a Mahalanobis bound on the step at the clip never binds."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        fit = MountEstimator(1, 0.05)
        fit.axis_frozen = False
        half = rng.normal(size=(3, 3))
        fit.p = half @ half.T + 1e-3 * np.eye(3)
        before = fit.p.copy()
        fit.update(rng.normal(size=3), rng.normal(0.0, 20.0), 0.05**2 + rng.uniform(0.0, 0.5) ** 2)
        step = fit.theta
        assert step @ np.linalg.solve(before, step) <= fit.clip**2 * (1 + 1e-9)


def test_a_released_pedestal_restarts_from_the_weighted_least_squares_of_every_reading_taken():
    """While frozen the pedestal terms are consider parameters (never moved, their covariance
    the prior's); at the release the fit is the batch solution of every reading, each weighed by
    its variance and by the forgetting since, with the prior as three pseudo-readings of zero:
    checked against numpy's least squares on the stacked, whitened rows."""
    rng = np.random.default_rng(11)
    fit = MountEstimator(1, 0.05, check_every=10)
    rows, residuals, variances, ages = [], [], [], []
    truth = np.array([0.3, 0.2, 0.32])
    for k in range(10):
        row = np.array([rng.normal(0.0, 0.5), rng.normal(0.0, 0.5), 1.0])
        variance = (0.05 * rng.uniform(1.0, 4.0)) ** 2
        residual = row @ truth + rng.normal(0.0, math.sqrt(variance))
        fit.forget(5.0)
        ages = [age + 5.0 for age in ages]
        assert fit.axis_frozen and not fit.theta[:2].any()  # consider parameters: never moved
        fit.update(row, residual, variance)
        rows.append(row), residuals.append(residual), variances.append(variance), ages.append(0.0)
    assert not fit.axis_frozen  # released at the tenth reading
    weight = np.sqrt(np.exp(-np.array(ages) / fit.memory) / np.array(variances))
    design = np.vstack([np.array(rows) * weight[:, None], np.eye(3) / 2.0])  # the prior: 2° on each
    target = np.concatenate([np.array(residuals) * weight, np.zeros(3)])
    expected = np.linalg.lstsq(design, target, rcond=None)[0]
    np.testing.assert_allclose(fit.theta, expected, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fit.p, np.linalg.inv(design.T @ design), rtol=1e-9, atol=1e-12)
    # from its own covariance the filter would have been left with the consider terms at 0
    assert np.abs(fit.theta[:2]).min() > 0.05


def test_a_fit_readings_variance_grows_as_the_worlds_sensor_noise_does_with_less_light():
    """The controller's noise for a reading at light L in view is its datasheet 1σ × 1000 / L,
    the law the world's sensor draws its noise by (`read_pointing`), floored at the sensor's sun
    threshold; the light read from the photocurrent through the datasheet's responsivity."""
    from hybridtrack import sites
    from hybridtrack.control import Controller, make_plan
    from hybridtrack.control.plan import east_park
    from hybridtrack.fuzzy import FuzzyWeatherClassifier
    from hybridtrack.sensor import SensorModel, read_pointing
    from hybridtrack.simulation import _drives

    frame = synthetic("nanjing", "2013-06-21 08:00", "2013-06-21 08:10", weather="sunny", seed=1)
    model = SensorModel(noise=0.05)  # the sensor read here; a run's world takes imperfections.sensor_noise
    config = SimulationConfig()
    collector = Collector("trough-ns")
    plan = make_plan(frame.index, np.arange(len(frame), dtype=float), sites.get("nanjing"), collector,
                     config.controller)
    controller = Controller(config.controller, _drives(collector, config), plan, FuzzyWeatherClassifier(),
                            config.sky, model.dark_current, east_park(collector), None, model.responsivity,
                            model.direct_threshold)
    assert config.controller.sensor_noise == model.noise  # the datasheet the controller is given
    for light in (1000.0, 640.0, 250.0, 121.0):
        controller.out["intensity"][0] = model.dark_current + model.responsivity * light
        sigma = read_pointing([0.0], light, 0.0, 0.0, [0.0], [1.0], model)[0][0]
        assert controller._reading_variance(0) == pytest.approx(sigma**2, rel=1e-12)
    controller.out["intensity"][0] = model.dark_current + model.responsivity * 60.0  # below the threshold
    assert controller._reading_variance(0) == pytest.approx((0.05 * 1000.0 / 120.0) ** 2, rel=1e-12)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_the_evenings_residual_offset_is_not_carried_into_the_morning(engine):
    """The memory a controller carries out of a day, its offsets changed by 0.4°: the next day's
    run is the same to the last number from its wake on, as its offsets start the day from zero
    (before it, at night stow, the log's calibration column still shows the carried offset)."""
    config = SimulationConfig(seed=2, engine=engine)
    before = simulate(synthetic("nanjing", "2013-09-22", weather="sunny", seed=2), "nanjing", collector="fresnel",
                      strategy="hybrid", config=config)
    frame = synthetic("nanjing", "2013-09-23", weather="mixed", seed=2)
    runs = []
    for shift in (0.0, 0.4):
        memory = dict(before.memory, offsets=[o + shift for o in before.memory["offsets"]])
        runs.append(simulate(frame, "nanjing", collector="fresnel", strategy="hybrid", config=config,
                             warm_start=memory))
    first, second = (run.log for run in runs)
    wake = int(first["mode"].ne("stow_night").to_numpy().argmax())
    assert wake > 0 and first.drop(columns="calibration").equals(second.drop(columns="calibration"))
    assert first["calibration"].iloc[wake:].equals(second["calibration"].iloc[wake:])
    assert runs[0].summary["tracking_error_deg"] == runs[1].summary["tracking_error_deg"]


@pytest.mark.parametrize("gain", [math.nan, math.inf, -0.1, 101.0])
def test_a_pull_gain_that_is_not_a_number_from_0_to_100_is_refused(gain):
    with pytest.raises(HybridtrackError, match="pull_gain"):
        ControllerConfig(pull_gain=gain)


def test_the_pull_gain_round_trips_through_toml(tmp_path):
    config = SimulationConfig(controller=ControllerConfig(pull_gain=0.5))
    assert SimulationConfig.from_toml(config.to_toml(tmp_path / "run.toml")).controller.pull_gain == 0.5


#: Issue 10's bar missed since the filter predicts an outlier scan once, not twice (335a5ab): p95
#: 0.3372 -> 0.3502° and 0.3435 -> 0.3511°. Over the 96 acceptance runs the change moved p95 by
#: +0.0006° on average (sd 0.0044°), and over 160 runs on seeds 6-15 by +0.0001° (sd 0.0027°) with
#: the same 10 runs above 0.35°: noise at the bar's thin margin, not a trend; kept strict, so a
#: change that brings them back under the bar says so. The true sun with refraction (the world's
#: and the controller's) did: 0.3416° and 0.3382° (September's Fresnel row, 0.3485°, is now the
#: closest to the bar). Empty, and kept for the next change that moves a run over it.
_OVER_THE_BAR: dict = {}


@pytest.mark.parametrize("date, collector", [
    pytest.param(date, collector, marks=pytest.mark.xfail(strict=True, reason=f"p95 {_OVER_THE_BAR[date, collector]}° "
                 "over the 0.35° bar (see _OVER_THE_BAR)") if (date, collector) in _OVER_THE_BAR else ())
    for date in ["2013-03-20", "2013-06-21", "2013-09-23", "2013-12-21"] for collector in ["fresnel", "trough-ns"]])
def test_nanjings_day_of_short_clear_gaps_stays_within_issue_10s_p95(date, collector):
    """Seed 3, the worst sky of issue 10's day set in every season: the pulled gaps that threw the
    fit (Fresnel p95 0.373°, 0.367°, 0.366°, 0.384° with the sensor's noise alone), the pedestal
    released in September with the prior's 2° (0.354°), and the evening's offset carried into an
    overcast morning (trough-ns, September, 0.380°)."""
    frame = synthetic("nanjing", date, weather="mixed", seed=3)
    result = simulate(frame, "nanjing", collector=collector, strategy="hybrid", config=SimulationConfig(seed=3))
    assert result.summary["tracking_error_deg"]["p95"] <= 0.35


def test_lanzhous_mixed_june_day_finds_a_tilted_troughs_tilt_within_0_1_degrees():
    """The 1° axis azimuth and tilt: the tilt identifiable (1σ ≤ 0.05°) and within 0.1° (0.106°
    with the sensor's noise alone)."""
    frame = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1)
    config = SimulationConfig(imperfections=Imperfections(axis_azimuth_error=1.0, axis_tilt_error=1.0), seed=1)
    fit = simulate(frame, "lanzhou", collector="trough-ns", strategy="hybrid", config=config).summary["calibration"]
    assert not fit["pedestal_frozen"] and fit["std"]["axis_tilt_error"] <= 0.05
    assert abs(fit["axis_tilt_error"] - 1.0) <= 0.1


@pytest.mark.parametrize("collector", [Collector("trough-ns"), Collector("trough-ew"), Collector("fresnel"),
                                       Collector("heliostat"), Collector("heliostat", aim=(30.0, -80.0, 40.0))])
def test_the_targets_derivatives_match_central_differences_of_the_turned_mount(collector):
    sun = solar_position(local_range("2021-06-21", "Asia/Shanghai", freq="10min"), "lanzhou")
    sun = sun[sun["altitude"] > 2.0]
    altitude, azimuth = sun["altitude"].to_numpy(), sun["azimuth"].to_numpy()
    names = parameter_names(collector)
    h = 1e-3
    expected = np.zeros((len(altitude), 1 if collector.single_axis else 2, len(names)))
    for k, name in enumerate(names):
        up, down = (MountEstimate.from_parameters(names, [sign * h if n == name else 0.0 for n in names])
                    .targets(altitude, azimuth, collector) for sign in (1.0, -1.0))
        difference = up - down
        if not collector.single_axis:  # the azimuth axis turns through north
            difference[:, 0] = (difference[:, 0] + 180.0) % 360.0 - 180.0
        expected[:, :, k] = difference / (2.0 * h)
    got = jacobian(altitude, azimuth, collector)
    assert np.abs(expected[:, :, :2]).max() > 0.1  # the pedestal terms do move the targets
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-6)  # the differences err by O(h²)
