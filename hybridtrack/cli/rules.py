"""The rule viewer: ``hybridtrack rules --intensity I --variation V``, as MATLAB's ruleview."""

from __future__ import annotations

import argparse

from .base import add_force_argument, command, real_number
from .fuzzy import check_reading, load_fuzzy_config, tuned_config_warnings


def _rules_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--intensity", type=real_number, required=True, help="sensor photocurrent, mA")
    parser.add_argument("--variation", type=real_number, required=True, help="its variation over the window, mA")
    parser.add_argument("--config", help="classifier config (.toml, MATLAB .fis or FCL .fcl); the published one by "
                                         "default")
    parser.add_argument("--plot", metavar="FILE", help="also draw the rule viewer (PNG, SVG or PDF)")
    add_force_argument(parser)


def rule_table(explanation, config) -> str:
    """Each rule's antecedent memberships, firing strength and clipped consequent, then the result."""
    lines = [f"reading: intensity {explanation.intensity:g}, variation {explanation.variation:g} "
             f"(normalised {explanation.normalised[0]:.3f}, {explanation.normalised[1]:.3f})"]
    for rule in explanation.rules:
        parts = [f"{name} is {term} {explanation.memberships[name][term]:.3f}" for name, term in rule["when"].items()]
        lines.append(f"rule {rule['rule']}: {' AND '.join(parts)} -> fires {rule['firing']:.3f} "
                     f"-> {rule['then']} clipped at {rule['firing']:.3f}")
    strengths = {}
    for rule in explanation.rules:
        strengths[rule["then"]] = max(strengths.get(rule["then"], 0.0), rule["firing"])
    lines.append("aggregate (max of the clipped consequents): "
                 + ", ".join(f"{term} {level:.3f}" for term, level in strengths.items()))
    centroid = "undefined (no rule fires)" if explanation.score != explanation.score else f"{explanation.score:.3f}"
    lines.append(f"centroid {centroid} -> {explanation.weather}  (bands: "
                 + ", ".join(f"{name} {lo:g}-{hi:g}" for name, lo, hi in config.bands) + ")")
    return "\n".join(lines)


@command("rules", "show how each fuzzy rule fires for one reading (a rule viewer)", _rules_arguments)
def _rules(args: argparse.Namespace) -> int:
    from ..fuzzy import FuzzyWeatherClassifier

    check_reading(args)
    clf = FuzzyWeatherClassifier(load_fuzzy_config(args.config))
    with tuned_config_warnings():
        explanation = clf.explain(args.intensity, args.variation)
    print(rule_table(explanation, clf.config))
    if args.plot:
        from ..report import plot_rules, save_figure

        print(f"wrote {save_figure(plot_rules(clf, args.intensity, args.variation), args.plot)}")
    return 0
