"""The sun sensor: photocurrent range, variation window, pointing validity, classes by weather."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.sensor import SensorModel, coarse_offset, read_photocurrent, read_pointing, sensor_view
from hybridtrack.sky import synthetic
from hybridtrack.sun import solar_position


@pytest.fixture(scope="module")
def views():
    out = {}
    for site, date in (("lanzhou", "2021-06-21"), ("nanjing", "2013-12-22")):
        for weather in ("sunny", "cloudy", "overcast"):
            out[(site, weather)] = sensor_view(synthetic(site, date, weather=weather, seed=21), seed=21)
    return out


def test_photocurrent_spans_the_field_range(views):
    sunny_lanzhou = views[("lanzhou", "sunny")]["intensity_ma"]
    assert 280 < sunny_lanzhou.max() < 345  # clear June noon at Lanzhou near the top of 30-300 mA
    assert sunny_lanzhou.min() == pytest.approx(30.0, abs=2.0)  # dark current at night
    sunny_nanjing = views[("nanjing", "sunny")]["intensity_ma"].max()
    assert 200 < sunny_nanjing < 290
    assert views[("lanzhou", "overcast")]["intensity_ma"].max() < 120


def test_weather_types_land_in_the_published_classes(views):
    clf = FuzzyWeatherClassifier()
    for (site, weather), frame in views.items():
        up = solar_position(frame.index, site)["altitude"] > 10
        labels = clf.classify(frame["intensity_ma"][up], frame["variation_ma"][up])
        share = (labels == weather).mean()
        assert share > 0.6, (site, weather, labels.value_counts(normalize=True).to_dict())


def test_variation_is_the_range_over_the_trailing_window():
    index = pd.date_range("2021-06-21 12:00", periods=40, freq="1min", tz="Asia/Shanghai")
    intensity = pd.Series(100.0, index=index)
    intensity.iloc[10] = 250.0
    variation = SensorModel(window="20min").variation(intensity)
    assert variation.iloc[9] == 0 and variation.iloc[10] == 150.0
    assert variation.iloc[29] == 150.0 and variation.iloc[30] == 0.0  # the spike leaves after 20 minutes
    with_nan = intensity.copy()
    with_nan.iloc[5] = np.nan
    assert SensorModel().variation(with_nan).notna().all()


def test_recorded_photocurrent_is_used_as_is():
    frame = synthetic("nanjing", "2013-06-21", weather="sunny", seed=1)
    frame["photocurrent"] = 123.0
    view = sensor_view(frame)
    assert (view["intensity_ma"] == 123.0).all() and view.attrs["intensity_source"] == "recorded"


def test_under_a_clear_sky_the_sensor_reports_the_sun_offset_and_its_noise():
    model = SensorModel(noise=0.03)
    reading, valid = read_pointing([0.25], 900.0, 20.0, 0.0, [3.0], [0.0], model)
    assert valid and reading[0] == pytest.approx(0.25)
    # noise is 0.03° at 1000 W/m² in view and grows as 1000 over the light in view
    reading, _ = read_pointing([0.0], 480.0, 20.0, 0.0, [0.0], [1.0], model)
    assert reading[0] == pytest.approx(0.03 * 1000.0 / (480.0 * np.cos(0.0) + 20.0))


def test_a_bright_patch_pulls_the_reading_to_the_brightness_weighted_centre():
    model = SensorModel(noise=0.0)
    # sun 0.5° off the axis with 300 W/m² of beam and 20 of aureole; a 100 W/m² patch 4° from the sun
    reading, valid = read_pointing([0.5], 300.0, 20.0, 100.0, [4.0], [0.0], model)
    sun = 300.0 * np.cos(np.radians(0.5)) + 20.0
    assert valid and reading[0] == pytest.approx((sun * 0.5 + 100.0 * 4.5) / (sun + 100.0))
    # the patch outside the fine view pulls nothing; the sun outside it leaves the patch alone in view
    assert read_pointing([0.5], 300.0, 20.0, 100.0, [12.0], [0.0], model)[0][0] == pytest.approx(0.5)
    alone, valid = read_pointing([11.0], 300.0, 20.0, 150.0, [-4.0], [0.0], model)
    assert valid and alone[0] == pytest.approx(7.0)


def test_too_little_light_in_view_is_no_reading():
    model = SensorModel()
    reading, valid = read_pointing([0.1], 90.0, 10.0, 0.0, [0.0], [0.0], model)  # 100 W/m² < 120
    assert not valid and np.isnan(reading[0])
    reading, valid = read_pointing([0.1], float("nan"), 10.0, 0.0, [0.0], [0.0], model)  # unknown light
    assert not valid


def test_photocurrent_falls_with_the_offset_and_the_coarse_cells_find_the_sun():
    model = SensorModel(current_noise=0.0)
    assert read_photocurrent(0.0, 1000.0, 100.0, 0.0, model) == pytest.approx(30.0 + 0.271 * (1000.0 + 50.0))
    assert read_photocurrent(60.0, 1000.0, 100.0, 0.0, model) == pytest.approx(30.0 + 0.271 * (500.0 + 50.0))
    assert read_photocurrent(95.0, 1000.0, 100.0, 0.0, model) == pytest.approx(30.0 + 0.271 * 50.0)
    assert coarse_offset(-40.0, 800.0, 0.5, model) == pytest.approx(-40.0 + 0.5 * model.coarse_accuracy)
    assert np.isnan(coarse_offset(40.0, 50.0, 0.0, model))  # too little direct light to find the sun
    assert np.isnan(coarse_offset(95.0, 800.0, 0.0, model))  # behind the cells


@pytest.mark.parametrize("kwargs, message", [({"diffuse_share": 1.5}, "diffuse_share"),
                                             ({"window": "soon"}, "window 'soon'"),
                                             ({"field_of_view": 0}, "field_of_view")])
def test_bad_sensor_parameters(kwargs, message):
    with pytest.raises(HybridtrackError, match=message):
        SensorModel(**kwargs)


def test_a_recorded_pointing_signal_is_what_the_controller_reads():
    """A logger's own sensor signal is replayed as recorded: the observation carries it, and a
    missing reading is no reading."""
    import math

    import numpy as np

    from hybridtrack import sites
    from hybridtrack.collectors import Collector
    from hybridtrack.control import Observation
    from hybridtrack.drive import Drive
    from hybridtrack.sky import synthetic
    from hybridtrack.world import Imperfections, World

    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)
    recorded = np.where(np.arange(len(frame)) % 7 == 0, np.nan, np.linspace(-0.3, 0.3, len(frame)))
    world = World(frame.assign(pointing=recorded), sites.get("lanzhou"), Collector("trough-ns"), Imperfections(),
                  SensorModel(), [Drive()], 0, {})
    obs = Observation(1)
    for i in (700, 701, 707):
        world.observe(i, obs)
        assert (math.isnan(obs.offset[0]) and not obs.valid) if i % 7 == 0 else \
            (obs.offset[0] == recorded[i] and obs.valid)


def test_a_heliostat_needs_a_recorded_pointing_signal_per_axis():
    from hybridtrack import HybridtrackError, simulate
    from hybridtrack.sky import synthetic

    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1).assign(pointing=0.0)
    with pytest.raises(HybridtrackError, match="a column per axis: pointing, pointing_2"):
        simulate(frame, "lanzhou", collector="heliostat")
