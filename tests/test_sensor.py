"""The sun sensor: photocurrent range, variation window, pointing validity, classes by weather."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.sensor import SensorModel, sensor_view
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


def test_pointing_signal_valid_only_with_sun_in_view():
    model = SensorModel(noise=0.0, bias=0.05)
    measured, valid = model.pointing([0.2, 0.2, 15.0, np.nan, 0.1], [800, 100, 800, 800, np.nan])
    assert list(valid) == [True, False, False, False, False]
    assert measured[0] == pytest.approx(0.25) and np.isnan(measured[1:]).all()
    rng = np.random.default_rng(0)
    noisy, _ = SensorModel(noise=0.03).pointing(np.zeros(20000), np.full(20000, 900.0), rng=rng)
    assert noisy.std() == pytest.approx(0.03, rel=0.05)


def test_direct_response_falls_with_offset_and_field_of_view():
    model = SensorModel(field_of_view=10.0)
    np.testing.assert_allclose(model.direct_response([0.0, 5.0, 11.0]), [1.0, np.cos(np.radians(5.0)), 0.0])


@pytest.mark.parametrize("kwargs, message", [({"diffuse_share": 1.5}, "diffuse_share"),
                                             ({"window": "soon"}, "window 'soon'"),
                                             ({"field_of_view": 0}, "field_of_view")])
def test_bad_sensor_parameters(kwargs, message):
    with pytest.raises(HybridtrackError, match=message):
        SensorModel(**kwargs)
