"""Parameter studies: ``sweep``."""

from __future__ import annotations

import argparse

from ..errors import HybridtrackError
from .base import add_dask_arguments, add_force_argument, command


def _sweep_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", metavar="SWEEP.toml", help="the sweep: [base] run, [grid] of values, [plot] axes "
                                                           "(see examples/sweep-deadband.toml)")
    parser.add_argument("--out", required=True,
                        help="folder for runs.parquet (one row per run), tradeoff.png and sweep.toml")
    add_force_argument(parser)
    add_dask_arguments(parser, default="a local cluster on this machine's cores")


@command("sweep", "run a grid of runs (config fields, sites, dates, weather, seeds, strategies, collectors) on Dask",
         _sweep_arguments)
def _sweep(args: argparse.Namespace) -> int:
    from ..cluster import MAX_WORKERS, check_where
    from ..params import whole
    from ..outputs import claim, held
    from ..sweep import Sweep, SweepInterrupted, partial_file, pareto_front, run_sweep, save_sweep, sweep_files

    if args.workers is not None:  # named as the flag, as field's is ('workers must be ...' had not been)
        whole(args.workers, "--workers", 1, MAX_WORKERS)
    if args.scheduler is not None and not args.scheduler.strip():  # --scheduler "$ADDR" with ADDR unset
        raise HybridtrackError(f"--scheduler must be an address such as 'tcp://host:8786', got {args.scheduler!r}; "
                               "leave it out for a local cluster (an unset shell variable?)")
    check_where(args.scheduler, args.workers)  # before anything is printed: a refusal is the one line
    sweep = Sweep.from_toml(args.file)
    # a folder that cannot be used fails now, not after the runs
    claim([*sweep_files(args.out).values(), partial_file(args.out)])
    runs = len(sweep.runs())
    heading = f"{args.file}: {runs} run{'s' if runs != 1 else ''} over {', '.join(sweep.grid)}"
    # the folder is this sweep's while its runs run: another sweep into it is refused before its
    # own runs (both had passed the check of the empty folder, and the one that ended second lost
    # its files to the other's, or with --force wrote its table beside the other's sweep.toml)
    with held(sweep_files(args.out)["table"].parent):
        try:
            # said once the runs have somewhere to go: a scheduler that cannot be reached is the one line
            table = run_sweep(sweep, scheduler=args.scheduler, workers=args.workers,
                              started=lambda: print(heading, flush=True))
        except SweepInterrupted as stopped:  # said as what stopped it: Ctrl-C (130) or SIGTERM (143)
            raise type(stopped.stop or KeyboardInterrupt())(_keep_finished(stopped, args.out)) from None
    written = save_sweep(table, sweep, args.out)  # it claims its files again, as any run may now
    partial_file(args.out).unlink(missing_ok=True)  # an earlier interrupted sweep's, claimed (--force) and replaced
    failed = table[table["error"].notna()]
    keys = [k for k in ("run", *sweep.grid) if k in table]
    front = pareto_front(table, sweep.x, sweep.y)
    if len(front):
        print(f"Pareto front of {sweep.x} against {sweep.y} ({len(front)} of {len(table) - len(failed)} runs):")
        print(front[keys + [sweep.x, sweep.y]].to_string(index=False))
    else:  # every run failed, or none has both metrics (no sun): not pandas' "Empty DataFrame"
        print(f"Pareto front of {sweep.x} against {sweep.y}: no run has both ({len(failed)} run"
              f"{'s' if len(failed) != 1 else ''} failed)")
    if len(failed):
        print(f"{len(failed)} run{'s' if len(failed) != 1 else ''} failed:")
        for _, row in failed.head(10).iterrows():
            print(f"  run {row['run']}: {row['error']}")
    print("wrote " + ", ".join(str(p) for p in written.values()))
    if len(failed) == len(table):
        raise HybridtrackError(f"every run failed; run {failed['run'].iloc[0]}: {failed['error'].iloc[0]}")
    return 0


def _keep_finished(stopped, out: str) -> str:
    """Write an interrupted sweep's finished runs to ``runs.partial.parquet``; what to tell the user."""
    from ..cluster import holding_interrupts
    from ..outputs import write
    from ..sweep import partial_file

    if stopped.table is None:
        return f"none of the {stopped.planned} runs had finished; nothing written"
    path = partial_file(out)
    with holding_interrupts():  # the user is already stopping: Ctrl-C again must not lose the runs being kept
        write(path, lambda target: stopped.table.to_parquet(target, index=False))
    return f"the {len(stopped.table)} of {stopped.planned} runs that had finished are in {path}"
