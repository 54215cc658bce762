"""IEC 61131-7 Fuzzy Control Language (FCL): read and write Mamdani systems.

A function block declares its inputs and outputs (``VAR_INPUT``, ``VAR_OUTPUT``), the terms
of each (``FUZZIFY``, ``DEFUZZIFY``) and its rules (``RULEBLOCK``)::

    FUZZIFY service
        RANGE := (0 .. 10);
        TERM poor := gaussmf(1.5, 0);
        TERM good := (1, 0) (4, 1) (6, 1) (9, 0);
    END_FUZZIFY
    DEFUZZIFY tip
        RANGE := (0 .. 30);
        TERM cheap := (0, 0) (5, 1) (10, 0);
        METHOD : COG;
    END_DEFUZZIFY
    RULEBLOCK rules
        AND : MIN; OR : MAX; ACT : MIN; ACCU : MAX;
        RULE 1 : IF service IS poor OR food IS rancid THEN tip IS cheap;
        RULE 2 : IF service IS NOT good THEN tip IS average WITH 0.5;
    END_RULEBLOCK

The standard describes terms as point lists; triangles and trapezoids are written so
(``(a, 0) (b, 1) (c, 0)``), and point lists read back as triangles and trapezoids, open
shoulders included (a shoulder extends to the end of the range, as the standard's constant
continuation does). The other nine types are written as an extension, ``TYPE(p1, p2, ...)``
with MATLAB's type name and parameter order, as in ``.fis`` files. ``RANGE`` in FUZZIFY (a
common extension) gives an input's universe; without it the universe spans the terms'
points. Methods: AND ``MIN``/``PROD``; OR ``MAX``/``ASUM`` (probabilistic or); ACT
``MIN``/``PROD``; ACCU ``MAX``, ``SUM`` and ``PROBOR`` (the last two as jFuzzyLogic spells
them); METHOD ``COG`` (centroid), ``COA`` (bisector), ``MM`` (mean of maximum), ``LM``
and ``RM`` (left- and rightmost maximum). ``DEFAULT := value`` is kept (the output when no
rule fires); ``DEFAULT := NC`` means none. Anything else (singletons, ``COGS``, bounded sums,
parentheses or mixed AND/OR in a rule, hedges) is refused with the file and line.

References
----------
IEC 61131-7:2000, Programmable controllers - Part 7: Fuzzy control programming.
International Electrotechnical Commission, Geneva.
Cingolani, P. and Alcalá-Fdez, J. (2013). jFuzzyLogic: a Java library to design fuzzy logic
controllers according to the standard for fuzzy control programming. International Journal
of Computational Intelligence Systems 6(sup1), 61-75. https://doi.org/10.1080/18756891.2013.818190
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import HybridtrackError
from ..outputs import claim, removing_empty_folders, write
from .config import FuzzyConfig, Methods, Term, Variable
from .membership import SHAPES, from_matlab, to_matlab
from .system import MamdaniSystem, SystemRule, format_number, system_of

__all__ = ["read_fcl", "write_fcl", "fcl_text"]

_AND = {"MIN": "min", "PROD": "prod"}
_OR = {"MAX": "max", "ASUM": "probor"}
_ACT = {"MIN": "min", "PROD": "prod"}
_ACCU = {"MAX": "max", "SUM": "sum", "PROBOR": "probor"}
_DEFUZZ = {"COG": "centroid", "COA": "bisector", "MM": "mom", "LM": "som", "RM": "lom"}
_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_BLOCKS = ("FUNCTION_BLOCK", "END_FUNCTION_BLOCK", "VAR_INPUT", "VAR_OUTPUT", "END_VAR", "FUZZIFY", "END_FUZZIFY",
           "DEFUZZIFY", "END_DEFUZZIFY", "RULEBLOCK", "END_RULEBLOCK")


def _name(text: str, what: str) -> str:
    if not _IDENTIFIER.match(text):
        raise HybridtrackError(f"{what} {text!r} is not an FCL identifier (letters, digits and _)")
    return text


def _block_name(text: str) -> str:
    """`text` as the function block's identifier, each character FCL does not take an underscore:
    the block's name is a label no rule refers to, and a tuned system's ('published-tuned') had
    made every tuned classifier unwritable as FCL (after its fit)."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", text)
    return name if _IDENTIFIER.match(name) else f"_{name}"


def _points(term: Term) -> str:
    p = [format_number(v) for v in term.params]
    ys = ("0", "1", "0") if term.shape == "trimf" else ("0", "1", "1", "0")
    return " ".join(f"({x}, {y})" for x, y in zip(p, ys))


def _term(term: Term) -> str:
    if term.shape in ("trimf", "trapmf"):
        return _points(term)
    return f"{term.shape}({', '.join(format_number(v) for v in to_matlab(term.shape, term.params))})"


def _key(table: dict[str, str], value: str) -> str:
    return next(key for key, mine in table.items() if mine == value)


def fcl_text(system: MamdaniSystem) -> str:
    """The system as an IEC 61131-7 function block."""
    methods = system.methods
    lines = [f"FUNCTION_BLOCK {_block_name(system.name)}", "", "VAR_INPUT"]
    lines += [f"    {_name(var.name, 'input')} : REAL;" for var in system.inputs]
    lines += ["END_VAR", "", "VAR_OUTPUT"]
    lines += [f"    {_name(var.name, 'output')} : REAL;" for var in system.outputs]
    lines += ["END_VAR", ""]

    def terms(var: Variable) -> None:
        lines.append(f"    RANGE := ({format_number(var.universe[0])} .. {format_number(var.universe[1])});")
        lines.extend(f"    TERM {_name(t.name, 'term')} := {_term(t)};" for t in var.terms)

    for var in system.inputs:
        lines.append(f"FUZZIFY {var.name}")
        terms(var)
        lines += ["END_FUZZIFY", ""]
    for o, var in enumerate(system.outputs):
        lines.append(f"DEFUZZIFY {var.name}")
        terms(var)
        lines.append(f"    METHOD : {_key(_DEFUZZ, methods.defuzzification)};")
        default = system.default(o)
        lines.append(f"    DEFAULT := {'NC' if default is None else format_number(default)};")
        lines += ["END_DEFUZZIFY", ""]
    lines += ["RULEBLOCK rules", f"    AND : {_key(_AND, methods.and_method)};",
              f"    OR : {_key(_OR, methods.or_method)};", f"    ACT : {_key(_ACT, methods.implication)};",
              f"    ACCU : {_key(_ACCU, methods.aggregation)};"]
    for number, rule in enumerate(system.rules, start=1):
        lines.append(f"    RULE {number} : {system.describe(rule)};")
    lines += ["END_RULEBLOCK", "", "END_FUNCTION_BLOCK"]
    return "\n".join(lines) + "\n"


@removing_empty_folders()
def write_fcl(config: FuzzyConfig | MamdaniSystem, path) -> Path:
    """Write a classifier config or a system as an FCL file and return its path."""
    system = system_of(config) if isinstance(config, FuzzyConfig) else config
    text = fcl_text(system)
    path, = claim([path])
    write(path, lambda target: target.write_text(text))
    return path


# -- reading ---------------------------------------------------------------------------------------


def _strip_comments(text: str) -> str:
    """Comments ``(* *)`` and ``//`` blanked out, line breaks kept (so line numbers hold)."""
    text = re.sub(r"\(\*.*?\*\)", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def _statements(path: Path, text: str) -> list[tuple[int, str]]:
    """Block keywords (one line each) and ``;``-terminated statements, with their first line."""
    out: list[tuple[int, str]] = []
    buffer, start = "", 0
    for number, raw in enumerate(_strip_comments(text).splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if not buffer.strip() and line.split()[0].upper() in _BLOCKS:
            out.append((number, line.rstrip(";").strip()))
            continue
        if not buffer.strip():
            start = number
        buffer += " " + line
        while ";" in buffer:
            statement, buffer = buffer.split(";", 1)
            if statement.strip():
                out.append((start, " ".join(statement.split())))
            start = number
    if buffer.strip():
        raise HybridtrackError(f"{path}:{start}: statement without a closing ';': "  # its start: a TOML file
                               f"{' '.join(buffer.split())!r:.80}")  # had been printed whole, as one line
    return out


class _Reader:
    def __init__(self, path: Path):
        self.path = path
        self.name = path.stem
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.terms: dict[str, list[tuple[int, str, str]]] = {}
        self.ranges: dict[str, tuple[float, float]] = {}
        self.defaults: dict[str, float | None] = {}
        self.methods: dict[str, tuple[int, str]] = {}
        self.rules: list[tuple[int, str]] = []

    def fail(self, number: int, message: str):
        raise HybridtrackError(f"{self.path}:{number}: {message}")

    def number(self, number: int, text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            self.fail(number, f"expected a number, got {text!r}")
        if value != value or abs(value) == float("inf"):
            self.fail(number, f"expected a finite number, got {text!r}")
        return value

    def method(self, number: int, key: str, value: str, table: dict, attr: str) -> None:
        value = value.upper()
        if value not in table:
            self.fail(number, f"{key} : {value} is not supported; use {', '.join(table)}")
        previous = self.methods.get(attr)
        if previous and previous[1] != table[value]:
            self.fail(number, f"{key} differs from the one on line {previous[0]}; one set of methods per system")
        self.methods[attr] = (number, table[value])

    def read(self, statements: list[tuple[int, str]]) -> None:
        block, owner = None, None
        for number, statement in statements:
            words = statement.split()
            head = words[0].upper()
            if head in _BLOCKS:
                if head.startswith("END_"):
                    block, owner = None, None
                    continue
                block = head
                owner = words[1] if len(words) > 1 else None
                if head == "FUNCTION_BLOCK" and owner:
                    self.name = owner
                if head in ("FUZZIFY", "DEFUZZIFY"):
                    known = self.inputs if head == "FUZZIFY" else self.outputs
                    if owner not in known:
                        where = "VAR_INPUT" if head == "FUZZIFY" else "VAR_OUTPUT"
                        self.fail(number, f"{head} {owner}: not declared in {where}")
                    self.terms.setdefault(owner, [])
                continue
            if block in ("VAR_INPUT", "VAR_OUTPUT"):
                match = re.fullmatch(r"(\w+)\s*:\s*REAL", statement, flags=re.I)
                if not match:
                    self.fail(number, f"expected 'name : REAL;' in {block}, got {statement!r}")
                (self.inputs if block == "VAR_INPUT" else self.outputs).append(match[1])
            elif block in ("FUZZIFY", "DEFUZZIFY"):
                self.variable_statement(number, statement, block, owner)
            elif block == "RULEBLOCK":
                self.rule_statement(number, statement)
            else:
                self.fail(number, f"statement outside a block: {statement!r}")

    def variable_statement(self, number: int, statement: str, block: str, owner: str) -> None:
        match = re.fullmatch(r"TERM\s+(\w+)\s*:=\s*(.+)", statement, flags=re.I)
        if match:
            self.terms[owner].append((number, match[1], match[2]))
            return
        match = re.fullmatch(r"RANGE\s*:=\s*\(\s*(\S+)\s*\.\.\s*(\S+)\s*\)", statement, flags=re.I)
        if match:
            self.ranges[owner] = (self.number(number, match[1]), self.number(number, match[2]))
            return
        if block == "DEFUZZIFY":
            match = re.fullmatch(r"(METHOD|ACCU)\s*:\s*(\w+)", statement, flags=re.I)
            if match and match[1].upper() == "METHOD":
                if match[2].upper() == "COGS":
                    self.fail(number, "METHOD : COGS (singleton outputs, Sugeno-like) is not supported")
                return self.method(number, "METHOD", match[2], _DEFUZZ, "defuzzification")
            if match:
                return self.method(number, "ACCU", match[2], _ACCU, "aggregation")
            match = re.fullmatch(r"DEFAULT\s*:=\s*(\S+)", statement, flags=re.I)
            if match:
                self.defaults[owner] = None if match[1].upper() == "NC" else self.number(number, match[1])
                return
        self.fail(number, f"cannot read {statement!r} in {block} {owner}")

    def rule_statement(self, number: int, statement: str) -> None:
        match = re.fullmatch(r"(AND|OR|ACT|ACCU)\s*:\s*(\w+)", statement, flags=re.I)
        if match:
            key = match[1].upper()
            table, attr = {"AND": (_AND, "and_method"), "OR": (_OR, "or_method"), "ACT": (_ACT, "implication"),
                           "ACCU": (_ACCU, "aggregation")}[key]
            return self.method(number, key, match[2], table, attr)
        match = re.fullmatch(r"RULE\s+\w+\s*:\s*(.+)", statement, flags=re.I)
        if not match:
            self.fail(number, f"cannot read {statement!r} in RULEBLOCK")
        self.rules.append((number, match[1]))

    # -- building ------------------------------------------------------------------------------

    def variable(self, name: str) -> Variable:
        if name not in self.terms or not self.terms[name]:
            self.fail(1, f"variable {name} has no terms (FUZZIFY/DEFUZZIFY block missing or empty)")
        parsed = [(number, term, self.shape(number, text)) for number, term, text in self.terms[name]]
        if name in self.ranges:
            universe = self.ranges[name]
        else:
            xs = [x for _, _, (kind, values) in parsed if kind == "points" for x, _ in values]
            if len(xs) < 2 or any(kind != "points" for _, _, (kind, _) in parsed):
                self.fail(parsed[0][0], f"{name} needs RANGE := (low .. high); its terms do not bound it")
            universe = (min(xs), max(xs))
        terms = []
        for number, term, (kind, values) in parsed:
            shape, params = values if kind == "shape" else self.polyline(number, values, universe)
            item = Term(term, shape, params)
            item.check(f"{self.path}:{number}")
            terms.append(item)
        var = Variable(name, universe, tuple(terms))
        try:
            var.check(name)
        except HybridtrackError as exc:
            self.fail(self.terms[name][0][0], str(exc))
        return var

    def shape(self, number: int, text: str):
        match = re.fullmatch(r"(\w+)\s*\(([^()]*)\)", text.strip())
        if match:
            shape = match[1].lower()
            if shape not in SHAPES:
                self.fail(number, f"membership type {match[1]!r} is not supported; use {', '.join(SHAPES)} "
                                  "or a point list")
            values = [self.number(number, v) for v in match[2].split(",")]
            return "shape", (shape, from_matlab(shape, values))
        pairs = re.findall(r"\(\s*([^,()]+?)\s*,\s*([^,()]+?)\s*\)", text)
        if not pairs or re.sub(r"\(\s*[^,()]+?\s*,\s*[^,()]+?\s*\)", "", text).strip():
            self.fail(number, f"cannot read term {text!r}: expected points (x, y) ... or TYPE(params)")
        return "points", [(self.number(number, x), self.number(number, y)) for x, y in pairs]

    def polyline(self, number: int, points, universe) -> tuple[str, tuple[float, ...]]:
        xs = [x for x, _ in points]
        ys = tuple(y for _, y in points)
        if any(a > b for a, b in zip(xs, xs[1:])):
            self.fail(number, "the points of a term must run left to right")
        lo, hi = min(universe[0], xs[0]), max(universe[1], xs[-1])
        layouts = {(0, 1, 0): ("trimf", xs), (0, 1, 1, 0): ("trapmf", xs), (1, 0): ("trapmf", [lo, lo, *xs]),
                   (0, 1): ("trapmf", [*xs, hi, hi]), (1, 1, 0): ("trapmf", [lo, *xs]),
                   (0, 1, 1): ("trapmf", [*xs, hi])}
        if ys not in layouts:
            self.fail(number, f"point lists must make a triangle, trapezoid or shoulder (y 0-1-0, 0-1-1-0, 1-0, "
                              f"0-1), got y {list(ys)}")
        shape, params = layouts[ys]
        return shape, tuple(params)

    def rule(self, number: int, text: str, inputs, outputs) -> SystemRule:
        match = re.fullmatch(r"IF\s+(.+?)\s+THEN\s+(.+?)(?:\s+WITH\s+(\S+))?", text, flags=re.I)
        if not match:
            self.fail(number, f"cannot read rule {text!r}: expected IF ... THEN ... [WITH weight]")
        if "(" in match[1] or ")" in match[1]:
            self.fail(number, "parentheses in a rule are not supported (MATLAB's rule layout has none)")
        parts = re.split(r"\s+(AND|OR)\s+", match[1], flags=re.I)
        connections = {c.upper() for c in parts[1::2]}
        if len(connections) > 1:
            self.fail(number, "a rule mixing AND and OR is not supported (MATLAB's rule layout has one connection)")
        antecedent = self.clauses(number, parts[0::2], inputs, "input")
        consequent = self.clauses(number, [c.strip() for c in match[2].split(",")], outputs, "output")
        weight = self.number(number, match[3]) if match[3] else 1.0
        if not 0.0 <= weight <= 1.0:
            self.fail(number, f"the rule weight must be between 0 and 1, got {weight}")
        return SystemRule(antecedent, consequent, weight, "or" if connections == {"OR"} else "and")

    def clauses(self, number: int, clauses, variables, kind: str) -> tuple[int, ...]:
        indices = [0] * len(variables)
        names = [v.name for v in variables]
        for clause in clauses:
            match = re.fullmatch(r"(NOT\s+)?(\w+)\s+IS\s+(NOT\s+)?(\w+)", clause.strip(), flags=re.I)
            if not match:
                self.fail(number, f"cannot read {clause!r}: expected 'variable IS [NOT] term'")
            if match[2] not in names:
                self.fail(number, f"{match[2]!r} is not an {kind}; {kind}s are {', '.join(names)}")
            var = variables[names.index(match[2])]
            if match[4] not in var.term_names:
                self.fail(number, f"{var.name} has no term {match[4]!r}; its terms are {', '.join(var.term_names)}")
            if indices[names.index(match[2])]:
                self.fail(number, f"{var.name} appears twice in one rule")
            index = var.term_names.index(match[4]) + 1
            indices[names.index(match[2])] = -index if bool(match[1]) != bool(match[3]) else index
        return tuple(indices)


def read_fcl(path, *, resolution=None) -> MamdaniSystem:
    """Read an IEC 61131-7 FCL function block into a `MamdaniSystem`.

    Parameters
    ----------
    path : str or Path
    resolution : (int, int), optional
        Samples across the input and output universes; (1001, 3001) by default.
    """
    from ..io import read_text
    from ..io.files import input_path

    path = input_path(path, "fuzzy system file")
    reader = _Reader(path)
    reader.read(_statements(path, read_text(path)))
    if not reader.inputs or not reader.outputs:
        raise HybridtrackError(f"{path}: no VAR_INPUT or VAR_OUTPUT declarations; is this an FCL file?")
    inputs = tuple(reader.variable(name) for name in reader.inputs)
    outputs = tuple(reader.variable(name) for name in reader.outputs)
    if not reader.rules:
        raise HybridtrackError(f"{path}: no RULE in any RULEBLOCK")
    rules = tuple(reader.rule(number, text, inputs, outputs) for number, text in reader.rules)
    methods = Methods(**{attr: value for attr, (_, value) in reader.methods.items()})
    defaults = tuple(reader.defaults.get(name) for name in reader.outputs)
    options = {"resolution": tuple(resolution)} if resolution is not None else {}
    try:
        return MamdaniSystem(inputs, outputs, rules, methods, name=reader.name,
                             defaults=defaults if any(d is not None for d in defaults) else (), **options)
    except HybridtrackError as exc:
        raise HybridtrackError(f"{path}: {exc}") from None
