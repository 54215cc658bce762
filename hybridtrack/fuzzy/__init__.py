"""Fuzzy inference: any Mamdani system (.fis, FCL), the sky classifier as one, engines, tuning.

See docs/fuzzy-engine.md.
"""

from .classifier import UNKNOWN, Explanation, FuzzyWeatherClassifier
from .config import LABELS, SHAPES, FuzzyConfig, Methods, Rule, Term, Variable
from .files import read_system, write_system
from .system import MamdaniSystem, SystemRule

__all__ = ["FuzzyConfig", "FuzzyWeatherClassifier", "Explanation", "Rule", "Term", "Variable", "SHAPES",
           "LABELS", "UNKNOWN", "tune", "Methods", "MamdaniSystem", "SystemRule", "read_system", "write_system"]


def tune(config, samples, **options):
    """Fit membership parameters to labelled readings; see `hybridtrack.fuzzy.tuning.tune`."""
    from .tuning import tune as _tune

    return _tune(config, samples, **options)
