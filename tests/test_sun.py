"""The sun: PLC model against SPA, the published site figures, and the alternative series."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.collectors import trough_angle
from hybridtrack.sun import COLUMNS, altitude_azimuth, solar_position
from hybridtrack.times import local_range

NANJING_DAYS = ["2013-03-20", "2013-06-21", "2013-09-23", "2013-12-22"]


def day(date, site, freq="1min"):
    return local_range(date, sites.get(site).tz, freq=freq)


def test_both_models_return_the_documented_columns():
    times = day("2013-06-21", "nanjing", "1h")
    for model in ("spa", "plc"):
        frame = solar_position(times, "nanjing", model)
        assert tuple(frame.columns) == COLUMNS
        assert frame.index.equals(times)
        np.testing.assert_allclose(frame["zenith"], 90 - frame["altitude"])


def test_plc_trough_angle_stays_within_published_bound_of_spa():
    """docs/physics.md §2: 0.123° against pvlib's SPA at Nanjing, typical days, altitude above 10°."""
    worst = {}
    for date in NANJING_DAYS:
        times = day(date, "nanjing")
        spa = solar_position(times, "nanjing", "spa")
        plc = solar_position(times, "nanjing", "plc")
        high = spa["altitude"] > 10
        error = np.abs(trough_angle(spa.altitude, spa.azimuth) - trough_angle(plc.altitude, plc.azimuth))[high]
        worst[date] = error.max()
    print("PLC vs SPA worst trough-angle error (deg):", {k: round(v, 4) for k, v in worst.items()})
    assert max(worst.values()) < 0.13
    assert max(worst.values()) == pytest.approx(0.123, abs=0.002)  # the published figure itself


def test_plc_altitude_is_geometric_and_apparent_adds_refraction():
    times = day("2021-06-21", "lanzhou", "10min")
    spa = solar_position(times, "lanzhou", "spa")
    plc = solar_position(times, "lanzhou", "plc")
    up = spa["altitude"] > 5
    assert np.abs(plc.altitude - spa.altitude)[up].max() < 0.12
    # refraction: the same size in both models, positive, largest near the horizon
    refraction_spa = (spa.apparent_altitude - spa.altitude)[up]
    refraction_plc = (plc.apparent_altitude - plc.altitude)[up]
    assert (refraction_plc > 0).all()
    np.testing.assert_allclose(refraction_plc, refraction_spa, atol=0.005)


@pytest.mark.parametrize(
    "site, date, clock, altitude, maximum",
    [("lanzhou", "2021-06-21", "13:00", 77.25, 77.33), ("lanzhou", "2021-12-21", "13:00", 30.45, 30.46),
     ("nanjing", "2013-06-21", None, None, 81.98), ("nanjing", "2013-12-22", None, None, 35.11)],
)
def test_site_altitudes_match_spa_as_domain_explains(site, date, clock, altitude, maximum):
    import pvlib

    times = day(date, site, "10s")
    frame = solar_position(times, site, "spa")
    where = sites.get(site)
    spa = pvlib.solarposition.spa_python(times, where.latitude, where.longitude, altitude=where.altitude,
                                         delta_t=67.0)["elevation"]  # pvlib itself, geometric
    np.testing.assert_allclose(frame["altitude"], spa, rtol=0, atol=1e-9)
    assert frame["altitude"].max() == pytest.approx(maximum, abs=0.005)  # the figures docs/physics.md §1 gives
    if clock:
        # printed to 0.01°, and not consistently: 77.25 rounds SPA's apparent altitude (77.247),
        # 30.45 its geometric one (30.451); the geometric value is within 0.01° of both
        at = frame.loc[pd.Timestamp(f"{date} {clock}", tz="Asia/Shanghai"), "altitude"]
        assert at == pytest.approx(altitude, abs=0.01)


def test_azimuth_keeps_every_quadrant():
    # at latitude 10° in June the sun culminates in the north, which a plain arcsin would lose
    alt, az = altitude_azimuth(23.44, np.array([-90.0, -30.0, 0.0, 30.0, 90.0]), 10.0)
    assert az[2] == pytest.approx(0.0)  # culminates due north
    assert 0 < az[1] < 90 and 270 < az[3] < 360
    assert az[0] == pytest.approx(360 - az[4])
    _, south = altitude_azimuth(-10.0, 0.0, 40.0)
    assert south == pytest.approx(180.0)


def test_spa_declination_and_hour_angle_are_consistent():
    times = day("2013-03-20", "nanjing", "1min")
    spa = solar_position(times, "nanjing")
    alt, az = altitude_azimuth(spa.declination, spa.hour_angle, sites.get("nanjing").latitude)
    np.testing.assert_allclose(alt, spa.altitude, atol=1e-9)
    np.testing.assert_allclose(np.cos(np.radians(az - spa.azimuth)), 1.0, atol=1e-12)
    noon = spa["altitude"].idxmax()
    assert abs(spa.loc[noon, "hour_angle"]) < 0.3  # hour angle ~0 at solar noon
    morning = (spa.index < noon) & (spa.altitude > 0)
    assert (spa.hour_angle[morning] < 0).all() and (spa.hour_angle[(spa.index > noon) & (spa.altitude > 0)] > 0).all()


def test_lamm_equation_of_time_within_15_s_of_spa_2012_2015():
    times = pd.date_range("2012-01-01", "2015-12-31 23:00", freq="3h", tz="UTC")
    spa = solar_position(times, "nanjing", "spa")
    lamm = solar_position(times, "nanjing", "plc", equation_of_time="lamm")
    worst_seconds = 60 * np.abs(lamm.equation_of_time - spa.equation_of_time).max()
    assert worst_seconds < 15


def test_cooper_declination_is_selectable_and_close():
    times = day("2013-06-21", "nanjing", "1h")
    cooper = solar_position(times, "nanjing", "plc", declination="cooper")
    assert cooper.declination.iloc[12] == pytest.approx(23.45 * np.sin(np.radians(360 * (284 + 172) / 365)))
    assert cooper.declination.iloc[12] == pytest.approx(23.44, abs=0.05)


def test_plc_model_reads_any_clock_the_same():
    """The same instants in UTC and in Beijing time give the same PLC sun."""
    beijing = day("2021-09-23", "lanzhou", "15min")
    a = solar_position(beijing, "lanzhou", "plc")
    b = solar_position(beijing.tz_convert("UTC"), "lanzhou", "plc")
    np.testing.assert_allclose(a.to_numpy(), b.to_numpy())


def test_naive_times_are_refused_clearly():
    with pytest.raises(HybridtrackError, match="naive"):
        solar_position(pd.date_range("2013-06-21", periods=3, freq="h"), "nanjing")


@pytest.mark.parametrize("options, message", [({"model": "kepler"}, "unknown sun model"),
                                              ({"model": "plc", "declination": "x"}, "unknown declination"),
                                              ({"model": "plc", "equation_of_time": "x"}, "unknown equation-of-time")])
def test_unknown_model_options_are_refused(options, message):
    with pytest.raises(HybridtrackError, match=message):
        solar_position(day("2013-06-21", "nanjing", "1h"), "nanjing", **options)


@pytest.mark.parametrize("date", ["2021-03-14", "2021-11-07"])
def test_plc_model_reads_the_clock_on_dst_days(date):
    """On a DST day the clock reading, not the time since midnight, gives the solar time."""
    denver = sites.custom(39.74, -104.99, "America/Denver", 1609)
    times = pd.date_range(f"{date} 08:00", f"{date} 17:00", freq="30min", tz="America/Denver")
    spa = solar_position(times, denver, "spa")
    plc = solar_position(times, denver, "plc")
    assert np.abs(spa["hour_angle"] - plc["hour_angle"]).max() < 0.5
    assert np.abs(spa["altitude"] - plc["altitude"]).max() < 0.5


def test_a_missing_time_has_no_sun_in_any_model():
    index = pd.DatetimeIndex(["2021-06-21 12:00", None, "2021-06-21 13:00"]).tz_localize("Asia/Shanghai")
    for model in ("plc", "spa"):
        sun = solar_position(index, "lanzhou", model)
        assert sun.iloc[1].isna().all() and sun.iloc[[0, 2]].notna().all().all()


@pytest.mark.parametrize("options, message", [
    (dict(temperature=-273.15), r"temperature \(°C\) = -273.15 is outside \[-90, 60\]"),  # an altitude of -537°
    (dict(temperature=float("nan")), "must be a finite number"),  # NaN altitudes, without a word
    (dict(temperature="20"), "must be a finite number"),  # pvlib's TypeError
    (dict(model="plc", declination=["cooper"]), "declination must be a model's name"),  # TypeError: unhashable
    (dict(declination="cooper"), "declination applies to the PLC model .* only; model 'spa' would not use"),
])
def test_solar_positions_options_are_checked_before_use(options, message):
    times = pd.date_range("2021-06-21 05:00", periods=3, freq="h", tz="Asia/Shanghai")
    with pytest.raises(HybridtrackError, match=message):
        solar_position(times, "lanzhou", **options)


def test_times_beyond_pandas_nanoseconds_are_refused_by_their_span():
    """pandas keeps seconds-resolution stamps of the year 3000: the PLC model raised OutOfBoundsDatetime."""
    times = pd.DatetimeIndex(np.array(["3000-06-21T06:00"], dtype="datetime64[s]")).tz_localize("UTC")
    with pytest.raises(HybridtrackError, match="times must lie within 1678-01-01 to 2261-12-31"):
        solar_position(times, "lanzhou", "plc")
