"""The fuzzy classifier's configuration: inputs, terms, output, rules and label bands.

Parameters follow scikit-fuzzy's argument order (``gaussmf``: mean, sigma; ``gauss2mf``:
mean1, sigma1, mean2, sigma2; ``trimf``: a, b, c; ``trapmf``: a, b, c, d). MATLAB's ``.fis``
order differs for the Gaussians; `hybridtrack.fuzzy.fis` converts.

The default is the published system (docs/fuzzy-engine.md): intensity 30-300 mA and variation
0-180 mA, each normalised onto 0-10; Gaussian terms; a triangular output on 0-30; four rules.
The sigmas are a documented choice, since the publication gives only the shapes. Intensity
terms use σ = 1.5: a term is down to 0.004 five units from its peak ("nothing left").
Variation terms use σ = 2.5, the narrowest width at which the published reading
(200.1 mA, 84.6 mA) is cloudy through the cloudy rule firing (0.106 against the sunny rule's
0.048) rather than through a near-empty tie. All four published readings then land in their
classes at least 1.1 score units inside the band.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import HybridtrackError
from .membership import SHAPES, centre, check_params, membership

__all__ = ["Term", "Variable", "Rule", "Methods", "FuzzyConfig", "SHAPES", "LABELS", "METHOD_CHOICES"]

#: The classifier's inputs, in the order it takes a reading's values.
INPUT_NAMES = ("intensity", "variation")

#: The weather labels the controller understands, in score order.
LABELS = ("overcast", "cloudy", "sunny")

#: The keys of a rule in the TOML layout besides its variables' names.
RULE_KEYS = ("weight", "connection")

#: The inference options of a Mamdani system and the choices of each.
METHOD_CHOICES = {"and_method": ("min", "prod"), "or_method": ("max", "probor"), "implication": ("min", "prod"),
                  "aggregation": ("max", "sum", "probor"),
                  "defuzzification": ("centroid", "bisector", "mom", "som", "lom")}


@dataclass(frozen=True)
class Methods:
    """How a Mamdani system combines: AND, OR, implication, aggregation, defuzzification.

    The defaults are MATLAB's and scikit-fuzzy's (min, max, min, max, centroid). Rule
    weights multiply the firing strength before implication; aggregation runs over the
    rules' implied sets (MATLAB's definition; with max it is the same as scikit-fuzzy's
    maximum per output term).
    """

    and_method: str = "min"
    or_method: str = "max"
    implication: str = "min"
    aggregation: str = "max"
    defuzzification: str = "centroid"

    def check(self, where: str = "methods") -> None:
        """Raise `HybridtrackError` naming an unknown method."""
        for key, choices in METHOD_CHOICES.items():
            value = getattr(self, key)
            if value not in choices:
                raise HybridtrackError(f"{where}.{key}: unknown method {value!r}; choose from {', '.join(choices)}")

    def to_dict(self) -> dict[str, str]:
        """Plain dict of the five choices."""
        return {key: getattr(self, key) for key in METHOD_CHOICES}


def _finite_interval(bounds) -> bool:
    """Two finite numbers in increasing order whose width is finite too."""
    return len(bounds) == 2 and bounds[0] < bounds[1] and math.isfinite(bounds[1] - bounds[0])


@dataclass(frozen=True)
class Term:
    """A linguistic term: a name and a membership function on its variable's universe."""

    name: str
    shape: str
    params: tuple[float, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", tuple(float(p) for p in self.params))

    @property
    def centre(self) -> float:
        """Where the term peaks (the middle of its plateau; an open sigmoid's 0.5 crossing)."""
        return centre(self.shape, self.params)

    def check(self, where: str) -> None:
        """Raise `HybridtrackError` if the shape or its parameters are invalid."""
        check_params(self.shape, self.params, where)


@dataclass(frozen=True)
class Variable:
    """An input or output variable: its universe, its terms and (inputs) the raw range.

    Parameters
    ----------
    name : str
        ``intensity`` and ``variation`` for the inputs, ``weather`` for the output.
    universe : tuple of float
        The normalised universe, (0, 10) for inputs and (0, 30) for the output.
    terms : tuple of Term
    raw_range : tuple of float, optional
        Inputs only: the raw reading mapped linearly onto the universe (clipped), in `unit`.
    unit : str
        Unit of the raw reading, e.g. ``"mA"``.
    """

    name: str
    universe: tuple[float, float]
    terms: tuple[Term, ...]
    raw_range: tuple[float, float] | None = None
    unit: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "universe", tuple(float(v) for v in self.universe))
        object.__setattr__(self, "terms", tuple(self.terms))
        if self.raw_range is not None:
            object.__setattr__(self, "raw_range", tuple(float(v) for v in self.raw_range))

    def term(self, name: str) -> Term:
        """The term called `name`."""
        for term in self.terms:
            if term.name == name:
                return term
        raise HybridtrackError(f"variable {self.name!r} has no term {name!r}; it has {', '.join(self.term_names)}")

    @property
    def term_names(self) -> tuple[str, ...]:
        """The names of the terms, in order."""
        return tuple(term.name for term in self.terms)

    def to_universe(self, readings) -> np.ndarray:
        """Raw readings (in `unit`) mapped linearly onto the universe, clipped: ``u0 + (u1 - u0)
        (P - Pmin)/(Pmax - Pmin)`` with (Pmin, Pmax) the `raw_range`; without one, the readings
        are on the universe already and are returned as they are.

        Parameters
        ----------
        readings : float or array_like

        Returns
        -------
        numpy.ndarray
        """
        values = np.asarray(readings, float)
        if self.raw_range is None:
            return values
        lo, hi = self.raw_range
        u0, u1 = self.universe
        raw = np.clip(values, lo, hi)  # first, so 1e308 mA cannot overflow the scaling
        return np.clip(u0 + (u1 - u0) * (raw - lo) / (hi - lo), u0, u1)

    def check(self, where: str) -> None:
        """Raise `HybridtrackError` if the variable is not usable."""
        for name in ("universe", "raw_range"):
            bounds = getattr(self, name)
            if bounds is not None and not _finite_interval(bounds):
                raise HybridtrackError(f"{where}: {name} must be two finite numbers [low, high] with low < high, "
                                       f"got {list(bounds)}")
        if not self.terms:
            raise HybridtrackError(f"{where}: no terms")
        if len(set(self.term_names)) != len(self.terms):
            raise HybridtrackError(f"{where}: duplicate term names in {list(self.term_names)}")
        for term in self.terms:
            term.check(f"{where}.terms.{term.name}")
        for k, term in enumerate(self.terms):
            for other in self.terms[k + 1:]:
                if term.shape == other.shape and term.params == other.params:
                    raise HybridtrackError(f"{where}: terms {term.name!r} and {other.name!r} overlap completely "
                                           f"({term.shape} {list(term.params)}); rules could not tell them apart")


@dataclass(frozen=True)
class Rule:
    """IF the named inputs are their terms THEN the output is `then`.

    Parameters
    ----------
    when : mapping of str to str
        Input name to term name; an input left out does not matter to the rule.
    then : str
        Output term name.
    weight : float
        Multiplies the rule's firing strength, 0-1 (MATLAB's rule weight).
    connection : {"and", "or"}
        How the conditions combine, with the system's AND or OR method.
    negated : iterable of str
        Inputs whose condition reads "is not": their membership is taken as one minus it.
    """

    when: Mapping[str, str]
    then: str
    weight: float = 1.0
    connection: str = "and"
    negated: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "when", tuple(sorted(dict(self.when).items())))
        object.__setattr__(self, "negated", tuple(sorted(set(self.negated))))
        object.__setattr__(self, "weight", float(self.weight))

    @property
    def conditions(self) -> dict[str, str]:
        """The rule's conditions as a dict, input name to term name."""
        return dict(self.when)

    def describe(self, inputs: tuple[str, ...]) -> str:
        """``intensity is strong AND variation is not small -> sunny`` (with ``(weight 0.5)``)."""
        parts = [f"{name} is {'not ' if name in self.negated else ''}{self.conditions[name]}"
                 for name in inputs if name in self.conditions]
        weight = f" (weight {self.weight:g})" if self.weight != 1.0 else ""
        return f"{f' {self.connection.upper()} '.join(parts)} -> {self.then}{weight}"

    def check(self, where: str) -> None:
        """Raise `HybridtrackError` for a bad weight, connection or negation."""
        if not 0.0 <= self.weight <= 1.0:
            raise HybridtrackError(f"{where}: weight must be between 0 and 1, got {self.weight}")
        if self.connection not in ("and", "or"):
            raise HybridtrackError(f"{where}: connection must be 'and' or 'or', got {self.connection!r}")
        stray = sorted(set(self.negated) - set(self.conditions))
        if stray:
            raise HybridtrackError(f"{where}: negates {stray[0]!r}, which the rule does not name")


def _default_inputs() -> tuple[Variable, Variable]:
    intensity = Variable(
        "intensity", (0.0, 10.0),
        (Term("weak", "gaussmf", (0.0, 1.5)), Term("medium", "gaussmf", (5.0, 1.5)),
         Term("strong", "gaussmf", (10.0, 1.5))),
        raw_range=(30.0, 300.0), unit="mA",
    )
    variation = Variable(
        "variation", (0.0, 10.0),
        (Term("small", "gaussmf", (0.0, 2.5)), Term("large", "gaussmf", (10.0, 2.5))),
        raw_range=(0.0, 180.0), unit="mA",
    )
    return intensity, variation


def _default_output() -> Variable:
    return Variable(
        "weather", (0.0, 30.0),
        (Term("overcast", "trimf", (0.0, 5.0, 10.0)), Term("cloudy", "trimf", (10.0, 15.0, 20.0)),
         Term("sunny", "trimf", (20.0, 25.0, 30.0))),
    )


PUBLISHED_RULES = (
    Rule({"intensity": "strong", "variation": "small"}, "sunny"),
    Rule({"intensity": "strong", "variation": "large"}, "cloudy"),
    Rule({"intensity": "medium", "variation": "large"}, "cloudy"),
    Rule({"intensity": "weak", "variation": "small"}, "overcast"),
)

#: The published table completed with its two unruled cells (``data/fuzzy-complete.toml``). A
#: choice, not a correction: it turns the published overcast reading (143.4, 45.0) cloudy.
COMPLETE_RULES = PUBLISHED_RULES + (
    Rule({"intensity": "medium", "variation": "small"}, "cloudy"),
    Rule({"intensity": "weak", "variation": "large"}, "overcast"),
)


@dataclass(frozen=True)
class FuzzyConfig:
    """A complete Mamdani weather classifier: two inputs, one output, rules and bands.

    Parameters
    ----------
    inputs : tuple of Variable
        ``intensity`` then ``variation``, each with a `raw_range`.
    output : Variable
        ``weather`` on 0-30.
    rules : tuple of Rule
    bands : tuple of (label, low, high)
        The score band of each weather label, covering the output universe in order; a score
        belongs to the band with ``low <= score < high`` (the last band includes its top).
    resolution : tuple of int
        Samples across (input universes, output universe); both engines evaluate the system
        on these samples, as scikit-fuzzy does.
    name : str
    labelled_range : tuple of (low, high), optional
        Set by tuning: the raw range of each input (in order) that the labelled readings
        covered. A classifier warns when it is applied outside it
        (`hybridtrack.fuzzy.tuning.OutsideLabelsWarning`). Written as ``[labelled_range]``.
    methods : Methods
        AND, OR, implication, aggregation and defuzzification (min, max, min, max and
        centroid by default, as published).
    """

    inputs: tuple[Variable, ...] = field(default_factory=_default_inputs)
    output: Variable = field(default_factory=_default_output)
    rules: tuple[Rule, ...] = PUBLISHED_RULES
    bands: tuple[tuple[str, float, float], ...] = (("overcast", 0.0, 10.0), ("cloudy", 10.0, 20.0),
                                                   ("sunny", 20.0, 30.0))
    resolution: tuple[int, int] = (1001, 3001)
    name: str = "published"
    labelled_range: tuple[tuple[float, float], ...] | None = None
    methods: Methods = Methods()

    def __post_init__(self) -> None:
        object.__setattr__(self, "inputs", tuple(self.inputs))
        object.__setattr__(self, "rules", tuple(self.rules))
        object.__setattr__(self, "bands", tuple((str(n), float(lo), float(hi)) for n, lo, hi in self.bands))
        object.__setattr__(self, "resolution", tuple(int(r) for r in self.resolution))
        if self.labelled_range is not None:
            object.__setattr__(self, "labelled_range", tuple((float(lo), float(hi)) for lo, hi in self.labelled_range))
        self.validate()

    # -- construction ------------------------------------------------------------------------

    @classmethod
    def default(cls) -> FuzzyConfig:
        """The published system (docs/fuzzy-engine.md)."""
        return cls()

    @classmethod
    def complete(cls) -> FuzzyConfig:
        """The published system with its two unruled cells filled (six rules)."""
        return cls(rules=COMPLETE_RULES, name="complete")

    def replace(self, **changes) -> FuzzyConfig:
        """A copy with some fields changed (validated)."""
        return replace(self, **changes)

    def with_params(self, variable: str, term: str, params) -> FuzzyConfig:
        """A copy with one term's parameters changed."""
        def swap(var: Variable) -> Variable:
            if var.name != variable:
                return var
            var.term(term)
            return replace(var, terms=tuple(replace(t, params=tuple(params)) if t.name == term else t
                                            for t in var.terms))

        return replace(self, inputs=tuple(swap(v) for v in self.inputs), output=swap(self.output))

    # -- validation --------------------------------------------------------------------------

    @property
    def input_names(self) -> tuple[str, ...]:
        """Names of the inputs, in order."""
        return tuple(v.name for v in self.inputs)

    def variable(self, name: str) -> Variable:
        """The input or output variable called `name`."""
        for var in (*self.inputs, self.output):
            if var.name == name:
                return var
        names = ", ".join((*self.input_names, self.output.name))
        raise HybridtrackError(f"no variable {name!r}; the config has {names}")

    def validate(self) -> None:
        """Raise `HybridtrackError` naming the first problem found."""
        from .system import check_resolution

        check_resolution(self.resolution)  # first: the terms' reach is checked on these samples
        if len(self.inputs) != 2:
            raise HybridtrackError(f"config needs two inputs (intensity, variation), got {len(self.inputs)}")
        if self.input_names == INPUT_NAMES[::-1]:  # the photocurrent had been scored as the variation
            raise HybridtrackError("inputs: intensity must come first, then variation (the classifier takes a "
                                   f"reading's intensity and variation in that order), got {list(self.input_names)}")
        from .classifier import impossible_reading

        for var, reading in zip(self.inputs, INPUT_NAMES):
            var.check(f"inputs.{var.name}")
            if var.raw_range is None:
                raise HybridtrackError(f"inputs.{var.name}: raw_range is missing")
            # the readings a sensor gives: [30, 1e308] mA had mapped every real one onto the universe's floor
            bound = next((v for v in var.raw_range if impossible_reading(v, reading)), None)
            if bound is not None:
                raise HybridtrackError(f"inputs.{var.name}: raw_range {list(var.raw_range)}: {bound:g} is no reading; "
                                       f"{impossible_reading(bound, reading)}")
        self.output.check(f"output.{self.output.name}")
        self._validate_reach()
        if len(set(self.input_names)) != 2 or self.output.name in self.input_names:
            raise HybridtrackError(f"variable names must differ, got {list(self.input_names)} and {self.output.name!r}")
        self._validate_names()
        if not self.rules:
            raise HybridtrackError("the rule table is empty")
        for number, rule in enumerate(self.rules, start=1):
            where = f"rules[{number}]"
            if not rule.conditions:
                raise HybridtrackError(f"{where}: a rule needs at least one condition")
            rule.check(where)
            for name, term in rule.conditions.items():
                if name not in self.input_names:
                    raise HybridtrackError(f"{where}: unknown input {name!r}; inputs are {', '.join(self.input_names)}")
                if term not in self.variable(name).term_names:
                    terms = ", ".join(self.variable(name).term_names)
                    raise HybridtrackError(f"{where}: unknown term {term!r} for {name}; terms are {terms}")
            if rule.then not in self.output.term_names:
                raise HybridtrackError(
                    f"{where}: unknown output term {rule.then!r}; terms are {', '.join(self.output.term_names)}"
                )
        if len({(rule.when, rule.connection, rule.negated) for rule in self.rules}) != len(self.rules):
            raise HybridtrackError("the rule table has two rules with the same conditions")
        self.methods.check()
        self._validate_bands()
        if self.labelled_range is not None and (
                len(self.labelled_range) != len(self.inputs)
                or not all(math.isfinite(lo) and math.isfinite(hi) and lo <= hi for lo, hi in self.labelled_range)):
            raise HybridtrackError(f"labelled_range needs a finite [low, high] for each input, got {self.labelled_range}")

    def _validate_reach(self) -> None:
        """Refuse a term that is 0 at every sample of its universe (one beyond it, or narrower than
        a sample's spacing off the samples): no rule on it could fire, and a classifier of such
        terms had called every reading unknown without a word."""
        for var, samples, where in [*((v, self.resolution[0], "inputs") for v in self.inputs),
                                    (self.output, self.resolution[1], "output")]:
            grid = np.linspace(*var.universe, samples)
            for term in var.terms:
                if not membership(term.shape, term.params, grid).max() > 0.0:
                    raise HybridtrackError(f"{where}.{var.name}.terms.{term.name}: {term.shape} {list(term.params)} "
                                           f"is 0 at every one of the {samples:,} samples of the universe "
                                           f"{var.universe[0]:g}-{var.universe[1]:g}; no rule on it could fire")

    def _validate_names(self) -> None:
        """Refuse the names a TOML rule table would read as something else, so that every config
        `to_toml` writes `from_toml` reads back: a variable named like a rule's own keys
        (`RULE_KEYS`), and an input term whose name reads as a negation (``not ...``) or loses its
        blanks when a negation is read."""
        for var in (*self.inputs, self.output):
            if var.name in RULE_KEYS:
                raise HybridtrackError(f"{'output' if var is self.output else 'inputs'}.{var.name}: a variable "
                                       f"cannot be named {var.name!r}, a rule's own key in the TOML layout")
        for var in self.inputs:
            for term in var.term_names:
                if term.lower().startswith("not ") or term != term.strip():
                    raise HybridtrackError(f"inputs.{var.name}.terms.{term}: a term name {term!r} would read as "
                                           "another in a rule (a rule's 'not TERM' negates TERM); rename it")

    def _validate_bands(self) -> None:
        if not self.bands:
            raise HybridtrackError("bands: no weather bands")
        lo, hi = self.output.universe
        edges = [band[1] for band in self.bands] + [self.bands[-1][2]]
        if edges[0] != lo or edges[-1] != hi:
            raise HybridtrackError(f"bands must cover the output universe {lo}-{hi}, they cover {edges[0]}-{edges[-1]}")
        for (name, low, high), (next_name, next_low, _) in zip(self.bands, self.bands[1:]):
            if next_low != high:
                raise HybridtrackError(f"bands {name!r} and {next_name!r} must meet: {high} vs {next_low}")
        for name, low, high in self.bands:
            if not low < high:
                raise HybridtrackError(f"band {name!r} is inverted or empty: {low}-{high}")
        if len({band[0] for band in self.bands}) != len(self.bands):
            raise HybridtrackError("bands: duplicate labels")

    # -- TOML --------------------------------------------------------------------------------

    def to_dict(self) -> dict:
        """A plain dict in the TOML layout."""
        def terms(var: Variable) -> dict:
            return {t.name: {"shape": t.shape, "params": list(t.params)} for t in var.terms}

        inputs = {}
        for var in self.inputs:
            inputs[var.name] = {"raw_range": list(var.raw_range), "unit": var.unit,
                                "universe": list(var.universe), "terms": terms(var)}
        data = {
            "name": self.name,
            "resolution": {"input": self.resolution[0], "output": self.resolution[1]},
            "inputs": inputs,
            "output": {"name": self.output.name, "universe": list(self.output.universe), "terms": terms(self.output)},
            "bands": {name: [low, high] for name, low, high in self.bands},
            "methods": self.methods.to_dict(),
            "rules": [self._rule_dict(rule) for rule in self.rules],
        }
        if self.labelled_range is not None:
            data["labelled_range"] = {var.name: list(pair) for var, pair in zip(self.inputs, self.labelled_range)}
        return data

    def _rule_dict(self, rule: Rule) -> dict:
        spec = {name: f"not {term}" if name in rule.negated else term for name, term in rule.conditions.items()}
        spec[self.output.name] = rule.then
        if rule.weight != 1.0:
            spec["weight"] = rule.weight
        if rule.connection != "and":
            spec["connection"] = rule.connection
        return spec

    @classmethod
    def from_dict(cls, data: Mapping, *, source: str = "config") -> FuzzyConfig:
        """Build and validate a config from the TOML layout; unknown keys are refused."""
        reader = _Reader(source)
        if isinstance(data, Mapping) and {"controller", "imperfections", "drive"} & set(data):
            reader.fail("", "a run config (controller, imperfections, drive, ...), not a fuzzy classifier config; "
                            "give a fuzzy config, such as the fuzzy.toml hybridtrack init writes")
        data = reader.table(data, "", {"name", "resolution", "inputs", "output", "bands", "rules", "labelled_range", "methods"})
        default = cls()
        inputs = tuple(
            reader.variable(name, spec, f"inputs.{name}", is_input=True)
            for name, spec in reader.table(data.get("inputs"), "inputs").items()
        ) if "inputs" in data else default.inputs
        if tuple(var.name for var in inputs) == INPUT_NAMES[::-1]:  # by name, not by where a table stands
            inputs = inputs[::-1]
        output_spec = reader.table(data.get("output", {}), "output", {"name", "universe", "terms"})
        output = reader.variable(output_spec.get("name", "weather"), output_spec, "output", is_input=False) \
            if "output" in data else default.output
        rules = default.rules
        if "rules" in data:
            if not isinstance(data["rules"], list):
                raise HybridtrackError(f"{source}: rules must be an array of tables ([[rules]])")
            rules = tuple(reader.rule(spec, number, output.name) for number, spec in enumerate(data["rules"], 1))
        bands = default.bands
        if "bands" in data:
            bands = tuple((name, *reader.pair(value, f"bands.{name}"))
                          for name, value in reader.table(data["bands"], "bands").items())
        resolution = default.resolution
        if "resolution" in data:
            res = reader.table(data["resolution"], "resolution", {"input", "output"})
            resolution = (reader.integer(res.get("input", resolution[0]), "resolution.input"),
                          reader.integer(res.get("output", resolution[1]), "resolution.output"))
        name = data.get("name", "custom")
        if not isinstance(name, str):
            raise HybridtrackError(f"{source}: name must be a string, got {name!r}")
        labelled = None
        if "labelled_range" in data:
            spans = reader.table(data["labelled_range"], "labelled_range", {var.name for var in inputs})
            labelled = tuple(reader.pair(spans[var.name], f"labelled_range.{var.name}") if var.name in spans
                             else reader.fail("labelled_range", f"{var.name} is missing") for var in inputs)
        methods = Methods()
        if "methods" in data:
            spec = reader.table(data["methods"], "methods", set(METHOD_CHOICES))
            for key, value in spec.items():
                if not isinstance(value, str):
                    reader.fail(f"methods.{key}", f"must be a string, got {value!r}")
            methods = Methods(**spec)
        try:
            return cls(inputs=inputs, output=output, rules=rules, bands=bands, resolution=resolution, name=name,
                       labelled_range=labelled, methods=methods)
        except HybridtrackError as exc:
            raise HybridtrackError(f"{source}: {exc}") from None

    @classmethod
    def from_toml(cls, path) -> FuzzyConfig:
        """Load a config from a TOML file (see ``data/fuzzy-complete.toml``)."""
        from ..io import read_toml

        return cls.from_dict(read_toml(path), source=str(path))

    def to_toml(self, path) -> Path:
        """Write the config as TOML; `from_toml` reads it back equal."""
        from ..io import write_toml

        return write_toml(self.to_dict(), path)

    # -- MATLAB .fis -------------------------------------------------------------------------

    @classmethod
    def from_fis(cls, path, **options) -> FuzzyConfig:
        """Load a MATLAB Mamdani ``.fis`` file; `options` as for `hybridtrack.fuzzy.fis.read_fis`."""
        from .fis import read_fis

        return read_fis(path, **options)

    def to_fis(self, path) -> Path:
        """Write the config as a MATLAB ``.fis`` file (see `hybridtrack.fuzzy.fis`)."""
        from .fis import write_fis

        return write_fis(self, path)

    # -- IEC 61131-7 FCL ---------------------------------------------------------------------

    @classmethod
    def from_fcl(cls, path, *, raw_ranges=None, bands=None, resolution=None) -> FuzzyConfig:
        """Load an FCL function block with two inputs and one output (see `hybridtrack.fuzzy.fcl`)."""
        from .fcl import read_fcl
        from .system import config_from_system

        system = read_fcl(path, resolution=resolution)
        return config_from_system(system, raw_ranges=raw_ranges, bands=bands, where=str(path))

    def to_fcl(self, path) -> Path:
        """Write the config as an IEC 61131-7 FCL function block."""
        from .fcl import write_fcl

        return write_fcl(self, path)

    def system(self):
        """The general `hybridtrack.fuzzy.system.MamdaniSystem` this classifier runs."""
        from .system import system_of

        return system_of(self)


class _Reader:
    """Type-checks the TOML layout, naming the key of the first problem."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, message: str):
        raise HybridtrackError(f"{self.source}: {where}: {message}" if where else f"{self.source}: {message}")

    def table(self, value, where: str, allowed: set[str] | None = None) -> dict:
        if not isinstance(value, Mapping):
            self.fail(where, f"must be a table, got {type(value).__name__}")
        if allowed is not None:
            unknown = sorted(set(value) - allowed)
            if unknown:
                self.fail(where, f"unknown key {unknown[0]!r}; allowed: {', '.join(sorted(allowed))}")
        return dict(value)

    def number(self, value, where: str) -> float:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
            self.fail(where, f"must be a number, got {value!r}")
        return float(value)

    def integer(self, value, where: str) -> int:
        """A whole number, numpy's too (np.int64 had been refused where np.float64 was taken)."""
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
            self.fail(where, f"must be a whole number, got {value!r}")
        return int(value)

    def pair(self, value, where: str) -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            self.fail(where, f"must be [low, high], got {value!r}")
        return self.number(value[0], where), self.number(value[1], where)

    def variable(self, name: str, spec, where: str, *, is_input: bool) -> Variable:
        keys = {"raw_range", "unit", "universe", "terms"} if is_input else {"name", "universe", "terms"}
        spec = self.table(spec, where, keys)
        terms = []
        for term_name, term_spec in self.table(spec.get("terms"), f"{where}.terms").items():
            term_where = f"{where}.terms.{term_name}"
            term_spec = self.table(term_spec, term_where, {"shape", "params"})
            shape = term_spec.get("shape")
            if not isinstance(shape, str):
                self.fail(term_where, f"shape must be a string, got {shape!r}")
            params = term_spec.get("params")
            if not isinstance(params, list):
                self.fail(term_where, f"params must be a list of numbers, got {params!r}")
            terms.append(Term(term_name, shape, tuple(self.number(p, f"{term_where}.params") for p in params)))
        universe = self.pair(spec.get("universe", [0.0, 10.0] if is_input else [0.0, 30.0]), f"{where}.universe")
        if not is_input:
            return Variable(name, universe, tuple(terms))
        if "raw_range" not in spec:
            self.fail(where, "raw_range is missing")
        unit = spec.get("unit", "")
        if not isinstance(unit, str):
            self.fail(f"{where}.unit", f"must be a string, got {unit!r}")
        return Variable(name, universe, tuple(terms), self.pair(spec["raw_range"], f"{where}.raw_range"), unit)

    def rule(self, spec, number: int, output_name: str) -> Rule:
        where = f"rules[{number}]"
        spec = self.table(spec, where)
        weight = self.number(spec.pop("weight", 1.0), f"{where}.weight")
        connection = spec.pop("connection", "and")
        for key, value in spec.items():
            if not isinstance(value, str):
                self.fail(f"{where}.{key}", f"must be a term name, got {value!r}")
        if not isinstance(connection, str):
            self.fail(f"{where}.connection", f"must be 'and' or 'or', got {connection!r}")
        if output_name not in spec:
            self.fail(where, f"says nothing of the output {output_name!r}")
        then = spec.pop(output_name)
        negated = [name for name, term in spec.items() if term.lower().startswith("not ")]
        when = {name: term[4:].strip() if name in negated else term for name, term in spec.items()}
        return Rule(when, then, weight, connection, negated)
