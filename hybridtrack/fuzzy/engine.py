"""Two engines for one Mamdani system: scikit-fuzzy's own (the reference) and a vectorised one.

Both evaluate the system the way scikit-fuzzy defines it on sampled universes. Input
memberships are linear interpolations of the sampled terms. A rule fires at the minimum of
its conditions, and each output term is clipped at the maximum firing of its rules. The
clipped terms are aggregated by maximum and defuzzified by the exact centroid of the
piecewise-linear result, with the cut points added.

The fast engine never builds the aggregated curve per sample. On grid cells where only one
output term is non-zero, the term's clipped area and first moment are polynomials in its
clip level between consecutive sample values (quadratic and cubic), so they are tabulated
once per config and looked up per sample. Cells where output terms overlap, which the
published system has none of, are integrated densely per sample with the same cut points
as scikit-fuzzy.

When no rule fires, the aggregated set is empty and has no centroid. scikit-fuzzy then
raises (arrays) or returns nothing (scalars). Here the score is NaN and the label
``unknown``, from both engines; a NaN input gives the same.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache, reduce

import numpy as np

from .config import FuzzyConfig, Term, Variable

__all__ = ["sample_term", "CompiledSystem", "evaluate_fast", "evaluate_skfuzzy"]

# t = 0, 1/3, 2/3, 1 -> cubic coefficients (c0 + c1 t + c2 t^2 + c3 t^3)
_T = np.array([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])
_FIT = np.linalg.inv(np.vander(_T, 4, increasing=True))


def sample_term(term: Term, x: np.ndarray) -> np.ndarray:
    """A term's membership at the points `x` (the formulas scikit-fuzzy uses)."""
    p = term.params
    x = np.asarray(x, float)
    if term.shape == "gaussmf":
        return np.exp(-((x - p[0]) ** 2) / (2.0 * p[1] ** 2))
    if term.shape == "gauss2mf":
        left = np.exp(-((x - p[0]) ** 2) / (2.0 * p[1] ** 2))
        right = np.exp(-((x - p[2]) ** 2) / (2.0 * p[3] ** 2))
        return np.where(x < p[0], left, np.where(x > p[2], right, 1.0))
    a, b, c, d = (p[0], p[1], p[1], p[2]) if term.shape == "trimf" else p
    with np.errstate(divide="ignore", invalid="ignore"):
        rise = np.where(b > a, (x - a) / (b - a), 1.0)
        fall = np.where(d > c, (d - x) / (d - c), 1.0)
    y = np.clip(np.minimum(rise, fall), 0.0, 1.0)
    y = np.where((x < a) | (x > d), 0.0, y)
    return np.where((x >= b) & (x <= c), 1.0, y)


def _cell_integrals(y1, y2, v1, v2, s):
    """Exact area and first moment of min(s, L) over cells where L runs linearly v1 -> v2."""
    dv, dy = v2 - v1, y2 - y1
    with np.errstate(divide="ignore", invalid="ignore"):
        cut = np.where(dv != 0.0, y1 + (s - v1) * dy / dv, y2)
    c = np.clip(cut, y1, y2)
    at_c = v1 + (c - y1) * np.where(dy > 0, dv / np.where(dy > 0, dy, 1.0), 0.0)
    p1, q1, q2 = np.minimum(s, v1), np.minimum(s, at_c), np.minimum(s, v2)
    area = 0.5 * (c - y1) * (p1 + q1) + 0.5 * (y2 - c) * (q1 + q2)
    moment = ((c - y1) * (p1 * (2 * y1 + c) + q1 * (y1 + 2 * c))
              + (y2 - c) * (q1 * (2 * c + y2) + q2 * (c + 2 * y2))) / 6.0
    return area, moment


@dataclass
class _TermTable:
    """Area and moment of one clipped output term over its own cells, piecewise in the clip level."""

    levels: np.ndarray  # breakpoints, ascending
    area: np.ndarray  # (intervals, 4) cubic coefficients in t
    moment: np.ndarray

    @classmethod
    def build(cls, y: np.ndarray, values: np.ndarray, cells: np.ndarray) -> _TermTable:
        y1, y2, v1, v2 = y[cells], y[cells + 1], values[cells], values[cells + 1]
        levels = np.unique(np.concatenate([[0.0], v1, v2]))
        if len(levels) == 1:
            levels = np.array([0.0, 1.0])
        s = (levels[:-1, None] + _T[None, :] * np.diff(levels)[:, None]).reshape(-1, 1)
        area, moment = _cell_integrals(y1, y2, v1, v2, s)
        shape = (len(levels) - 1, 4)
        return cls(levels, area.sum(axis=1).reshape(shape) @ _FIT.T, moment.sum(axis=1).reshape(shape) @ _FIT.T)

    def __call__(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        level = np.clip(s, 0.0, self.levels[-1])
        i = np.clip(np.searchsorted(self.levels, level, side="right") - 1, 0, len(self.levels) - 2)
        t = (level - self.levels[i]) / (self.levels[i + 1] - self.levels[i])
        powers = np.stack([np.ones_like(t), t, t * t, t * t * t], axis=-1)
        return np.einsum("...k,...k->...", powers, self.area[i]), np.einsum("...k,...k->...", powers, self.moment[i])


@dataclass(frozen=True)
class _OutputStage:
    """The sampled output terms and their tables; depends on the output variable only."""

    y: np.ndarray
    samples: np.ndarray  # (terms, points)
    shared_cells: np.ndarray
    tables: tuple[_TermTable, ...]


@lru_cache(maxsize=32)
def _output_stage(output: Variable, points: int) -> _OutputStage:
    y = np.linspace(*output.universe, points)
    samples = np.array([sample_term(t, y) for t in output.terms])
    active = (samples[:, :-1] > 0) | (samples[:, 1:] > 0)  # (terms, cells)
    count = active.sum(axis=0)
    tables = tuple(_TermTable.build(y, samples[k], np.flatnonzero(active[k] & (count == 1)))
                   for k in range(len(output.terms)))
    return _OutputStage(y, samples, np.flatnonzero(count >= 2), tables)


class CompiledSystem:
    """A config sampled and tabulated once, ready to evaluate many readings fast."""

    def __init__(self, config: FuzzyConfig):
        self.config = config
        n_in, n_out = config.resolution
        self.universes = [np.linspace(*var.universe, n_in) for var in config.inputs]
        self.input_samples = [[sample_term(t, u) for t in var.terms] for var, u in zip(config.inputs, self.universes)]
        stage = _output_stage(config.output, n_out)
        self.y, self.output_samples = stage.y, stage.samples
        self.shared_cells, self.tables = stage.shared_cells, stage.tables
        names = config.output.term_names
        self.rule_terms = [
            [(i, config.inputs[i].term_names.index(rule.conditions[var.name]))
             for i, var in enumerate(config.inputs) if var.name in rule.conditions]
            for rule in config.rules
        ]
        self.rule_output = np.array([names.index(rule.then) for rule in config.rules])

    def memberships(self, x: np.ndarray) -> list[np.ndarray]:
        """Input memberships, one (N, terms) array per input; `x` is (N, 2), normalised."""
        return [np.stack([np.interp(x[:, i], u, mf) for mf in samples], axis=-1)
                for i, (u, samples) in enumerate(zip(self.universes, self.input_samples))]

    def firing(self, x: np.ndarray) -> np.ndarray:
        """Firing strength of every rule, (N, rules)."""
        mu = self.memberships(x)
        return np.stack([reduce(np.minimum, [mu[i][:, t] for i, t in terms]) for terms in self.rule_terms], axis=-1)

    def strengths(self, firing: np.ndarray) -> np.ndarray:
        """Clip level of every output term, (N, terms): max over the rules that name it."""
        out = np.zeros((firing.shape[0], len(self.tables)))
        for k in range(len(self.tables)):
            mine = self.rule_output == k
            if mine.any():
                out[:, k] = firing[:, mine].max(axis=1) if mine.sum() > 1 else firing[:, mine][:, 0]
                out[np.isnan(firing).any(axis=1), k] = np.nan
        return out

    def centroid(self, strengths: np.ndarray, chunk: int = 4096) -> np.ndarray:
        """Crisp score of each row of clip levels; NaN where the aggregated set is empty."""
        area = np.zeros(strengths.shape[0])
        moment = np.zeros(strengths.shape[0])
        for k, table in enumerate(self.tables):
            a, m = table(strengths[:, k])
            area += a
            moment += m
        if len(self.shared_cells):
            for start in range(0, len(strengths), chunk):
                a, m = self._shared(strengths[start:start + chunk])
                area[start:start + chunk] += a
                moment[start:start + chunk] += m
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(area > 0, moment / area, np.nan)

    def _shared(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Dense integration over cells where output terms overlap, with every term's cut points."""
        j = self.shared_cells
        y1, y2 = self.y[j], self.y[j + 1]
        v1, v2 = self.output_samples[:, j], self.output_samples[:, j + 1]  # (terms, cells)
        level = s[:, :, None]  # (N, terms, 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cut = y1 + (level - v1) * (y2 - y1) / (v2 - v1)
        inside = (v2 != v1) & (cut > y1) & (cut < y2)
        cuts = np.where(inside, cut, y1).transpose(0, 2, 1)  # (N, cells, terms)
        edges = np.broadcast_to(np.stack([y1, y2], axis=-1), (len(s), len(j), 2))
        points = np.sort(np.concatenate([edges, cuts], axis=-1), axis=-1)  # (N, cells, P)
        frac = (points - y1[:, None]) / (y2 - y1)[:, None]
        # each term's interpolant at the points, clipped at its level; then the max over terms
        values = v1.T[None, :, :, None] + frac[:, :, None, :] * (v2 - v1).T[None, :, :, None]
        mu = np.minimum(values, s[:, None, :, None]).max(axis=2)
        width = np.diff(points, axis=-1)
        p, q, a, b = mu[..., :-1], mu[..., 1:], points[..., :-1], points[..., 1:]
        area = (0.5 * width * (p + q)).sum(axis=(1, 2))
        moment = (width * (p * (2 * a + b) + q * (a + 2 * b)) / 6.0).sum(axis=(1, 2))
        return area, moment


def evaluate_fast(system: CompiledSystem, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Scores and rule firing strengths for normalised readings `x` (N, 2)."""
    firing = system.firing(x)
    return system.centroid(system.strengths(firing)), firing


def _skfuzzy_system(config: FuzzyConfig):
    import skfuzzy as fuzz
    from skfuzzy import control as ctrl

    shapes = {"gaussmf": fuzz.gaussmf, "gauss2mf": fuzz.gauss2mf, "trimf": fuzz.trimf, "trapmf": fuzz.trapmf}

    def sample(term: Term, universe: np.ndarray) -> np.ndarray:
        if term.shape in ("trimf", "trapmf"):
            return shapes[term.shape](universe, list(term.params))
        return shapes[term.shape](universe, *term.params)

    n_in, n_out = config.resolution
    antecedents = {}
    for var in config.inputs:
        ant = ctrl.Antecedent(np.linspace(*var.universe, n_in), var.name)
        for term in var.terms:
            ant[term.name] = sample(term, ant.universe)
        antecedents[var.name] = ant
    consequent = ctrl.Consequent(np.linspace(*config.output.universe, n_out), config.output.name,
                                 defuzzify_method="centroid")
    for term in config.output.terms:
        consequent[term.name] = sample(term, consequent.universe)
    rules = []
    for rule in config.rules:
        parts = [antecedents[name][term] for name, term in rule.conditions.items()]
        rules.append(ctrl.Rule(reduce(lambda a, b: a & b, parts), consequent[rule.then]))
    return ctrl.ControlSystem(rules), consequent


def evaluate_skfuzzy(config: FuzzyConfig, x: np.ndarray, *, one_at_a_time: bool = False) -> np.ndarray:
    """Scores from scikit-fuzzy's own control API for normalised readings `x` (N, 2).

    Array inputs go through one ``ControlSystemSimulation`` call. scikit-fuzzy refuses the
    whole array when any reading fires no rule. In that case the readings whose clip levels,
    as scikit-fuzzy computed them, are all zero are marked NaN and the rest run again.
    `one_at_a_time` runs a scalar simulation per reading instead, for benchmarking.
    """
    from skfuzzy.control import ControlSystemSimulation
    from skfuzzy.control.exceptions import EmptyMembershipError
    from skfuzzy.defuzzify import EmptyMembershipError as EmptyArrayError

    system, consequent = _skfuzzy_system(config)
    names = config.input_names
    scores = np.full(len(x), np.nan)
    todo = np.flatnonzero(~np.isnan(x).any(axis=1))
    if one_at_a_time:
        sim = ControlSystemSimulation(system)
        for i in todo:
            for k, name in enumerate(names):
                sim.input[name] = float(x[i, k])
            sim.compute()
            scores[i] = sim.output.get(consequent.label, np.nan)  # lenient: nothing when no rule fires
        return scores
    while len(todo):
        sim = ControlSystemSimulation(system, cache=False)
        for k, name in enumerate(names):
            sim.input[name] = x[todo, k]
        try:
            sim.compute()
        except (EmptyMembershipError, EmptyArrayError):
            cuts = [term.membership_value[sim] for term in consequent.terms.values()]
            levels = np.stack([np.broadcast_to(np.nan_to_num(np.asarray(c, float)), (len(todo),))
                               for c in cuts if c is not None], axis=-1)
            empty = ~(levels > 0).any(axis=1)
            if not empty.any():  # pragma: no cover - would mean scikit-fuzzy changed its rules
                raise
            todo = todo[~empty]
            continue
        scores[todo] = np.asarray(sim.output[consequent.label], float)
        break
    return scores
