"""The sky class, as the controller works it out from its own sensor's photocurrent.

The photocurrent depends on where the collector points (the sensor rides on it), so the
controller classifies it scan by scan: the variation is the range (max − min) over a trailing
window, kept with two monotonic queues, and the classifier runs as a lookup table over its
normalised inputs with bilinear interpolation. PLC fuzzy function blocks are commonly compiled
to such tables (IEC 61131-7 leaves the inference method to the implementation); the table's
largest score error against the exact engine is measured in the tests and stated in the docs.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from .modes import SKY_CODES, UNKNOWN

__all__ = ["ClassifierTable", "SkyWatch"]

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
        self.codes = [SKY_CODES.index(b[0]) if b[0] in SKY_CODES else UNKNOWN for b in bands]

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


class SkyWatch:
    """Photocurrent in, sky class out: a trailing-window range, then the tabulated classifier."""

    __slots__ = ("table", "window", "highs", "lows")

    def __init__(self, table: ClassifierTable, window_minutes: float):
        self.table = table
        self.window = window_minutes
        self.highs: deque = deque()
        self.lows: deque = deque()

    def update(self, t: float, intensity: float) -> tuple[int, float, float]:
        """Take the photocurrent at scan time `t`; return (sky code, score, variation)."""
        highs, lows = self.highs, self.lows
        if not math.isnan(intensity):
            while highs and highs[-1][1] <= intensity:
                highs.pop()
            highs.append((t, intensity))
            while lows and lows[-1][1] >= intensity:
                lows.pop()
            lows.append((t, intensity))
        start = t - self.window
        while highs and highs[0][0] <= start:
            highs.popleft()
        while lows and lows[0][0] <= start:
            lows.popleft()
        variation = highs[0][1] - lows[0][1] if highs else math.nan
        score = self.table.score(intensity, variation)
        return self.table.code(score), score, variation
