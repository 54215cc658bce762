"""Rule tables as pytest cases: keep expected classifier behaviour as data.

A rule-table file holds rows of raw ``intensity`` and ``variation`` (mA), the expected
``weather`` label, and optionally the expected ``score`` with a ``tolerance``. It can be CSV
(with ``# config: path.toml`` comment lines naming the classifier config, relative to the
file) or TOML (``config = "path.toml"`` and ``[[case]]`` tables).

Two ways to run one:

* the plugin (installed with hybridtrack, entry point ``pytest11``) collects every file named
  ``test_*.rules.csv`` or ``test_*.rules.toml`` as a test module, one test per row;
* the helper, for a file under any name::

      import pytest
      from hybridtrack.testing import rule_table_cases

      @pytest.mark.parametrize("case", rule_table_cases("my_rules.csv"))
      def test_my_rules(case):
          case.check()

A failing case reports the expected and actual label and score, each input's memberships
and every rule's firing strength.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import pytest

__all__ = ["RuleCase", "RuleCaseFailure", "load_cases", "rule_table_cases", "rule_peak_cases"]


class RuleCaseFailure(AssertionError):
    """A rule-table row the classifier does not reproduce."""


@dataclass(frozen=True)
class RuleCase:
    """One expected behaviour: readings in, label (and score) out."""

    intensity: float
    variation: float
    weather: str | None
    score: float | None = None
    tolerance: float | None = None
    config_path: str | None = None
    source: str = ""
    row: int = 0
    line: int | None = None

    @property
    def id(self) -> str:
        """A readable test id: ``line4-246mA-27mA-sunny`` (the file's line), else ``row2-...``."""
        expected = self.weather or f"score{self.score:g}"
        where = f"line{self.line}" if self.line else f"row{self.row}"
        return f"{where}-{self.intensity:g}mA-{self.variation:g}mA-{expected}"

    @property
    def where(self) -> str:
        """``file:line`` (or ``source row N``) of the case, for messages."""
        if self.line:
            return f"{self.source}:{self.line}"
        return f"{self.source} row {self.row}" if self.source else f"row {self.row}"

    def classifier(self):
        """The classifier the case runs against (its file's config, else the published one)."""
        return _classifier(self.config_path)

    def check(self, classifier=None) -> None:
        """Raise `RuleCaseFailure` with the full explanation unless the case holds."""
        clf = classifier if classifier is not None else self.classifier()
        explanation = clf.explain(self.intensity, self.variation)
        problems = []
        if self.weather is not None and explanation.weather != self.weather:
            problems.append(f"expected {self.weather}, got {explanation.weather}")
        if self.score is not None:
            tolerance = self.tolerance if self.tolerance is not None else 0.5
            if not (abs(explanation.score - self.score) <= tolerance):
                problems.append(f"expected score {self.score:g} ± {tolerance:g}, got {explanation.score:.4f}")
        if problems:
            config = self.config_path or "the published system (built in)"
            raise RuleCaseFailure(
                f"{self.where}: {'; '.join(problems)} for intensity {self.intensity:g} mA, "
                f"variation {self.variation:g} mA\nconfig: {config}\n{explanation}"
            )


_CLASSIFIERS: dict[str | None, object] = {}


def _classifier(config_path: str | None):
    from .fuzzy import FuzzyConfig, FuzzyWeatherClassifier

    if config_path not in _CLASSIFIERS:
        config = FuzzyConfig.from_toml(config_path) if config_path else FuzzyConfig.default()
        _CLASSIFIERS[config_path] = FuzzyWeatherClassifier(config)
    return _CLASSIFIERS[config_path]


def _config_reference(path: Path) -> str | None:
    from .io import read_text, read_toml

    if path.suffix.lower() == ".toml":
        reference = read_toml(path, "rule table").get("config")
    else:
        reference = None
        for line in read_text(path).splitlines():
            stripped = line.strip()
            if stripped.startswith("#") and stripped[1:].strip().lower().startswith("config:"):
                reference = stripped[1:].strip()[len("config:"):].strip()
    return str((path.parent / reference).resolve()) if reference else None


def _data_lines(path: Path, rows: int) -> list[int] | None:
    """The file's line number (1-based) of each table row, or None if they cannot be matched."""
    import re

    from .io import read_text

    text = read_text(path).splitlines()
    if path.suffix.lower() == ".toml":
        lines = [n for n, line in enumerate(text, 1) if re.match(r"\s*\[\[\s*cases?\s*\]\]", line)]
    else:
        lines = [n for n, line in enumerate(text, 1) if line.strip() and not line.strip().startswith("#")][1:]
    return lines if len(lines) == rows else None


class _Row:
    """Reads one table row's values, naming the file and line of the first problem."""

    def __init__(self, values: dict, where: str):
        self.values, self.where = values, where

    def fail(self, message: str):
        from .errors import HybridtrackError

        raise HybridtrackError(f"{self.where}: {message}")

    def number(self, column: str, *, required: bool) -> float | None:
        value = self.values.get(column)
        if value is None or (isinstance(value, str) and not value.strip()) or (
                isinstance(value, float) and math.isnan(value)):
            if required:
                self.fail(f"column {column!r} is empty")
            return None
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"column {column!r}: {value!r} is not a number")
        if not math.isfinite(number):
            self.fail(f"column {column!r}: {value!r} is not a finite number")
        return number

    def label(self, column: str) -> str | None:
        value = self.values.get(column)
        if value is None or (isinstance(value, float) and math.isnan(value)) or not str(value).strip():
            return None
        return str(value).strip().lower()


def _case(row: _Row, config, config_path, source: str, number: int, line: int | None) -> RuleCase:
    """One checked case: numbers finite and inside the config's ranges, labels the config's own."""
    readings = []
    for var in config.inputs:
        value = row.number(var.name, required=True)
        lo, hi = var.raw_range
        if not lo <= value <= hi:
            row.fail(f"{var.name} {value:g} {var.unit} is outside the config's range {lo:g}-{hi:g} {var.unit} "
                     "(the classifier would clip it to the edge; test the edge itself instead)")
        readings.append(value)
    weather = row.label("weather")
    bands = [band[0] for band in config.bands]
    if weather is not None and weather not in bands:
        row.fail(f"unknown weather label {weather!r}; the config's labels are {', '.join(bands)}")
    score, tolerance = row.number("score", required=False), row.number("tolerance", required=False)
    lo, hi = config.output.universe
    if score is not None and not lo <= score <= hi:
        row.fail(f"score {score:g} is outside the output universe {lo:g}-{hi:g}")
    if tolerance is not None and tolerance < 0:
        row.fail(f"tolerance {tolerance:g} is negative")
    if weather is None and score is None:
        row.fail("neither a weather label nor a score to check")
    return RuleCase(readings[0], readings[1], weather, score, tolerance, config_path, source, number, line)


def load_cases(path) -> list[RuleCase]:
    """Read a rule-table file (CSV or TOML) into `RuleCase` rows, checked against its config.

    A problem in a row (text where a number belongs, a reading outside the config's raw range,
    a label the config does not have, a negative tolerance) is a `HybridtrackError` naming the
    file and line, never a silent clip.
    """
    from .errors import HybridtrackError
    from .io import read_table
    from .io.files import input_path

    path = input_path(path, "rule table")
    frame = read_table(path)
    for column in ("intensity", "variation"):
        if column not in frame.columns:
            raise HybridtrackError(f"{path}: missing column {column!r} (need intensity, variation and weather "
                                   "or score)")
    if "weather" not in frame.columns and "score" not in frame.columns:
        raise HybridtrackError(f"{path}: needs a 'weather' or a 'score' column")
    config_path = _config_reference(path)
    try:
        config = _classifier(config_path).config
    except HybridtrackError as exc:
        raise HybridtrackError(f"{path}: its config: {exc}") from None
    lines = _data_lines(path, len(frame))
    first = 1 if path.suffix.lower() == ".toml" else 2
    cases = []
    for k, values in enumerate(frame.to_dict("records")):
        line = lines[k] if lines else None
        where = f"{path}:{line}" if line else f"{path}: row {k + first}"
        cases.append(_case(_Row(values, where), config, config_path, str(path), k + first, line))
    return cases


def rule_table_cases(path) -> list:
    """``pytest.param`` objects, one per row of a rule-table file, with readable ids."""
    return [pytest.param(case, id=case.id) for case in load_cases(path)]


def rule_peak_cases(config=None) -> list:
    """One case per rule: the raw readings at its terms' peaks should give its output's band.

    Inputs a rule leaves out are set to the middle of their raw range.
    """
    from .fuzzy import FuzzyConfig

    config = config if config is not None else FuzzyConfig.default()
    band_of = {}
    for term in config.output.terms:
        for name, lo, hi in config.bands:
            if lo <= term.centre <= hi:
                band_of[term.name] = name
                break
    params = []
    for number, rule in enumerate(config.rules, start=1):
        raw = []
        for var in config.inputs:
            lo, hi = var.raw_range
            u0, u1 = var.universe
            peak = var.term(rule.conditions[var.name]).centre if var.name in rule.conditions else 0.5 * (u0 + u1)
            raw.append(lo + (hi - lo) * (peak - u0) / (u1 - u0))
        case = RuleCase(raw[0], raw[1], band_of.get(rule.then), source=f"{config.name} rule", row=number)
        params.append(pytest.param(case, id=f"rule{number}-{rule.describe(config.input_names).replace(' ', '_')}"))
    return params


# --- the pytest plugin ----------------------------------------------------------------------


def pytest_collect_file(file_path, parent):
    """Collect ``test_*.rules.csv`` and ``test_*.rules.toml`` files as rule tables."""
    name = file_path.name
    if name.startswith("test_") and (name.endswith(".rules.csv") or name.endswith(".rules.toml")):
        return RuleTableFile.from_parent(parent, path=file_path)
    return None


class RuleTableFile(pytest.File):
    """A rule-table file: one test item per row."""

    def collect(self):
        from .errors import HybridtrackError

        try:
            cases = load_cases(self.path)
        except HybridtrackError as exc:
            raise self.CollectError(str(exc)) from None
        for case in cases:
            yield RuleCaseItem.from_parent(self, name=case.id, case=case)


class RuleCaseItem(pytest.Item):
    """One rule-table row run as a test."""

    def __init__(self, *, case: RuleCase, **kwargs):
        super().__init__(**kwargs)
        self.case = case

    def runtest(self) -> None:
        self.case.check()

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, RuleCaseFailure):
            return str(excinfo.value)
        return super().repr_failure(excinfo)

    def reportinfo(self):
        line = self.case.line or self.case.row
        return self.path, line - 1, f"rule table {self.case.where}: {self.case.id}"
