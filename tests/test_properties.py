"""Property tests: what holds for every input, not just the chosen ones."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from hybridtrack.collectors import (
    fresnel_angle, heliostat_normal, jack_heights, sun_vector, trough_angle,
)
from hybridtrack.control import MODES, STRATEGIES, Controller, ControllerConfig, ControllerPlan, Observation
from hybridtrack.drive import Drive
from hybridtrack.skyinputs import SkyInputConfig
from hybridtrack.fuzzy import FuzzyWeatherClassifier

altitude = st.floats(0.01, 90.0)
azimuth = st.floats(0.0, 359.999)
CLASSIFIER = FuzzyWeatherClassifier()


@given(altitude, azimuth, st.sampled_from([0.0, 270.0, 45.0, 180.0]))
def test_single_axis_angles_stay_in_range_while_the_sun_is_up(alt, az, axis):
    assert 0.0 <= float(trough_angle(alt, az, axis)) <= 180.0


@given(altitude, azimuth, st.floats(-30, 30), st.floats(1, 30))
def test_fresnel_rows_stay_in_range(alt, az, d, h):
    assert 0.0 <= float(fresnel_angle(alt, az, d, h)) <= 180.0


@given(st.floats(0.5, 89.5), st.floats(0.01, 179.99))
def test_morning_and_evening_mirror_each_other(alt, az):
    morning, evening = trough_angle(alt, az), trough_angle(alt, 360.0 - az)
    assert abs(float(morning) + float(evening) - 180.0) < 1e-9


@given(altitude, azimuth, st.tuples(st.floats(-200, 200), st.floats(-200, 200), st.floats(1, 300)))
def test_heliostats_obey_the_law_of_reflection(alt, az, aim):
    n = heliostat_normal(alt, az, aim)
    s = sun_vector(alt, az)
    reflected = 2 * np.dot(n, s) * n - s
    target = np.asarray(aim) / np.linalg.norm(aim)
    assert np.allclose(reflected, target, atol=1e-9) and abs(np.linalg.norm(n) - 1) < 1e-12
    z = jack_heights(n[None, :])[0]
    assert np.all(np.isfinite(z)) if n[2] > 1e-3 else True


readings = st.one_of(st.floats(min_value=-1e4, max_value=1e4), st.just(float("nan")))


@given(st.lists(st.tuples(readings, readings), min_size=1, max_size=50))
def test_scores_are_in_range_or_nan_and_labels_follow_the_bands(pairs):
    i, v = np.array(pairs).T
    scores = CLASSIFIER.score(i, v)
    assert np.all(np.isnan(scores) | ((scores >= 0) & (scores <= 30)))
    labels = CLASSIFIER.label(scores)
    for score, label in zip(scores, labels):
        expected = "unknown" if np.isnan(score) else "overcast" if score < 10 else "cloudy" if score < 20 else "sunny"
        assert label == expected


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 350), st.floats(0, 200)), min_size=1, max_size=10))
def test_both_engines_agree_everywhere(pairs):
    i, v = np.array(pairs).T
    np.testing.assert_allclose(CLASSIFIER.score(i, v), CLASSIFIER.score(i, v, engine="skfuzzy"), atol=1e-6)


@st.composite
def controller_runs(draw):
    n = draw(st.integers(5, 150))
    start = draw(st.floats(5, 170))
    steps = draw(arrays(float, n, elements=st.floats(-2, 2)))
    model = np.clip(start + np.cumsum(steps), -20, 200)  # may wander outside the limits
    wind = draw(arrays(float, n, elements=st.one_of(st.floats(0, 30), st.just(float("nan")))))
    awake = draw(arrays(bool, n))
    intensity = draw(arrays(float, n, elements=st.one_of(st.floats(0, 400), st.just(float("nan")))))
    offset = draw(arrays(float, n, elements=st.one_of(st.floats(-3, 3), st.just(float("nan")))))
    valid = draw(arrays(bool, n))
    strategy = draw(st.sampled_from(list(STRATEGIES)))
    plan = ControllerPlan(np.arange(n, dtype=float), model[:, None], awake, np.zeros(n))
    return plan, wind, intensity, offset, valid, strategy


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(controller_runs())
def test_the_controller_stays_in_limits_stows_on_gusts_and_moves_only_past_the_deadband(case):
    plan, wind, intensity, offset, valid, strategy = case
    drive = Drive()
    config = ControllerConfig(strategy=strategy)
    controller = Controller(config, [drive], plan, CLASSIFIER, SkyInputConfig.published(), 30.0, [10.0])
    obs, angle = Observation(1), drive.stow
    angles = []
    for i in range(len(wind)):  # a perfect plant: the encoder reads the angle, the sensor what it is given
        obs.i, obs.t, obs.wind, obs.intensity, obs.true_sky = i, float(i), wind[i], intensity[i], 0
        obs.encoder[0], obs.offset[0], obs.valid = angle, offset[i], bool(valid[i])
        obs.coarse[0] = offset[i]
        angle = min(max(angle + controller.step(obs)[0], drive.limits[0]), drive.limits[1])
        angles.append(angle)
    out = controller.outputs()
    angle = np.array(angles)
    assert np.all((out.target[:, 0] >= drive.limits[0]) & (out.target[:, 0] <= drive.limits[1]))
    modes = np.asarray(MODES)[out.mode]
    gust = ~(wind <= 17.2)
    assert np.all(modes[gust] == "stow_wind")
    previous = np.concatenate([[drive.stow], angle[:-1]])
    moved = angle != previous
    tracking = np.isin(modes, ["astronomical", "sensor"])
    reading = out.reading[:, 0]
    assert np.all(np.abs(out.target[:, 0] - reading)[moved & tracking] > drive.deadband)
