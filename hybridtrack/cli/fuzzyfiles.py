"""Fuzzy system files: ``hybridtrack fuzzy convert IN OUT`` and ``hybridtrack fuzzy eval FILE``."""

from __future__ import annotations

import argparse

from ..errors import HybridtrackError
from .base import add_force_argument, command


def _arguments(parser: argparse.ArgumentParser) -> None:
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    convert = actions.add_parser("convert", help="convert a system between .fis, .fcl and .toml",
                                 description="Convert a Mamdani system between MATLAB .fis, IEC 61131-7 .fcl and "
                                             "the sky classifier's .toml (two inputs, one output), by file suffix.")
    convert.add_argument("source", metavar="IN", help="system to read (.fis, .fcl or .toml)")
    convert.add_argument("target", metavar="OUT", help="file to write (.fis, .fcl or .toml)")
    add_force_argument(convert)
    evaluate = actions.add_parser("eval", help="evaluate a system file at some inputs",
                                  description="Evaluate a Mamdani system file (.fis, .fcl or .toml) at one reading. "
                                              "A classifier .toml takes raw readings (mA), mapped through its inputs' "
                                              "raw_range as the classifier maps them.")
    evaluate.add_argument("source", metavar="FILE", help="system to read (.fis, .fcl or .toml)")
    evaluate.add_argument("values", metavar="NAME=VALUE", nargs="+", help="one value per input, e.g. service=2")
    evaluate.add_argument("--engine", choices=("auto", "numba", "numpy", "skfuzzy"), default="auto",
                          help="inference engine (default auto: compiled when numba is installed)")


@command("fuzzy", "fuzzy system files: convert between .fis, .fcl and .toml, evaluate", _arguments)
def _fuzzy(args: argparse.Namespace) -> int:
    from ..fuzzy.files import read_system, write_system

    system = read_system(args.source)
    if args.action == "convert":
        counts = ", ".join(f"{n} {what}{'s' if n != 1 else ''}" for n, what in (
            (len(system.inputs), "input"), (len(system.outputs), "output"), (len(system.rules), "rule")))
        print(f"wrote {write_system(system, args.target)} ({counts})")
        return 0
    return _evaluate(system, args)


def _evaluate(system, args: argparse.Namespace) -> int:
    import numpy as np

    from ..fuzzy.engine import CompiledSystem, evaluate, evaluate_skfuzzy
    from .base import parse_mapping, real_number

    given = parse_mapping(args.values, "NAME=VALUE")
    unknown = sorted(set(given) - set(system.input_names))
    missing = [name for name in system.input_names if name not in given]
    if unknown or missing:
        problem = f"unknown input {unknown[0]!r}" if unknown else f"no value for input {missing[0]!r}"
        raise HybridtrackError(f"{problem}; the inputs are {', '.join(system.input_names)}")
    try:
        x = np.array([[real_number(given[name]) for name in system.input_names]])
    except argparse.ArgumentTypeError as exc:
        raise HybridtrackError(f"input values must be numbers: {exc}") from None
    for name, value in zip(system.input_names, x[0]):
        if not np.isfinite(value):
            raise HybridtrackError(f"input {name!r} must be a finite number, got {value}")
    if str(args.source).lower().endswith(".toml"):  # a classifier's readings: refused as classify refuses them
        from ..fuzzy.classifier import NEVER_NEGATIVE, impossible_reading

        for name, value, reading in zip(system.input_names, x[0], NEVER_NEGATIVE):
            why = impossible_reading(value, reading)
            if why:
                raise HybridtrackError(f"input {name!r} {value:g} is no reading: {why}")
    x = np.array([[var.to_universe(value) for var, value in zip(system.inputs, x[0])]])  # a .toml's raw_range
    if args.engine == "skfuzzy":
        values = [evaluate_skfuzzy(system, x, output=o)[0] for o in range(len(system.outputs))]
    else:
        values = evaluate(CompiledSystem(system), x, engine=args.engine)[0][0]
    for var, value in zip(system.outputs, values):
        print(f"{var.name} = {value:.6g}")
    return 0
