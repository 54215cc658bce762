"""Mamdani engines on the same systems and readings, in one process: speed and agreement.

Run: ``python benchmarks/fuzzy.py [--repeats N] [--readings N]``. Three systems: the published
sky classifier (2 inputs, 4 rules), ``mixed27`` (3 inputs, 27 rules, nine membership types,
overlapping output terms) and MATLAB's ``tipper.fis``. For each, this project's compiled
(numba) engine evaluates a year of minutes (525,600 readings); its numpy fallback and the
peers, slower, run on the first readings of the same set: scikit-fuzzy's control API with array
inputs (the reference) and one reading at a time, simpful, and pyfuzzylite when installed
(GPL-3.0; a benchmark peer only, never a dependency of this project). Rates are readings
per second; "max |diff|" is the largest difference from scikit-fuzzy (arrays) over the
readings both evaluated. simpful and pyfuzzylite evaluate the input terms exactly and
integrate the output set their own way, so they differ from scikit-fuzzy's sampled system
by their discretisation, not by a mistake.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from _timing import median_seconds, print_table

from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.fuzzy.engine import CompiledSystem, evaluate, evaluate_skfuzzy
from hybridtrack.fuzzy.fis import read_fis_system
from hybridtrack.fuzzy.membership import membership

YEAR_OF_MINUTES = 525_600
CONFORMANCE = Path(__file__).resolve().parent.parent / "tests" / "fuzzy_conformance"


def simpful_engine(system):
    """A simpful system built from ours (exact input terms, 1000 output subdivisions by default)."""
    import simpful as sf

    class Shape(sf.MF_object):
        def __init__(self, term):
            self.term = term

        def _execute(self, x):
            return float(membership(self.term.shape, self.term.params, x))

    fs = sf.FuzzySystem(show_banner=False)
    for var in (*system.inputs, *system.outputs):
        sets = [sf.FuzzySet(function=Shape(t), term=t.name) for t in var.terms]
        fs.add_linguistic_variable(var.name, sf.LinguisticVariable(sets, universe_of_discourse=list(var.universe)))
    rules = []
    for rule in system.rules:
        ifs = [f"({v.name} IS {v.terms[abs(i) - 1].name})" if i > 0 else f"(NOT ({v.name} IS {v.terms[-i - 1].name}))"
               for v, i in zip(system.inputs, rule.antecedent) if i]
        then = [f"({v.name} IS {v.terms[i - 1].name})" for v, i in zip(system.outputs, rule.consequent) if i]
        rules.append(f"IF {f' {rule.connection.upper()} '.join(ifs)} THEN {then[0]}")
    fs.add_rules(rules)
    names = [v.name for v in system.inputs]
    output = system.outputs[0].name

    def run(x):
        out = np.empty(len(x))
        for n, row in enumerate(x):
            for name, value in zip(names, row):
                fs.set_variable(name, float(value), verbose=False)
            out[n] = fs.Mamdani_inference([output], subdivisions=system.resolution[1] - 1)[output]
        return out

    return run


def fuzzylite_engine(system):
    """A pyfuzzylite engine built from ours (vectorised; centroid over the same number of samples)."""
    import fuzzylite as fl

    def term(t):
        p = t.params
        make = {"trimf": lambda: fl.Triangle(t.name, *p), "trapmf": lambda: fl.Trapezoid(t.name, *p),
                "gaussmf": lambda: fl.Gaussian(t.name, p[0], p[1]),
                "gauss2mf": lambda: fl.GaussianProduct(t.name, p[0], p[1], p[2], p[3]),
                "gbellmf": lambda: fl.Bell(t.name, p[2], p[0], p[1]), "sigmf": lambda: fl.Sigmoid(t.name, p[0], p[1]),
                "dsigmf": lambda: fl.SigmoidDifference(t.name, p[0], p[1], p[3], p[2]),
                "psigmf": lambda: fl.SigmoidProduct(t.name, p[0], p[1], p[3], p[2]),
                "pimf": lambda: fl.PiShape(t.name, *p), "smf": lambda: fl.SShape(t.name, *p),
                "zmf": lambda: fl.ZShape(t.name, *p)}
        return make[t.shape]()

    inputs = [fl.InputVariable(v.name, minimum=v.universe[0], maximum=v.universe[1], lock_range=True,
                               terms=[term(t) for t in v.terms]) for v in system.inputs]
    out = system.outputs[0]
    output = fl.OutputVariable(out.name, minimum=out.universe[0], maximum=out.universe[1],
                               aggregation=fl.Maximum(), defuzzifier=fl.Centroid(system.resolution[1]),
                               terms=[term(t) for t in out.terms])
    rules = []
    for rule in system.rules:
        ifs = [f"{v.name} is {'not ' if i < 0 else ''}{v.terms[abs(i) - 1].name}"
               for v, i in zip(system.inputs, rule.antecedent) if i]
        rules.append(fl.Rule.create(f"if {f' {rule.connection} '.join(ifs)} then {out.name} is "
                                    f"{out.terms[rule.consequent[0] - 1].name}"))
    block = fl.RuleBlock(conjunction=fl.Minimum(), disjunction=fl.Maximum(), implication=fl.Minimum(),
                         activation=fl.General(), rules=rules)
    engine = fl.Engine(input_variables=inputs, output_variables=[output], rule_blocks=[block])

    def run(x):
        for k, var in enumerate(inputs):
            var.value = x[:, k]
        engine.process()
        return np.asarray(output.value, float)

    return run


def measure(name, system, readings, args, rows, ours=None):
    """Time every engine on `system` and add a table row for each."""
    compiled = CompiledSystem(system)
    array_part = readings[: args.array_subset]
    reference = evaluate_skfuzzy(system, array_part)
    engines = {
        "hybridtrack, numba": (ours or (lambda x: evaluate(compiled, x, engine="numba")[0][:, 0]), len(readings)),
        "hybridtrack, numpy": (lambda x: evaluate(compiled, x, engine="numpy")[0][:, 0], args.numpy_subset),
        "scikit-fuzzy, arrays": (lambda x: evaluate_skfuzzy(system, x), args.array_subset),
        "scikit-fuzzy, one at a time": (lambda x: evaluate_skfuzzy(system, x, one_at_a_time=True),
                                        args.scalar_subset),
    }
    for peer, build, count in (("simpful", simpful_engine, args.scalar_subset),
                               ("pyfuzzylite (GPL)", fuzzylite_engine, args.array_subset * 10)):
        try:
            engines[peer] = (build(system), count)
        except ImportError:
            rows.append([name, peer, "not installed", "", "", ""])
    base = None
    for engine, (run, count) in engines.items():
        part = readings[:count]
        repeats = args.repeats if count >= 10_000 else 1
        seconds = median_seconds(lambda: run(part), repeats)
        rate = count / seconds
        base = base or rate
        overlap = min(count, len(reference))
        diff = np.nanmax(np.abs(run(part[:overlap]) - reference[:overlap]))
        rows.append([name, engine, f"{count:,}", f"{rate:,.0f}", f"{base / rate:,.1f}x", f"{diff:.1e}"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--readings", type=int, default=YEAR_OF_MINUTES)
    parser.add_argument("--array-subset", type=int, default=2000)
    parser.add_argument("--scalar-subset", type=int, default=200)
    parser.add_argument("--numpy-subset", type=int, default=10_000)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    rows: list[list[str]] = []

    clf = FuzzyWeatherClassifier()
    raw = rng.uniform([30.0, 0.0], [300.0, 180.0], size=(args.readings, 2))
    normalised = clf.normalise(raw[:, 0], raw[:, 1])
    measure("published classifier", clf.config.system(), normalised, args, rows,
            ours=lambda x: clf.score(x[:, 0], x[:, 1], raw=False))
    for path in (CONFORMANCE / "mixed27.fis", CONFORMANCE / "tipper.fis"):
        system = read_fis_system(path)
        x = np.stack([rng.uniform(*v.universe, args.readings) for v in system.inputs], axis=1)
        measure(path.name, system, x, args, rows)
    print(f"Mamdani engines, same systems and readings; median of {args.repeats} runs where 10,000+ readings")
    print_table(["system", "engine", "readings timed", "readings/s", "numba is", "max |diff| vs scikit-fuzzy"],
                rows)


if __name__ == "__main__":
    main()
