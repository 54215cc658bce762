"""Fitting the input membership functions to labelled readings.

Samples are rows of raw ``intensity`` and ``variation`` (mA) with a target ``weather`` label,
a target ``score``, or both. The loss is the mean squared score error against target
scores. Against labels it is a squared hinge: zero once the score sits inside its label's
band by `margin` units, growing with the distance outside, plus one for every wrong label
(so the fit cannot park scores just across a band edge). A reading that fires no rule
costs as much as being a whole band off. The input terms' parameters are optimised
derivative-free (differential evolution, then bounded Powell) in a parameterisation that keeps every term valid:
centres stay inside the universe and in their original order, widths stay positive, and
triangle and trapezoid corners stay sorted. The output terms, bands and rules are left as
they are.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .classifier import FuzzyWeatherClassifier
from .config import FuzzyConfig, Term

__all__ = ["tune", "TuningReport", "read_samples", "evaluate"]


@dataclass(frozen=True)
class TuningReport:
    """How well a config fits the samples, before and after tuning."""

    samples: int
    accuracy_before: float | None
    accuracy_after: float | None
    rmse_before: float | None
    rmse_after: float | None
    loss_before: float
    loss_after: float
    evaluations: int
    changed: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Plain dict, JSON-ready."""
        return dict(self.__dict__)

    def __str__(self) -> str:
        def fmt(value, spec):
            return "-" if value is None else format(value, spec)

        return "\n".join([
            f"{self.samples} samples, {self.evaluations} evaluations",
            f"  label accuracy  {fmt(self.accuracy_before, '.1%'):>8} -> {fmt(self.accuracy_after, '.1%')}",
            f"  score RMSE      {fmt(self.rmse_before, '.3f'):>8} -> {fmt(self.rmse_after, '.3f')}",
            f"  loss            {self.loss_before:>8.4f} -> {self.loss_after:.4f}",
        ])


def read_samples(source) -> pd.DataFrame:
    """Labelled readings from a CSV path or a DataFrame, checked.

    Columns: ``intensity``, ``variation`` (raw mA), and ``weather`` and/or ``score``;
    optional ``tolerance`` (used by rule-table tests).
    """
    if isinstance(source, pd.DataFrame):
        frame, where = source.copy(), "samples"
    else:
        from ..io import read_table

        frame, where = read_table(source), str(source)
    missing = [c for c in ("intensity", "variation") if c not in frame.columns]
    if missing:
        raise HybridtrackError(f"{where}: missing column {missing[0]!r} (need intensity, variation and weather or score)")
    if "weather" not in frame.columns and "score" not in frame.columns:
        raise HybridtrackError(f"{where}: needs a 'weather' or a 'score' column to fit to")
    if frame.empty:
        raise HybridtrackError(f"{where}: no rows")
    from ..io import numeric_columns

    return numeric_columns(frame, ("intensity", "variation", "score", "tolerance"), where)


def evaluate(config: FuzzyConfig, samples: pd.DataFrame, margin: float = 0.5) -> dict:
    """Loss, label accuracy and score RMSE of `config` on checked `samples`."""
    clf = FuzzyWeatherClassifier(config)
    scores = clf.score(samples["intensity"].to_numpy(), samples["variation"].to_numpy())
    return _metrics(clf, config, scores, samples, margin)


def _metrics(clf, config, scores, samples, margin) -> dict:
    span = config.output.universe[1] - config.output.universe[0]
    penalty = (span / len(config.bands)) ** 2
    losses = []
    out = {"accuracy": None, "rmse": None}
    if "score" in samples.columns:
        target = samples["score"].to_numpy(float)
        err = np.where(np.isnan(scores), np.sqrt(penalty), scores - target)
        losses.append(err**2)
        out["rmse"] = float(np.sqrt(np.mean(err**2)))
    if "weather" in samples.columns:
        bands = {name: (lo, hi) for name, lo, hi in config.bands}
        labels = samples["weather"].astype(str).str.strip().str.lower().to_numpy()
        unknown = sorted(set(labels) - set(bands))
        if unknown:
            raise HybridtrackError(f"samples: unknown weather label {unknown[0]!r}; the bands are {', '.join(bands)}")
        lo = np.array([bands[label][0] for label in labels]) + margin
        hi = np.array([bands[label][1] for label in labels]) - margin
        outside = np.maximum(lo - scores, 0.0) + np.maximum(scores - hi, 0.0)
        wrong = clf.label(scores) != labels
        # a wrong label costs a unit on top of its distance: a score parked just across a
        # band edge is nearly free to a squared hinge, but it is still a wrong answer
        losses.append(np.where(np.isnan(scores), penalty, outside**2 + wrong))
        out["accuracy"] = float(np.mean(~wrong))
    out["loss"] = float(np.mean(np.sum(losses, axis=0)))
    return out


class _Parameterisation:
    """Maps a free vector in [0, 1]^n to valid, ordered input terms (and back)."""

    def __init__(self, config: FuzzyConfig):
        self.config = config
        self.slots = []  # (input index, term index)
        for i, var in enumerate(config.inputs):
            for j, term in enumerate(var.terms):
                self.slots.append((i, j, term.shape))

    def _width(self, i: int) -> float:
        lo, hi = self.config.inputs[i].universe
        return hi - lo

    def encode(self, config: FuzzyConfig) -> np.ndarray:
        values = []
        for i, j, shape in self.slots:
            lo, _ = config.inputs[i].universe
            w = self._width(i)
            p = config.inputs[i].terms[j].params
            if shape == "gaussmf":
                values += [(p[0] - lo) / w, np.log(p[1] / (0.02 * w)) / np.log(50.0)]
            elif shape == "gauss2mf":
                values += [(p[0] - lo) / w, np.log(p[1] / (0.02 * w)) / np.log(50.0),
                           (p[2] - lo) / w, np.log(p[3] / (0.02 * w)) / np.log(50.0)]
            else:
                values += [(v - lo) / w for v in p]
        return np.clip(np.array(values), 0.0, 1.0)

    def decode(self, vector: np.ndarray) -> FuzzyConfig:
        vector = np.clip(vector, 0.0, 1.0)
        inputs = list(self.config.inputs)
        k = 0
        for i, j, shape in self.slots:
            lo, _ = inputs[i].universe
            w = self._width(i)
            n = {"gaussmf": 2, "gauss2mf": 4}.get(shape, len(inputs[i].terms[j].params))
            v = vector[k:k + n]
            k += n
            if shape == "gaussmf":
                params = (lo + w * v[0], 0.02 * w * 50.0 ** v[1])
            elif shape == "gauss2mf":
                m1, m2 = sorted((lo + w * v[0], lo + w * v[2]))
                params = (m1, 0.02 * w * 50.0 ** v[1], m2, 0.02 * w * 50.0 ** v[3])
            else:
                params = tuple(sorted(lo + w * v))
                if params[-1] - params[0] < 1e-3 * w:
                    return None
            terms = list(inputs[i].terms)
            terms[j] = Term(terms[j].name, shape, params)
            inputs[i] = inputs[i].__class__(inputs[i].name, inputs[i].universe, tuple(terms),
                                            inputs[i].raw_range, inputs[i].unit)
        for var, original in zip(inputs, self.config.inputs):
            centres = [t.centre for t in var.terms]
            order = np.argsort([t.centre for t in original.terms], kind="stable")
            if any(centres[a] > centres[b] for a, b in zip(order, order[1:])):
                return None
        try:
            return self.config.replace(inputs=tuple(inputs))
        except HybridtrackError:
            return None



def tune(config: FuzzyConfig | None, samples, *, method: str = "global", margin: float = 0.5,
         maxiter: int = 60, popsize: int = 8, restarts: int = 8, seed: int = 0) -> tuple[FuzzyConfig, TuningReport]:
    """Fit the input membership parameters of `config` to labelled readings.

    Parameters
    ----------
    config : FuzzyConfig or None
        Starting point; the published system when None.
    samples : pandas.DataFrame or path
        Columns ``intensity``, ``variation`` (raw mA) and ``weather`` and/or ``score``.
    method : {"global", "local"}
        ``global``: differential evolution (seeded, starting from `config`) and then Powell
        from its best point; ``local``: Powell from `config` only, faster, may stop in a
        local minimum.
    margin : float
        How far inside its band a labelled reading's score should sit.
    maxiter : int
        Generations of the population search, and Powell iterations per run.
    popsize : int
        Population size multiplier of the differential evolution.
    restarts : int
        At most this many further Powell runs from the best point so far, in a new order of
        directions, while they still improve the fit.
    seed : int
        Seeds the order of Powell's directions, for reproducible fits.

    Returns
    -------
    (FuzzyConfig, TuningReport)
        The tuned config (named ``<name>-tuned``) and the before/after report.
    """
    from scipy.optimize import differential_evolution, minimize

    config = config if config is not None else FuzzyConfig.default()
    samples = read_samples(samples)
    if not margin >= 0:
        raise HybridtrackError(f"margin must be non-negative, got {margin!r}")
    if method not in ("global", "local"):
        raise HybridtrackError(f"unknown tuning method {method!r}; choose 'global' or 'local'")
    intensity = samples["intensity"].to_numpy(float)
    variation = samples["variation"].to_numpy(float)
    mapping = _Parameterisation(config)
    evaluations = 0
    start = mapping.encode(config)
    best = {"loss": np.inf, "vector": start}

    def loss(vector: np.ndarray) -> float:
        nonlocal evaluations
        evaluations += 1
        candidate = mapping.decode(vector)
        if candidate is None:
            return 1e6  # an invalid or disordered term set
        clf = FuzzyWeatherClassifier(candidate)
        value = _metrics(clf, candidate, clf.score(intensity, variation), samples, margin)["loss"]
        if value < best["loss"]:  # Powell may end on an extrapolated point; keep the best seen
            best.update(loss=value, vector=np.array(vector))
        return value

    before = evaluate(config, samples, margin)
    if method == "global":  # a seeded population search first: the loss has many local minima
        differential_evolution(loss, [(0.0, 1.0)] * len(start), x0=start, seed=seed, popsize=popsize,
                               maxiter=maxiter, tol=1e-8, polish=False, init="sobol")
    rng = np.random.default_rng(seed)
    for _ in range(restarts + 1):  # Powell stalls on the kinks of min/max; restart from the best
        previous = best["loss"]
        directions = np.eye(len(start))[rng.permutation(len(start))]
        minimize(loss, best["vector"], method="Powell", bounds=[(0.0, 1.0)] * len(start),
                 options={"maxiter": maxiter, "xtol": 1e-5, "ftol": 1e-8, "direc": directions})
        if best["loss"] > previous - 1e-9 * max(previous, 1e-12) or best["loss"] == 0.0:
            break
    tuned = mapping.decode(best["vector"]) if best["loss"] < before["loss"] else None
    tuned = (tuned or config).replace(name=f"{config.name}-tuned")
    after = evaluate(tuned, samples, margin)
    changed = {}
    for old, new in zip(config.inputs, tuned.inputs):
        for a, b in zip(old.terms, new.terms):
            if not np.allclose(a.params, b.params):
                changed[f"{old.name}.{a.name}"] = {"before": list(a.params), "after": [round(v, 6) for v in b.params]}
    report = TuningReport(len(samples), before["accuracy"], after["accuracy"], before["rmse"], after["rmse"],
                          before["loss"], after["loss"], evaluations, changed)
    return tuned, report
