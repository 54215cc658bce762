"""The metrics on a log small enough to score by hand (docs/metrics.md is the definition).

Every other test of a summary compares one run with another, or a bound; these hold the
definitions themselves to numbers worked out in the comments."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack.metrics import acceptance, daily, moved_axes, summarize, weighted_quantile

#: Six steps of a north-south trough (θ½ = 1.0°). Direct light on the aperture is DNI × incidence.
#:   step  mode          sky       sun up  DNI  incidence  error   scored weight   offered
#:   0     stow_night    unknown   no        0  0.0        nan     -               0
#:   1     sensor        sunny     yes     800  1.0         0.2    800             800
#:   2     sensor        sunny     yes     600  0.5        -0.6    300             300
#:   3     astronomical  cloudy    yes     400  1.0         1.0    400             400
#:   4     stow_wind     sunny     yes     500  1.0        30.0    - (stowed)      500
#:   5     search        overcast  yes       0  1.0         2.0    - (no light)    0
INDEX = pd.date_range("2021-06-21 12:00", periods=6, freq="1min", tz="Asia/Shanghai")
LOG = pd.DataFrame({
    "mode": ["stow_night", "sensor", "sensor", "astronomical", "stow_wind", "search"],
    "sky": ["unknown", "sunny", "sunny", "cloudy", "sunny", "overcast"],
    "dni": [0.0, 800.0, 600.0, 400.0, 500.0, 0.0],
    "error": [np.nan, 0.2, -0.6, 1.0, 30.0, 2.0],
    "angle": [90.0, 90.0, 91.0, 91.0, 92.0, 92.0],
    "wind_speed": [1.0, 2.0, 3.0, 4.0, 20.0, 5.0],
}, index=INDEX)
SUN_UP = np.array([False, True, True, True, True, True])
INCIDENCE = np.array([0.0, 1.0, 0.5, 1.0, 1.0, 1.0])
EVENTS = pd.DataFrame({"time": INDEX[[1, 3, 3, 4, 5]],
                       "from": ["stow_night", "sensor", "astronomical", "astronomical", "stow_wind"],
                       "to": ["sensor", "astronomical", "astronomical", "stow_wind", "search"],
                       "reason": ["sunrise", "sky cloudy", "a guard", "gust", "calm"]})


@pytest.fixture(scope="module")
def summary():
    return summarize(LOG, site="x", collector="trough-ns", strategy="hybrid", moves=2, travel=2.0, events=EVENTS,
                     sun_up=SUN_UP, incidence=INCIDENCE)


def test_the_acceptance_is_one_on_the_sun_and_half_at_the_half_angle():
    # η(e) = 1 / (1 + (e/θ½)⁴): η(0) = 1, η(θ½) = 1/2, η(2θ½) = 1/17, and even in e
    np.testing.assert_allclose(acceptance([0.0, 1.0, -1.0, 2.0, 0.4], 1.0),
                               [1.0, 0.5, 0.5, 1 / 17, 1 / (1 + 0.4 ** 4)], rtol=1e-15)
    assert acceptance(0.25, 0.25) == pytest.approx(0.5) and acceptance(np.inf, 0.8) == 0.0


def test_the_pointing_error_is_weighted_by_the_direct_light_on_the_aperture(summary):
    error = summary["tracking_error_deg"]
    # weights 800, 300, 400 (Σ 1500); the stowed step and the one without light are not scored
    # RMS  = √((800·0.04 + 300·0.36 + 400·1.0) / 1500) = √(540/1500) = √0.36 = 0.6
    # mean = (800·0.2 − 300·0.6 + 400·1.0) / 1500 = 380/1500 = 0.25333
    # max  = 1.0 (the 30° while stowed and the 2° without light are not tracking errors)
    assert error["rms"] == pytest.approx(0.6, abs=1e-5)
    assert error["mean"] == pytest.approx(380 / 1500, abs=1e-5)
    assert error["max"] == 1.0
    # p95: |e| sorted 0.2, 0.6, 1.0 with weights 800, 300, 400: the CDF is 0.533, 0.733, 1.0, so 1.0
    assert error["p95"] == 1.0
    # within 0.5°: only the 0.2° step, 800/1500
    assert summary["within_0_5_deg"] == pytest.approx(800 / 1500, abs=1e-5)


def test_energy_capture_counts_a_stow_in_sunshine_as_a_loss(summary):
    # offered: 800 + 300 + 400 + 500 (stowed in sunshine) = 2000
    # captured: 800/(1 + 0.2⁴) + 300/(1 + 0.6⁴) + 400/(1 + 1⁴) + 0
    #         = 800/1.0016 + 300/1.1296 + 200 = 798.722 + 265.581 + 200 = 1264.303
    captured = 800 / 1.0016 + 300 / 1.1296 + 200
    assert summary["energy_capture"] == pytest.approx(captured / 2000, abs=1e-5)  # 0.63215
    assert summary["energy_capture"] == pytest.approx(0.63215, abs=1e-5)


def test_shares_are_over_every_step_and_the_night_is_where_the_sun_is_down(summary):
    sixth = round(1 / 6, 5)
    assert summary["mode_share"] == {"stow_night": sixth, "stow_wind": sixth, "astronomical": sixth,
                                     "sensor": round(2 / 6, 5), "search": sixth, "fault": 0.0}
    # the sun is down at step 0 only: that step is night, whatever the log's sky says
    assert summary["sky_share"] == {"sunny": 0.5, "cloudy": sixth, "overcast": sixth, "unknown": 0.0,
                                    "night": sixth}
    assert summary["steps"] == 6 and summary["moves"] == 2 and summary["travel_deg"] == 2.0


def test_every_event_row_is_a_switch_or_an_alarm(summary):
    # 5 rows: 4 change mode (1 of them sensor→astronomical, between tracking modes; 1 into
    # stow_wind), 1 (astronomical→astronomical) is an alarm; none is a fault
    assert {k: summary[k] for k in ("mode_switches", "tracking_switches", "stow_events", "faults", "alarms")} == \
        {"mode_switches": 4, "tracking_switches": 1, "stow_events": 1, "faults": 0, "alarms": 1}


def test_moves_are_the_steps_an_axis_turned():
    # angles 90, 90, 91, 91, 92, 92: turned at steps 2 and 4
    np.testing.assert_array_equal(moved_axes(LOG), [0, 0, 1, 0, 1, 0])
    # a heliostat's azimuth is logged modulo 360: 359.5 → 0.5 is a turn of 1°, and counts once per axis
    both = pd.DataFrame({"angle": [10.0, 11.0, 11.0], "angle_azimuth": [359.5, 0.5, 0.5]})
    np.testing.assert_array_equal(moved_axes(both), [0, 2, 0])


def test_the_weighted_quantile_by_hand():
    # weights 1, 1, 2 on 3, 1, 2: sorted 1, 2, 3 with CDF 0.25, 0.75, 1.0
    assert weighted_quantile([3.0, 1.0, 2.0], [1.0, 1.0, 2.0], 0.25) == 1.0
    assert weighted_quantile([3.0, 1.0, 2.0], [1.0, 1.0, 2.0], 0.5) == 2.0
    assert weighted_quantile([3.0, 1.0, 2.0], [1.0, 1.0, 2.0], 0.95) == 3.0
    assert np.isnan(weighted_quantile([1.0], [0.0], 0.5))


def test_the_daily_table_of_one_day_is_the_summary_by_hand(summary):
    table = daily(LOG, collector="trough-ns", tz="Asia/Shanghai", sun_up=SUN_UP, incidence=INCIDENCE)
    assert len(table) == 1
    row = table.iloc[0]
    assert row["rms"] == pytest.approx(0.6) and row["p95"] == 1.0 and row["max"] == 1.0
    assert row["energy_capture"] == pytest.approx((800 / 1.0016 + 300 / 1.1296 + 200) / 2000)
    assert row["moves"] == 2 and row["stow_wind_min"] == 1.0 and row["stow_night_min"] == 1.0
    # DNI at 1 min a step: (0 + 800 + 600 + 400 + 500 + 0) W/m² × 1/60 h = 38.33 Wh/m²
    assert row["dni_kwh_m2"] == pytest.approx(2300 / 60 / 1000)
    assert row["max_wind"] == 20.0
    assert row["sky_sunny"] == pytest.approx(0.5) and row["sky_night"] == pytest.approx(1 / 6)


def test_a_day_without_a_wind_reading_has_no_highest_wind_and_no_warning():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's "All-NaN slice encountered" had reached the user
        table = daily(LOG.assign(wind_speed=np.nan), collector="trough-ns", tz="Asia/Shanghai", sun_up=SUN_UP,
                      incidence=INCIDENCE)
    assert np.isnan(table.iloc[0]["max_wind"]) and table.iloc[0]["moves"] == 2


@pytest.mark.parametrize("log, message", [
    (LOG.iloc[:0], "the log has no steps"),  # KeyError: "None of ['date'] are in the columns"
    (LOG.drop(columns="sky"), "the log has no 'sky' column"),  # KeyError: 'sky'
    (LOG.drop(columns=["wind_speed", "dni"]), "the log has no 'dni', 'wind_speed' column"),
    (LOG.to_dict("list"), "the log must be a run's log, a DataFrame on a DatetimeIndex; got dict"),  # AttributeError
    (LOG.reset_index(drop=True), "a DataFrame on a DatetimeIndex; got DataFrame"),
    (LOG.tz_localize(None), "the log's index must be tz-aware and increasing"),  # TypeError (helper-36)
    (LOG.iloc[::-1], "the log's index must be tz-aware and increasing"),  # NaN energy capture each day
    (LOG.drop(columns="angle"), "the log has no 'angle' column"),  # every day's moves 0
    (LOG.assign(dni="x"), "the log's column 'dni' must hold numbers"),  # ValueError
    (LOG.assign(wind_speed="calm"), "the log's column 'wind_speed' must hold numbers"),
    (pd.concat([LOG, LOG[["dni"]]], axis=1), "the log has the column 'dni' more than once"),  # broadcast error
])
def test_a_log_the_daily_table_cannot_count_is_refused_by_name(log, message):
    from hybridtrack.errors import HybridtrackError

    with pytest.raises(HybridtrackError, match=message):
        daily(log, collector="trough-ns", tz="Asia/Shanghai", sun_up=SUN_UP[:len(log)], incidence=INCIDENCE)
