"""A general type-1 Mamdani system: any number of inputs and outputs, MATLAB's rule layout.

`MamdaniSystem` is what ``.fis`` and FCL files hold and what the engine runs. Rules are
index lists, as in MATLAB: per input 0 ("any"), ``k`` (term k, from 1) or ``-k`` ("not
term k"); per output 0 (the rule says nothing of it), ``k`` or ``-k`` (the complement of
term k); a weight 0-1 and AND or OR. The sky classifier's `FuzzyConfig` is one such system
(two inputs, one output) plus what a classifier needs besides: raw sensor ranges and label
bands; `FuzzyConfig.system` and `FuzzyConfig.from_system` convert.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import HybridtrackError
from .config import FuzzyConfig, Methods, Rule, Variable

__all__ = ["MamdaniSystem", "SystemRule", "system_of", "config_from_system", "format_number", "check_resolution",
           "MAX_RESOLUTION"]


def format_number(value: float) -> str:
    """The shortest text that reads back as the same float (``10`` rather than ``10.0``)."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


@dataclass(frozen=True)
class SystemRule:
    """One rule in MATLAB's layout (see the module docstring)."""

    antecedent: tuple[int, ...]
    consequent: tuple[int, ...]
    weight: float = 1.0
    connection: str = "and"

    def __post_init__(self) -> None:
        if sum(1 for v in self.antecedent if v) <= 1:  # one condition: AND and OR are the same rule
            object.__setattr__(self, "connection", "and")
        object.__setattr__(self, "antecedent", tuple(int(v) for v in self.antecedent))
        object.__setattr__(self, "consequent", tuple(int(v) for v in self.consequent))
        object.__setattr__(self, "weight", float(self.weight))


@dataclass(frozen=True)
class MamdaniSystem:
    """Inputs, outputs, rules, methods and the sampling of the universes.

    Parameters
    ----------
    inputs, outputs : tuple of Variable
    rules : tuple of SystemRule
    methods : Methods
    defaults : tuple of (float or None)
        Per output, the value given when no rule fires (FCL's ``DEFAULT``); empty or None
        leaves it NaN. ``.fis`` files have no such value.
    resolution : (int, int)
        Samples across every input universe and every output universe. The engine evaluates
        the system on these samples exactly as scikit-fuzzy does: input memberships are
        linear interpolations of the sampled terms, and the output set is sampled with its
        cut points added.
    name : str
    """

    inputs: tuple[Variable, ...]
    outputs: tuple[Variable, ...]
    rules: tuple[SystemRule, ...]
    methods: Methods = Methods()
    resolution: tuple[int, int] = (1001, 3001)
    name: str = "system"
    defaults: tuple[float | None, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "defaults", tuple(None if d is None else float(d) for d in self.defaults))
        for key in ("inputs", "outputs", "rules"):
            object.__setattr__(self, key, tuple(getattr(self, key)))
        object.__setattr__(self, "resolution", tuple(int(r) for r in self.resolution))
        self.validate()

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.inputs)

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(v.name for v in self.outputs)

    def validate(self) -> None:
        """Raise `HybridtrackError` naming the first problem."""
        if not self.inputs or not self.outputs:
            raise HybridtrackError("a system needs at least one input and one output")
        names = (*self.input_names, *self.output_names)
        if len(set(names)) != len(names):
            raise HybridtrackError(f"variable names must differ, got {list(names)}")
        for var in self.inputs:
            var.check(f"inputs.{var.name}")
        for var in self.outputs:
            var.check(f"outputs.{var.name}")
        self.methods.check()
        if not self.rules:
            raise HybridtrackError("the rule table is empty")
        for number, rule in enumerate(self.rules, start=1):
            self._check_rule(rule, f"rules[{number}]")
        if self.defaults and len(self.defaults) != len(self.outputs):
            raise HybridtrackError(f"defaults: one per output ({len(self.outputs)}), got {len(self.defaults)}")
        if any(d is not None and d != d for d in self.defaults):
            raise HybridtrackError("defaults must be numbers")
        check_resolution(self.resolution)

    def _check_rule(self, rule: SystemRule, where: str) -> None:
        if len(rule.antecedent) != len(self.inputs) or len(rule.consequent) != len(self.outputs):
            raise HybridtrackError(f"{where}: needs {len(self.inputs)} input and {len(self.outputs)} output indices, "
                                   f"got {len(rule.antecedent)} and {len(rule.consequent)}")
        for var, index in (*zip(self.inputs, rule.antecedent), *zip(self.outputs, rule.consequent)):
            if abs(index) > len(var.terms):
                raise HybridtrackError(f"{where}: {var.name} has no term {abs(index)}")
        if not any(rule.antecedent):
            raise HybridtrackError(f"{where}: a rule needs at least one condition")
        if not any(rule.consequent):
            raise HybridtrackError(f"{where}: a rule needs at least one consequent")
        Rule({}, "", rule.weight, rule.connection).check(where)

    def default(self, output: int) -> float | None:
        """The value of output `output` when no rule fires, or None (NaN)."""
        return self.defaults[output] if self.defaults else None

    def describe(self, rule: SystemRule) -> str:
        """``IF service IS poor OR food IS rancid THEN tip IS cheap``."""
        def phrase(var, index):
            return f"{var.name} IS {'NOT ' if index < 0 else ''}{var.terms[abs(index) - 1].name}"

        ifs = [phrase(v, i) for v, i in zip(self.inputs, rule.antecedent) if i]
        thens = [phrase(v, i) for v, i in zip(self.outputs, rule.consequent) if i]
        weight = f" WITH {format_number(rule.weight)}" if rule.weight != 1.0 else ""
        return f"IF {f' {rule.connection.upper()} '.join(ifs)} THEN {', '.join(thens)}{weight}"


def system_of(config: FuzzyConfig) -> MamdaniSystem:
    """The `MamdaniSystem` a classifier config runs (two inputs, one output)."""
    rules = []
    for rule in config.rules:
        conditions = rule.conditions
        antecedent = []
        for var in config.inputs:
            index = var.term_names.index(conditions[var.name]) + 1 if var.name in conditions else 0
            antecedent.append(-index if var.name in rule.negated else index)
        consequent = (config.output.term_names.index(rule.then) + 1,)
        rules.append(SystemRule(tuple(antecedent), consequent, rule.weight, rule.connection))
    return MamdaniSystem(config.inputs, (config.output,), tuple(rules), config.methods, config.resolution, config.name)


#: The most samples across a universe, ten times the default's across an input: the dense
#: defuzzifications (mom, som, lom, bisector) hold a chunk of readings by samples, 1.5 GB at this
#: many; 10**9 (a slip of a few digits) had filled the memory until the system killed the command.
MAX_RESOLUTION = 10_001


def check_resolution(resolution) -> None:
    """Refuse a `resolution` that is not two sample counts from 3 to `MAX_RESOLUTION`.

    Parameters
    ----------
    resolution : tuple of int
        Samples across (input universes, output universe).
    """
    if len(resolution) != 2 or any(not 3 <= r <= MAX_RESOLUTION for r in resolution):
        raise HybridtrackError(f"resolution needs two sample counts from 3 to {MAX_RESOLUTION:,}, got "
                               f"{list(resolution)}")


def config_from_system(system: MamdaniSystem, *, raw_ranges=None, units=None, bands=None, resolution=None,
                       where: str = "system") -> FuzzyConfig:
    """A classifier config from a two-input, one-output system.

    `raw_ranges` are the raw sensor ranges of the two inputs (the published 30-300 mA and
    0-180 mA by default). By default the `bands` meet halfway between the centres of
    neighbouring output terms, which gives the published 10/20 split for the published terms.
    """
    if any(d is not None for d in system.defaults):
        raise HybridtrackError(f"{where}: the classifier labels a reading 'unknown' when no rule fires; "
                               "it takes no DEFAULT output value")
    if len(system.inputs) != 2 or len(system.outputs) != 1:
        raise HybridtrackError(f"{where}: the sky classifier needs two inputs and one output, this system has "
                               f"{len(system.inputs)} and {len(system.outputs)}")
    ranges = raw_ranges if raw_ranges is not None else ((30.0, 300.0), (0.0, 180.0))
    units = units if units is not None else ("mA", "mA")
    inputs = tuple(Variable(v.name, v.universe, v.terms, tuple(r), u) for v, r, u in zip(system.inputs, ranges, units))
    output = system.outputs[0]
    rules = []
    for number, rule in enumerate(system.rules, start=1):
        if rule.consequent[0] < 0:
            raise HybridtrackError(f"{where}: rules[{number}]: a negated consequent cannot be a weather label")
        when = {var.name: var.terms[abs(i) - 1].name for var, i in zip(inputs, rule.antecedent) if i}
        negated = [var.name for var, i in zip(inputs, rule.antecedent) if i < 0]
        rules.append(Rule(when, output.terms[rule.consequent[0] - 1].name, rule.weight, rule.connection, negated))
    if bands is None:
        ordered = sorted(output.terms, key=lambda t: t.centre)
        cuts = [0.5 * (a.centre + b.centre) for a, b in zip(ordered, ordered[1:])]
        edges = [output.universe[0], *cuts, output.universe[1]]
        bands = tuple((t.name, lo, hi) for t, lo, hi in zip(ordered, edges, edges[1:]))
    try:
        return FuzzyConfig(inputs=inputs, output=output, rules=tuple(rules), bands=tuple(bands),
                           resolution=tuple(resolution) if resolution is not None else system.resolution,
                           name=system.name, methods=system.methods)
    except HybridtrackError as exc:
        raise HybridtrackError(f"{where}: {exc}") from None
