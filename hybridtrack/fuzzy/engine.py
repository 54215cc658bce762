"""The Mamdani engine: any system, evaluated exactly as scikit-fuzzy discretises it.

The discretised system is scikit-fuzzy's. Every term is sampled on its variable's universe
(`MamdaniSystem.resolution` points). An input's membership in a term is the linear
interpolation of the sampled term. A rule fires at the AND (min or product) or OR (max or
probabilistic or) of its conditions, a negated condition counting one minus the membership,
times its weight. Each rule's output term, sampled, is clipped at the firing strength
(implication min) or scaled by it (product). The implied sets are aggregated (max, sum or
probabilistic or) at the universe's samples plus the points where each clipped term crosses
its clip level ("cut points"), and the aggregated set is the piecewise-linear curve through
those points. Centroid and bisector are exact for that curve; mom, som and lom take the
points at its maximum. With max aggregation this is what ``skfuzzy.control`` computes.

Two implementations run it. The numpy one (`CompiledSystem`) never builds the aggregated
curve where only one output term is non-zero: there a term's clipped area and first moment
are polynomials in its clip level between consecutive sample values (quadratic and cubic),
tabulated once per system. Cells where output terms overlap are integrated densely with the
cut points. The compiled one (`hybridtrack.fuzzy.compiled`, numba) is used when numba is
installed; it is exact the same way and tested against this one and against scikit-fuzzy.

When no rule fires, the aggregated set is empty and has no centroid. scikit-fuzzy then
raises (arrays) or returns nothing (scalars). Here the output is NaN; a NaN input gives the
same.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import HybridtrackError
from .config import FuzzyConfig, Term, Variable
from .membership import membership
from .system import MamdaniSystem, system_of

__all__ = ["sample_term", "CompiledSystem", "evaluate_fast", "evaluate_skfuzzy", "skfuzzy_system"]

# t = 0, 1/3, 2/3, 1 -> cubic coefficients (c0 + c1 t + c2 t^2 + c3 t^3)
_T = np.array([0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])
_FIT = np.linalg.inv(np.vander(_T, 4, increasing=True))


def sample_term(term: Term, x: np.ndarray) -> np.ndarray:
    """A term's membership at the points `x` (the formulas scikit-fuzzy uses)."""
    return membership(term.shape, term.params, x)


def sample_curve(var: Variable, index: int, y: np.ndarray) -> np.ndarray:
    """Output term `index` (from 1) sampled on `y`; ``-index`` is its complement."""
    values = sample_term(var.terms[abs(index) - 1], y)
    return 1.0 - values if index < 0 else values


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


def _level_integrals(y1, y2, v1, v2, levels, s):
    """Area and first moment of min(s, L) summed over the cells, at the levels `s` (intervals, 4)
    taken inside each interval between consecutive `levels` (every v1 and v2 is one of them).

    In an interval a cell lies wholly below the level (its whole area counts), wholly above it
    (s times its width), or crosses it; only the crossing cells are integrated, each over the
    intervals it spans. That is linear in the cells, where integrating every cell at every level
    was quadratic (0.2-0.4 s an output term at 3,001 points, paid by every new process)."""
    intervals = len(levels) - 1
    first = np.searchsorted(levels, np.minimum(v1, v2))  # the cell crosses intervals first .. last - 1
    last = np.searchsorted(levels, np.maximum(v1, v2))
    dy = y2 - y1

    def below(weights):  # the sum over cells wholly below each interval
        return np.cumsum(np.bincount(last, weights=weights, minlength=intervals + 1))[:intervals]

    def above(weights):  # the sum over cells wholly above each interval
        return np.cumsum(np.bincount(first, weights=weights, minlength=intervals + 1)[::-1])[::-1][1:]

    area = below(0.5 * dy * (v1 + v2))[:, None] + s * above(dy)[:, None]
    moment = (below(dy * (v1 * (2 * y1 + y2) + v2 * (y1 + 2 * y2)) / 6.0)[:, None]
              + s * above(0.5 * dy * (y1 + y2))[:, None])
    spans = last - first
    cell = np.repeat(np.arange(len(dy)), spans)
    interval = first[cell] + np.arange(len(cell)) - np.repeat(np.cumsum(spans) - spans, spans)
    crossing_area, crossing_moment = _cell_integrals(y1[cell, None], y2[cell, None], v1[cell, None],
                                                     v2[cell, None], s[interval])
    for j in range(s.shape[1]):
        area[:, j] += np.bincount(interval, weights=crossing_area[:, j], minlength=intervals)
        moment[:, j] += np.bincount(interval, weights=crossing_moment[:, j], minlength=intervals)
    return area, moment


@dataclass
class _TermTable:
    """Area and moment of one implied term over some cells, piecewise cubic in the firing level."""

    levels: np.ndarray  # breakpoints, ascending
    area: np.ndarray  # (intervals, 4) cubic coefficients in t
    moment: np.ndarray

    @classmethod
    def build(cls, y: np.ndarray, values: np.ndarray, cells: np.ndarray, implication: str) -> _TermTable:
        y1, y2, v1, v2 = y[cells], y[cells + 1], values[cells], values[cells + 1]
        if implication == "prod":  # s * L: linear in s on [0, 1]
            area = (0.5 * (y2 - y1) * (v1 + v2)).sum()
            moment = ((y2 - y1) * (v1 * (2 * y1 + y2) + v2 * (y1 + 2 * y2)) / 6.0).sum()
            return cls(np.array([0.0, 1.0]), np.array([[0.0, area, 0.0, 0.0]]), np.array([[0.0, moment, 0.0, 0.0]]))
        levels = np.unique(np.concatenate([[0.0], v1, v2]))
        if len(levels) == 1:
            levels = np.array([0.0, 1.0])
        s = levels[:-1, None] + _T[None, :] * np.diff(levels)[:, None]  # 4 levels in each interval
        area, moment = _level_integrals(y1, y2, v1, v2, levels, s)
        return cls(levels, area @ _FIT.T, moment @ _FIT.T)

    def __call__(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        level = np.clip(s, 0.0, self.levels[-1])
        i = np.clip(np.searchsorted(self.levels, level, side="right") - 1, 0, len(self.levels) - 2)
        t = (level - self.levels[i]) / (self.levels[i + 1] - self.levels[i])
        powers = np.stack([np.ones_like(t), t, t * t, t * t * t], axis=-1)
        return np.einsum("...k,...k->...", powers, self.area[i]), np.einsum("...k,...k->...", powers, self.moment[i])


@dataclass(frozen=True)
class OutputStage:
    """One output: its sampled implied terms ("units") and their tables.

    With max aggregation a unit is an output term (or its complement) and its level is the
    largest firing of the rules naming it; with sum or probor a unit is a rule.
    """

    y: np.ndarray
    curves: np.ndarray  # (units, points)
    implication: str
    aggregation: str
    shared_cells: np.ndarray  # cells integrated densely
    tables: tuple[_TermTable, ...]


@lru_cache(maxsize=64)
def _output_stage(output: Variable, points: int, unit_curves: tuple[int, ...], implication: str,
                  aggregation: str) -> OutputStage:
    y = np.linspace(*output.universe, points)
    curves = np.array([sample_curve(output, k, y) for k in unit_curves]).reshape(len(unit_curves), points)
    active = (curves[:, :-1] > 0) | (curves[:, 1:] > 0)  # (units, cells)
    count = active.sum(axis=0)
    if aggregation == "sum":  # sums of implied sets integrate term by term, overlapping or not
        mine, shared = active, np.array([], dtype=int)
    else:
        mine, shared = active & (count == 1), np.flatnonzero(count >= 2)
    tables = tuple(_TermTable.build(y, curves[u], np.flatnonzero(mine[u]), implication) for u in range(len(curves)))
    return OutputStage(y, curves, implication, aggregation, shared, tables)


def _aggregate(values: np.ndarray, method: str, axis: int) -> np.ndarray:
    if method == "max":
        return values.max(axis=axis)
    if method == "sum":
        return values.sum(axis=axis)
    return 1.0 - np.prod(1.0 - values, axis=axis)  # probor


def _implied(level, curve, implication):
    return np.minimum(level, curve) if implication == "min" else level * curve


def _cell_points(stage: OutputStage, levels: np.ndarray, cells: np.ndarray):
    """Points (edges and cut points, sorted) and aggregated values in `cells`: (N, cells, P) each."""
    y1, y2 = stage.y[cells], stage.y[cells + 1]
    v1, v2 = stage.curves[:, cells], stage.curves[:, cells + 1]  # (units, cells)
    edges = np.broadcast_to(np.stack([y1, y2], axis=-1), (len(levels), len(cells), 2))
    if stage.implication == "min":
        level = levels[:, :, None]  # (N, units, 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cut = y1 + (level - v1) * (y2 - y1) / (v2 - v1)
        crosses = (v1 >= level) != (v2 >= level)  # scikit-fuzzy's test for a cut in the cell
        inside = crosses & (cut > y1) & (cut < y2)
        cuts = np.where(inside, cut, y1).transpose(0, 2, 1)  # (N, cells, units)
        points = np.sort(np.concatenate([edges, cuts], axis=-1), axis=-1)
    else:
        points = np.array(edges)
    frac = (points - y1[:, None]) / (y2 - y1)[:, None]
    curve = v1.T[None, :, :, None] + frac[:, :, None, :] * (v2 - v1).T[None, :, :, None]  # (N, cells, units, P)
    values = _aggregate(_implied(levels[:, None, :, None], curve, stage.implication), stage.aggregation, axis=2)
    return points, values


def _trapezoids(points, values):
    width = np.diff(points, axis=-1)
    p, q, a, b = values[..., :-1], values[..., 1:], points[..., :-1], points[..., 1:]
    return 0.5 * width * (p + q), width * (p * (2 * a + b) + q * (a + 2 * b)) / 6.0


def centroid_parts(stage: OutputStage, levels: np.ndarray, chunk: int = 2048) -> tuple[np.ndarray, np.ndarray]:
    """Area and first moment of the aggregated set for each row of unit levels (N, units)."""
    area = np.zeros(levels.shape[0])
    moment = np.zeros(levels.shape[0])
    for u, table in enumerate(stage.tables):
        a, m = table(levels[:, u])
        area += a
        moment += m
    if len(stage.shared_cells):
        for start in range(0, len(levels), chunk):
            a, m = _trapezoids(*_cell_points(stage, levels[start:start + chunk], stage.shared_cells))
            area[start:start + chunk] += a.sum(axis=(1, 2))
            moment[start:start + chunk] += m.sum(axis=(1, 2))
    return area, moment


def _bisector(points, values):
    """The point halving the area under each row's piecewise-linear curve (N, P) -> (N,)."""
    area, _ = _trapezoids(points, values)
    total = np.cumsum(area, axis=1)
    half = 0.5 * total[:, -1:]
    k = np.argmax(total >= half, axis=1)[:, None]
    rest = (half - (np.take_along_axis(total, k, 1) - np.take_along_axis(area, k, 1)))[:, 0]
    x1, x2 = np.take_along_axis(points, k, 1)[:, 0], np.take_along_axis(points, k + 1, 1)[:, 0]
    p, q = np.take_along_axis(values, k, 1)[:, 0], np.take_along_axis(values, k + 1, 1)[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(x2 > x1, (q - p) / (x2 - x1), 0.0)
        step = 2.0 * rest / (p + np.sqrt(np.maximum(p * p + 2.0 * slope * rest, 0.0)))
    return x1 + np.where(rest > 0, step, 0.0)


#: Points within this fraction of the maximum count as at the maximum (mom, som, lom): the
#: implied set's value at a cut point is its clip level up to rounding.
MAXIMUM_TOLERANCE = 1e-12


def _of_maximum(points, values, method):
    top = values.max(axis=1, keepdims=True)
    at_top = values >= top * (1.0 - MAXIMUM_TOLERANCE)
    if method == "som":
        return np.where(at_top, points, np.inf).min(axis=1)
    if method == "lom":
        return np.where(at_top, points, -np.inf).max(axis=1)
    return (np.where(at_top, points, 0.0).sum(axis=1)) / at_top.sum(axis=1)


def defuzzify_dense(stage: OutputStage, levels: np.ndarray, method: str, chunk: int = 256) -> np.ndarray:
    """Bisector, mom, som or lom of each row of unit levels, from the whole sampled curve."""
    out = np.empty(levels.shape[0])
    cells = np.arange(len(stage.y) - 1)
    for start in range(0, len(levels), chunk):
        points, values = _cell_points(stage, levels[start:start + chunk], cells)
        n = len(points)
        if method == "bisector":
            out[start:start + n] = _bisector(points.reshape(n, -1), values.reshape(n, -1))
            continue
        # each point once: cell starts and cut points, then the last edge
        keep = np.ones(points.shape[-1], bool)
        keep[-1] = False
        flat = np.concatenate([points[..., keep].reshape(n, -1), points[:, -1, -1:]], axis=1)
        vals = np.concatenate([values[..., keep].reshape(n, -1), values[:, -1, -1:]], axis=1)
        first = np.ones(flat.shape, bool)
        first[:, 1:] = flat[:, 1:] > flat[:, :-1]  # duplicates: an edge standing in for a missing cut
        out[start:start + n] = _of_maximum(np.where(first, flat, np.nan), np.where(first, vals, -1.0), method)
    return out


class CompiledSystem:
    """A system sampled and tabulated once, ready to evaluate many readings (numpy)."""

    def __init__(self, system: MamdaniSystem | FuzzyConfig):
        if isinstance(system, FuzzyConfig):
            self.config = system
            system = system_of(system)
        self.system = system
        n_in, n_out = system.resolution
        self.universes = [np.linspace(*var.universe, n_in) for var in system.inputs]
        self.input_samples = [[sample_term(t, u) for t in var.terms] for var, u in zip(system.inputs, self.universes)]
        self.antecedents = np.array([rule.antecedent for rule in system.rules])  # (rules, inputs)
        self.weights = np.array([rule.weight for rule in system.rules])
        self.is_or = np.array([rule.connection == "or" for rule in system.rules])
        methods = system.methods
        self.stages, self.rule_units = [], []
        for o, output in enumerate(system.outputs):
            consequents = [rule.consequent[o] for rule in system.rules]
            if methods.aggregation == "max":
                curves = tuple(dict.fromkeys(k for k in consequents if k))
                units = np.array([curves.index(k) if k else -1 for k in consequents])
            else:
                curves = tuple(k for k in consequents if k)
                units = np.cumsum([bool(k) for k in consequents]) - 1
                units = np.where(np.array(consequents) != 0, units, -1)
            self.stages.append(_output_stage(output, n_out, curves, methods.implication, methods.aggregation))
            self.rule_units.append(units)

    # kept for the classifier's tests and plots: the single output's stage
    @property
    def shared_cells(self) -> np.ndarray:
        return self.stages[0].shared_cells

    def memberships(self, x: np.ndarray) -> list[np.ndarray]:
        """Input memberships, one (N, terms) array per input; `x` is (N, inputs) on the universes."""
        return [np.stack([np.interp(x[:, i], u, mf) for mf in samples], axis=-1)
                for i, (u, samples) in enumerate(zip(self.universes, self.input_samples))]

    def firing(self, x: np.ndarray) -> np.ndarray:
        """Firing strength of every rule, weight included, (N, rules)."""
        mu = self.memberships(np.asarray(x, float))
        methods = self.system.methods
        out = np.empty((len(x), len(self.weights)))
        for r, (indices, is_or) in enumerate(zip(self.antecedents, self.is_or)):
            parts = [mu[i][:, k - 1] if k > 0 else 1.0 - mu[i][:, -k - 1] for i, k in enumerate(indices) if k]
            value = parts[0]
            for part in parts[1:]:
                if is_or:
                    value = np.maximum(value, part) if methods.or_method == "max" else value + part - value * part
                else:
                    value = np.minimum(value, part) if methods.and_method == "min" else value * part
            out[:, r] = value * self.weights[r]
        return out

    def unit_levels(self, firing: np.ndarray, output: int = 0) -> np.ndarray:
        """The level of each of an output's units, (N, units)."""
        units = self.rule_units[output]
        count = len(self.stages[output].curves)
        if self.system.methods.aggregation != "max":
            return firing[:, units >= 0]
        levels = np.zeros((len(firing), count))
        for u in range(count):
            levels[:, u] = firing[:, units == u].max(axis=1)
        return levels

    def outputs(self, firing: np.ndarray) -> np.ndarray:
        """Crisp value of every output, (N, outputs); NaN where the output's set is empty."""
        method = self.system.methods.defuzzification
        out = np.empty((len(firing), len(self.stages)))
        bad = np.isnan(firing).any(axis=1)
        for o, stage in enumerate(self.stages):
            levels = np.nan_to_num(self.unit_levels(firing, o))
            area, moment = centroid_parts(stage, levels)
            empty = ~(area > 0) | bad
            if method == "centroid":
                with np.errstate(invalid="ignore", divide="ignore"):
                    out[:, o] = np.where(empty, np.nan, moment / np.where(empty, 1.0, area))
            else:
                value = np.full(len(firing), np.nan)
                value[~empty] = defuzzify_dense(stage, levels[~empty], method)
                out[:, o] = value
        return out


def evaluate_fast(system: CompiledSystem, x: np.ndarray, *, engine: str = "auto",
                  with_firing: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """First output's values and every rule's firing strength for readings `x` (N, inputs).

    `engine`: ``auto`` (compiled when numba is installed), ``numba`` or ``numpy``.
    """
    outputs, firing = evaluate(system, x, engine=engine, with_firing=with_firing)
    return outputs[:, 0], firing


def evaluate(system: CompiledSystem, x: np.ndarray, *, engine: str = "auto",
             with_firing: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Every output's value (N, outputs) and every rule's firing (N, rules) for readings `x`.

    Without `with_firing` the compiled engine may skip storing the firing (None is returned
    in its place), which saves a pass over memory.
    """
    try:
        x = np.ascontiguousarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise HybridtrackError(f"readings must be numbers: {exc}") from None
    if x.ndim != 2 or x.shape[1] != len(system.system.inputs):
        raise HybridtrackError(f"readings must be an (N, {len(system.system.inputs)}) array, one column per input "
                               f"({', '.join(system.system.input_names)}); got shape {x.shape}")
    if engine not in ("auto", "numba", "numpy"):
        raise HybridtrackError(f"unknown engine {engine!r}; choose auto, numba or numpy")
    outputs = None
    if engine != "numpy":
        from . import compiled

        kernel = compiled.kernel_for(system, required=engine == "numba")
        if kernel is not None:
            outputs, firing = kernel.evaluate(x, with_firing)
    if outputs is None:
        firing = system.firing(x)
        outputs = system.outputs(firing)
    for o in range(outputs.shape[1]):  # FCL's DEFAULT: the value when no rule fires
        default = system.system.default(o)
        if default is not None:
            outputs[np.isnan(outputs[:, o]) & ~np.isnan(x).any(axis=1), o] = default
    return outputs, firing


def _probor(a, b):
    return a + b - a * b


def skfuzzy_system(system: MamdaniSystem, output: int = 0):
    """The system (one output of it) built with scikit-fuzzy's control API, and its consequent.

    scikit-fuzzy clips by min and aggregates output terms by max only, and has no negated
    consequent; other systems are refused.
    """
    import skfuzzy as fuzz  # noqa: F401  (the control API needs the package)
    from skfuzzy import control as ctrl

    methods = system.methods
    if methods.implication != "min" or methods.aggregation != "max":
        raise HybridtrackError("scikit-fuzzy's control API has min implication and max aggregation only")
    n_in, n_out = system.resolution
    antecedents = []
    for var in system.inputs:
        ant = ctrl.Antecedent(np.linspace(*var.universe, n_in), var.name)
        for term in var.terms:
            ant[term.name] = sample_term(term, ant.universe)
        antecedents.append(ant)
    out = system.outputs[output]
    consequent = ctrl.Consequent(np.linspace(*out.universe, n_out), out.name, defuzzify_method=methods.defuzzification)
    used = {abs(rule.consequent[output]) for rule in system.rules}
    for k, term in enumerate(out.terms, start=1):
        if k in used:  # scikit-fuzzy's array mode fails on a term no rule names; it adds nothing anyway
            consequent[term.name] = sample_term(term, consequent.universe)
    and_func = np.fmin if methods.and_method == "min" else np.multiply
    or_func = np.fmax if methods.or_method == "max" else _probor
    rules = []
    for number, rule in enumerate(system.rules, start=1):
        k = rule.consequent[output]
        if k == 0:
            continue
        if k < 0:
            raise HybridtrackError(f"rules[{number}]: scikit-fuzzy has no negated consequent")
        parts = []
        for ant, var, i in zip(antecedents, system.inputs, rule.antecedent):
            if i:
                term = ant[var.terms[abs(i) - 1].name]
                parts.append(~term if i < 0 else term)
        antecedent = parts[0]
        for part in parts[1:]:
            antecedent = (antecedent | part) if rule.connection == "or" else (antecedent & part)
        then = consequent[out.terms[k - 1].name]
        rules.append(ctrl.Rule(antecedent, then % rule.weight if rule.weight != 1.0 else then,
                               and_func=and_func, or_func=or_func))
    return ctrl.ControlSystem(rules), consequent


def evaluate_skfuzzy(config: FuzzyConfig | MamdaniSystem, x: np.ndarray, *, one_at_a_time: bool = False,
                     output: int = 0) -> np.ndarray:
    """Values of one output from scikit-fuzzy's own control API for readings `x` (N, inputs).

    Array inputs go through one ``ControlSystemSimulation`` call. scikit-fuzzy refuses the
    whole array when any reading fires no rule. In that case the readings whose clip levels,
    as scikit-fuzzy computed them, are all zero are marked NaN and the rest run again.
    `one_at_a_time` runs a scalar simulation per reading instead, for benchmarking.
    """
    from skfuzzy.control import ControlSystemSimulation
    from skfuzzy.control.exceptions import EmptyMembershipError
    from skfuzzy.defuzzify import EmptyMembershipError as EmptyArrayError

    system = system_of(config) if isinstance(config, FuzzyConfig) else config
    control, consequent = skfuzzy_system(system, output)
    names = [var.name for var in system.inputs if var.name in {a.label for a in control.antecedents}]
    columns = {var.name: k for k, var in enumerate(system.inputs)}
    scores = np.full(len(x), np.nan)
    todo = np.flatnonzero(~np.isnan(x).any(axis=1))
    if one_at_a_time:
        sim = ControlSystemSimulation(control)
        for i in todo:
            for name in names:
                sim.input[name] = float(x[i, columns[name]])
            sim.compute()
            scores[i] = sim.output.get(consequent.label, np.nan)  # lenient: nothing when no rule fires
        return scores
    while len(todo):
        sim = ControlSystemSimulation(control, cache=False)
        for name in names:
            sim.input[name] = x[todo, columns[name]]
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
