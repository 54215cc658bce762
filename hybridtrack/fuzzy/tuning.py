"""Fitting the input membership functions to labelled readings, without misleading.

Samples are rows of raw ``intensity`` and ``variation`` (mA) with a target ``weather`` label,
a target ``score``, or both. The loss is the mean squared score error against target
scores. Against labels it is a squared hinge: zero once the score sits inside its label's
band by `margin` units, growing with the distance outside, plus one for every wrong label
(so the fit cannot park scores just across a band edge). A reading that fires no rule
costs as much as being a whole band off. The input terms' parameters are optimised
derivative-free (differential evolution, then bounded Powell) in a parameterisation that keeps
every term valid: centres stay inside the universe and in their original order, widths stay
positive, and triangle and trapezoid corners stay sorted. The output terms, bands and rules
are left as they are.

A fit to a few dozen readings can score well on them and still be physically wrong, so every
candidate must also pass the physical constraints (`constraint_violations`, on a grid over the
whole input space):

* more light with the same variation is never less sunny: along every row of constant
  variation the score never falls more than `MONOTONE_TOLERANCE` below its running maximum,
  and the label never steps down;
* the sunny (top) band is unbounded on the high-intensity side: the brightest, steadiest reading
  is in the top band (readings above the raw range are clipped to it, so the band reaches
  infinity);
* darkness is overcast: the dark current with no variation is in the bottom band.

A candidate that breaks them costs more than any that keeps them. The report gives the
accuracy on the training readings beside the k-fold cross-validated accuracy (each fold tuned
without its held-out readings) and the spread of the fit across seeds; the tuned config records
the raw range its labels covered (``labelled_range``) and a classifier built on it warns
(`OutsideLabelsWarning`) when it is applied outside that range.
"""

from __future__ import annotations

import numbers
import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from ..params import number, whole
from .classifier import FuzzyWeatherClassifier, refuse_impossible_readings
from .config import FuzzyConfig, Term

__all__ = ["tune", "check_margin", "check_folds", "check_seeds", "check_seed", "TuningReport", "read_samples", "evaluate",
           "cross_validate", "constraint_violations", "labelled_range", "outside_labels", "warn_outside_labels",
           "OutsideLabelsWarning", "MONOTONE_TOLERANCE"]

#: How far (score units) the score may dip below its running maximum as intensity rises at
#: constant variation: the discretised centroid of the published system wobbles by 0.26 on this grid.
MONOTONE_TOLERANCE = 0.5
#: Grid of the constraint check: points along intensity and along variation (normalised).
CONSTRAINT_GRID = (55, 11)


class OutsideLabelsWarning(UserWarning):
    """A tuned classifier is applied to readings outside the range its labels covered."""


@dataclass(frozen=True)
class TuningReport:
    """How well a config fits the samples before and after tuning, and how far to trust it.

    ``accuracy_after`` is measured on the readings the fit saw; ``accuracy_cv`` on readings each
    fold's fit did not see (pooled over the folds), the honest figure. ``seeds`` gives the training
    accuracy of the fit from each seed, ``seed`` the seed whose fit was returned (the lowest
    loss), and ``spread`` how far each term's centre moves across them (normalised units).
    ``constraints_before``/``constraints_after`` list the physical constraints each config breaks
    (empty: all hold).
    """

    samples: int
    accuracy_before: float | None
    accuracy_after: float | None
    rmse_before: float | None
    rmse_after: float | None
    loss_before: float
    loss_after: float
    evaluations: int
    changed: dict = field(default_factory=dict)
    folds: int = 0
    accuracy_cv: float | None = None
    rmse_cv: float | None = None
    accuracy_cv_folds: list = field(default_factory=list)
    seeds: dict = field(default_factory=dict)
    seed: int | None = None
    spread: dict = field(default_factory=dict)
    constraints_before: list = field(default_factory=list)
    constraints_after: list = field(default_factory=list)
    labelled_range: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """Plain dict, JSON-ready."""
        return dict(self.__dict__)

    def __str__(self) -> str:
        def fmt(value, spec):
            return "-" if value is None else format(value, spec)

        lines = [
            f"{self.samples} samples, {self.evaluations} evaluations",
            f"  label accuracy  {fmt(self.accuracy_before, '.1%'):>8} -> {fmt(self.accuracy_after, '.1%')}"
            " on the training readings",
            f"  score RMSE      {fmt(self.rmse_before, '.3f'):>8} -> {fmt(self.rmse_after, '.3f')}",
            f"  loss            {self.loss_before:>8.4f} -> {self.loss_after:.4f}",
        ]
        if self.folds:
            by_fold = [v for v in self.accuracy_cv_folds if v is not None]
            lines.append(f"  cross-validated {'':>8}    {fmt(self.accuracy_cv, '.1%')} label accuracy on held-out "
                         f"readings ({self.folds}-fold" + (f", folds {min(by_fold):.0%}-{max(by_fold):.0%}"
                                                          if by_fold else "") + ")"
                         + (f", score RMSE {self.rmse_cv:.3f}" if self.rmse_cv is not None else ""))
        if len(self.seeds) > 1:
            accuracies = [v for v in self.seeds.values() if v is not None]
            worst = max(self.spread.items(), key=lambda item: item[1]) if self.spread else None
            lines.append(f"  across seeds {', '.join(map(str, self.seeds))}: training accuracy "
                         + (f"{min(accuracies):.1%}-{max(accuracies):.1%}" if accuracies else "-")
                         + (f"; term centres move up to {worst[1]:.2f} units ({worst[0]})" if worst else "")
                         + f"; kept seed {self.seed}'s fit, the lowest loss")
        lines.append("  physical constraints: " + ("hold" if not self.constraints_after
                                                    else "BROKEN: " + "; ".join(self.constraints_after))
                     + (" (the starting config broke: " + "; ".join(self.constraints_before) + ")"
                        if self.constraints_before else ""))
        if self.labelled_range:
            lines.append("  labelled range: " + ", ".join(f"{name} {lo:.4g}-{hi:.4g}" for name, (lo, hi)
                                                          in self.labelled_range.items())
                         + " (a tuned classifier warns outside it)")
        return "\n".join(lines)


def read_samples(source, config: FuzzyConfig | None = None) -> pd.DataFrame:
    """Labelled readings from a CSV path or a DataFrame, checked.

    Columns: ``intensity``, ``variation`` (raw mA), and ``weather`` and/or ``score``;
    optional ``tolerance`` (used by rule-table tests). Every reading, label and score must be
    given: an empty or infinite cell, a reading below zero, or a label that none of `config`'s
    bands names (when a config is given) is refused by its row and column.

    Parameters
    ----------
    source : str, Path or pandas.DataFrame
        The table (a CSV or TOML ``[[case]]`` file), or the readings themselves.
    config : FuzzyConfig, optional
        The config the labels are for: its bands name the weather labels allowed.

    Returns
    -------
    pandas.DataFrame
        The readings, with ``intensity``, ``variation``, ``score`` and ``tolerance`` as floats.
    """
    if isinstance(source, pd.DataFrame):
        frame, where = source.copy(), "samples"
    else:
        from ..io import read_table

        frame, where = read_table(source), str(source)
    missing = [c for c in ("intensity", "variation") if c not in frame.columns]
    if missing:
        raise HybridtrackError(f"{where}: missing column {missing[0]!r} "
                               "(need intensity, variation and weather or score)")
    if "weather" not in frame.columns and "score" not in frame.columns:
        raise HybridtrackError(f"{where}: needs a 'weather' or a 'score' column to fit to")
    if frame.empty:
        raise HybridtrackError(f"{where}: no rows")
    from ..io import numeric_columns, table_row

    if "weather" in frame.columns and frame["weather"].isna().any():
        raise HybridtrackError(f"{where}: row {table_row(frame, int(np.flatnonzero(frame['weather'].isna())[0]))}, "
                               "column 'weather': empty")

    frame = numeric_columns(frame, ("intensity", "variation", "score", "tolerance"), where,
                            required=("intensity", "variation", "score"))
    refuse_impossible_readings(frame, ("intensity", "variation"), where)
    if config is not None and "weather" in frame.columns:
        _refuse_unknown_labels(frame, config, where)
    return frame


def _labels(samples: pd.DataFrame) -> np.ndarray:
    """The samples' weather labels as the bands name them: stripped, in lower case."""
    return samples["weather"].astype(str).str.strip().str.lower().to_numpy()


def _refuse_unknown_labels(frame: pd.DataFrame, config: FuzzyConfig, where: str) -> None:
    """Refuse the first weather label that none of `config`'s bands names, by its row."""
    from ..io import table_row

    bands = [name for name, _, _ in config.bands]
    unknown = np.flatnonzero(~np.isin(_labels(frame), bands))
    if len(unknown):
        row = int(unknown[0])
        raise HybridtrackError(f"{where}: row {table_row(frame, row)}, column 'weather': unknown weather label "
                               f"{frame['weather'].iloc[row]!r}; the bands are {', '.join(bands)}")


def evaluate(config: FuzzyConfig, samples: pd.DataFrame, margin: float = 0.5) -> dict:
    """Loss, label accuracy and score RMSE of `config` on `samples` (checked by `read_samples`)."""
    samples = read_samples(samples, config)
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
        labels = _labels(samples)
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


def constraint_violations(config: FuzzyConfig, *, tolerance: float = MONOTONE_TOLERANCE) -> tuple[float, list[str]]:
    """How far `config` breaks the physical constraints, and which ones (see the module notes).

    Returns
    -------
    (float, list of str)
        A graded amount (0 when every constraint holds) that a fit can reduce, and one sentence
        per broken constraint.
    """
    clf = FuzzyWeatherClassifier(config)
    (a, b), out = config.inputs, config.output
    u = np.linspace(*a.universe, CONSTRAINT_GRID[0])
    v = np.linspace(*b.universe, CONSTRAINT_GRID[1])
    gu, gv = np.meshgrid(u, v)  # rows of constant variation, intensity rising along each row
    span = out.universe[1] - out.universe[0]
    score = np.nan_to_num(clf.score(gu, gv, raw=False), nan=out.universe[0] - span)  # no rule: the lowest
    amount, broken = 0.0, []
    dip = np.max(np.maximum.accumulate(score, axis=1) - score)
    edges = np.array([band[2] for band in config.bands[:-1]])
    band = np.searchsorted(edges, score, side="right")
    steps_down = int(np.sum(np.diff(band, axis=1) < 0))
    if dip > tolerance or steps_down:
        amount += max(dip - tolerance, 0.0) + steps_down
        broken.append(f"more light is less sunny somewhere (the score dips {dip:.2f} as intensity rises"
                      f"{f', the label steps down {steps_down} times' if steps_down else ''})")
    (top, top_lo, _), (bottom, _, bottom_hi) = config.bands[-1], config.bands[0]
    brightest, darkest = score[0, -1], score[0, 0]
    if not brightest >= top_lo:
        amount += top_lo - brightest + 1.0
        broken.append(f"the brightest steady reading is not {top} (score {brightest:.2f}): the {top} region "
                      "is bounded on the high-intensity side")
    if not darkest < bottom_hi:
        amount += darkest - bottom_hi + 1.0
        broken.append(f"darkness (the dark current, no variation) is not {bottom} (score {darkest:.2f})")
    return float(amount), broken


def labelled_range(samples: pd.DataFrame) -> tuple[tuple[float, float], tuple[float, float]]:
    """The raw (min, max) of intensity and of variation over checked `samples`."""
    return tuple((float(np.nanmin(samples[c])), float(np.nanmax(samples[c]))) for c in ("intensity", "variation"))


def outside_labels(config: FuzzyConfig, intensity, variation) -> np.ndarray:
    """Which readings fall outside the range the config's labels covered (False if it has none)."""
    a, b = np.broadcast_arrays(np.asarray(intensity, float), np.asarray(variation, float))
    if config.labelled_range is None:
        return np.zeros(a.shape, bool)
    (ilo, ihi), (vlo, vhi) = config.labelled_range
    return (a < ilo) | (a > ihi) | (b < vlo) | (b > vhi)  # NaN readings are not outside: they are unknown


def warn_outside_labels(config: FuzzyConfig, intensity, variation, *, stacklevel: int = 4) -> int:
    """Warn (`OutsideLabelsWarning`) if any reading is outside the config's labelled range.

    Returns the number of such readings.
    """
    outside = outside_labels(config, intensity, variation)
    count = int(outside.sum())
    if count:
        (ilo, ihi), (vlo, vhi) = config.labelled_range
        a, b = config.inputs
        warnings.warn(f"{count} of {outside.size} readings lie outside the range the tuned config "
                      f"{config.name!r} was labelled on ({a.name} {ilo:g}-{ihi:g} {a.unit}, {b.name} {vlo:g}-{vhi:g} "
                      f"{b.unit}); its answers there are extrapolation", OutsideLabelsWarning, stacklevel=stacklevel)
    return count


#: The largest seed a fit takes: scipy's population search takes seeds below 2**32, and each of up
#: to 20 seeds (`check_seeds`) adds one.
MAX_TUNE_SEED = 2**32 - 1 - 19


@dataclass(frozen=True)
class _Options:
    method: str = "global"
    margin: float = 0.5
    maxiter: int = 60
    popsize: int = 8
    restarts: int = 8

    def __post_init__(self) -> None:
        """Refuse counts that are no whole numbers or out of range (a raw TypeError deep in
        scipy, or a fit of no iterations, before)."""
        whole(self.maxiter, "maxiter", 1, 100_000)
        whole(self.popsize, "popsize", 1, 1_000)
        whole(self.restarts, "restarts", 0, 1_000)


def _fit(config: FuzzyConfig, samples: pd.DataFrame, options: _Options, seed: int) -> tuple[FuzzyConfig, int]:
    """The best valid, physically sound config found from `config`, and the evaluations spent."""
    from scipy.optimize import differential_evolution, minimize

    intensity = samples["intensity"].to_numpy(float)
    variation = samples["variation"].to_numpy(float)
    mapping = _Parameterisation(config)
    evaluations = 0
    start = mapping.encode(config)
    best = {"loss": np.inf, "vector": start}
    unsound = 1e3  # a config that breaks a physical constraint costs more than any that keeps them

    def loss(vector: np.ndarray) -> float:
        nonlocal evaluations
        evaluations += 1
        candidate = mapping.decode(vector)
        if candidate is None:
            return 1e6  # an invalid or disordered term set
        clf = FuzzyWeatherClassifier(candidate)
        value = _metrics(clf, candidate, clf.score(intensity, variation), samples, options.margin)["loss"]
        violation, _ = constraint_violations(candidate)
        if violation > 0:
            value = unsound + violation
        if value < best["loss"]:  # Powell may end on an extrapolated point; keep the best seen
            best.update(loss=value, vector=np.array(vector))
        return value

    initial = loss(start)
    if options.method == "global":  # a seeded population search first: the loss has many local minima
        differential_evolution(loss, [(0.0, 1.0)] * len(start), x0=start, seed=seed, popsize=options.popsize,
                               maxiter=options.maxiter, tol=1e-8, polish=False, init="sobol")
    rng = np.random.default_rng(seed)
    for _ in range(options.restarts + 1):  # Powell stalls on the kinks of min/max; restart from the best
        previous = best["loss"]
        directions = np.eye(len(start))[rng.permutation(len(start))]
        minimize(loss, best["vector"], method="Powell", bounds=[(0.0, 1.0)] * len(start),
                 options={"maxiter": options.maxiter, "xtol": 1e-5, "ftol": 1e-8, "direc": directions})
        if best["loss"] > previous - 1e-9 * max(previous, 1e-12) or best["loss"] == 0.0:
            break
    tuned = mapping.decode(best["vector"]) if best["loss"] < initial else None
    return (tuned or config), evaluations


def _folds(samples: pd.DataFrame, folds: int, seed: int) -> np.ndarray:
    """A fold number per reading, stratified by label when there are labels."""
    rng = np.random.default_rng(seed)
    fold = np.empty(len(samples), int)
    groups = samples.groupby(_labels(samples)).indices \
        if "weather" in samples.columns else {"all": np.arange(len(samples))}
    offset = 0
    for _, members in sorted(groups.items()):
        members = rng.permutation(members)
        fold[members] = (np.arange(len(members)) + offset) % folds
        offset += len(members)
    return fold


def cross_validate(config: FuzzyConfig | None, samples, *, folds: int = 5, seed: int = 0, progress=None,
                   **options) -> dict:
    """k-fold cross-validated accuracy (and score RMSE) of tuning `config` to `samples`.

    Each fold is held out in turn, the config is tuned on the other readings (same options as
    `tune`), and the held-out readings are classified by that fit. Folds are stratified by label.
    `progress`, if given, is called with 1 after each fold's fit.

    Returns
    -------
    dict
        ``accuracy`` and ``rmse`` pooled over every held-out reading (None without labels or
        scores), ``accuracy_folds`` per fold, ``folds``.
    """
    config = config if config is not None else FuzzyConfig.default()
    samples = read_samples(samples, config)
    opts = _Options(**options)
    check_folds(folds, len(samples), none=False)
    check_seed(seed)
    assignment = _folds(samples, folds, seed)
    scores = np.full(len(samples), np.nan)
    per_fold = []
    for k in range(folds):
        held = assignment == k
        fitted, _ = _fit(config, samples[~held], opts, seed)
        if progress is not None:
            progress(1)
        part = evaluate(fitted, samples[held], opts.margin)
        per_fold.append(part["accuracy"])
        scores[held] = FuzzyWeatherClassifier(fitted).score(samples["intensity"].to_numpy(float)[held],
                                                            samples["variation"].to_numpy(float)[held])
    pooled = _metrics(FuzzyWeatherClassifier(config), config, scores, samples, opts.margin)
    return {"folds": folds, "accuracy": pooled["accuracy"], "rmse": pooled["rmse"], "accuracy_folds": per_fold}


def _centre_spread(fits: list[FuzzyConfig]) -> dict[str, float]:
    spread = {}
    for i, var in enumerate(fits[0].inputs):
        for j, term in enumerate(var.terms):
            centres = [fit.inputs[i].terms[j].centre for fit in fits]
            spread[f"{var.name}.{term.name}"] = round(float(np.ptp(centres)), 4)
    return spread


def check_margin(margin, config: FuzzyConfig, name: str = "margin") -> float:
    """`margin` as a float, refused unless finite and within the width of the output universe.

    Parameters
    ----------
    margin : float
        How far inside its band a label's score should sit (score units).
    config : FuzzyConfig
        The config whose output universe bounds it.
    name : str
        What the message calls it (``"--margin"`` on the command line).

    Returns
    -------
    float
    """
    low, high = config.output.universe
    return number(margin, f"{name} (score units)", 0, high - low)


def check_folds(folds: int, samples: int, name: str = "folds", *, none: bool = True) -> int:
    """`folds`, refused unless between 2 and the number of samples, or 0 where `none` allows it.

    Parameters
    ----------
    folds : int
        k of the k-fold cross-validation; 0 for none.
    samples : int
        How many labelled readings there are.
    name : str
        What the message calls it (``"--folds"`` on the command line).
    none : bool
        Whether 0 (no cross-validation) is allowed.

    Returns
    -------
    int
    """
    if isinstance(folds, bool) or not isinstance(folds, numbers.Integral) \
            or not ((none and folds == 0) or 2 <= folds <= samples):
        raise HybridtrackError(f"{name} must be {'0 (none) or ' if none else ''}between 2 and the number of samples "
                               f"({samples}), got {folds!r}")
    return folds


def check_seeds(seeds: int, name: str = "seeds") -> int:
    """`seeds`, refused unless between 1 and 20.

    Parameters
    ----------
    seeds : int
        How many seeds to fit from.
    name : str
        What the message calls it (``"--seeds"`` on the command line).

    Returns
    -------
    int
    """
    return whole(seeds, name, 1, 20)


def check_seed(seed: int, name: str = "seed") -> int:
    """`seed`, refused unless a whole number from 0 to `MAX_TUNE_SEED`.

    Parameters
    ----------
    seed : int
        The fit's seed.
    name : str
        What the message calls it (``"--seed"`` on the command line).

    Returns
    -------
    int
    """
    return whole(seed, name, 0, MAX_TUNE_SEED)


def tune(config: FuzzyConfig | None, samples, *, method: str = "global", margin: float = 0.5,
         maxiter: int = 60, popsize: int = 8, restarts: int = 8, seed: int = 0, folds: int = 0,
         seeds: int = 1, progress=None) -> tuple[FuzzyConfig, TuningReport]:
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
        Seeds the population search and the order of Powell's directions, for reproducible fits.
    folds : int
        With 2 or more, also report the `folds`-fold cross-validated accuracy (`cross_validate`).
    seeds : int
        With 2 or more, also fit from seeds ``seed + 1 ...``, return the fit of lowest loss (the
        first seed's of equal ones; `TuningReport.seed` names it) and report the spread of the
        fits: one seed's search can stop in a local optimum that another's passes.
    progress : callable, optional
        Called with 1 after each of the ``1 + folds + seeds - 1`` fits (e.g. a tqdm bar's update).

    Returns
    -------
    (FuzzyConfig, TuningReport)
        The tuned config (named ``<name>-tuned``, with the labels' `labelled_range`) and the
        report. Every candidate must keep the physical constraints (`constraint_violations`);
        if the starting config breaks them, the fit moves towards keeping them and the report
        says which still fail.

    References
    ----------
    .. [1] Storn, R. & Price, K. (1997). Differential evolution: a simple and efficient heuristic
       for global optimization over continuous spaces. Journal of Global Optimization 11,
       341-359. doi:10.1023/A:1008202821328 (through `scipy.optimize.differential_evolution`).
    .. [2] Powell, M. J. D. (1964). An efficient method for finding the minimum of a function of
       several variables without calculating derivatives. The Computer Journal 7(2), 155-162.
       (DOI not verified here, so none is given; through `scipy.optimize.minimize`.)
    """
    config = config if config is not None else FuzzyConfig.default()
    samples = read_samples(samples, config)
    check_margin(margin, config)
    if method not in ("global", "local"):
        raise HybridtrackError(f"unknown tuning method {method!r}; choose 'global' or 'local'")
    check_seeds(seeds)
    check_seed(seed)
    check_folds(folds, len(samples))
    options = _Options(method, margin, maxiter, popsize, restarts)
    cv = cross_validate(config, samples, folds=folds, seed=seed, progress=progress, **options.__dict__) if folds \
        else {}
    before = evaluate(config, samples, margin)
    step = progress if progress is not None else (lambda _: None)
    fits = []
    for k in range(seeds):
        fits.append(_fit(config, samples, options, seed + k))
        step(1)
    # each fit judged on the labels without a labelled range, which would warn of readings outside it
    scored = [evaluate(fit.replace(labelled_range=None), samples, margin) for fit, _ in fits]
    kept = int(np.argmin([evaluation["loss"] for evaluation in scored]))  # the first of equal losses
    (fitted, evaluations), after = fits[kept], scored[kept]
    span = labelled_range(samples)
    tuned = fitted.replace(name=f"{config.name}-tuned", labelled_range=span)
    seed_accuracy = {seed + k: evaluation["accuracy"] for k, evaluation in enumerate(scored)}
    changed = {}
    for old, new in zip(config.inputs, tuned.inputs):
        for a, b in zip(old.terms, new.terms):
            if not np.allclose(a.params, b.params):
                changed[f"{old.name}.{a.name}"] = {"before": list(a.params), "after": [round(v, 6) for v in b.params]}
    report = TuningReport(
        len(samples), before["accuracy"], after["accuracy"], before["rmse"], after["rmse"], before["loss"],
        after["loss"], evaluations, changed, folds=folds, accuracy_cv=cv.get("accuracy"), rmse_cv=cv.get("rmse"),
        accuracy_cv_folds=cv.get("accuracy_folds", []), seeds=seed_accuracy, seed=seed + kept,
        spread=_centre_spread([fit for fit, _ in fits]) if seeds > 1 else {},
        constraints_before=constraint_violations(config)[1], constraints_after=constraint_violations(tuned)[1],
        labelled_range={var.name: list(pair) for var, pair in zip(config.inputs, span)})
    return tuned, report
