"""The fuzzy sky classifier's commands: ``classify``, ``tune`` and ``surface``."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import warnings

from ..errors import HybridtrackError
from ..outputs import claim, strict_json, write
from .base import add_force_argument, command, real_number, whole_number


@contextlib.contextmanager
def tuned_config_warnings():
    """Print a tuned config's `OutsideLabelsWarning` as one ``hybridtrack: warning:`` line each."""
    from ..fuzzy.tuning import OutsideLabelsWarning

    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", OutsideLabelsWarning)
            yield
    finally:  # outside catch_warnings: re-shown there, a warning would be caught again, for ever
        for warning in caught:
            if issubclass(warning.category, OutsideLabelsWarning):
                print(f"hybridtrack: warning: {warning.message}", file=sys.stderr)
            else:
                warnings.showwarning(warning.message, warning.category, warning.filename, warning.lineno)


def load_fuzzy_config(path):
    from ..fuzzy import FuzzyConfig

    if path is None:
        return FuzzyConfig.default()
    if str(path).lower().endswith(".fis"):
        return FuzzyConfig.from_fis(path)
    if str(path).lower().endswith(".fcl"):
        return FuzzyConfig.from_fcl(path)
    return FuzzyConfig.from_toml(path)


def check_reading(args: argparse.Namespace) -> None:
    """Refuse an ``--intensity`` or ``--variation`` that is not a finite number (NaN fires no
    rule; an infinite one would be clipped to the end of its range) or no sensor gives (below zero:
    ``--intensity -500 --variation -20`` had been classified overcast; 1e308 mA sunny)."""
    from ..fuzzy.classifier import impossible_reading

    for name in ("intensity", "variation"):
        value = getattr(args, name)
        if value is not None and not math.isfinite(value):
            raise HybridtrackError(f"--{name} must be a finite number, got {value}")
        why = None if value is None else impossible_reading(value, name)
        if why:
            raise HybridtrackError(f"--{name} {value:g} is no reading: {why}")


def _classify_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", nargs="?", help="CSV of readings to classify (instead of --intensity/--variation)")
    parser.add_argument("--intensity", type=real_number, help="sensor photocurrent, mA")
    parser.add_argument("--variation", type=real_number, help="its variation over the window, mA")
    parser.add_argument("--config",
                        help="classifier config (.toml, MATLAB .fis or FCL .fcl); the published one by default")
    parser.add_argument("--json", action="store_true", help="print JSON: score, weather and each rule's firing")
    parser.add_argument("--intensity-col", default="intensity",
                        help="file: column of the photocurrent, mA (default intensity)")
    parser.add_argument("--variation-col", default="variation",
                        help="file: column of the variation, mA (default variation)")
    parser.add_argument("--out", help="file: write the readings with sky_score and sky columns here")
    add_force_argument(parser)
    parser.add_argument("--engine", choices=("fast", "numba", "numpy", "skfuzzy"), default="fast",
                        help="inference engine: fast (numba, or numpy without it; the default), numba, numpy or "
                             "skfuzzy")


@command("classify", "classify sky readings with the fuzzy classifier", _classify_arguments)
def _classify(args: argparse.Namespace) -> int:
    with tuned_config_warnings():
        return _classify_readings(args)


def _classify_readings(args: argparse.Namespace) -> int:
    from ..fuzzy import FuzzyWeatherClassifier
    from ..fuzzy.classifier import refuse_impossible_readings

    clf = FuzzyWeatherClassifier(load_fuzzy_config(args.config))
    if args.file is None:
        if args.intensity is None or args.variation is None:
            raise HybridtrackError("give --intensity and --variation, or a CSV file of readings")
        check_reading(args)
        explanation = clf.explain(args.intensity, args.variation)
        print(strict_json(explanation.to_dict(), indent=2) if args.json else explanation)
        return 0
    from ..io import numeric_columns, read_table

    table = read_table(args.file)
    wanted = [args.intensity_col.lower(), args.variation_col.lower()]
    for column in wanted:
        if column not in table.columns:
            raise HybridtrackError(f"{args.file}: no column {column!r}; columns are {', '.join(table.columns)}")
    readings = numeric_columns(table[wanted], wanted, str(args.file))
    refuse_impossible_readings(readings, wanted, str(args.file))
    table["sky_score"] = clf.score(readings[wanted[0]].to_numpy(), readings[wanted[1]].to_numpy(), engine=args.engine)
    table["sky"] = clf.label(table["sky_score"].to_numpy())
    if args.out:
        write(claim([args.out])[0], lambda file: table.to_csv(file, index=False, float_format="%.6g"))
        print(f"wrote {len(table)} rows to {args.out}")
    counts = table["sky"].value_counts()
    print(", ".join(f"{label} {counts.get(label, 0)}" for label in [b[0] for b in clf.config.bands] + ["unknown"]))
    return 0


def _tune_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("labels", help="CSV (or TOML [[case]]) of intensity, variation and weather and/or score")
    parser.add_argument("--config", help="starting config (.toml, MATLAB .fis or FCL .fcl); the published one by "
                                         "default")
    parser.add_argument("--out", required=True, help="where to write the tuned config (.toml, .fis or .fcl)")
    parser.add_argument("--method", choices=("global", "local"), default="global",
                        help="global: population search then Powell (default); local: Powell only")
    parser.add_argument("--margin", type=real_number, default=0.5,
                        help="how far inside its band a label's score should sit, score units (default 0.5)")
    parser.add_argument("--seed", type=whole_number, default=0, help="seed for reproducible fits (default 0)")
    parser.add_argument("--folds", type=whole_number, default=5,
                        help="k of the k-fold cross-validated accuracy (default 5; 0 skips it)")
    parser.add_argument("--seeds", type=whole_number, default=3,
                        help="fit from this many seeds, keep the fit of lowest loss and report how far the fits "
                             "spread (default 3; 1 fits once)")
    parser.add_argument("--report", metavar="DIR",
                        help="also write report.json, surfaces.png (before/after) and confusion.png here")
    add_force_argument(parser)


@command("tune", "fit the classifier's membership functions to labelled readings", _tune_arguments)
def _tune(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..fuzzy.files import file_format
    from ..fuzzy.tuning import check_folds, check_margin, check_seed, check_seeds, read_samples, tune

    suffix = file_format(args.out)  # tuned.fcl had been written as TOML, which no reader then took
    check_seed(args.seed, "--seed")
    check_seeds(args.seeds, "--seeds")  # these checks before the progress bar
    start = load_fuzzy_config(args.config)
    check_margin(args.margin, start, "--margin")
    samples = read_samples(args.labels, start)
    check_folds(args.folds, len(samples), "--folds")
    report_files = [Path(args.report) / name for name in ("report.json", "surfaces.png", "confusion.png")] \
        if args.report else []
    claim([args.out, *report_files])  # before the fit, not after it
    from ..progress import bar as progress_bar

    fits = 1 + args.folds + max(args.seeds - 1, 0)
    with progress_bar(fits, unit="fit", desc="tuning", disable=fits < 2) as bar:
        tuned, report = tune(start, samples, method=args.method, margin=args.margin, seed=args.seed,
                             folds=args.folds, seeds=args.seeds, progress=bar.update)
    out = {".fis": tuned.to_fis, ".fcl": tuned.to_fcl, ".toml": tuned.to_toml}[suffix](args.out)
    print(report)
    for name, change in report.changed.items():
        print(f"  {name}: {change['before']} -> {change['after']}")
    print(f"wrote {out}" + (f" (a {suffix} file cannot keep the labelled range; use .toml to keep the warning)"
                            if suffix != ".toml" else ""))
    if args.report:
        from ..report import plot_confusion, plot_tuning, save_figure

        folder = Path(args.report)
        write(folder / "report.json", lambda file: file.write_text(strict_json(report.to_dict(), indent=2) + "\n"))
        surfaces = save_figure(plot_tuning(start, tuned, samples), folder / "surfaces.png")
        confusion = save_figure(plot_confusion(start, tuned, samples), folder / "confusion.png")
        print(f"wrote {folder / 'report.json'}, {surfaces}, {confusion}")
    return 0


def _surface_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="classifier config (.toml, MATLAB .fis or FCL .fcl); the published one by "
                                         "default")
    parser.add_argument("--out", default="surface.png", help="image to write (default surface.png)")
    add_force_argument(parser)
    parser.add_argument("--points", type=whole_number, default=121, help="grid points along each input (default 121)")


@command("surface", "draw the classifier's decision surface and membership functions", _surface_arguments)
def _surface(args: argparse.Namespace) -> int:
    from ..fuzzy import FuzzyWeatherClassifier
    from ..report import plot_fuzzy_surface, save_figure

    if not 5 <= args.points <= 1001:
        raise HybridtrackError(f"--points must be between 5 and 1001, got {args.points}")
    clf = FuzzyWeatherClassifier(load_fuzzy_config(args.config))
    print(f"wrote {save_figure(plot_fuzzy_surface(clf, points=args.points), args.out)}")
    return 0
