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
        z = truth + rng.normal(0.0, np.sqrt(r))
        residual, variance = z - kf.x[0, 0], kf.P[0, 0] + r  # before the update, as the gate reads it
        for f in (fast, wrapped):
            assert f.innovation(z) == pytest.approx((residual, variance), rel=1e-9, abs=1e-12)
        if rng.random() < 0.8:  # some scans have no reading to take in
            for f in (fast, wrapped):
                f.update(z)
            kf.update(np.array([[z]]))
        for f in (fast, wrapped):
            assert (f.angle, f.rate) == pytest.approx((kf.x[0, 0], kf.x[1, 0]), rel=1e-9, abs=1e-12)
        np.testing.assert_allclose([[fast.p00, fast.p01], [fast.p01, fast.p11]], kf.P, rtol=1e-9, atol=1e-15)
    assert abs(fast.angle - truth) < 1.0  # it tracked the ramp it was given


def test_the_engines_are_chosen_by_name():
    assert isinstance(make_filter("fast", 1e-4, 0.0025), FastKalman)
    assert isinstance(make_filter("filterpy", 1e-4, 0.0025), FilterpyKalman)
