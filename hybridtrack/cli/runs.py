"""Running the tracker: ``demo``, ``simulate``, ``replay`` and ``compare``."""

from __future__ import annotations

import argparse
import warnings

import numpy as np
import pandas as pd

from .. import sites
from ..errors import HybridtrackError
from ..outputs import claim, strict_json, write
from .base import (
    add_force_argument,
    add_record_arguments,
    add_run_arguments,
    add_site_arguments,
    add_synthetic_arguments,
    collector_from_arguments,
    command,
    flag_named,
    leaving_out,
    read_record,
    simulation_config,
    site_from_arguments,
    synthetic_frame,
    synthetic_span,
)


def _run(frame, site, args, strategy: str | None, config, *, label: str = ""):
    from ..progress import bar as progress_bar
    from ..simulation import simulate

    days = (frame.index[-1] - frame.index[0]) / pd.Timedelta(days=1)
    with progress_bar(len(frame), unit="step", desc=label or strategy or config.controller.strategy,
                      disable=days < 2) as bar:
        return simulate(frame, site, collector=collector_from_arguments(args), strategy=strategy, config=config,
                        progress=bar.update)


def summary_table(summaries: dict[str, dict]) -> str:
    """Key metrics of one or more runs, one column each."""
    rows = [("steps", lambda s: f"{s['steps']:,}"),
            ("tracking error RMS (°)", lambda s: _fmt(s["tracking_error_deg"]["rms"], ".3f")),
            ("tracking error p95 (°)", lambda s: _fmt(s["tracking_error_deg"]["p95"], ".3f")),
            ("tracking error max (°)", lambda s: _fmt(s["tracking_error_deg"]["max"], ".3f")),
            ("mean error, bias (°)", lambda s: _fmt(s["tracking_error_deg"]["mean"], "+.3f")),
            ("within 0.5° (DNI share)", lambda s: _fmt(s["within_0_5_deg"], ".1%")),
            ("energy capture", lambda s: _fmt(s["energy_capture"], ".2%")),
            ("moves", lambda s: f"{s['moves']:,}"),
            ("travel (°)", lambda s: f"{s['travel_deg']:,.0f}"),
            ("mode switches", lambda s: f"{s['mode_switches']}"),
            ("wind stow events", lambda s: f"{s['stow_events']}")]
    first = next(iter(summaries.values()))  # shares of every step of the run (docs/metrics.md)
    rows += [(f"mode {m}", lambda s, m=m: _fmt(s["mode_share"].get(m), ".1%")) for m in first["mode_share"]]
    rows += [(f"sky {k}", lambda s, k=k: _fmt(s["sky_share"].get(k), ".1%")) for k in first["sky_share"]]
    table = pd.DataFrame({name: [pick(summary) for _, pick in rows] for name, summary in summaries.items()},
                         index=[label for label, _ in rows])
    return table.to_string()


def _fmt(value, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def _claim_run_folder(args: argparse.Namespace) -> None:
    """Refuse a bad ``--out`` before the run rather than after it."""
    from ..simulation import Result

    if args.out:
        claim(Result.files(args.out).values())


def _finish(result, args, *, heading: str) -> None:
    written = result.save(args.out) if args.out else None  # saved first: a failing standard output loses no run
    print(heading)
    print(summary_table({result.summary["strategy"]: result.summary}))
    if written:
        print("wrote " + ", ".join(str(p) for p in written.values()))


DEMO_FOLDER = "hybridtrack-demo"


def _demo_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", default=DEMO_FOLDER, help=f"folder for the results (default {DEMO_FOLDER}; a demo "
                                                           "run again replaces its own files there)")
    add_force_argument(parser)


@command("demo", "a built-in mixed-sky day at Lanzhou: run the hybrid tracker, print the summary, "
                 "write the report", _demo_arguments)
def _demo(args: argparse.Namespace) -> int:
    from ..collectors import Collector
    from ..outputs import replacing
    from ..simulation import simulate
    from ..sky import synthetic

    with replacing(args.force or args.out == DEMO_FOLDER) as replaced:  # the same day each time: its own files
        _claim_run_folder(args)
    site = sites.get("lanzhou")
    frame = synthetic(site, "2021-06-21", weather="mixed", seed=5, gusts_per_day=2.0)
    result = simulate(frame, site, collector=Collector("fresnel"), strategy="hybrid")
    with replacing(True):
        written = result.save(args.out)
    print("demo: Lanzhou linear Fresnel row, 2021-06-21, mixed sky with gusts (seed 5), hybrid strategy, default "
          "imperfections")
    print(summary_table({"hybrid": result.summary}))
    print(f"wrote {written['report']} (the day at a glance), {written['summary']}, {written['log']}, "
          f"{written['events']}" + (" (replacing those of an earlier run)" if replaced else ""))
    return 0


def _add_stream_argument(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument("--stream", action="store_true",
                        help=f"run {what} a local day at a time in bounded memory, streaming the log to --out "
                             "(log.parquet, events.csv, summary.json; no report.png): for spans too long to hold "
                             "in memory, such as a year at 1 s (docs/long-runs.md)")


def _stream(source, args, config, *, heading: str) -> int:
    """A streamed run (`hybridtrack.streaming`): a progress bar on stderr, the summary, the files."""
    from ..simulation import Result
    from ..streaming import AwakeAtMidnightWarning, progress_bar, stream, stream_files

    if not args.out:
        raise HybridtrackError("--stream writes its log to disk: give --out FOLDER")
    claim(stream_files(args.out).values())  # a bad --out is refused before the bar
    if (args.strategy or config.controller.strategy) == "hybrid-oracle":
        source.check_true_sky()  # and a sky label the oracle cannot read, by its line
    source.check_span()  # and a span without a whole local day
    with leaving_out(args, [Result.files(args.out)["report"]], "--stream"), \
            progress_bar(source, label=config.controller.strategy) as bar:
        with warnings.catch_warnings():  # said below, in a line of its own
            warnings.simplefilter("ignore", AwakeAtMidnightWarning)
            result = stream(source, args.out, collector=collector_from_arguments(args), strategy=args.strategy,
                            config=config, progress=bar.update)
    print(heading + f" (streamed in {result.summary['streamed']['segments']} day-long segments)")
    for line in result.kept_as_read.lines():
        print(line)
    if "awake_at_midnight" in result.summary["streamed"]:
        awake = result.summary["streamed"]["awake_at_midnight"]
        print(f"awake at midnight: {awake['count']} day(s), the first {awake['first']}: {awake['why']}")
    print(summary_table({result.summary["strategy"]: result.summary}))
    print("wrote " + ", ".join(str(p) for p in result.files.values()))
    return 0


def _simulate_arguments(parser: argparse.ArgumentParser) -> None:
    add_synthetic_arguments(parser)
    add_run_arguments(parser)
    _add_stream_argument(parser, "the days")


@command("simulate", "run a tracker over synthetic days", _simulate_arguments)
def _simulate(args: argparse.Namespace) -> int:
    site = site_from_arguments(args)
    if args.stream:
        return _stream_synthetic(args, site)
    frame = synthetic_frame(args, site)
    _claim_run_folder(args)
    result = _run(frame, site, args, args.strategy, simulation_config(args, args.seed))
    _finish(result, args, heading=f"{site.name}, {args.date} ({args.days} day{'s' if args.days > 1 else ''}, "
                                  f"{args.weather}), {result.collector.kind}, {result.summary['strategy']}")
    return 0


def _stream_synthetic(args: argparse.Namespace, site) -> int:
    from ..streaming import synthetic_days

    if "," in args.weather:  # before synthetic_span counts the list against --days
        raise HybridtrackError("--stream takes one --weather for every day (climate draws each day from the site's "
                               "monthly climate), not a per-day list")
    first, last = synthetic_span(args)
    source = synthetic_days(site, first, last, weather=args.weather, freq=args.freq, seed=args.seed,
                            gusts_per_day=args.gusts_per_day)
    config = simulation_config(args, args.seed)
    return _stream(source, args, config,
                   heading=f"{site.name}, {args.date} ({args.days} day{'s' if args.days > 1 else ''}, {args.weather}, "
                           f"each day seeded from (seed, date)), {collector_from_arguments(args).kind}, "
                           f"{config.controller.strategy}")


def _replay_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="recorded weather file (CSV or a pvlib format)")
    add_site_arguments(parser, record=True)
    add_record_arguments(parser)
    parser.add_argument("--step", default=None, help="control step the record is resampled to (default 1min; not "
                                                     "with --stream, which runs a frame at its own step)")
    add_run_arguments(parser)
    _add_stream_argument(parser, "a weather frame saved as .parquet or .csv (its own step, read as written: a "
                                 "value the reader would repair, such as a negative or impossible irradiance, is "
                                 "refused by row and column)")


def _replay_frame(args: argparse.Namespace):
    if args.step is not None:
        from ..simulation import run_step

        # before the file is read: 'step '0min' must be positive' had named no flag, and a step no run
        # takes (1W) was refused after the report, naming the frame's median step, not the flag
        with flag_named("--step"):
            run_step(args.step)
    site = site_from_arguments(args)
    frame = read_record(args, args.file, site=site, freq=args.step or "1min")
    from ..io import validation_report

    if len(frame) < 2:  # the run's own refusal had named no flag
        raise HybridtrackError(f"--step {args.step or '1min'}: {args.file} makes {len(frame)} step at that step; a run "
                               "needs at least two: give a shorter --step")
    print(validation_report(frame))
    return site, frame


def replay_config(args: argparse.Namespace, has_wind: bool):
    """The run's config for a recorded file: a file with no wind at all (`has_wind` false) is
    tracked through, not stowed all day (``wind_missing = "track"``), unless the config chose
    otherwise; said aloud."""
    import dataclasses

    config = simulation_config(args)
    if not has_wind and not args.config:
        print("wind: MISSING in this file; replayed as tracking through (controller.wind_missing = 'track'), "
              "not as calm")
        config = dataclasses.replace(config, controller=dataclasses.replace(config.controller, wind_missing="track"))
    return config


def _refuse_unknown_sky(frame, path: str) -> None:
    """Refuse, for the hybrid-oracle policy, a file's sky labels that name no sky, by the file's line
    and column (the reader found them: ``sky_unknown``), before any run; the run's own refusal had
    named a time stamp of the frame."""
    unknown = frame.attrs.get("validation", {}).get("sky_unknown")
    if unknown:
        from ..control import SKY_CODES

        header = frame.attrs["validation"].get("columns", {}).get("sky", "sky")
        raise HybridtrackError(f"{path}: column {header!r}: {unknown['first']} is no sky label ({unknown['count']} "
                               f"such); the hybrid-oracle policy reads {', '.join(map(repr, SKY_CODES))}")


def _has_wind(frame) -> bool:
    return "wind_speed" in frame.columns and bool(np.isfinite(frame["wind_speed"].to_numpy(float)).any())


#: The flags of a record's reading and resampling, by the argument each sets and its unset value:
#: a streamed replay reads a weather frame as saved, at its own step, so none of them is taken.
_READING_FLAGS = (("--map", "map", None), ("--units", "units", None), ("--format", "format", None),
                  ("--step", "step", None), ("--dayfirst/--monthfirst", "dayfirst", None),
                  ("--decomposition", "decomposition", "erbs"), ("--strict", "strict", False),
                  ("--lenient", "lenient", False), ("--fill-nights", "fill_nights", False))


def _refuse_reading_flags(args: argparse.Namespace) -> None:
    """Refuse with ``--stream`` the flags it would not take (``--step 30min`` had run the file at
    its own 10-minute step without a word; ``--dayfirst``, ``--lenient`` and the rest likewise)."""
    given = [flag for flag, name, unset in _READING_FLAGS if getattr(args, name) != unset]
    if given:
        raise HybridtrackError(f"--stream reads a weather frame as saved (a time index, dni, ...), at its own step: "
                               f"{', '.join(given)} {'is' if len(given) == 1 else 'are'} not taken; convert the "
                               "record once with read_weather (resampled to the step you want), or run it without "
                               "--stream")


@command("replay", "run a tracker over a recorded weather file", _replay_arguments)
def _replay(args: argparse.Namespace) -> int:
    if args.stream:
        from ..streaming import recorded_days

        _refuse_reading_flags(args)
        site = site_from_arguments(args)
        source = recorded_days(args.file, site, tz=args.tz)
        source.check_span()  # before the wind's note
        config = replay_config(args, source.wind_measured)
        return _stream(source, args, config,
                       heading=f"replay of {args.file} at {site.name}, {collector_from_arguments(args).kind}, "
                               f"{config.controller.strategy}")
    site, frame = _replay_frame(args)
    config = replay_config(args, _has_wind(frame))
    if (args.strategy or config.controller.strategy) == "hybrid-oracle":
        _refuse_unknown_sky(frame, args.file)
    _claim_run_folder(args)
    result = _run(frame, site, args, args.strategy, config)
    _finish(result, args, heading=f"replay of {args.file} at {site.name}, {result.collector.kind}, "
                                  f"{result.summary['strategy']}")
    return 0


def _compare_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", nargs="?", help="recorded weather file to replay (else synthetic days from --date)")
    add_synthetic_arguments(parser, date_required=False, record=True)
    add_record_arguments(parser)
    parser.add_argument("--step", default="1min", help="control step a record is resampled to (default 1min)")
    add_run_arguments(parser)


def _compare_files(folder, policies) -> list:
    """Every file ``compare --out`` writes: one run folder per strategy and the comparison."""
    from pathlib import Path

    from ..simulation import Result

    files = [path for name in policies for path in Result.files(Path(folder) / name, plot=False).values()]
    return files + [Path(folder) / "comparison.json", Path(folder) / "comparison.png"]


@command("compare", "run every strategy on the same weather and compare them", _compare_arguments)
def _compare(args: argparse.Namespace) -> int:
    from ..control import STRATEGIES

    if args.file is None and args.date is None:
        raise HybridtrackError("give a recorded FILE, or --date for synthetic days")
    if args.strategy is not None:
        raise HybridtrackError("compare runs every strategy: --strategy is not taken (run simulate or replay for one)")
    if args.file is not None:
        site, frame = _replay_frame(args)
        config = replay_config(args, _has_wind(frame))
    else:
        if args.site is not None and args.tz is not None:
            raise HybridtrackError("--tz is a recorded file's time zone; synthetic days at --site keep its clock")
        site = site_from_arguments(args)
        frame = synthetic_frame(args, site)
        config = simulation_config(args, args.seed)
    policies = [s for s in STRATEGIES if s != "hybrid-oracle" or "sky" in frame.columns]
    if args.file is not None and "hybrid-oracle" in policies:  # before the other policies' runs
        _refuse_unknown_sky(frame, args.file)
    if len(policies) < len(STRATEGIES):
        print("hybrid-oracle left out: the frame has no true 'sky' column")
    if args.out:
        claim(_compare_files(args.out, policies))
    left_out = sorted(set(_compare_files(args.out, STRATEGIES)) - set(_compare_files(args.out, policies))) \
        if args.out else []
    with leaving_out(args, left_out, "hybrid-oracle left out"):
        results = {strategy: _run(frame, site, args, strategy, config) for strategy in policies}
        written = _save_comparison(results, args.out) if args.out else None  # first: a failing stdout loses none
    first = next(iter(results.values()))
    print(f"{site.name}, {first.summary['start'][:10]} to {first.summary['end'][:10]}, {first.collector.kind}: "
          "every strategy on the same weather and world")
    print(summary_table({name: r.summary for name, r in results.items()}))
    if written:
        print(f"wrote {written}")
    return 0


def _save_comparison(results: dict, out: str) -> str:
    """Each strategy's folder, ``comparison.json`` and ``comparison.png`` in `out`; what was written."""
    from pathlib import Path

    from ..report import plot_compare, save_figure

    folder = Path(out)
    for name, result in results.items():
        result.save(folder / name, plot=False)
    summaries = strict_json({n: r.summary for n, r in results.items()}, indent=2) + "\n"
    write(folder / "comparison.json", lambda file: file.write_text(summaries))
    return f"{save_figure(plot_compare(results), folder / 'comparison.png')}, {folder / 'comparison.json'} " \
           "and one folder per strategy"
