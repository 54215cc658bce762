"""Numbers checked at the door: finite, within a physical range, whole where they count;
durations positive.

Each helper returns the value in its plain Python type, or raises `HybridtrackError` naming
the parameter, its range and the value given; config classes, CLI flags and API arguments
share them so that the same mistake reads the same everywhere.
"""

from __future__ import annotations

import math
import numbers
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import HybridtrackError

__all__ = ["number", "whole", "seed", "duration", "refuse_unitless", "LONGEST_DURATION", "angle_pair"]

#: The largest seed: numpy's generators take any non-negative integer; this keeps it in 64 bits.
MAX_SEED = 2**63 - 1


def _range(low: float, high: float, above: bool) -> str:
    opening = "(" if above else "["
    return f"{opening}{low:g}, {high:g}]"


def number(value, name: str, low: float = -math.inf, high: float = math.inf, *, above: bool = False) -> float:
    """`value` as a float, refused unless a finite real number within [`low`, `high`].

    Parameters
    ----------
    value : object
    name : str
        Where the value came from, e.g. ``"drive: speed"``.
    low, high : float
        The physical range, inclusive.
    above : bool
        Exclude `low` itself: the value must be greater than it.

    Returns
    -------
    float
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not _finite(value):
        bounded = f" within {_range(low, high, above)}" if math.isfinite(low) or math.isfinite(high) else ""
        raise HybridtrackError(f"{name} must be a finite number{bounded}, got {value!r:.60}")
    if value < low or value > high or (above and value == low):
        raise HybridtrackError(f"{name} = {value!r} is outside {_range(low, high, above)}")
    return float(value)


def _finite(value: numbers.Real) -> bool:
    """Whether `value` is a finite float: an integer past any float (10**400) is not, where
    `math.isfinite` raised OverflowError."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def whole(value, name: str, least: int = 0, most: int = 10_000) -> int:
    """`value` as an int, refused unless a whole number (not a float) within [`least`, `most`]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not least <= value <= most:
        raise HybridtrackError(f"{name} must be a whole number within [{least:,}, {most:,}], got {value!r}")
    return int(value)


def seed(value, name: str = "seed") -> int:
    """A random seed: a whole number from 0 to 2**63 - 1."""
    return whole(value, name, 0, MAX_SEED)


#: A day unit written in lower case (``1d``, ``2 d``): pandas 3.1 warns that it will stop reading it.
_LOWER_DAY = re.compile(r"(?<=[0-9. ])d(?![A-Za-z])")


def timedelta(text) -> pd.Timedelta:
    """``pd.Timedelta(text)``, reading a day written ``1d`` as ``1D`` (pandas 3.1 deprecates the
    lower case with a warning that would print beside a command's one line, and pandas 4 will
    refuse it); raises what ``pd.Timedelta`` raises."""
    return pd.Timedelta(_LOWER_DAY.sub("D", text) if isinstance(text, str) else text)


_BARE_NUMBER = re.compile(r"\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*")


def refuse_unitless(value, what: str) -> None:
    """Refuse a duration written as a bare number (``5``, ``"5"``), naming `what`: pandas reads
    one as nanoseconds, so a TOML ``dwell = "5"`` had been a dwell of 5 ns."""
    if (_real(value) and not isinstance(value, np.timedelta64)) or \
            (isinstance(value, str) and _BARE_NUMBER.fullmatch(value)):
        shown = str(value).strip()
        raise HybridtrackError(f"{what} {value!r} has no unit; write it with one, such as '{shown}min' or '{shown}s'")


#: The longest controller or sensor timing `duration` takes: each (a dwell, a hold, a window, a
#: time constant, a distrust) works within the controller's day, whose offsets and windows start
#: afresh each morning; a longer one is a slip of unit (``"400D"`` for ``"400min"``).
LONGEST_DURATION = pd.Timedelta(days=1)


def duration(text, name: str) -> pd.Timedelta:
    """A positive, finite duration with a unit such as ``"20min"``, at most `LONGEST_DURATION`."""
    refuse_unitless(text, name)
    try:
        value = timedelta(text)
    except (TypeError, ValueError, OverflowError):
        value = None
    if value is None or value is pd.NaT or value <= pd.Timedelta(0):
        raise HybridtrackError(f"{name} {text!r} is not a positive duration such as '20min'")
    if value > LONGEST_DURATION:
        raise HybridtrackError(f"{name} {text!r} is longer than a day, the controller's day that every timing "
                               "works within: a slip of unit?")
    return value


def angle_pair(values, name: str, low: float, high: float) -> tuple[float, float]:
    """Two finite angles in increasing order within [`low`, `high`] degrees, e.g. an axis's limits."""
    pair = tuple(values)
    if len(pair) != 2:
        raise HybridtrackError(f"{name} must be [low, high], got {list(pair)!r}")
    first, second = (number(v, name, low, high) for v in pair)
    if not first < second:
        raise HybridtrackError(f"{name} must be [low, high] with low < high, got {list(pair)!r}")
    return first, second


def path(value, what: str) -> Path:
    """`value` (text, bytes or a path) as a Path, refused with `what` unless it is a non-empty path
    without a NUL (which no file system takes: Python raised a ValueError). A leading ``~`` is the
    user's home, as the shell and pandas read it (a folder named ``~`` had been made here, while
    pandas wrote into the home folder's)."""
    if isinstance(value, bytes):
        value = os.fsdecode(value)
    if not isinstance(value, (str, os.PathLike)) or not str(os.fspath(value)).strip():
        raise HybridtrackError(f"{what} must be a path, got {value!r:.80}")
    text = str(os.fspath(value))
    if "\0" in text:
        raise HybridtrackError(f"{what} must be a path, got {text!r:.80}, which holds a NUL character")
    return Path(os.path.expanduser(text))


def real_numbers(dtype) -> bool:
    """Whether a column of `dtype` holds real numbers: numeric, and neither True/False nor complex
    (both pass pandas' ``is_numeric_dtype``)."""
    types = pd.api.types
    return types.is_numeric_dtype(dtype) and not types.is_bool_dtype(dtype) and not types.is_complex_dtype(dtype)


def _real(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def finite_array(values, *, not_numbers: str, infinite: str) -> np.ndarray:
    """`values` (a Series, frame, array, list or number) as a float array of real numbers, NaN
    where a value is missing (a None among numbers in a list too); refused with ``"<not_numbers>, got ..."``
    unless numbers (text, True and complex numbers are not, nor a True among numbers in a list) and
    ``"<infinite>, got inf"`` where one is infinite; a ragged list is no numbers either (numpy
    raised its ValueError)."""
    try:
        array = np.asarray(values.to_numpy() if isinstance(values, (pd.Series, pd.DataFrame)) else values)
    except ValueError:
        raise HybridtrackError(f"{not_numbers}, got {values!r:.60}") from None
    if isinstance(values, (list, tuple)) and any(isinstance(v, (bool, np.bool_))
                                                 for v in np.asarray(values, dtype=object).flat):
        raise HybridtrackError(f"{not_numbers}, got {values!r:.60}")  # numpy read [True, 2.0] as [1.0, 2.0]
    cells = list(array.flat) if array.dtype.kind == "O" else []
    if any(_real(v) for v in cells) and all(_real(v) or v is None for v in cells):
        array = array.astype(float)  # Python's numbers in a list with a None: None is missing (None alone is not)
    if array.dtype.kind not in "fiu":
        raise HybridtrackError(f"{not_numbers}, got {values!r:.60}")
    array = array.astype(float, copy=False)
    if np.isinf(array).any():
        raise HybridtrackError(f"{infinite}, got inf")
    return array

