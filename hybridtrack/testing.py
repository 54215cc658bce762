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

    @property
    def id(self) -> str:
        """A readable test id: ``row2-246mA-27mA-sunny``."""
        expected = self.weather or f"score{self.score:g}"
        return f"row{self.row}-{self.intensity:g}mA-{self.variation:g}mA-{expected}"

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
            where = f"{self.source} row {self.row}: " if self.source else ""
            raise RuleCaseFailure(
                f"{where}{'; '.join(problems)} for intensity {self.intensity:g} mA, variation {self.variation:g} mA\n"
                f"{explanation}"
            )


_CLASSIFIERS: dict[str | None, object] = {}


def _classifier(config_path: str | None):
    from .fuzzy import FuzzyConfig, FuzzyWeatherClassifier

    if config_path not in _CLASSIFIERS:
        config = FuzzyConfig.from_toml(config_path) if config_path else FuzzyConfig.default()
        _CLASSIFIERS[config_path] = FuzzyWeatherClassifier(config)
    return _CLASSIFIERS[config_path]


def _optional(value) -> float | None:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return None
    return float(value)


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


def load_cases(path) -> list[RuleCase]:
    """Read a rule-table file (CSV or TOML) into `RuleCase` rows, checked."""
    from .errors import HybridtrackError
    from .fuzzy.tuning import read_samples

    path = Path(path)
    frame = read_samples(path)
    if "weather" not in frame.columns and "score" not in frame.columns:  # pragma: no cover - read_samples checks
        raise HybridtrackError(f"{path}: needs a 'weather' or 'score' column")
    config_path = _config_reference(path)
    cases = []
    for number, row in enumerate(frame.to_dict("records"), start=2 if path.suffix.lower() != ".toml" else 1):
        weather = row.get("weather")
        weather = None if weather is None or (isinstance(weather, float) and math.isnan(weather)) \
            else str(weather).strip().lower()
        cases.append(RuleCase(float(row["intensity"]), float(row["variation"]), weather,
                              _optional(row.get("score")), _optional(row.get("tolerance")),
                              config_path, str(path), number))
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
        return self.path, self.case.row, f"rule-table row {self.case.row}: {self.case.id}"
