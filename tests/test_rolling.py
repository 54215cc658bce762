"""The compiled trailing range against pandas' rolling max less min (its reference)."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack.errors import HybridtrackError
from hybridtrack.rolling import _range_pass_python, trailing_range


def _series(seed, n=3000, nan_share=0.1, irregular=True):
    rng = np.random.default_rng(seed)
    steps = rng.choice([0, 30, 60, 60, 60, 90, 600, 3600], size=n) if irregular else np.full(n, 60)  # 0: a repeat
    index = pd.Timestamp("2021-06-01", tz="Asia/Shanghai") + pd.to_timedelta(np.cumsum(steps), unit="s")
    values = np.round(rng.normal(100.0, 30.0, n), 1)  # rounded: ties, which the deques must keep right
    values[rng.random(n) < nan_share] = np.nan
    return pd.Series(values, index=index, name="intensity_ma")


def _pandas(values, window):
    rolling = values.rolling(pd.Timedelta(window), min_periods=1)
    return rolling.max() - rolling.min()


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("window", ["1min", "20min", "2h"])
def test_compiled_range_is_pandas_bit_for_bit(seed, window):
    values = _series(seed, irregular=seed % 2 == 0, nan_share=0.1 * (seed % 3))
    expected = _pandas(values, window)
    _same_bits(trailing_range(values, window, engine="compiled"), expected)
    _same_bits(trailing_range(values, window, engine="pandas"), expected)


def _same_bits(got, expected):
    pd.testing.assert_series_equal(got, expected, check_exact=True)
    assert np.array_equal(got.to_numpy().view(np.int64), expected.to_numpy().view(np.int64))  # NaN's sign too


@pytest.mark.parametrize("seed", range(4))
def test_infinite_values_are_missing_as_in_pandas(seed):
    values = _series(seed, n=400)
    rng = np.random.default_rng(seed)
    values[rng.random(len(values)) < 0.15] = np.inf
    values[rng.random(len(values)) < 0.15] = -np.inf
    for window in ("1min", "20min"):
        _same_bits(trailing_range(values, window, engine="compiled"), _pandas(values, window))
    runs = pd.Series([np.inf, -np.inf] * 3 + [1.0, np.nan, np.inf], index=values.index[:9])
    _same_bits(trailing_range(runs, "3min", engine="compiled"), _pandas(runs, "3min"))


@pytest.mark.parametrize("unit", ["s", "ms", "us", "ns"])
@pytest.mark.parametrize("window", ["1ns", "1500ms", "0min", "-5min", pd.Timedelta.max])
def test_odd_windows_and_units_are_pandas(unit, window):
    index = pd.date_range("1900-01-01", periods=40, freq="1s", unit=unit).repeat(2)  # repeated stamps
    values = pd.Series(np.random.default_rng(1).normal(size=80).round(1), index=index)
    values.iloc[[3, 4, 5]] = np.nan
    _same_bits(trailing_range(values, window, engine="compiled"), _pandas(values, window))


def test_a_frame_is_left_to_pandas():
    values = _series(4, n=100).to_frame()
    pd.testing.assert_frame_equal(trailing_range(values, "20min", engine="compiled"), _pandas(values, "20min"))


def test_python_pass_is_the_compiled_pass():
    values = _series(7)
    stamps = values.index.as_unit("ns").asi8
    width = pd.Timedelta("20min").value
    from hybridtrack.rolling import _range_pass
    np.testing.assert_array_equal(_range_pass_python(stamps, values.to_numpy(), width),
                                  _range_pass(stamps, values.to_numpy(), width))


def test_hand_computed_window_and_nan_runs():
    index = pd.date_range("2021-01-01 10:00", periods=7, freq="10min", tz="UTC")
    values = pd.Series([5.0, 1.0, np.nan, np.nan, np.nan, 4.0, 2.0], index=index)
    # window (t − 20 min, t]: the stamp itself and the one before it
    got = trailing_range(values, "20min", engine="compiled").to_numpy()
    np.testing.assert_array_equal(got, [0.0, 4.0, 0.0, np.nan, np.nan, 0.0, 2.0])


def test_an_index_not_ascending_is_left_to_pandas():
    values = _series(3, n=50, nan_share=0.0).iloc[::-1]
    pd.testing.assert_series_equal(trailing_range(values, "20min", engine="compiled"), _pandas(values, "20min"))


def test_unknown_engine_is_refused():
    with pytest.raises(HybridtrackError, match="unknown engine 'fast'"):
        trailing_range(_series(0, n=10), "20min", engine="fast")


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("window", [1.0, 3.0, 20.0])
def test_the_controllers_own_trailing_range_and_mean_are_pandas(seed, window):
    """The reference controller's sky watch keeps its own windows (`control.skywatch.TrailingRange`,
    `TrailingMean`, scan by scan in minutes); the compiled kernel is tested against them, and they
    against pandas' rolling max − min and mean over (t − window, t] here. Stamps are whole and
    half minutes, exact in binary, so no window edge is a matter of rounding."""
    from hybridtrack.control.skywatch import TrailingMean, TrailingRange

    rng = np.random.default_rng(seed)
    minutes = np.cumsum(rng.choice([0.5, 1.0, 1.0, 1.5, 2.0, 30.0], size=600))
    values = np.round(rng.normal(100.0, 30.0, 600), 1)  # rounded: ties
    values[rng.random(600) < 0.15] = np.nan
    values[100:140] = np.nan  # a run longer than every window: empty windows
    spread, mean = TrailingRange(window), TrailingMean(window)
    got_range = np.array([spread.add(t, v) for t, v in zip(minutes, values)])
    got_mean = np.array([mean.add(t, v) for t, v in zip(minutes, values)])
    series = pd.Series(values, index=pd.Timestamp("2021-06-21") + pd.to_timedelta(minutes, unit="min"))
    rolling = series.rolling(pd.Timedelta(minutes=window), min_periods=1)
    np.testing.assert_array_equal(got_range, (rolling.max() - rolling.min()).to_numpy())
    np.testing.assert_allclose(got_mean, rolling.mean().to_numpy(), rtol=1e-12, atol=1e-9)
    assert np.isnan(got_range).any() and not np.isnan(got_range).all()
