"""A trailing time window's range (max − min), compiled where numba is installed.

The sky's variation input is the range of the photocurrent over a trailing time window
(`hybridtrack.skyinputs`). pandas computes it as ``rolling(window).max() - rolling(window).min()``:
two passes, each finding the window's bounds again, about 40 ms a site-year at 1-minute steps,
twice per run. `trailing_range` finds the bounds once and keeps both extremes in monotonic
deques (Lemire 2006), in one compiled pass. It takes the same window as pandas (right-closed,
``(t − window, t]`` in the index's own unit, stamps ascending), skips NaN and ±inf as pandas does
and is NaN where the window has no value, so it returns the same numbers; a test holds the two
equal bit for bit. Without numba, for a DataFrame, or on an index that is not ascending, it is
pandas' own.

References
----------
Lemire, D. (2006). Streaming maximum-minimum filter using no more than three comparisons per
element. Nordic Journal of Computing 13(4), 328-339. arXiv:cs/0610046
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .errors import HybridtrackError

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the fallback is tested by asking for pandas
    numba = None

__all__ = ["trailing_range", "ENGINES"]

ENGINES = ("auto", "compiled", "pandas")


def trailing_range(values: pd.Series, window: str | pd.Timedelta, *, engine: str = "auto") -> pd.Series:
    """max − min of `values` over the trailing time window ``(t − window, t]`` at every stamp.

    Parameters
    ----------
    values : pandas.Series
        On a DatetimeIndex; NaN and ±inf are skipped (as pandas' rolling skips them).
    window : str or pandas.Timedelta
        The window's length, e.g. ``"20min"``.
    engine : {"auto", "compiled", "pandas"}
        ``pandas``: ``rolling(window, min_periods=1)``'s max less its min; ``compiled`` the same
        numbers in one pass (numba); ``auto`` compiled where it can be.

    Returns
    -------
    pandas.Series
        NaN where the window holds no value.

    References
    ----------
    Lemire, D. (2006). Streaming maximum-minimum filter using no more than three comparisons
    per element. Nordic Journal of Computing 13(4), 328-339. arXiv:cs/0610046
    """
    if engine not in ENGINES:
        raise HybridtrackError(f"unknown engine {engine!r}; choose {', '.join(ENGINES)}")
    width = pd.Timedelta(window)
    index = values.index
    compiled = engine == "compiled" or (engine == "auto" and numba is not None)
    if not (compiled and isinstance(values, pd.Series) and isinstance(index, pd.DatetimeIndex)
            and index.is_monotonic_increasing):
        rolling = values.rolling(width, min_periods=1)
        return rolling.max() - rolling.min()
    # pandas takes the window in the index's unit, truncated: 1500 ms is 1 s on an index of seconds
    in_unit = pd.Timedelta(width.value).as_unit(index.unit).value
    spread = _range_pass(index.as_unit("ns").asi8, values.to_numpy(float), in_unit)
    return pd.Series(spread, index=index, name=values.name)


def _range_pass_python(stamps: np.ndarray, values: np.ndarray, width: int) -> np.ndarray:
    """The window's max − min at every stamp: the window's start moves up as the stamps pass
    it (never past the stamp itself, as in pandas); each deque keeps the indexes of values that
    may yet be the window's max (min), in order, so its front is the extreme. Infinite values
    are missing, as pandas' rolling takes them."""
    n = values.shape[0]
    out = np.empty(n)
    highs, lows = np.empty(n, np.int64), np.empty(n, np.int64)
    high_front = high_back = low_front = low_back = 0  # each deque is [front, back)
    start = 0
    for i in range(n):
        value = values[i]
        if np.isfinite(value):
            while high_back > high_front and values[highs[high_back - 1]] <= value:
                high_back -= 1
            highs[high_back] = i
            high_back += 1
            while low_back > low_front and values[lows[low_back - 1]] >= value:
                low_back -= 1
            lows[low_back] = i
            low_back += 1
        while start < i and stamps[i] - stamps[start] >= width:
            start += 1
        while high_back > high_front and highs[high_front] < start:
            high_front += 1
        while low_back > low_front and lows[low_front] < start:
            low_front += 1
        out[i] = values[highs[high_front]] - values[lows[low_front]] if high_back > high_front else np.nan
    return out


_range_pass = _range_pass_python if numba is None else numba.njit(cache=True, nogil=True)(_range_pass_python)
