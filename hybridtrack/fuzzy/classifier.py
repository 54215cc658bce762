"""`FuzzyWeatherClassifier`: photocurrent and its variation in, sky score and label out."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from ..params import finite_array
from .config import FuzzyConfig
from .engine import CompiledSystem, evaluate_fast, evaluate_skfuzzy

__all__ = ["FuzzyWeatherClassifier", "Explanation", "UNKNOWN", "ENGINES", "NEVER_NEGATIVE",
           "refuse_impossible_readings", "impossible_reading", "READING_LIMIT"]

#: The label given when no rule fires or an input is missing.
UNKNOWN = "unknown"
ENGINES = ("fast", "numba", "numpy", "skfuzzy", "skfuzzy-scalar")


@dataclass(frozen=True)
class Explanation:
    """One reading taken apart: normalised inputs, memberships, rule firings, score, label."""

    intensity: float
    variation: float
    normalised: tuple[float, float]
    memberships: dict[str, dict[str, float]]
    rules: list[dict]
    score: float
    weather: str

    def to_dict(self) -> dict:
        """JSON-ready dict: ``{"score", "weather", "rules", ...}`` (NaN score as None)."""
        return {
            "intensity": self.intensity,
            "variation": self.variation,
            "normalised": list(self.normalised),
            "score": None if np.isnan(self.score) else self.score,
            "weather": self.weather,
            "memberships": self.memberships,
            "rules": self.rules,
        }

    def __str__(self) -> str:
        lines = [f"score {self.score:.3f} -> {self.weather}" if not np.isnan(self.score)
                 else f"score undefined (no rule fires) -> {self.weather}"]
        for var, terms in self.memberships.items():
            lines.append(f"  {var}: " + ", ".join(f"{t} {m:.3f}" for t, m in terms.items()))
        lines += [f"  rule {r['rule']}: {r['text']}  fires {r['firing']:.3f}" for r in self.rules]
        return "\n".join(lines)


#: Why a raw reading is never below zero, by input.
NEVER_NEGATIVE = {"intensity": "a photocurrent in mA is never below zero",
                  "variation": "a variation is a range, max - min, never below zero"}
#: mA: more than any sun sensor's photocurrent, or its range, can be: ten times a 10,000 mA
#: reader's limit. A reading past it is a unit mixed up (µA read as mA) or garbage (1e308 mA
#: had been taken as the brightest sun); a weather frame's photocurrent is held to it too.
READING_LIMIT = 100_000.0


def impossible_reading(value: float, name: str) -> str | None:
    """Why a raw reading of input `name` (``intensity`` or ``variation``) is none a sensor gives,
    or None for a possible one (NaN, no reading, included)."""
    if value < 0.0:
        return NEVER_NEGATIVE[name]
    if value > READING_LIMIT:
        return f"over {READING_LIMIT:,.0f} mA, which no sun sensor gives (a unit mixed up?)"
    return None


def refuse_impossible_readings(frame: pd.DataFrame, columns, where: str) -> None:
    """Refuse a table's first raw reading no sensor gives (`impossible_reading`), by its row and
    column: the earliest row, intensity before variation within it.

    Parameters
    ----------
    frame : pandas.DataFrame
        Readings as numbers (`hybridtrack.io.numeric_columns`).
    columns : sequence of str
        The intensity and variation columns, in that order.
    where : str
        The file, for the message.
    """
    from ..io import table_row

    columns = list(columns)
    values = frame[columns].to_numpy(float)
    with np.errstate(invalid="ignore"):
        bad = np.argwhere((values < 0.0) | (values > READING_LIMIT))
    if len(bad):
        row, k = (int(i) for i in bad[0])
        raise HybridtrackError(f"{where}: row {table_row(frame, row)}, column {columns[k]!r}: {values[row, k]:g} is "
                               f"no reading; {impossible_reading(values[row, k], list(NEVER_NEGATIVE)[k])}")


def _readings(values, name: str) -> np.ndarray:
    """`values` as a float array of readings: real numbers, NaN where there is no reading. Text
    ('246'), True and an infinite reading had been taken (inf mA as the brightest sun). A reading
    below zero is clipped onto the input's range, as any reading past it: a recorded photocurrent
    below zero is a logger's offset a run survives (`hybridtrack.faults`); the command line, where
    a person types or files readings, refuses it (`refuse_impossible_readings`)."""
    return finite_array(values, not_numbers=f"{name} must be numbers (NaN where there is no reading)",
                        infinite=f"{name} must be finite (NaN where there is no reading)")


class FuzzyWeatherClassifier:
    """Mamdani classifier of the sky from a sun sensor's light (docs/fuzzy-engine.md).

    Parameters
    ----------
    config : FuzzyConfig, optional
        The system; the published one by default.

    Examples
    --------
    >>> clf = FuzzyWeatherClassifier()
    >>> clf.classify(246.0, 27.0)
    'sunny'
    """

    def __init__(self, config: FuzzyConfig | None = None):
        self.config = config if config is not None else FuzzyConfig.default()
        self._system = CompiledSystem(self.config)

    # -- inputs ------------------------------------------------------------------------------

    def normalise(self, intensity, variation) -> np.ndarray:
        """Raw readings (mA) onto the input universes, clipped: ``10 (P - Pmin)/(Pmax - Pmin)``."""
        columns = [var.to_universe(values) for var, values in zip(self.config.inputs, (intensity, variation))]
        return np.stack(np.broadcast_arrays(*columns), axis=-1)

    def _prepare(self, intensity, variation, raw: bool) -> tuple[np.ndarray, tuple]:
        if isinstance(intensity, pd.Series) and isinstance(variation, pd.Series) and \
                not intensity.index.equals(variation.index):
            raise HybridtrackError("intensity and variation are Series on different indexes; align them first "
                                   "(numpy would pair them by position)")
        readings = _readings(intensity, "intensity"), _readings(variation, "variation")
        try:
            a, b = np.broadcast_arrays(*readings)
        except ValueError as exc:
            raise HybridtrackError(f"intensity and variation must be numbers of matching shape: {exc}") from None
        if raw:
            if self.config.labelled_range is not None:  # a tuned config: say when it extrapolates
                from .tuning import warn_outside_labels

                warn_outside_labels(self.config, a, b)
            x = self.normalise(a, b)
        else:
            x = np.stack([np.clip(a, *self.config.inputs[0].universe), np.clip(b, *self.config.inputs[1].universe)],
                         axis=-1)
        return x.reshape(-1, 2), a.shape

    @staticmethod
    def _wrap(values: np.ndarray, shape: tuple, template, name: str):
        out = values.reshape(shape)
        if isinstance(template, pd.Series):
            return pd.Series(out, index=template.index, name=name)
        if shape == ():
            return out.item()
        return out

    # -- outputs -----------------------------------------------------------------------------

    def score(self, intensity, variation, *, raw: bool = True, engine: str = "fast"):
        """Crisp weather score(s) in the output universe (0-30); NaN where no rule fires.

        Parameters
        ----------
        intensity, variation : float, array_like or pandas.Series
            Sensor photocurrent and its variation: raw mA when `raw`, else normalised 0-10.
        raw : bool
            Whether the inputs are raw readings to normalise with the config's ranges.
        engine : {"fast", "numba", "numpy", "skfuzzy", "skfuzzy-scalar"}
            ``fast``: the compiled engine, or numpy where numba is missing; ``numba`` and
            ``numpy``: that one; ``skfuzzy``: scikit-fuzzy's control API with array inputs
            (the reference); ``skfuzzy-scalar``: scikit-fuzzy one reading at a time.

        Returns
        -------
        float, ndarray or pandas.Series
            Shaped like the inputs; a Series keeps its index.
        """
        x, shape = self._prepare(intensity, variation, raw)
        if engine in ("fast", "numba", "numpy"):
            scores, _ = evaluate_fast(self._system, x, engine="auto" if engine == "fast" else engine,
                                      with_firing=False)
        elif engine in ("skfuzzy", "skfuzzy-scalar"):
            scores = evaluate_skfuzzy(self.config, x, one_at_a_time=engine == "skfuzzy-scalar")
        else:
            raise HybridtrackError(f"unknown engine {engine!r}; choose from {', '.join(ENGINES)}")
        template = intensity if isinstance(intensity, pd.Series) else variation
        return self._wrap(scores, shape, template, "sky_score")

    def label_codes(self, scores) -> tuple[np.ndarray, tuple[str, ...]]:
        """Each score's label as a code into the names returned with it (the config's bands,
        then ``unknown`` for NaN): `label` without building a string per score."""
        values = np.asarray(scores, float)
        names = tuple(band[0] for band in self.config.bands) + (UNKNOWN,)
        edges = np.array([band[2] for band in self.config.bands[:-1]])
        index = np.searchsorted(edges, values, side="right")
        return np.where(np.isnan(values), len(names) - 1, index), names

    def label(self, scores):
        """Weather label of each score by the config's bands; ``unknown`` for NaN."""
        values = np.asarray(scores, float)
        index, names = self.label_codes(values)
        names = np.array(names, dtype=object)
        if values.ndim == 0:
            return str(names[int(index)])
        labels = names[index]
        if isinstance(scores, pd.Series):
            return pd.Series(labels, index=scores.index, name="sky")
        return labels

    def classify(self, intensity, variation, *, raw: bool = True, engine: str = "fast"):
        """Weather label(s): ``sunny``, ``cloudy``, ``overcast`` (the bands'), or ``unknown``."""
        return self.label(self.score(intensity, variation, raw=raw, engine=engine))

    def firing(self, intensity, variation, *, raw: bool = True) -> np.ndarray:
        """Firing strength of every rule, shape (N, rules)."""
        x, _ = self._prepare(intensity, variation, raw)
        return evaluate_fast(self._system, x)[1]

    def explain(self, intensity: float, variation: float, *, raw: bool = True) -> Explanation:
        """Take one reading apart: memberships, each rule's firing, score and label."""
        x, _ = self._prepare(intensity, variation, raw)
        x = x[:1]
        score_value, firing = evaluate_fast(self._system, x)
        mu = self._system.memberships(x)
        memberships = {var.name: {t: float(m) for t, m in zip(var.term_names, mu[i][0])}
                       for i, var in enumerate(self.config.inputs)}
        names = self.config.input_names
        rules = [{"rule": n, "text": rule.describe(names), "when": rule.conditions, "then": rule.then,
                  "firing": float(firing[0, n - 1])} for n, rule in enumerate(self.config.rules, start=1)]
        score_value = float(score_value[0])
        return Explanation(float(intensity), float(variation), (float(x[0, 0]), float(x[0, 1])),
                           memberships, rules, score_value, self.label(score_value))
