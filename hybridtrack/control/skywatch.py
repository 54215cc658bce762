"""The sky class, as the controller works it out from its own sensor's photocurrent.

The photocurrent depends on where the collector points (the sensor rides on it), so the
controller classifies it scan by scan, with the inputs `hybridtrack.skyinputs` defines (by
default the light relative to the clear sky it expects, and its range over a trailing window,
kept with two monotonic queues), and the classifier runs as a lookup table over its
normalised inputs with bilinear interpolation. PLC fuzzy function blocks are commonly compiled
to such tables (IEC 61131-7 leaves the inference method to the implementation); the table's
largest score error against the exact engine is measured in the tests and stated in the docs.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from .modes import UNKNOWN, sky_code

__all__ = ["ClassifierTable", "SkyWatch", "TrailingRange", "TrailingMean"]

#: Tables already made, by (classifier type, config, points): a year's run and its warm-up day share one.
_TABLES: dict = {}


class ClassifierTable:
    """A fuzzy classifier tabulated on a grid of its normalised inputs (0-10 each).

    Parameters
    ----------
    classifier : FuzzyWeatherClassifier
    points : int
        Grid points along each input.
    """

    def __init__(self, classifier, points: int = 201):
        key = (type(classifier), classifier.config, points)
        if key not in _TABLES:
            grid = np.linspace(0.0, 10.0, points)
            x, y = np.meshgrid(grid, grid, indexing="ij")
            scores = np.asarray(classifier.score(x.ravel(), y.ravel(), raw=False), float)
            if len(_TABLES) >= 16:
                _TABLES.pop(next(iter(_TABLES)))
            _TABLES[key] = scores.reshape(points, points).tolist()
        self.scores = _TABLES[key]
        self.step = 10.0 / (points - 1)
        self.last = points - 1
        inputs = classifier.config.inputs
        self.ranges = [tuple(var.raw_range) for var in inputs]
        bands = classifier.config.bands
        self.edges = [band[2] for band in bands[:-1]]
        self.codes = [sky_code(b[0], UNKNOWN) for b in bands]

    def _normalised(self, value: float, which: int) -> float:
        lo, hi = self.ranges[which]
        return min(max(10.0 * (value - lo) / (hi - lo), 0.0), 10.0) / self.step

    def score(self, intensity: float, variation: float) -> float:
        """The classifier's score, bilinear between grid points; NaN for a NaN reading."""
        if math.isnan(intensity) or math.isnan(variation):
            return math.nan
        u, v = self._normalised(intensity, 0), self._normalised(variation, 1)
        i, j = min(int(u), self.last - 1), min(int(v), self.last - 1)
        fu, fv = u - i, v - j
        row0, row1 = self.scores[i], self.scores[i + 1]
        return ((1.0 - fu) * ((1.0 - fv) * row0[j] + fv * row0[j + 1])
                + fu * ((1.0 - fv) * row1[j] + fv * row1[j + 1]))

    def code(self, score: float) -> int:
        """The sky code of a score by the config's bands."""
        if math.isnan(score):
            return UNKNOWN
        for edge, code in zip(self.edges, self.codes):
            if score < edge:
                return code
        return self.codes[-1]


class TrailingRange:
    """Max − min over a trailing window (t − window, t], NaN readings skipped: two monotonic queues."""

    __slots__ = ("window", "highs", "lows")

    def __init__(self, window: float):
        self.window = window
        self.highs: deque = deque()
        self.lows: deque = deque()

    def add(self, t: float, value: float) -> float:
        """Take a value at time `t`; return the range over the window ending at `t` (NaN if empty)."""
        highs, lows = self.highs, self.lows
        if not math.isnan(value):
            while highs and highs[-1][1] <= value:
                highs.pop()
            highs.append((t, value))
            while lows and lows[-1][1] >= value:
                lows.pop()
            lows.append((t, value))
        start = t - self.window
        while highs and highs[0][0] <= start:
            highs.popleft()
        while lows and lows[0][0] <= start:
            lows.popleft()
        return highs[0][1] - lows[0][1] if highs else math.nan


class TrailingMean:
    """The mean over a trailing window (t − window, t], NaN readings skipped."""

    __slots__ = ("window", "values", "total")

    def __init__(self, window: float):
        self.window = window
        self.values: deque = deque()
        self.total = 0.0

    def add(self, t: float, value: float) -> float:
        """Take a value at time `t`; return the mean over the window ending at `t` (NaN if empty)."""
        values = self.values
        if not math.isnan(value):
            values.append((t, value))
            self.total += value
        start = t - self.window
        while values and values[0][0] <= start:
            self.total -= values.popleft()[1]
        if not values:
            self.total = 0.0
            return math.nan
        return self.total / len(values)


class SkyWatch:
    """Photocurrent in, sky class out, as `hybridtrack.skyinputs.sky_inputs` defines the inputs.

    ``absolute`` mode: the photocurrent (its trailing `smoothing` mean) and its range over the
    trailing window. ``relative`` mode: the light over the clear-sky light the controller expects
    at that time and place (capped at 1), put on the classifier's mA scale, and its range; below
    `min_altitude` of computed sun the absolute inputs (or no label) are used instead.

    Parameters
    ----------
    table : ClassifierTable
    inputs : SkyInputConfig
        The input choices (mode, window, smoothing, low-sun rule, scales).
    dark_current : float
        mA: the sensor's datasheet dark current.
    """

    __slots__ = ("table", "inputs", "dark", "mean", "absolute_range", "relative_range", "window_minutes")

    def __init__(self, table: ClassifierTable, inputs, dark_current: float):
        import pandas as pd

        self.table = table
        self.inputs = inputs
        self.dark = dark_current
        window = pd.Timedelta(inputs.window) / pd.Timedelta(minutes=1)
        smoothing = pd.Timedelta(inputs.smoothing) / pd.Timedelta(minutes=1) if inputs.smoothing else 0.0
        self.mean = TrailingMean(smoothing) if smoothing else None
        self.absolute_range = TrailingRange(window)
        self.relative_range = TrailingRange(window)
        self.window_minutes = window

    def inputs_at(self, t: float, intensity: float, expected: float, altitude: float) -> tuple[float, float]:
        """The classifier's two inputs (mA scale) for the photocurrent at scan time `t`, with the
        clear-sky light above dark the controller `expected` and its computed sun's `altitude`."""
        settings = self.inputs
        absolute = self.mean.add(t, intensity) if self.mean is not None else intensity
        absolute_variation = self.absolute_range.add(t, absolute)
        if settings.mode == "absolute":
            return absolute, absolute_variation
        low = not (altitude >= settings.min_altitude) or not expected > 0
        relative = math.nan if low else min((absolute - self.dark) / expected, 1.0)
        relative_variation = self.relative_range.add(t, relative)
        if low:
            return (absolute, absolute_variation) if settings.low_sun == "absolute" else (math.nan, math.nan)
        (lo, hi), (vlo, vhi) = self.table.ranges
        floor = settings.relative_floor
        share = min(max((relative - floor) / (1.0 - floor), 0.0), 1.0)
        return lo + (hi - lo) * share, vlo + (vhi - vlo) * relative_variation / settings.full_variation

    def update(self, t: float, intensity: float, expected: float, altitude: float) -> tuple[int, float, float]:
        """Take the photocurrent at scan time `t`; return (sky code, score, variation input)."""
        level, variation = self.inputs_at(t, intensity, expected, altitude)
        score = self.table.score(level, variation)
        return self.table.code(score), score, variation
