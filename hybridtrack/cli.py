"""The ``hybridtrack`` command line.

Every command has ``--help``. A mistake a user can make (bad file, column, site, date or
parameter) prints one line, ``hybridtrack: error: ...``, and exits with status 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

import numpy as np
import pandas as pd

from . import __version__, sites
from .errors import HybridtrackError

EXIT_USAGE = 2

_COMMANDS: dict[str, tuple[Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]] = {}
_HELP: dict[str, str] = {}


def command(name: str, help: str, arguments: Callable[[argparse.ArgumentParser], None]):
    """Register the decorated function as sub-command `name`; `arguments` adds its flags."""

    def register(run):
        _COMMANDS[name] = (arguments, run)
        _HELP[name] = help
        return run

    return register


def add_site_arguments(parser: argparse.ArgumentParser, *, default: str | None = None) -> None:
    """``--site NAME`` or ``--lat --lon --tz [--altitude]``."""
    group = parser.add_argument_group("site", f"a built-in site ({', '.join(sites.names())}) or coordinates")
    group.add_argument("--site", default=None, help=f"built-in site name{f' (default {default})' if default else ''}")
    group.add_argument("--lat", type=float, help="latitude, degrees north")
    group.add_argument("--lon", type=float, help="longitude, degrees east")
    group.add_argument("--tz", help="IANA time zone of the local clock, e.g. Asia/Shanghai")
    group.add_argument("--altitude", type=float, default=0.0, help="metres above sea level (with --lat/--lon)")
    parser.set_defaults(_default_site=default)


def site_from_arguments(args: argparse.Namespace) -> sites.Site:
    """The site the user named, or the one given by coordinates."""
    coordinates = (args.lat, args.lon, args.tz)
    if args.site is not None:
        if any(value is not None for value in coordinates):
            raise HybridtrackError("give either --site or --lat/--lon/--tz, not both")
        return sites.get(args.site)
    if all(value is not None for value in coordinates):
        return sites.custom(args.lat, args.lon, args.tz, args.altitude)
    if any(value is not None for value in coordinates):
        raise HybridtrackError("--lat, --lon and --tz go together; one of them is missing")
    if args._default_site:
        return sites.get(args._default_site)
    raise HybridtrackError("no site: give --site NAME or --lat LAT --lon LON --tz TZ")


def add_collector_arguments(parser: argparse.ArgumentParser) -> None:
    """``--collector`` and the geometry flags of each kind."""
    from .collectors import KINDS

    group = parser.add_argument_group("collector")
    group.add_argument("--collector", choices=KINDS, default="trough-ns", help="collector kind (default trough-ns)")
    group.add_argument("--axis-azimuth", type=float, help="trough/Fresnel axis azimuth, degrees from north")
    group.add_argument("--row-distance", type=float, default=5.0,
                       help="Fresnel: signed row distance from the receiver line, m, east positive (default 5)")
    group.add_argument("--receiver-height", type=float, default=10.0, help="Fresnel: receiver height, m (default 10)")
    group.add_argument("--aim", type=float, nargs=3, default=(0.0, 20.0, 100.0), metavar=("E", "N", "U"),
                       help="heliostat: aim point from the mirror centre, m (default 0 20 100)")


def collector_from_arguments(args: argparse.Namespace):
    """The `Collector` the flags describe."""
    from .collectors import Collector

    return Collector(args.collector, args.axis_azimuth, args.row_distance, args.receiver_height, tuple(args.aim))


# --- sun ------------------------------------------------------------------------------------


def _sun_arguments(parser: argparse.ArgumentParser) -> None:
    add_site_arguments(parser, default="nanjing")
    parser.add_argument("--date", required=True, help="local date, YYYY-MM-DD")
    parser.add_argument("--start", default="05:00", help="local start time HH:MM (default 05:00)")
    parser.add_argument("--end", default="20:00", help="local end time HH:MM (default 20:00)")
    parser.add_argument("--freq", default="10min", help="step, e.g. 1min, 10s (default 10min)")
    parser.add_argument("--model", choices=("spa", "plc"), default="spa", help="sun model (default spa)")
    parser.add_argument("--declination", choices=("wang-liu", "cooper"), default="wang-liu",
                        help="PLC model: declination series (default wang-liu)")
    parser.add_argument("--eot", choices=("wang-liu", "lamm"), default="wang-liu",
                        help="PLC model: equation of time (default wang-liu)")
    add_collector_arguments(parser)
    parser.add_argument("--csv", metavar="OUT", help="write the table as CSV instead of printing it")
    parser.add_argument("--plot", metavar="PNG", help="also draw the sun path and targets")


@command("sun", "sun position and collector target angles over a day", _sun_arguments)
def _sun(args: argparse.Namespace) -> int:
    from .collectors import Collector
    from .sun import solar_position
    from .times import local_range

    site = site_from_arguments(args)
    collector: Collector = collector_from_arguments(args)
    times = local_range(args.date, site.tz, start=args.start, end=args.end, freq=args.freq)
    position = solar_position(times, site, args.model, declination=args.declination, equation_of_time=args.eot)
    angles = collector.angles(position["altitude"], position["azimuth"])
    table = pd.concat([position[["altitude", "apparent_altitude", "azimuth", "declination",
                                 "hour_angle", "equation_of_time"]], angles], axis=1)
    if args.csv:
        table.to_csv(args.csv, float_format="%.6f", index_label="time")
        print(f"wrote {len(table)} rows to {args.csv}")
    else:
        shown = table.copy()
        shown.index = shown.index.strftime("%Y-%m-%d %H:%M:%S")
        print(shown.round(3).to_string(na_rep="-"))
    up = position["altitude"] > 0
    print(f"\n{site.name} ({site.latitude:.4f}°, {site.longitude:.4f}°) {args.date}, "
          f"model {args.model}, collector {collector.kind}")
    if up.any():
        peak = position["altitude"].idxmax()
        print(f"  sun up in range {up.index[up.to_numpy()][0]:%H:%M}-{up.index[up.to_numpy()][-1]:%H:%M}; "
              f"highest {position['altitude'].max():.3f}° at {peak:%H:%M:%S}")
        if "rate" in angles:
            print(f"  fastest target rate {np.nanmax(np.abs(angles['rate'])):.3f} °/min")
    else:
        print("  the sun stays below the horizon in this range")
    if args.plot:
        from .report import plot_sun_path, save_figure

        title = f"{site.name} {args.date}: {collector.kind} ({args.model})"
        print(f"  plot: {save_figure(plot_sun_path(position, angles, title=title), args.plot)}")
    return 0


# --- fuzzy classifier ---------------------------------------------------------------------


def _load_config(path):
    from .fuzzy import FuzzyConfig

    if path is None:
        return FuzzyConfig.default()
    if str(path).lower().endswith(".fis"):
        return FuzzyConfig.from_fis(path)
    return FuzzyConfig.from_toml(path)


def _classify_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", nargs="?", help="CSV of readings to classify (instead of --intensity/--variation)")
    parser.add_argument("--intensity", type=float, help="sensor photocurrent, mA")
    parser.add_argument("--variation", type=float, help="its variation over the window, mA")
    parser.add_argument("--config", help="classifier config (.toml or MATLAB .fis); the published one by default")
    parser.add_argument("--json", action="store_true", help="print JSON: score, weather and each rule's firing")
    parser.add_argument("--intensity-col", default="intensity", help="file: column of the photocurrent (mA)")
    parser.add_argument("--variation-col", default="variation", help="file: column of the variation (mA)")
    parser.add_argument("--out", help="file: write the readings with sky_score and sky columns here")
    parser.add_argument("--engine", choices=("fast", "skfuzzy"), default="fast", help="inference engine")


@command("classify", "classify sky readings with the fuzzy classifier", _classify_arguments)
def _classify(args: argparse.Namespace) -> int:
    import json

    from .fuzzy import FuzzyWeatherClassifier

    clf = FuzzyWeatherClassifier(_load_config(args.config))
    if args.file is None:
        if args.intensity is None or args.variation is None:
            raise HybridtrackError("give --intensity and --variation, or a CSV file of readings")
        explanation = clf.explain(args.intensity, args.variation)
        print(json.dumps(explanation.to_dict(), indent=2) if args.json else explanation)
        return 0
    from .io import numeric_columns, read_table

    table = read_table(args.file)
    wanted = [args.intensity_col.lower(), args.variation_col.lower()]
    for column in wanted:
        if column not in table.columns:
            raise HybridtrackError(f"{args.file}: no column {column!r}; columns are {', '.join(table.columns)}")
    readings = numeric_columns(table[wanted], wanted, str(args.file))
    table["sky_score"] = clf.score(readings[wanted[0]].to_numpy(), readings[wanted[1]].to_numpy(), engine=args.engine)
    table["sky"] = clf.label(table["sky_score"].to_numpy())
    if args.out:
        table.to_csv(args.out, index=False, float_format="%.6g")
        print(f"wrote {len(table)} rows to {args.out}")
    counts = table["sky"].value_counts()
    print(", ".join(f"{label} {counts.get(label, 0)}" for label in [b[0] for b in clf.config.bands] + ["unknown"]))
    return 0


def _tune_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("labels", help="CSV (or TOML [[case]]) of intensity, variation and weather and/or score")
    parser.add_argument("--config", help="starting config (.toml or .fis); the published one by default")
    parser.add_argument("--out", required=True, help="where to write the tuned config (.toml or .fis)")
    parser.add_argument("--method", choices=("global", "local"), default="global",
                        help="global: population search then Powell (default); local: Powell only")
    parser.add_argument("--margin", type=float, default=0.5, help="how far inside its band a label's score should sit")
    parser.add_argument("--seed", type=int, default=0, help="seed for reproducible fits (default 0)")
    parser.add_argument("--report", help="also write the before/after report as JSON here")


@command("tune", "fit the classifier's membership functions to labelled readings", _tune_arguments)
def _tune(args: argparse.Namespace) -> int:
    import json

    from .fuzzy.tuning import tune

    tuned, report = tune(_load_config(args.config), args.labels, method=args.method, margin=args.margin,
                         seed=args.seed)
    out = tuned.to_fis(args.out) if args.out.lower().endswith(".fis") else tuned.to_toml(args.out)
    print(report)
    for name, change in report.changed.items():
        print(f"  {name}: {change['before']} -> {change['after']}")
    print(f"wrote {out}")
    if args.report:
        with open(args.report, "w") as handle:
            json.dump(report.to_dict(), handle, indent=2)
    return 0


def _surface_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", help="classifier config (.toml or .fis); the published one by default")
    parser.add_argument("--out", default="surface.png", help="image to write (default surface.png)")
    parser.add_argument("--points", type=int, default=121, help="grid points along each input (default 121)")


@command("surface", "draw the classifier's decision surface and membership functions", _surface_arguments)
def _surface(args: argparse.Namespace) -> int:
    from .fuzzy import FuzzyWeatherClassifier
    from .report import plot_fuzzy_surface, save_figure

    if not 5 <= args.points <= 1001:
        raise HybridtrackError(f"--points must be between 5 and 1001, got {args.points}")
    clf = FuzzyWeatherClassifier(_load_config(args.config))
    print(f"wrote {save_figure(plot_fuzzy_surface(clf, points=args.points), args.out)}")
    return 0


# --- skies and records ----------------------------------------------------------------------


def _parse_mapping(pairs, flag: str) -> dict[str, str]:
    mapping = {}
    for pair in pairs or []:
        name, sep, value = pair.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise HybridtrackError(f"{flag} takes NAME=VALUE, got {pair!r}")
        mapping[name.strip()] = value.strip()
    return mapping


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    """``--map``, ``--units``, ``--format``, ``--freq`` and ``--decomposition`` for recorded files."""
    group = parser.add_argument_group("recorded file")
    group.add_argument("--map", action="append", metavar="NAME=COLUMN",
                       help="which file column holds ghi, dni, dhi, wind_speed, temp_air, photocurrent or time "
                            "(repeatable), e.g. --map dni='Direct Normal'")
    group.add_argument("--units", action="append", metavar="NAME=UNIT", help="unit of a column, e.g. --units ghi=kW/m2")
    group.add_argument("--format", default="csv", help="csv (default), epw, tmy3, midc, srml, bsrn, surfrad, crn, solrad")
    group.add_argument("--decomposition", choices=("erbs", "dirint"), default="erbs",
                       help="how DNI and DHI are split from GHI alone (default erbs)")
    group.add_argument("--strict", action="store_true",
                       help="refuse the file at the first thing the checks would repair (default: repair and report)")


def read_record(args: argparse.Namespace, path: str, *, site=None, freq: str | None = None):
    """`read_weather` with the flags of `add_record_arguments`."""
    from .io import read_weather

    return read_weather(path, columns=_parse_mapping(args.map, "--map"), tz=args.tz, format=args.format, site=site,
                        units=_parse_mapping(args.units, "--units"), freq=freq, decomposition=args.decomposition,
                        strict=args.strict)


def _check_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="recorded weather file")
    add_record_arguments(parser)
    parser.add_argument("--tz", help="time zone of naive stamps, e.g. Asia/Shanghai")
    parser.add_argument("--site", help="site, to derive missing irradiance components")
    parser.add_argument("--freq", help="resample to this step, e.g. 1min")


@command("check", "read a recorded weather file and print its validation summary", _check_arguments)
def _check(args: argparse.Namespace) -> int:
    from .io import validation_report

    frame = read_record(args, args.file, site=args.site, freq=args.freq)
    print(validation_report(frame))
    return 0


def _sky_arguments(parser: argparse.ArgumentParser) -> None:
    _synthetic_arguments(parser)
    parser.add_argument("--out", help="write the weather frame (with sensor readings) as CSV")
    parser.add_argument("--plot", metavar="PNG", help="draw irradiance, sensor readings and wind")


@command("sky", "make a synthetic weather frame and show its sensor's view", _sky_arguments)
def _sky(args: argparse.Namespace) -> int:
    from .sensor import sensor_view

    site = site_from_arguments(args)
    frame = sensor_view(_synthetic_frame(args, site), seed=args.seed)
    print(_sky_table(frame, site).to_string(float_format=lambda v: f"{v:.2f}"))
    if args.out:
        frame.to_csv(args.out, float_format="%.3f", index_label="time")
        print(f"wrote {len(frame)} rows to {args.out}")
    if args.plot:
        from .report import plot_sky, save_figure

        print(f"plot: {save_figure(plot_sky(frame, site), args.plot)}")
    return 0


def _sky_table(frame: pd.DataFrame, site) -> pd.DataFrame:
    """Per day: weather, DNI, clearness index, sunshine, and the classifier's share of each label."""
    from .fuzzy import FuzzyWeatherClassifier
    from .sky import daily_summary
    from .sun import solar_position

    table = daily_summary(frame, site)
    table.insert(0, "weather", [frame.attrs.get("weather", {}).get(str(day), "?") for day in table.index])
    up = solar_position(frame.index, site)["altitude"].to_numpy() > 10.0
    labels = pd.Series(FuzzyWeatherClassifier().classify(frame["intensity_ma"].to_numpy()[up],
                                                         frame["variation_ma"].to_numpy()[up]),
                       index=frame.index[up].tz_convert(site.tz).date)
    shares = labels.groupby(level=0).value_counts(normalize=True).unstack(fill_value=0.0)
    for label in ("sunny", "cloudy", "overcast"):
        table[f"fuzzy_{label}"] = shares.get(label, pd.Series(0.0, index=table.index)).reindex(table.index).fillna(0.0)
    return table


# --- running the controller -----------------------------------------------------------------


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """Collector, strategy, config and output flags shared by simulate, replay and compare."""
    from .control import STRATEGIES

    add_collector_arguments(parser)
    group = parser.add_argument_group("run")
    group.add_argument("--strategy", choices=STRATEGIES, default="hybrid", help="tracking strategy (default hybrid)")
    group.add_argument("--config", help="simulation config (TOML: controller, imperfections, sensor, drive, seed)")
    group.add_argument("--perfect", action="store_true", help="no imperfections: a perfectly built and set-up field")
    group.add_argument("--out", help="folder for log, events.csv, summary.json and report.png")


def _simulation_config(args: argparse.Namespace, seed: int | None = None):
    import dataclasses

    from .simulation import SimulationConfig
    from .world import Imperfections

    config = SimulationConfig.from_toml(args.config) if args.config else SimulationConfig()
    if args.perfect:
        config = dataclasses.replace(config, imperfections=Imperfections.none())
    if seed is not None:
        config = dataclasses.replace(config, seed=seed)
    return config


def _synthetic_arguments(parser: argparse.ArgumentParser, *, date_required: bool = True) -> None:
    """Site, dates, weather, step, seed and gusts of synthetic days."""
    add_site_arguments(parser)
    parser.add_argument("--date", required=date_required, help="first local date, YYYY-MM-DD")
    parser.add_argument("--days", type=int, default=1, help="number of days (default 1)")
    parser.add_argument("--weather", default="mixed",
                        help="sunny, cloudy, overcast, mixed (default), climate, or one per day: sunny,cloudy,...")
    parser.add_argument("--freq", default="1min", help="step (default 1min)")
    parser.add_argument("--seed", type=int, default=0, help="random seed of sky and sensor (default 0)")
    parser.add_argument("--gusts-per-day", type=float, default=0.0, help="mean gust events a day (default 0)")


def _synthetic_frame(args: argparse.Namespace, site):
    import datetime as dt

    from .sky import synthetic
    from .times import parse_date

    if not 1 <= args.days <= 3660:
        raise HybridtrackError(f"--days must be between 1 and 3660, got {args.days}")
    first = parse_date(args.date)
    weather = args.weather.split(",") if "," in args.weather else args.weather
    return synthetic(site, first, first + dt.timedelta(days=args.days - 1), weather=weather, freq=args.freq,
                     seed=args.seed, gusts_per_day=args.gusts_per_day)


def _run(frame, site, args, strategy: str, config, *, label: str = ""):
    from tqdm import tqdm

    from .simulation import simulate

    days = (frame.index[-1] - frame.index[0]) / pd.Timedelta(days=1)
    with tqdm(total=len(frame), unit="step", desc=label or strategy, disable=days < 2, leave=False,
              file=sys.stderr) as bar:
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
    rows += [(f"mode {m}", lambda s, m=m: _fmt(s["mode_share"][m], ".1%"))
             for m in ("sensor", "astronomical", "search", "stow_wind", "stow_night")]
    rows += [(f"sky {k} (sun up)", lambda s, k=k: _fmt(s["sky_share"][k], ".1%")) for k in ("sunny", "cloudy", "overcast")]
    table = pd.DataFrame({name: [pick(summary) for _, pick in rows] for name, summary in summaries.items()},
                         index=[label for label, _ in rows])
    return table.to_string()


def _fmt(value, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def _finish(result, args, *, heading: str) -> None:
    print(heading)
    print(summary_table({result.summary["strategy"]: result.summary}))
    if args.out:
        written = result.save(args.out)
        print("wrote " + ", ".join(str(p) for p in written.values()))


def _demo_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", default="hybridtrack-demo", help="folder for the results (default hybridtrack-demo)")


@command("demo", "a built-in mixed-sky day at Lanzhou: run the hybrid tracker, print the summary, "
                 "write the report", _demo_arguments)
def _demo(args: argparse.Namespace) -> int:
    from .collectors import Collector
    from .simulation import simulate
    from .sky import synthetic

    site = sites.get("lanzhou")
    frame = synthetic(site, "2021-06-21", weather="mixed", seed=5, gusts_per_day=2.0)
    result = simulate(frame, site, collector=Collector("fresnel"), strategy="hybrid")
    print("demo: Lanzhou linear Fresnel row, 2021-06-21, mixed sky with gusts (seed 5), hybrid strategy, default "
          "imperfections")
    print(summary_table({"hybrid": result.summary}))
    written = result.save(args.out)
    print(f"wrote {written['report']} (the day at a glance), {written['summary']}, {written['log']}, "
          f"{written['events']}")
    return 0


def _simulate_arguments(parser: argparse.ArgumentParser) -> None:
    _synthetic_arguments(parser)
    add_run_arguments(parser)


@command("simulate", "run a tracker over synthetic days", _simulate_arguments)
def _simulate(args: argparse.Namespace) -> int:
    site = site_from_arguments(args)
    frame = _synthetic_frame(args, site)
    result = _run(frame, site, args, args.strategy, _simulation_config(args, args.seed))
    _finish(result, args, heading=f"{site.name}, {args.date} ({args.days} day{'s' if args.days > 1 else ''}, "
                                  f"{args.weather}), {result.collector.kind}, {args.strategy}")
    return 0


def _replay_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="recorded weather file (CSV or a pvlib format)")
    add_site_arguments(parser)
    add_record_arguments(parser)
    parser.add_argument("--step", default="1min", help="control step the record is resampled to (default 1min)")
    add_run_arguments(parser)


def _replay_frame(args: argparse.Namespace):
    site = site_from_arguments(args)
    frame = read_record(args, args.file, site=site, freq=args.step)
    from .io import validation_report

    print(validation_report(frame))
    return site, frame


@command("replay", "run a tracker over a recorded weather file", _replay_arguments)
def _replay(args: argparse.Namespace) -> int:
    site, frame = _replay_frame(args)
    result = _run(frame, site, args, args.strategy, _simulation_config(args))
    _finish(result, args, heading=f"replay of {args.file} at {site.name}, {result.collector.kind}, {args.strategy}")
    return 0


def _compare_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", nargs="?", help="recorded weather file to replay (else synthetic days from --date)")
    _synthetic_arguments(parser, date_required=False)
    add_record_arguments(parser)
    parser.add_argument("--step", default="1min", help="control step a record is resampled to (default 1min)")
    add_run_arguments(parser)


@command("compare", "run every strategy on the same weather and compare them", _compare_arguments)
def _compare(args: argparse.Namespace) -> int:
    from .control import STRATEGIES

    if args.file is None and args.date is None:
        raise HybridtrackError("give a recorded FILE, or --date for synthetic days")
    if args.file is not None:
        site, frame = _replay_frame(args)
        config = _simulation_config(args)
    else:
        site = site_from_arguments(args)
        frame = _synthetic_frame(args, site)
        config = _simulation_config(args, args.seed)
    results = {strategy: _run(frame, site, args, strategy, config) for strategy in STRATEGIES}
    first = next(iter(results.values()))
    print(f"{site.name}, {first.summary['start'][:10]} to {first.summary['end'][:10]}, {first.collector.kind}: "
          "every strategy on the same weather and world")
    print(summary_table({name: r.summary for name, r in results.items()}))
    if args.out:
        import json
        from pathlib import Path

        from .report import plot_compare, save_figure

        folder = Path(args.out)
        for name, result in results.items():
            result.save(folder / name, plot=False)
        (folder / "comparison.json").write_text(json.dumps({n: r.summary for n, r in results.items()}, indent=2) + "\n")
        print(f"wrote {save_figure(plot_compare(results), folder / 'comparison.png')}, {folder / 'comparison.json'} "
              f"and one folder per strategy")
    return 0


# --- entry point ----------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The parser with every registered command."""
    parser = argparse.ArgumentParser(
        prog="hybridtrack",
        description="Weather-aware hybrid sun tracking for concentrating solar collectors.",
    )
    parser.add_argument("--version", action="version", version=f"hybridtrack {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, (add_arguments, run) in _COMMANDS.items():
        child = sub.add_parser(name, help=_HELP[name], description=_HELP[name])
        add_arguments(child)
        child.set_defaults(_run=run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args._run(args)
    except BrokenPipeError:  # the reader went away (`| head`): not a mistake, just stop
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except HybridtrackError as exc:
        print(f"hybridtrack: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as exc:
        name = f" {exc.filename}" if exc.filename else ""
        print(f"hybridtrack: error: cannot use{name}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
