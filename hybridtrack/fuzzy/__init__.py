"""The fuzzy sky classifier: config, two engines, files, tuning (``domain.md`` §4)."""

from .classifier import UNKNOWN, Explanation, FuzzyWeatherClassifier
from .config import LABELS, SHAPES, FuzzyConfig, Rule, Term, Variable

__all__ = ["FuzzyConfig", "FuzzyWeatherClassifier", "Explanation", "Rule", "Term", "Variable", "SHAPES",
           "LABELS", "UNKNOWN", "tune"]


def tune(config, samples, **options):
    """Fit membership parameters to labelled readings; see `hybridtrack.fuzzy.tuning.tune`."""
    from .tuning import tune as _tune

    return _tune(config, samples, **options)
