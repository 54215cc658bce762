"""Whole fields: ``field``."""

from __future__ import annotations

import argparse
import dataclasses
import sys

import numpy as np

from ..errors import HybridtrackError, blamed
from .base import (
    add_dask_arguments, add_force_argument, add_synthetic_arguments, command, leaving_out, parse_mapping,
    simulation_config, STRATEGY_HELP, real_number, site_from_arguments, synthetic_frame, whole_number,
)


def _field_arguments(parser: argparse.ArgumentParser) -> None:
    from ..control import STRATEGIES
    from ..fields import FIELD_KINDS

    parser.add_argument("kind", choices=tuple(FIELD_KINDS),
                        help="a linear Fresnel field, a trough loop or a heliostat field")
    add_synthetic_arguments(parser)
    group = parser.add_argument_group("field")
    group.add_argument("--rows", help="Fresnel: row distances from the receiver line, m, comma-separated "
                                      "(default 20 rows, -9.5 to 9.5 every 1 m); write --rows=-4,0,4 when the first is "
                                      "negative")
    group.add_argument("--receiver-height", type=real_number, help="Fresnel: receiver height, m (default 10)")
    group.add_argument("--row-length", type=real_number, help="Fresnel: row length, m (default 100)")
    group.add_argument("--count", type=whole_number,
                       help="trough: collectors in the loop (default 12); heliostat: mirrors on rings when no "
                            "--positions (default 12)")
    group.add_argument("--collector-length", type=real_number, help="trough: collector length, m (default 150)")
    group.add_argument("--axis-azimuth", type=real_number,
                       help="Fresnel/trough: axis azimuth, degrees from north (default 0, north-south)")
    group.add_argument("--positions", help="heliostat: CSV of mirror centres with columns east, north (and up), m; "
                                           "aim_east, aim_north, aim_up give each its own aim point")
    group.add_argument("--aim", type=real_number, nargs=3, metavar=("E", "N", "U"),
                       help="heliostat: the receiver's aim point from the tower foot, m (default 0 0 100)")
    group.add_argument("--spread", action="append", metavar="NAME=SD",
                       help="standard deviation of a per-collector imperfection, e.g. --spread encoder_offset=0.3 "
                            "(repeatable; see hybridtrack.fields.ImperfectionSpread)")
    group.add_argument("--no-spread", action="store_true", help="every collector gets the config's imperfections")
    run = parser.add_argument_group("run")
    run.add_argument("--strategy", choices=STRATEGIES, help=STRATEGY_HELP)
    run.add_argument("--config", help="simulation config (TOML: controller, imperfections, sensor, drive, seed)")
    run.add_argument("--perfect", action="store_true", help="no imperfections at the centre of the draws")
    run.add_argument("--metric", help="collector metric the field map in --out shows (default rms; "
                                      "energy_capture, moves, p95, end_loss_share, ...)")
    run.add_argument("--no-log", action="store_true", help="keep only the metrics, not the collector x time log")
    run.add_argument("--out", help="folder for collectors.csv, events.csv, summary.json, field_map.png, log.nc")
    run.add_argument("--threads", type=whole_number,
                     help="threads of this process the collectors run on (default: one per core where the compiled "
                          "kernel runs them, fewer if memory would not hold that many runs; otherwise one)")
    add_dask_arguments(run, default="the collectors on threads of this process (--threads); --workers N runs them "
                                    "on a local cluster of N processes")
    add_force_argument(run)


def _spread(args: argparse.Namespace):
    from ..fields import ImperfectionSpread

    if args.no_spread:
        if args.spread:
            raise HybridtrackError("give either --spread or --no-spread, not both")
        return ImperfectionSpread.none()
    changes = {}
    known = {f.name for f in dataclasses.fields(ImperfectionSpread)}
    for name, value in parse_mapping(args.spread, "--spread").items():
        if name not in known:
            raise HybridtrackError(f"--spread: unknown imperfection {name!r}; known: {', '.join(sorted(known))}")
        try:
            changes[f"--spread {name}"] = (name, real_number(value))
        except argparse.ArgumentTypeError as exc:
            raise HybridtrackError(f"--spread {name}: {exc}") from None
    return _built(ImperfectionSpread, changes)


def _numbers(text: str, flag: str) -> list[float]:
    try:
        return [real_number(part) for part in text.split(",")]  # an empty item is refused, not skipped
    except argparse.ArgumentTypeError:
        raise HybridtrackError(f"{flag} takes numbers separated by commas, got {text!r}") from None


def read_positions(path: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Mirror centres (N, 2 or 3) and optional aim points (N, 3) from a CSV file (comma,
    semicolon, tab or bar; ``#`` comments), as `hybridtrack.io.read_table` reads small tables."""
    from ..fields import AIM_COLUMNS
    from ..io import numeric_columns
    from ..io.tables import read_table

    table = read_table(path)
    for column in ("east", "north"):
        if column not in table.columns:
            raise HybridtrackError(f"{path}: no column {column!r}; columns are {', '.join(table.columns)}")
    position_columns = [c for c in ("east", "north", "up") if c in table.columns]
    aim_columns = [c for c in AIM_COLUMNS if c in table.columns]
    if aim_columns and len(aim_columns) != 3:
        raise HybridtrackError(f"{path}: aim points need all of aim_east, aim_north, aim_up")
    columns = position_columns + aim_columns
    unread = [c for c in table.columns if c not in columns]
    if unread:  # an id or a name, or an 'elevation' meant as up: said (on stderr: stdout is the results), not dropped
        print(f"{path}: not read: {', '.join(map(str, unread))} (mirrors are read from east, north, up and "
              "aim_east, aim_north, aim_up)", file=sys.stderr)
    table = numeric_columns(table, columns, str(path), required=columns)
    aims = table[aim_columns].to_numpy(float) if aim_columns else None
    return table[position_columns].to_numpy(float), aims


def field_from_arguments(args: argparse.Namespace):
    """The field the flags describe; a refusal names the flags it came from (`_built`)."""
    from ..fields import FresnelField, HeliostatField, TroughLoop

    _refuse_other_kinds_flags(args)
    spread = _spread(args)
    if args.kind == "fresnel":
        rows = _numbers(args.rows, "--rows") if args.rows is not None else None
        return _built(FresnelField, {"--rows": ("row_distances", rows),
                                     "--receiver-height": ("receiver_height", args.receiver_height),
                                     "--row-length": ("row_length", args.row_length),
                                     "--axis-azimuth": ("axis_azimuth", args.axis_azimuth)}, spread=spread)
    if args.kind == "trough":
        return _built(TroughLoop, {"--count": ("count", args.count),
                                   "--collector-length": ("collector_length", args.collector_length),
                                   "--axis-azimuth": ("axis_azimuth", args.axis_azimuth)}, spread=spread)
    aim = {"--aim": ("aim", tuple(args.aim) if args.aim is not None else None)}
    if args.positions:
        positions, aims = read_positions(args.positions)
        if aims is not None and args.aim is not None:
            raise HybridtrackError(f"--aim gives every mirror one aim point; {args.positions} gives each its own "
                                   "(aim_east, aim_north, aim_up): give one or the other")
        try:
            return _built(HeliostatField, aim, positions=positions, aims=aims, spread=spread)
        except HybridtrackError as exc:  # heliostat N is the file's N-th mirror
            raise HybridtrackError(f"{args.positions}: {exc}") from None
    return _built(HeliostatField.rings, {"--count": ("count", args.count), **aim}, spread=spread)


def _built(make, flags: dict, **fixed):
    """``make(**fixed, ...)`` with the values `flags` gave, each flag's as ``(argument, value)``
    (a value of None: not given, the field's own default stands); a refusal names the flags it
    came from (`hybridtrack.errors.blamed`), as ``--rows: ...``, its message the API's own."""

    def build(chosen: dict):
        return make(**fixed, **dict(chosen.values()))

    given = {flag: pair for flag, pair in flags.items() if pair[1] is not None}
    try:
        return build(given)
    except HybridtrackError as exc:
        named = blamed(build, given, str(exc))
        raise HybridtrackError(f"{', '.join(named)}: {exc}" if named else str(exc)) from None


#: The field flags, and the kinds of field each describes.
_FLAG_KINDS = {"rows": ("fresnel",), "receiver_height": ("fresnel",), "row_length": ("fresnel",),
               "count": ("trough", "heliostat"), "collector_length": ("trough",),
               "axis_azimuth": ("fresnel", "trough"), "positions": ("heliostat",), "aim": ("heliostat",)}


def _refuse_other_kinds_flags(args: argparse.Namespace) -> None:
    """Refuse a flag the chosen kind of field has no use for (it would be ignored), and a ring
    count beside a positions file."""
    for name, kinds in _FLAG_KINDS.items():
        if getattr(args, name) is not None and args.kind not in kinds:
            raise HybridtrackError(f"--{name.replace('_', '-')} describes a {' or '.join(kinds)} field, not a "
                                   f"{args.kind} one")
    if args.kind == "heliostat" and args.positions is not None and args.count is not None:
        raise HybridtrackError("--count places mirrors on rings; --positions gives them: give one or the other")


def field_table(summary: dict) -> str:
    """A field summary as two aligned columns (the figures `FieldResult._repr_html_` shows)."""
    from ..fields import _SUMMARY_LABELS, _shown

    rows = [(label, summary[key]) for key, label in _SUMMARY_LABELS.items() if key in summary]
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label:<{width}}  {_shown(value)}" for label, value in rows)


@command("field", "run a tracker for every collector of a Fresnel field, a trough loop or a heliostat field",
         _field_arguments)
def _field(args: argparse.Namespace) -> int:
    from ..cluster import MAX_WORKERS, check_where
    from ..fields import FieldResult, collector_columns, simulate_field
    from ..outputs import claim
    from ..params import whole

    for flag, count in (("--threads", args.threads), ("--workers", args.workers)):
        if count is not None:  # named as the flag, as every other refusal is ("threads must be ..." had not been)
            whole(count, flag, 1, MAX_WORKERS)
    check_where(args.scheduler, args.workers, args.threads)  # at the door, not after the weather is made
    site = site_from_arguments(args)
    field = field_from_arguments(args)
    if args.metric is not None and args.metric not in collector_columns(field):
        raise HybridtrackError(f"--metric: no collector metric {args.metric!r}; "
                               f"choose from {', '.join(collector_columns(field))}")
    if args.metric is not None and not args.out:
        raise HybridtrackError("--metric colours the field map, which only --out writes: give --out FOLDER")
    frame = synthetic_frame(args, site)
    if args.out:
        claim(FieldResult.files(args.out, log=not args.no_log).values())
    no_log = [FieldResult.files(args.out)["log"]] if args.out and args.no_log else []
    with leaving_out(args, no_log, "--no-log"):
        result = simulate_field(frame, site, field, strategy=args.strategy, config=simulation_config(args, args.seed),
                                seed=args.seed, keep_log=not args.no_log and bool(args.out), progress=True,
                                threads=args.threads, workers=args.workers, scheduler=args.scheduler)
        # saved first: a standard output that fails to print loses nothing
        written = result.save(args.out, metric=args.metric or "rms") if args.out else None
    print(f"{site.name}, {args.date} ({args.days} day{'s' if args.days > 1 else ''}, {args.weather}), "
          f"{result.summary['field']} of {len(result.collectors)} ({result.summary['kind']}), "
          f"{result.summary['strategy']}")
    print(field_table(result.summary))
    shown = ["east", "north", "rms", "energy_capture", "moves"] + \
        (["end_loss_share"] if "end_loss_share" in result.collectors else [])
    print(result.collectors[shown].to_string(max_rows=12, float_format=lambda v: f"{v:.4g}"))
    if written:  # loses no run
        print("wrote " + ", ".join(str(p) for p in written.values()))
    return 0
