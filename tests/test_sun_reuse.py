"""Reusing sun positions inside a block gives the very numbers the model gives, computed once."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack.reuse import reuse_work
from hybridtrack.sites import get
from hybridtrack.sun import REMEMBERED_FROM, reuse_positions, solar_position


@pytest.mark.parametrize("model", ["spa", "spa-fast", "plc"])
def test_remembered_positions_equal_fresh_ones(model):
    times = pd.date_range("2021-06-21", "2021-06-23", freq="1min", tz="Asia/Shanghai")
    some = times[::7]
    with reuse_positions():
        solar_position(times, "nanjing", model)
        remembered = solar_position(some, "nanjing", model)
    pd.testing.assert_frame_equal(remembered, solar_position(some, "nanjing", model))


@pytest.mark.parametrize("block", [reuse_positions, reuse_work])  # a field's block opens the sun's memory too
def test_each_request_is_computed_once_and_only_inside_the_block(spa_calls, block):
    calls = spa_calls
    times = pd.date_range("2021-06-21", periods=REMEMBERED_FROM, freq="1min", tz="Asia/Shanghai")
    with block():
        solar_position(times, "nanjing")
        solar_position(times[10:50], "nanjing")
        solar_position(times, "nanjing")
        assert len(calls) == 1
        solar_position(times, "lanzhou")  # another site is another request
        solar_position(times, "nanjing", temperature=30.0)  # and other options
        assert len(calls) == 3
        later = pd.date_range("2021-07-22", periods=5, freq="1min", tz="Asia/Shanghai")
        solar_position(later, "nanjing")  # times it has not seen
        solar_position(later, "nanjing")  # too few to keep: computed again
        assert len(calls) == 5
    solar_position(times, "nanjing")
    assert len(calls) == 6


def test_memory_keeps_only_the_newest_answers(spa_calls):
    calls = spa_calls
    times = pd.date_range("2021-06-21", periods=REMEMBERED_FROM, freq="1min", tz="UTC")
    with reuse_positions(entries=2):
        for temperature in (10.0, 20.0, 30.0, 10.0):
            solar_position(times, "nanjing", temperature=temperature)
    assert len(calls) == 4  # the first answer was forgotten by the time it was asked again


def test_a_remembered_answer_serves_an_increasing_subset_and_refuses_a_stranger():
    from hybridtrack.sun import _positions

    known = pd.date_range("2021-06-21", periods=10, freq="1min", tz="Asia/Shanghai")
    np.testing.assert_array_equal(_positions(known, known[[1, 4, 9]]), [1, 4, 9])
    np.testing.assert_array_equal(_positions(known, known[[1, 4]].tz_convert("UTC").as_unit("us")), [1, 4])
    assert _positions(known, known[[2]] + pd.Timedelta(seconds=1)) is None
    assert _positions(known, pd.DatetimeIndex([known[-1] + pd.Timedelta(minutes=1)])) is None
    np.testing.assert_array_equal(_positions(known, known[[4, 1]]), [4, 1])  # not increasing: by hash


def test_a_block_inside_another_shares_its_memory():
    times = pd.date_range("2021-06-21", periods=REMEMBERED_FROM, freq="1min", tz="Asia/Shanghai")
    with reuse_positions():
        first = solar_position(times, "lanzhou", "spa")
        with reuse_positions():
            again = solar_position(times[10:20], "lanzhou", "spa")
            with pytest.MonkeyPatch.context() as patch:  # answered from memory: pvlib is not asked
                patch.setattr(pvlib.solarposition, "spa_python", None)
                pd.testing.assert_frame_equal(solar_position(times, "lanzhou", "spa"), first)
    pd.testing.assert_frame_equal(again, first.iloc[10:20])


def test_an_answer_remembered_after_another_of_the_same_request_is_recalled():
    """Two threads of a field may each remember an answer to one request; recalling the later
    must not compare the two entries' frames (pandas refuses frames on other indexes)."""
    from hybridtrack.sun import _remember

    times = pd.date_range("2021-06-21", periods=REMEMBERED_FROM, freq="1min", tz="UTC")
    later = times + pd.Timedelta(days=30)
    with reuse_positions():
        solar_position(times, "nanjing", "plc")
        fresh = solar_position(later, "nanjing", "plc")
        key = ("plc", get("nanjing"), 12.0, "wang-liu", "wang-liu")
        _remember(key, fresh)  # remembered again, as a second thread would
        pd.testing.assert_frame_equal(solar_position(later[5:9], "nanjing", "plc"), fresh.iloc[5:9])
