"""MATLAB Fuzzy Logic Toolbox ``.fis`` files (the v2 text format): read and write, in full.

A ``.fis`` file has ``[System]``, ``[InputN]``, ``[OutputN]`` and ``[Rules]`` sections of
``Key=value`` lines. Membership lines read ``MF1='weak':'gaussmf',[sigma mean]``, in
MATLAB's parameter order (see `hybridtrack.fuzzy.membership`). Rule lines read
``1 -2, 3 (0.5) : 2``: one term index per input (0 for "any", negative for "not"), one per
output, the weight in brackets, and 1 for AND or 2 for OR.

Every Mamdani option the engine runs is read: AND min/prod, OR max/probor, implication
min/prod, aggregation max/sum/probor, defuzzification centroid/bisector/mom/som/lom, the
eleven membership types, weights, negation, don't-care, any number of inputs and outputs.
Anything else is refused with the file and line: Sugeno systems, type-2 systems, custom
methods, unknown membership types, fractional (hedged) rule indices.

A ``.fis`` file has no place for a classifier's raw sensor ranges, label bands or the
sampling resolution; `read_fis` fills them (see `hybridtrack.fuzzy.system.config_from_system`).

References
----------
MathWorks (2024). Fuzzy Logic Toolbox User's Guide: ``readfis``, ``writefis``, FIS file
format. https://www.mathworks.com/help/fuzzy/readfis.html
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import HybridtrackError
from ..outputs import claim, removing_empty_folders, write
from .config import METHOD_CHOICES, FuzzyConfig, Methods, Term, Variable
from .membership import SHAPES, from_matlab, to_matlab
from .system import MamdaniSystem, SystemRule, config_from_system, format_number, system_of

__all__ = ["read_fis", "write_fis", "read_fis_system", "fis_text", "format_number"]

_METHOD_KEYS = {"AndMethod": "and_method", "OrMethod": "or_method", "ImpMethod": "implication",
                "AggMethod": "aggregation", "DefuzzMethod": "defuzzification"}
_SYSTEM_KEYS = {"Name", "Type", "Version", "NumInputs", "NumOutputs", "NumRules", *_METHOD_KEYS}
_TYPE2_KEYS = {"TypeReductionMethod", "OutputSampleRate"}


def _quote(text: str) -> str:
    if "'" in text or "\n" in text:
        raise HybridtrackError(f"name {text!r} cannot be written to a .fis file (quote or newline)")
    return f"'{text}'"


def fis_text(system: MamdaniSystem) -> str:
    """The system as MATLAB ``.fis`` (v2) text."""
    if any(d is not None for d in system.defaults):
        raise HybridtrackError("a .fis file has no place for a DEFAULT output value (MATLAB gives the middle of the "
                               "range when no rule fires); remove it from the system to write .fis")
    methods = system.methods
    lines = ["[System]", f"Name={_quote(system.name)}", "Type='mamdani'", "Version=2.0",
             f"NumInputs={len(system.inputs)}", f"NumOutputs={len(system.outputs)}", f"NumRules={len(system.rules)}"]
    lines += [f"{key}='{getattr(methods, attr)}'" for key, attr in _METHOD_KEYS.items()]
    lines.append("")

    def variable(header: str, var: Variable) -> None:
        lines.extend([header, f"Name={_quote(var.name)}",
                      f"Range=[{format_number(var.universe[0])} {format_number(var.universe[1])}]",
                      f"NumMFs={len(var.terms)}"])
        for i, term in enumerate(var.terms, start=1):
            params = " ".join(format_number(v) for v in to_matlab(term.shape, term.params))
            lines.append(f"MF{i}={_quote(term.name)}:'{term.shape}',[{params}]")
        lines.append("")

    for i, var in enumerate(system.inputs, start=1):
        variable(f"[Input{i}]", var)
    for i, var in enumerate(system.outputs, start=1):
        variable(f"[Output{i}]", var)
    lines.append("[Rules]")
    for rule in system.rules:
        lines.append(f"{' '.join(map(str, rule.antecedent))}, {' '.join(map(str, rule.consequent))} "
                     f"({format_number(rule.weight)}) : {1 if rule.connection == 'and' else 2}")
    return "\n".join(lines) + "\n"


@removing_empty_folders()
def write_fis(config: FuzzyConfig | MamdaniSystem, path) -> Path:
    """Write a classifier config or a system as a MATLAB ``.fis`` file and return its path."""
    system = system_of(config) if isinstance(config, FuzzyConfig) else config
    text = fis_text(system)
    path, = claim([path])
    write(path, lambda target: target.write_text(text))
    return path


_MF = re.compile(r"^'(?P<name>[^']*)'\s*:\s*'(?P<shape>[^']*)'\s*,\s*\[(?P<params>[^\]]*)\](?P<rest>.*)$")
_RULE = re.compile(r"^(?P<indices>[-+\d\s.,]+)\((?P<weight>[^)]*)\)\s*:\s*(?P<conn>\S+)$")


class _Source:
    """The lines of a .fis file by section, with their numbers, for messages that name them."""

    def __init__(self, path: Path, text: str):
        self.path = path
        self.sections: dict[str, list[tuple[int, str]]] = {}
        self.headers: dict[str, int] = {}
        current = None
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw.strip()
            if not line or line.startswith(("%", "#")):
                continue
            if line.startswith("[") and line.endswith("]") and "=" not in line:
                current = line[1:-1].strip()
                if current in self.sections:
                    self.fail(number, f"section [{current}] appears twice")
                self.sections[current] = []
                self.headers[current] = number
            elif current is None:
                self.fail(number, "text before the first [section]")
            else:
                self.sections[current].append((number, line))

    def fail(self, number: int | None, message: str):
        where = f"{self.path}:{number}" if number else f"{self.path}"
        raise HybridtrackError(f"{where}: {message}")

    def keys(self, section: str) -> dict[str, tuple[int, str]]:
        if section not in self.sections:
            self.fail(None, f"section [{section}] is missing")
        keys = {}
        for number, line in self.sections[section]:
            if "=" not in line:
                self.fail(number, f"expected Key=value in [{section}], got {line!r}")
            key, value = (part.strip() for part in line.split("=", 1))
            if key in keys:
                self.fail(number, f"{key} appears twice in [{section}]")
            keys[key] = (number, value)
        return keys

    def floats(self, number: int, text: str) -> list[float]:
        try:
            values = [float(v) for v in text.replace(",", " ").split()]
        except ValueError:
            self.fail(number, f"expected numbers, got {text!r}")
        if any(v != v or v in (float("inf"), float("-inf")) for v in values):
            self.fail(number, f"expected finite numbers, got {text!r}")
        return values

    def integer(self, keys, key: str, section: str) -> tuple[int, int]:
        if key not in keys:
            self.fail(self.headers.get(section), f"[{section}] has no {key}=")
        number, text = keys[key]
        try:
            return number, int(text)
        except ValueError:
            self.fail(number, f"{key} must be a whole number, got {text!r}")


def _string(value: str) -> str:
    return value[1:-1] if len(value) >= 2 and value[0] == value[-1] == "'" else value


def _variable(source: _Source, header: str) -> Variable:
    keys = source.keys(header)
    for key in keys:
        if key not in ("Name", "Range", "NumMFs") and not re.fullmatch(r"MF\d+", key):
            source.fail(keys[key][0], f"unknown key {key!r} in [{header}]")
    if "Name" not in keys or "Range" not in keys:
        source.fail(source.headers[header], f"[{header}] needs Name= and Range=")
    number, text = keys["Range"]
    bounds = source.floats(number, text.strip().strip("[]"))
    if len(bounds) != 2 or not bounds[0] < bounds[1]:
        source.fail(number, f"Range needs two numbers, low < high, got {text!r}")
    count_line, count = source.integer(keys, "NumMFs", header)
    if count < 1:
        source.fail(count_line, f"NumMFs must be at least 1, got {count}")
    extra = sorted(k for k in keys if k.startswith("MF") and not 1 <= int(k[2:]) <= count)
    if extra:
        source.fail(keys[extra[0]][0], f"[{header}] declares {count} MFs but has {extra[0]}=")
    terms = []
    for i in range(1, count + 1):
        if f"MF{i}" not in keys:
            source.fail(count_line, f"[{header}] declares {count} MFs but has no MF{i}=")
        number, text = keys[f"MF{i}"]
        match = _MF.match(text)
        if not match:
            source.fail(number, f"cannot read membership function {text!r}")
        if match["rest"].strip():
            source.fail(number, "type-2 membership functions (a second parameter list) are not supported")
        shape = match["shape"]
        if shape not in SHAPES:
            source.fail(number, f"membership type {shape!r} is not supported; use {', '.join(SHAPES)}")
        term = Term(match["name"], shape, from_matlab(shape, source.floats(number, match["params"])))
        term.check(f"{source.path}:{number}")
        terms.append(term)
    try:
        var = Variable(_string(keys["Name"][1]), tuple(bounds), tuple(terms))
        var.check(header)
    except HybridtrackError as exc:
        source.fail(source.headers[header], str(exc))
    return var


def _methods(source: _Source, system: dict) -> Methods:
    values = {}
    for key, attr in _METHOD_KEYS.items():
        if key not in system:
            continue
        number, text = system[key]
        value = _string(text).lower()
        if attr == "defuzzification" and value in ("wtaver", "wtsum"):
            source.fail(number, f"{key} {value!r} belongs to Sugeno systems, which are not supported")
        if value not in METHOD_CHOICES[attr]:
            source.fail(number, f"{key} {value!r} is not supported; use {', '.join(METHOD_CHOICES[attr])}")
        values[attr] = value
    return Methods(**values)


def _rule(source: _Source, number: int, line: str, inputs, outputs) -> SystemRule:
    match = _RULE.match(line)
    if not match:
        source.fail(number, f"cannot read rule {line!r}")
    if "," in match["indices"]:
        left, _, right = match["indices"].partition(",")
        ins, outs = source.floats(number, left), source.floats(number, right)
    else:  # the older layout without a comma
        values = source.floats(number, match["indices"])
        ins, outs = values[:len(inputs)], values[len(inputs):]
    if len(ins) != len(inputs) or len(outs) != len(outputs):
        source.fail(number, f"a rule needs {len(inputs)} input and {len(outputs)} output indices, "
                            f"got {len(ins)} and {len(outs)}")
    if any(v != int(v) for v in ins + outs):
        source.fail(number, "fractional term indices (hedges) are not supported")
    for var, index in (*zip(inputs, ins), *zip(outputs, outs)):
        if abs(index) > len(var.terms):
            source.fail(number, f"{var.name} has no term {int(abs(index))}")
    weight = source.floats(number, match["weight"])
    if len(weight) != 1 or not 0.0 <= weight[0] <= 1.0:
        source.fail(number, f"the rule weight must be one number between 0 and 1, got ({match['weight']})")
    if match["conn"] not in ("1", "2"):
        source.fail(number, f"the connection must be 1 (AND) or 2 (OR), got {match['conn']}")
    if not any(ins) or not any(outs):
        source.fail(number, "a rule needs at least one condition and one consequent")
    return SystemRule(tuple(int(v) for v in ins), tuple(int(v) for v in outs), weight[0],
                      "and" if match["conn"] == "1" else "or")


def read_fis_system(path, *, resolution=None) -> MamdaniSystem:
    """Read a MATLAB Mamdani ``.fis`` file into a `MamdaniSystem`.

    Parameters
    ----------
    path : str or Path
    resolution : (int, int), optional
        Samples across the input and output universes; (1001, 3001) by default.
    """
    from ..io import read_text
    from ..io.files import input_path

    path = input_path(path, "fuzzy system file")
    source = _Source(path, read_text(path))
    if "System" not in source.sections:
        source.fail(None, "no [System] section; is this a MATLAB .fis file?")
    system = source.keys("System")
    for key, (number, _) in system.items():
        if key in _TYPE2_KEYS:
            source.fail(number, f"{key}: type-2 fuzzy systems are not supported")
        if key not in _SYSTEM_KEYS:
            source.fail(number, f"unknown key {key!r} in [System]")
    number, kind = system.get("Type", (0, "'mamdani'"))
    kind = _string(kind).lower()
    if kind != "mamdani":
        source.fail(number, f"only Mamdani systems are supported, not {kind!r}")
    methods = _methods(source, system)
    count_in = source.integer(system, "NumInputs", "System")[1] if "NumInputs" in system else None
    count_out = source.integer(system, "NumOutputs", "System")[1] if "NumOutputs" in system else None
    found_in = sum(1 for name in source.sections if re.fullmatch(r"Input\d+", name))
    found_out = sum(1 for name in source.sections if re.fullmatch(r"Output\d+", name))
    for key, declared, found in (("NumInputs", count_in, found_in), ("NumOutputs", count_out, found_out)):
        if declared is not None and declared != found:
            source.fail(system[key][0], f"{key}={declared} but the file has {found} such sections")
    inputs = tuple(_variable(source, f"Input{i}") for i in range(1, found_in + 1))
    outputs = tuple(_variable(source, f"Output{i}") for i in range(1, found_out + 1))
    unknown = [name for name in source.sections
               if name not in ("System", "Rules") and not re.fullmatch(r"(Input|Output)\d+", name)]
    if unknown:
        source.fail(source.headers[unknown[0]], f"unknown section [{unknown[0]}]")
    rules = tuple(_rule(source, number, line, inputs, outputs) for number, line in source.sections.get("Rules", []))
    if "NumRules" in system:
        number, declared = source.integer(system, "NumRules", "System")
        if declared != len(rules):
            source.fail(number, f"NumRules={declared} but [Rules] has {len(rules)} rules")
    name = _string(system.get("Name", (0, path.stem))[1])
    options = {"resolution": tuple(resolution)} if resolution is not None else {}
    try:
        return MamdaniSystem(inputs, outputs, rules, methods, name=name, **options)
    except HybridtrackError as exc:
        source.fail(None, str(exc))


def read_fis(path, *, raw_ranges=None, bands=None, resolution=None) -> FuzzyConfig:
    """Read a MATLAB Mamdani ``.fis`` file into a classifier `FuzzyConfig`.

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
    system = read_fis_system(path, resolution=resolution)
    return config_from_system(system, raw_ranges=raw_ranges, bands=bands, where=str(path))
