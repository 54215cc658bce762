"""``hybridtrack ablate``: every policy over a seeded set of days, to show what the classifier is worth."""

from __future__ import annotations

import argparse
import math
import sys

from .. import params
from ..errors import HybridtrackError
from ..outputs import claim, write
from .base import add_force_argument, command, leaving_out, real_number, whole_number


#: ``--deadbands`` and ``--periods`` when not given (with ``--tradeoff``).
DEADBANDS, PERIODS = "0.1,0.2,0.4,0.8", "1min"


def _ablate_arguments(parser: argparse.ArgumentParser) -> None:
    from ..ablation import SEASONS
    from ..control import STRATEGIES

    parser.add_argument("--sites", nargs="+", default=["lanzhou", "nanjing"], help="sites (default lanzhou nanjing)")
    parser.add_argument("--seasons", nargs="+", default=list(SEASONS), choices=list(SEASONS),
                        help="typical days of these seasons (default all four)")
    parser.add_argument("--weather", nargs="+", default=["mixed"], help="sky of each day (default mixed)")
    parser.add_argument("--seeds", type=whole_number, default=5, help="seeds per site, season and weather (default 5)")
    parser.add_argument("--collectors", nargs="+", default=["trough-ns", "fresnel"],
                        help="collectors (default trough-ns fresnel)")
    parser.add_argument("--policies", nargs="+", choices=list(STRATEGIES),
                        help="policies (default all; with --tradeoff, the first, default hybrid)")
    parser.add_argument("--workers", type=whole_number, default=1, help="processes (default 1; the table is the same)")
    parser.add_argument("--config", help="simulation config (TOML) every policy shares")
    parser.add_argument("--out", help="folder for runs.csv, table.csv and ablation.png (tradeoff.png)")
    parser.add_argument("--tradeoff", action="store_true",
                        help="instead of every policy: one policy over a grid of drive deadbands and scan periods, "
                             "pointing error against moves a day")
    parser.add_argument("--deadbands", help=f"with --tradeoff: deadbands, degrees, comma-separated (default "
                                            f"{DEADBANDS})")
    parser.add_argument("--periods", help=f"with --tradeoff: scan periods, comma-separated (default {PERIODS}; e.g. "
                                          "1min,2min,5min)")
    add_force_argument(parser)


@command("ablate", "run every policy over a seeded set of days: what the classifier is worth, and why",
         _ablate_arguments)
def _ablate(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from ..ablation import ablate
    from ..control import STRATEGIES

    if not 1 <= args.seeds <= 1000:
        raise HybridtrackError(f"--seeds must be between 1 and 1000, got {args.seeds}")
    params.whole(args.workers, "--workers", 1, 64)
    if args.tradeoff:
        return _tradeoff(args)
    given = [flag for flag in ("--deadbands", "--periods") if getattr(args, flag[2:]) is not None]
    if given:  # they had been dropped without a word, and every policy run at the config's drive and 1 min
        raise HybridtrackError(f"{' and '.join(given)} {'go' if len(given) > 1 else 'goes'} with --tradeoff, which "
                               "runs one policy over deadbands and scan periods; give --tradeoff, or leave "
                               f"{'them' if len(given) > 1 else 'it'} out")
    plan = _plan(args, tuple(args.policies or STRATEGIES))
    config = _config(args)
    files = _files(args.out, "ablation.png")
    claim(files)  # before the runs, not after them
    days = len(plan.days())
    with _leaving_out_the_other_picture(args, "tradeoff.png", "without --tradeoff"):
        with tqdm(total=days, unit="day", desc="ablate", file=sys.stderr) as bar:
            result = ablate(plan, config=config, workers=args.workers, progress=bar.update)
        print(f"{days} day-runs ({len(args.sites)} sites × {len(args.seasons)} seasons × {len(args.weather)} "
              f"weather × {args.seeds} seeds × {len(args.collectors)} collectors), every policy on the same world")
        print(result.table.to_string(float_format=lambda v: f"{v:.4f}"))
        print(result.gap_note())
        if args.out:
            _write(files, result)
    return 0


def _plan(args: argparse.Namespace, policies: tuple[str, ...]):
    """The `AblationPlan` of the days the flags ask for, with `policies`."""
    from ..ablation import AblationPlan, checked_values

    for name in ("sites", "weather", "collectors"):  # refused naming the flag ('unknown site' had named none)
        checked_values(name, getattr(args, name), f"--{name}")
    return AblationPlan(tuple(args.sites), tuple(args.seasons), tuple(args.weather), tuple(range(1, args.seeds + 1)),
                        tuple(args.collectors), policies)


def _config(args: argparse.Namespace):
    """The ``--config`` file's run config, or None (the defaults) without one. An empty path
    (``--config "$CONFIG"`` with the variable unset) is refused as no file, not read as none."""
    from ..simulation import SimulationConfig

    return SimulationConfig.from_toml(args.config) if args.config is not None else None


def _files(out: str | None, picture: str) -> list:
    """The files an ablation or a trade-off writes into `out` (none without it)."""
    from pathlib import Path

    return [Path(out) / name for name in ("runs.csv", "table.csv", picture)] if out else []


def _leaving_out_the_other_picture(args: argparse.Namespace, picture: str, reason: str):
    """`leaving_out` for `picture`, the picture of the other mode (ablation or trade-off), which
    an earlier run's may have left beside this run's runs.csv and table.csv."""
    return leaving_out(args, _files(args.out, picture)[2:], reason)


def _write(files: list, result) -> None:
    """The runs, the table and the plot of an ablation or a trade-off, to the files claimed for them."""
    from ..report import save_figure

    runs, table, picture = claim(files)
    write(runs, lambda file: result.runs.to_csv(file, index=False, float_format="%.6g"))
    write(table, lambda file: result.table.to_csv(file, float_format="%.6g"))
    save_figure(result.plot(), picture)
    print(f"wrote {runs}, {table} and {picture}")


def _deadbands(text: str) -> tuple[float, ...]:
    try:
        values = tuple(real_number(v) for v in text.split(","))
    except argparse.ArgumentTypeError:
        raise HybridtrackError(f"--deadbands {text!r}: give degrees separated by commas, e.g. 0.1,0.2,0.4") from None
    if not all(math.isfinite(v) for v in values):
        raise HybridtrackError(f"--deadbands {text!r}: every deadband must be a finite number")
    return values


def _tradeoff(args: argparse.Namespace) -> int:
    """``ablate --tradeoff``: one policy over deadbands and scan periods."""
    from tqdm import tqdm

    from ..tradeoff import TradeoffPlan, checked_grid, tradeoff

    deadbands = DEADBANDS if args.deadbands is None else args.deadbands  # "" is refused, not the default
    periods = PERIODS if args.periods is None else args.periods
    days = _plan(args, ((args.policies or ["hybrid"])[0],))  # its sites by their own names (SITE_YEARS)
    # refused naming the flag ('tradeoff: period '0' is not a step' and 'drive: deadband' had named none)
    grid = {name: checked_grid(name, values, f"--{name}") for name, values in
            (("deadbands", _deadbands(deadbands)), ("periods", tuple(p.strip() for p in periods.split(","))))}
    plan = TradeoffPlan(grid["deadbands"], grid["periods"], days.sites, days.seasons, days.weather, days.seeds,
                        days.collectors, days.policies[0])
    config = _config(args)
    files = _files(args.out, "tradeoff.png")
    claim(files)  # before the runs, not after them
    with _leaving_out_the_other_picture(args, "ablation.png", "--tradeoff"):
        with tqdm(total=len(plan.days()), unit="day", desc="tradeoff", file=sys.stderr) as bar:
            result = tradeoff(plan, config=config, workers=args.workers, progress=bar.update)
        print(f"{plan.policy} over {len(plan.deadbands)} deadbands × {len(plan.periods)} scan periods on "
              f"{len(plan.days()) // len(plan.periods)} day(s); held: the error between scans")
        print(result.table.to_string(float_format=lambda v: f"{v:.4g}"))
        if args.out:
            _write(files, result)
    return 0
