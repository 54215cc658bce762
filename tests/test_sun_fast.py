"""The fast SPA truth against pvlib's own SPA: within its stated error, everywhere it is used."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.sun import COLUMNS, SPA_FAST_ERROR, solar_position, spa_fast


def _separation(alt1, az1, alt2, az2):
    """Angle between two sun directions, degrees."""
    a1, a2 = np.radians(alt1), np.radians(alt2)
    cos = np.sin(a1) * np.sin(a2) + np.cos(a1) * np.cos(a2) * np.cos(np.radians(az1 - az2))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


@pytest.mark.parametrize("name", ["lanzhou", "nanjing"])
def test_fast_truth_stays_within_its_stated_error_of_spa_over_a_year(name):
    site = sites.get(name)
    # 7 minutes: every phase of the hourly knots is visited over the year
    times = pd.date_range("2021-01-01", "2022-01-01", freq="7min", tz=site.tz, inclusive="left")
    pressure = pvlib.atmosphere.alt2pres(site.altitude)
    reference = pvlib.solarposition.spa_python(times, site.latitude, site.longitude, altitude=site.altitude,
                                               pressure=pressure, temperature=12.0, delta_t=67.0)
    fast = solar_position(times, site, "spa-fast")
    up = reference["elevation"].to_numpy() > -1.0
    assert np.abs(fast["altitude"] - reference["elevation"]).max() < SPA_FAST_ERROR
    assert np.abs(fast["apparent_altitude"] - reference["apparent_elevation"])[up].max() < SPA_FAST_ERROR
    direction = _separation(fast["altitude"], fast["azimuth"], reference["elevation"], reference["azimuth"])
    assert direction.max() < SPA_FAST_ERROR
    assert np.abs(fast["equation_of_time"] - reference["equation_of_time"]).max() < 60 * SPA_FAST_ERROR / 15


def test_fast_truth_matches_spa_on_the_reference_columns_and_any_order():
    site = sites.get("lanzhou")
    times = pd.date_range("2021-06-20", "2021-06-23", freq="1min", tz=site.tz)
    shuffled = times[np.random.default_rng(1).permutation(len(times))]
    fast = solar_position(shuffled, site, "spa-fast")
    spa = solar_position(shuffled, site, "spa")
    assert tuple(fast.columns) == COLUMNS and fast.index.equals(shuffled)
    np.testing.assert_allclose(fast.to_numpy(), spa.to_numpy(), atol=SPA_FAST_ERROR)


def test_fast_truth_across_a_daylight_saving_change():
    times = pd.date_range("2021-03-27", "2021-03-29", freq="1min", tz="Europe/Berlin")
    fast = spa_fast(times, 52.5, 13.4, 34.0)
    spa = pvlib.solarposition.spa_python(times, 52.5, 13.4, altitude=34.0, delta_t=67.0)
    np.testing.assert_allclose(fast["elevation"], spa["elevation"], atol=SPA_FAST_ERROR)


def test_few_stamps_run_the_reference_itself():
    times = pd.date_range("2021-06-21 08:00", periods=5, freq="1h", tz="Asia/Shanghai")
    fast = solar_position(times, "nanjing", "spa-fast")
    spa = solar_position(times, "nanjing", "spa")
    pd.testing.assert_frame_equal(fast, spa)


def test_fast_truth_refuses_naive_times_and_bad_knots():
    with pytest.raises(HybridtrackError, match="naive"):
        solar_position(pd.date_range("2021-06-21", periods=600, freq="1min"), "nanjing", "spa-fast")
    times = pd.date_range("2021-06-21", periods=600, freq="1min", tz="UTC")
    for knot in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(HybridtrackError, match="knot"):
            spa_fast(times, 30.0, 120.0, knot=knot)
    with pytest.raises(HybridtrackError, match="spa-fast"):
        solar_position(times, "nanjing", "spa-quick")
