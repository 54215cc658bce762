"""The clock's fields by integer arithmetic against pandas' own field accessors; dates and clock
times as they are written."""

import datetime as dt
import re

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.times import calendar_days, clock_hours, local_range, parse_clock, parse_date


@pytest.mark.parametrize("tz", ["Asia/Shanghai", "America/New_York", "Australia/Lord_Howe", "Etc/GMT+12"])
def test_clock_fields_match_pandas_through_daylight_saving(tz):
    index = pd.date_range("1968-12-30", "2031-01-02", freq="47min", tz="UTC").tz_convert(tz)
    day_of_year, year = calendar_days(index)
    np.testing.assert_array_equal(day_of_year, index.day_of_year)
    np.testing.assert_array_equal(year, index.year)
    expected = index.hour + index.minute / 60.0 + (index.second + index.microsecond / 1e6) / 3600.0
    np.testing.assert_allclose(clock_hours(index), expected, rtol=0, atol=1e-12)


def test_clock_fields_of_a_coarser_unit_and_a_naive_index():
    index = pd.date_range("2024-02-28 23:59:59.5", periods=500, freq="37s", tz="Europe/Paris", unit="ms")
    np.testing.assert_array_equal(calendar_days(index)[0], index.day_of_year)  # 29 February and on
    assert clock_hours(index)[0] == pytest.approx(23 + 59 / 60 + 59.5 / 3600, abs=1e-12)
    naive = pd.DatetimeIndex(["2021-12-31 23:30", "2022-01-01 00:15"])
    np.testing.assert_array_equal(calendar_days(naive)[0], [365, 1])
    np.testing.assert_allclose(clock_hours(naive), [23.5, 0.25])


def test_plus_seconds_is_pandas_to_timedelta_to_the_nanosecond():
    import numpy as np

    from hybridtrack.errors import HybridtrackError
    from hybridtrack.times import plus_seconds

    index = pd.date_range("2021-03-27 22:00", periods=6000, freq="1min", tz="Europe/Berlin")  # over a DST change
    rng = np.random.default_rng(3)
    for scale in (1.0, 500.0, 3.2e7):  # up to a year's clock fault with drift, where float seconds lose digits
        seconds = rng.normal(0.0, scale, len(index))
        seconds[7] = np.nan
        for start, expected in ((index, index + pd.to_timedelta(seconds, unit="s")),
                                (index[:1], index[0] + pd.to_timedelta(seconds, unit="s"))):
            got = plus_seconds(start, seconds)
            assert got.tz == index.tz and len(got) == len(index)
            assert np.array_equal(got.asi8, expected.asi8) and got[7] is pd.NaT
    whole = plus_seconds(index[:3].as_unit("s"), np.array([0.0, 20.0, -1.5]))
    assert list(whole) == [index[0], index[1] + pd.Timedelta(seconds=20), index[2] - pd.Timedelta(seconds=1.5)]
    with pytest.raises(HybridtrackError, match="beyond"):
        plus_seconds(index[:1], [1e10])


@pytest.mark.parametrize("text", ["20210621", "2021W251", "2021-W25-1", "2021-6-21"])
def test_a_date_not_written_yyyy_mm_dd_is_refused(text):
    """Python 3.11's fromisoformat read 20210621 and the ISO week date 2021W251 as 21 June, which
    the messages, the help and the docs never offer."""
    with pytest.raises(HybridtrackError, match=f"date '{text}' does not exist or is not YYYY-MM-DD"):
        parse_date(text)
    assert parse_date(" 2021-06-21 ") == dt.date(2021, 6, 21)


@pytest.mark.parametrize("text", ["1200", "12", "12:00+08:00", "7:00"])
def test_a_clock_time_not_written_hh_mm_is_refused(text):
    """fromisoformat took 12:00+08:00, a time in another zone than the site's, as noon."""
    with pytest.raises(HybridtrackError, match=f"clock time '{re.escape(text)}' is not HH:MM"):
        parse_clock(text)
    assert parse_clock("05:30") == dt.time(5, 30) and parse_clock("05:30:15") == dt.time(5, 30, 15)


@pytest.mark.parametrize("text, days", [("1d", 1.0), ("2 d", 2.0), ("1.5d", 1.5), ("1d12h", 1.5), ("1day", 1.0)])
def test_a_day_step_in_lower_case_reads_without_pandas_deprecation_warning(text, days):
    """pandas 3.1 warns that it will stop reading '1d' (a Pandas4Warning printed beside the
    command's one line); pandas 4 will refuse it. Steps and durations read it as '1D'."""
    import warnings

    from hybridtrack.params import duration
    from hybridtrack.times import parse_freq

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert parse_freq(text) == pd.Timedelta(days=days)
        if days <= 1:
            assert duration(text, "dwell") == pd.Timedelta(days=days)
        else:  # read as days, then refused: no controller timing is longer than its day
            with pytest.raises(HybridtrackError, match=f"dwell '{text}' is longer than a day"):
                duration(text, "dwell")


def test_each_stamp_stands_for_half_of_each_step_beside_it_and_a_gap_for_none():
    """Hand-counted: 15-min stamps, then a 2-h gap, then 1-min stamps (a stamp beside the gap takes
    its other step whole, an end stamp its one step); a step over an hour is capped at an hour; a
    lone stamp is a minute; a reading missed is integrated across (1.5 min each side), two missed
    are a gap; a stamp alone in a 3-h gap is a minute; two stamps 1 ns apart share one minute;
    jittered stamps (±20 s, helper-32: the shorter step either side had lost 19.8 %) add up to
    their span."""
    from hybridtrack.times import stamp_minutes

    start = pd.Timestamp("2021-06-21 06:00", tz="Asia/Shanghai")
    stamps = pd.DatetimeIndex([start + pd.Timedelta(minutes=m) for m in (0, 15, 30, 150, 151, 152)])
    np.testing.assert_array_equal(stamp_minutes(stamps), [15, 15, 15, 1, 1, 1])
    sparse = pd.DatetimeIndex([start, start + pd.Timedelta(hours=3)])
    np.testing.assert_array_equal(stamp_minutes(sparse), [60, 60])
    np.testing.assert_array_equal(stamp_minutes(stamps[:1]), [1])
    regular = pd.date_range(start, periods=5, freq="10s")
    np.testing.assert_array_equal(stamp_minutes(regular), np.full(5, 10 / 60))
    minutes = pd.date_range(start, periods=1000, freq="1min")
    np.testing.assert_array_equal(stamp_minutes(minutes.delete([100]))[98:102], [1, 1.5, 1.5, 1])
    np.testing.assert_array_equal(stamp_minutes(minutes.delete([200, 201]))[198:202], [1, 1, 1, 1])
    alone = pd.DatetimeIndex([*minutes[:300], minutes[400], *minutes[600:]])
    np.testing.assert_array_equal(stamp_minutes(alone)[299:302], [1, 1, 1])
    twice = minutes[:10].append(pd.DatetimeIndex([minutes[9] + pd.Timedelta(1, "ns")])).append(minutes[10:20])
    assert stamp_minutes(twice)[9:11].sum() == pytest.approx(1.0, rel=1e-9)
    jittered = minutes + pd.to_timedelta(np.random.default_rng(1).uniform(-20, 20, len(minutes)), unit="s")
    span = (jittered[-1] - jittered[0]) / pd.Timedelta(minutes=1)
    ends = (jittered[1] - jittered[0] + jittered[-1] - jittered[-2]) / pd.Timedelta(minutes=2)  # the ends' halves
    assert stamp_minutes(jittered).sum() == pytest.approx(span + ends, rel=1e-12)


def test_a_day_its_zone_skipped_is_named():
    """Samoa skipped 30 December 2011 crossing the date line: a run of that day had been refused
    as "the range ends (...) before it starts (...)" (helper-37)."""
    with pytest.raises(HybridtrackError, match="2011-12-30 does not exist on the local clock of Pacific/Apia: the "
                                               "zone skipped that day; choose another date"):
        local_range("2011-12-30", "Pacific/Apia")
    both = local_range("2011-12-29", "Pacific/Apia", end_date="2011-12-30", freq="1h")
    assert len(both) == 24 and both[-1] == pd.Timestamp("2011-12-29 23:00", tz="Pacific/Apia")


def test_a_range_that_ends_the_day_before_it_starts_says_so():
    """It had been told its last day did not exist on the zone's clock, the skipped day's message
    (helper-44)."""
    with pytest.raises(HybridtrackError, match="^the range ends on 2024-06-20, before it starts on 2024-06-21$"):
        local_range("2024-06-21", "UTC", end_date="2024-06-20")
