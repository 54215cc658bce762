"""MATLAB Fuzzy Logic Toolbox ``.fis`` files: read and write Mamdani systems.

The published classifier was built in MATLAB, so its systems travel as ``.fis`` text:
``[System]``, ``[InputN]``, ``[Output1]`` and ``[Rules]`` sections of ``Key=value`` lines.
Membership lines read ``MF1='weak':'gaussmf',[sigma mean]``; note MATLAB's parameter order
for the Gaussians (sigma first), which differs from scikit-fuzzy's and this project's
(mean first). Rule lines read ``3 1, 3 (1) : 1`` (input term indices, 0 for "any", output
term index, weight, 1 for AND).

Only what the classifier can run is accepted: a Mamdani system with min AND, min
implication, max aggregation, centroid defuzzification, two inputs, one output, AND rules
of weight 1 without negation, and the membership types of `SHAPES`. Anything else is refused
with the file and line.

A ``.fis`` file has no place for the raw sensor ranges, the label bands or the sampling
resolution. Reading fills the raw ranges from the published system (intensity 30-300 mA,
variation 0-180 mA) unless told otherwise. The bands meet halfway between the centres of
neighbouring output terms, which gives the published 10/20 split for the published terms.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import HybridtrackError
from .config import SHAPES, FuzzyConfig, Rule, Term, Variable

__all__ = ["read_fis", "write_fis"]

_REQUIRED_METHODS = {"AndMethod": "min", "ImpMethod": "min", "AggMethod": "max", "DefuzzMethod": "centroid"}
_PUBLISHED_RAW = ((30.0, 300.0), (0.0, 180.0))
_UNITS = ("mA", "mA")


def _to_matlab(term: Term) -> list[float]:
    p = list(term.params)
    if term.shape == "gaussmf":
        return [p[1], p[0]]
    if term.shape == "gauss2mf":
        return [p[1], p[0], p[3], p[2]]
    return p


def _from_matlab(shape: str, values: list[float]) -> tuple[float, ...]:
    if shape == "gaussmf" and len(values) == 2:
        return (values[1], values[0])
    if shape == "gauss2mf" and len(values) == 4:
        return (values[1], values[0], values[3], values[2])
    return tuple(values)


def _number(text: str) -> str:
    return f"{text:.10g}"


def write_fis(config: FuzzyConfig, path) -> Path:
    """Write `config` as a MATLAB ``.fis`` file and return its path."""
    path = Path(path)
    lines = ["[System]", f"Name='{config.name}'", "Type='mamdani'", "Version=2.0",
             f"NumInputs={len(config.inputs)}", "NumOutputs=1", f"NumRules={len(config.rules)}",
             "AndMethod='min'", "OrMethod='max'", "ImpMethod='min'", "AggMethod='max'", "DefuzzMethod='centroid'", ""]

    def variable(header: str, var: Variable) -> None:
        lines.extend([header, f"Name='{var.name}'",
                      f"Range=[{_number(var.universe[0])} {_number(var.universe[1])}]", f"NumMFs={len(var.terms)}"])
        for i, term in enumerate(var.terms, start=1):
            params = " ".join(_number(v) for v in _to_matlab(term))
            lines.append(f"MF{i}='{term.name}':'{term.shape}',[{params}]")
        lines.append("")

    for i, var in enumerate(config.inputs, start=1):
        variable(f"[Input{i}]", var)
    variable("[Output1]", config.output)
    lines.append("[Rules]")
    for rule in config.rules:
        conditions = rule.conditions
        indices = [var.term_names.index(conditions[var.name]) + 1 if var.name in conditions else 0
                   for var in config.inputs]
        lines.append(f"{' '.join(map(str, indices))}, {config.output.term_names.index(rule.then) + 1} (1) : 1")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return path


_MF = re.compile(r"^'(?P<name>[^']*)'\s*:\s*'(?P<shape>[^']*)'\s*,\s*\[(?P<params>[^\]]*)\]$")
_RULE = re.compile(r"^(?P<ins>[-\d\s.]+),(?P<outs>[-\d\s.]+)\((?P<weight>[^)]*)\)\s*:\s*(?P<conn>\d+)$")


def _sections(path: Path, text: str) -> dict[str, list[tuple[int, str]]]:
    sections: dict[str, list[tuple[int, str]]] = {}
    current = None
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith(("%", "#")):
            continue
        if line.startswith("[") and line.endswith("]") and "=" not in line:
            current = line[1:-1]
            if current in sections:
                raise HybridtrackError(f"{path}:{number}: section [{current}] appears twice")
            sections[current] = []
        elif current is None:
            raise HybridtrackError(f"{path}:{number}: text before the first [section]")
        else:
            sections[current].append((number, line))
    return sections


def _keys(path: Path, lines: list[tuple[int, str]], section: str) -> dict[str, tuple[int, str]]:
    keys = {}
    for number, line in lines:
        if "=" not in line:
            raise HybridtrackError(f"{path}:{number}: expected Key=value in [{section}], got {line!r}")
        key, value = line.split("=", 1)
        keys[key.strip()] = (number, value.strip())
    return keys


def _string(value: str) -> str:
    return value[1:-1] if len(value) >= 2 and value[0] == value[-1] == "'" else value


def _floats(path: Path, number: int, text: str) -> list[float]:
    try:
        return [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise HybridtrackError(f"{path}:{number}: expected numbers, got {text!r}") from None


def _variable(path: Path, sections, header: str, raw_range=None, unit: str = "") -> Variable:
    if header not in sections:
        raise HybridtrackError(f"{path}: section [{header}] is missing")
    keys = _keys(path, sections[header], header)
    for key in ("Name", "Range", "NumMFs"):
        if key not in keys:
            raise HybridtrackError(f"{path}: [{header}] has no {key}=")
    number, text = keys["Range"]
    bounds = _floats(path, number, text.strip("[]"))
    if len(bounds) != 2:
        raise HybridtrackError(f"{path}:{number}: Range needs two numbers, got {text!r}")
    count_line, count_text = keys["NumMFs"]
    try:
        count = int(count_text)
    except ValueError:
        raise HybridtrackError(f"{path}:{count_line}: NumMFs must be a whole number, got {count_text!r}") from None
    terms = []
    for i in range(1, count + 1):
        if f"MF{i}" not in keys:
            raise HybridtrackError(f"{path}: [{header}] declares {count} MFs but has no MF{i}=")
        number, text = keys[f"MF{i}"]
        match = _MF.match(text)
        if not match:
            raise HybridtrackError(f"{path}:{number}: cannot read membership function {text!r}")
        shape = match["shape"]
        if shape not in SHAPES:
            raise HybridtrackError(
                f"{path}:{number}: membership type {shape!r} is not supported; use {', '.join(SHAPES)}"
            )
        term = Term(match["name"], shape, _from_matlab(shape, _floats(path, number, match["params"])))
        term.check(f"{path}:{number}")
        terms.append(term)
    return Variable(_string(keys["Name"][1]), tuple(bounds), tuple(terms), raw_range, unit)



def read_fis(path, *, raw_ranges=None, bands=None, resolution=None) -> FuzzyConfig:
    """Read a MATLAB Mamdani ``.fis`` file into a `FuzzyConfig`.

    Parameters
    ----------
    path : str or Path
    raw_ranges : sequence of two (min, max), optional
        Raw sensor ranges of the two inputs; the published ones by default.
    bands : sequence of (label, low, high), optional
        Label bands; by default they meet halfway between neighbouring output term centres.
    resolution : (int, int), optional
        Sampling of the input and output universes; the default config's by default.
    """
    from ..io import read_text

    path = Path(path)
    sections = _sections(path, read_text(path))
    if "System" not in sections:
        raise HybridtrackError(f"{path}: no [System] section; is this a MATLAB .fis file?")
    system = _keys(path, sections["System"], "System")
    kind = _string(system.get("Type", (0, "'mamdani'"))[1]).lower()
    if kind != "mamdani":
        raise HybridtrackError(f"{path}:{system['Type'][0]}: only Mamdani systems are supported, not {kind!r}")
    for key, wanted in _REQUIRED_METHODS.items():
        if key in system and _string(system[key][1]).lower() != wanted:
            raise HybridtrackError(f"{path}:{system[key][0]}: {key} must be {wanted!r}, got {_string(system[key][1])!r}")
    for key, wanted in (("NumInputs", "2"), ("NumOutputs", "1")):
        if key in system and system[key][1] != wanted:
            raise HybridtrackError(f"{path}:{system[key][0]}: the classifier needs {key}={wanted}, got {system[key][1]}")
    ranges = raw_ranges if raw_ranges is not None else _PUBLISHED_RAW
    inputs = tuple(_variable(path, sections, f"Input{i}", tuple(ranges[i - 1]), _UNITS[i - 1]) for i in (1, 2))
    output = _variable(path, sections, "Output1")
    rules = []
    for number, line in sections.get("Rules", []):
        match = _RULE.match(line)
        if not match:
            raise HybridtrackError(f"{path}:{number}: cannot read rule {line!r}")
        ins = _floats(path, number, match["ins"])
        outs = _floats(path, number, match["outs"])
        if len(ins) != 2 or len(outs) != 1:
            raise HybridtrackError(f"{path}:{number}: a rule needs two input indices and one output index")
        if match["conn"] != "1":
            raise HybridtrackError(f"{path}:{number}: only AND rules (connection 1) are supported")
        if _floats(path, number, match["weight"]) != [1.0]:
            raise HybridtrackError(f"{path}:{number}: only rule weight 1 is supported, got ({match['weight']})")
        if any(v < 0 or v != int(v) for v in ins + outs):
            raise HybridtrackError(f"{path}:{number}: negated or fractional term indices are not supported")
        when = {}
        for var, index in zip(inputs, ins):
            if index > len(var.terms):
                raise HybridtrackError(f"{path}:{number}: {var.name} has no term {int(index)}")
            if index:
                when[var.name] = var.terms[int(index) - 1].name
        if not 1 <= outs[0] <= len(output.terms):
            raise HybridtrackError(f"{path}:{number}: {output.name} has no term {int(outs[0])}")
        rules.append(Rule(when, output.terms[int(outs[0]) - 1].name))
    if bands is None:
        ordered = sorted(output.terms, key=lambda t: t.centre)
        cuts = [0.5 * (a.centre + b.centre) for a, b in zip(ordered, ordered[1:])]
        edges = [output.universe[0], *cuts, output.universe[1]]
        bands = tuple((t.name, lo, hi) for t, lo, hi in zip(ordered, edges, edges[1:]))
    options = {"resolution": tuple(resolution)} if resolution is not None else {}
    name = _string(system.get("Name", (0, path.stem))[1])
    try:
        return FuzzyConfig(inputs=inputs, output=output, rules=tuple(rules), bands=tuple(bands), name=name, **options)
    except HybridtrackError as exc:
        raise HybridtrackError(f"{path}: {exc}") from None
