"""The controller's plain-float Kalman filter against filterpy's KalmanFilter, step by step.

A whole run with each (tests/test_simulation.py) agrees only where the filter's output changes a
drive command; here every state, covariance and innovation is compared, on irregular steps, with
resets, against a filterpy filter set up in this file from the model the module states (state
angle and rate, white-noise acceleration, Bar-Shalom et al. §6.2)."""

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from hybridtrack.control.kalman import FastKalman, FilterpyKalman, make_filter


def reference(q, r, angle=0.0, rate=0.0):
    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.H = np.array([[1.0, 0.0]])
    kf.R = np.array([[r]])
    kf.x = np.array([[angle], [rate]])
    kf.P = np.array([[1.0, 0.0], [0.0, 0.1]])
    return kf


def predict(kf, q, dt):
    kf.F = np.array([[1.0, dt], [0.0, 1.0]])
    kf.Q = q * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
    kf.predict()


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("q, r", [(1e-4, 0.0025), (1e-2, 0.04), (1e-6, 1e-4)])
def test_the_fast_filter_is_filterpys_at_every_step(seed, q, r):
    rng = np.random.default_rng(seed)
    fast, wrapped, kf = FastKalman(q, r), FilterpyKalman(q, r), reference(q, r)
    truth, rate = 40.0, 0.25
    for step in range(400):
        if step % 150 == 0:  # a restart, as after a stow: at the sun, at its rate
            for f in (fast, wrapped):
                f.reset(truth, rate)
            kf = reference(q, r, truth, rate)
        dt = float(rng.choice([0.5, 1.0, 1.0, 2.0, 7.0]))
        truth += rate * dt
        for f in (fast, wrapped):
            f.predict(dt)
        predict(kf, q, dt)
        scale = float(rng.choice([1.0, 1.0, 4.0, 131.6]))  # a heliostat's azimuth: 1/cos² of 0°, 60°, 85°
        z = truth + rng.normal(0.0, np.sqrt(r * scale))
        residual, variance = z - kf.x[0, 0], kf.P[0, 0] + r * scale  # before the update, as the gate reads it
        for f in (fast, wrapped):
            assert f.innovation(z, scale) == pytest.approx((residual, variance), rel=1e-9, abs=1e-12)
        if rng.random() < 0.8:  # some scans have no reading to take in
            for f in (fast, wrapped):
                f.update(z, scale)
            kf.update(np.array([[z]]), R=np.array([[r * scale]]))
        for f in (fast, wrapped):
            assert (f.angle, f.rate) == pytest.approx((kf.x[0, 0], kf.x[1, 0]), rel=1e-9, abs=1e-12)
        np.testing.assert_allclose([[fast.p00, fast.p01], [fast.p01, fast.p11]], kf.P, rtol=1e-9, atol=1e-15)
    assert abs(fast.angle - truth) < 1.0  # it tracked the ramp it was given


def test_a_heliostats_azimuth_reading_is_as_noisy_as_its_division_makes_it():
    """By hand: a small angle c across the sensor's face is c / cos φ of azimuth, so its variance
    is R / cos² φ: 4 at φ = 60°, 1/cos² 85° (the floor) from there to the zenith and past it; the
    elevation and a single axis keep R. Checked against the conversion itself (`axis_offset`)."""
    from hybridtrack.control.sensing import AZIMUTH, ELEVATION, axis_offset, reading_scale

    assert reading_scale([0.01, 0.0], AZIMUTH, [180.0, 60.0]) == pytest.approx(4.0, rel=1e-12)
    assert reading_scale([0.01, 0.0], AZIMUTH, [180.0, 0.0]) == 1.0
    floor = 1.0 / np.cos(np.radians(85.0)) ** 2
    for elevation in (85.0, 89.9, 95.0):
        assert reading_scale([0.01, np.nan], AZIMUTH, [180.0, elevation]) == pytest.approx(floor, rel=1e-12)
    assert reading_scale([0.01, 0.5], ELEVATION, [180.0, 70.0]) == 1.0
    assert reading_scale([0.3], 0, [12.0]) == 1.0
    for elevation, along in ((30.0, 0.2), (70.0, -0.4)):  # the scale is the square of the conversion's slope
        slope = (axis_offset([1e-4, along], AZIMUTH, [0.0, elevation])[0]
                 - axis_offset([-1e-4, along], AZIMUTH, [0.0, elevation])[0]) / 2e-4
        assert reading_scale([0.0, along], AZIMUTH, [0.0, elevation]) == pytest.approx(slope ** 2, rel=1e-6)


def test_the_engines_are_chosen_by_name():
    assert isinstance(make_filter("fast", 1e-4, 0.0025), FastKalman)
    assert isinstance(make_filter("filterpy", 1e-4, 0.0025), FilterpyKalman)


@pytest.mark.parametrize("strategy", ["sensor", "hybrid-always"])
def test_a_reading_the_gate_rejects_advances_the_filter_one_scan_not_two(strategy):
    """A reading that fails the innovation gate is a scan with no measurement: the filter predicts
    across that scan once. The controller's gate predicts before it judges the innovation; the
    controller then coasted every gate without a taken reading, so an outlier scan had predicted
    twice: the angle ran a scan's motion ahead and the variance grew twice. Compared with filterpy
    predicting once from the state before the scan."""
    from hybridtrack.control import Controller, ControllerConfig, ControllerPlan, Observation
    from hybridtrack.control.modes import SENSOR_STATUS
    from hybridtrack.drive import Drive
    from hybridtrack.fuzzy import FuzzyWeatherClassifier
    from hybridtrack.skyinputs import SkyInputConfig

    n, outlier = 60, 40
    model = np.linspace(40.0, 40.0 + 0.25 * (n - 1), n)[:, None]  # the sun at 0.25° a minute
    plan = ControllerPlan(np.arange(n, dtype=float), model, np.ones(n, bool), np.zeros(n))
    config = ControllerConfig(strategy=strategy)
    controller = Controller(config, [Drive()], plan, FuzzyWeatherClassifier(), SkyInputConfig.published(), 30.0,
                            [90.0])
    gate = controller.gates[0]
    obs, angle = Observation(1), 90.0
    for i in range(n):
        before = (gate.filter.angle, gate.filter.rate, gate.filter.p00, gate.filter.p01, gate.filter.p11)
        obs.i, obs.t, obs.wind, obs.intensity, obs.true_sky = i, float(i), 3.0, 280.0, -1
        miss = 1.5 if i == outlier else 0.0  # far outside the gate, inside the 2° plausibility bound
        obs.encoder[0], obs.offset[0], obs.valid, obs.coarse[0] = angle, model[i, 0] - angle + miss, True, 0.0
        angle = min(max(angle + controller.step(obs)[0], 0.0), 180.0)
        if i == outlier:
            break
    assert SENSOR_STATUS[controller.outputs().sensor_status[outlier]] == "outlier"
    kf = reference(config.process_noise, gate.filter.r, before[0], before[1])
    kf.P = np.array([[before[2], before[3]], [before[3], before[4]]])
    predict(kf, config.process_noise, 1.0)
    assert gate.filter.angle == pytest.approx(kf.x[0, 0], abs=1e-12)
    assert gate.filter.p00 == pytest.approx(kf.P[0, 0], rel=1e-12)
