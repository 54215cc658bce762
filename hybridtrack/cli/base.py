"""What every command shares: the command registry, and the flags for sites, collectors,
recorded files, synthetic days and runs."""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Callable, Iterable, Iterator

from .. import params, sites
from ..errors import HybridtrackError

EXIT_USAGE = 2
#: The shell's status for a command ended by SIGTERM (128 + 15).
EXIT_TERMINATED = 143


def _written_plainly(text: str, kind: str) -> str:
    """`text` unless it groups digits with underscores, or writes them in another script, both of
    which Python's ``int`` and ``float`` read as one number (``1_0`` and the full-width ``１０`` are
    10): on a command line either is a slip, not a number to guess at, and no file format the
    project reads takes them."""
    if "_" in text:
        raise argparse.ArgumentTypeError(f"{text!r} is not {kind} (no underscores: write 10, not 1_0)")
    if not text.isascii():
        raise argparse.ArgumentTypeError(f"{text!r} is not {kind} (write it in ASCII digits: 0-9)")
    return text


def whole_number(text: str) -> int:
    """A flag's whole number, as argparse's ``type``: ``int`` without its underscores."""
    try:
        return int(_written_plainly(text, "a whole number"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None


def real_number(text: str) -> float:
    """A flag's number, as argparse's ``type``: ``float`` without its underscores (NaN and
    infinities pass, to be refused by the parameter's own check, which names its range)."""
    try:
        return float(_written_plainly(text, "a number"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


_COMMANDS: dict[str, tuple[Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], int]]] = {}
_HELP: dict[str, str] = {}


def command(name: str, help: str, arguments: Callable[[argparse.ArgumentParser], None]):
    """Register the decorated function as sub-command `name`; `arguments` adds its flags."""

    def register(run):
        _COMMANDS[name] = (arguments, run)
        _HELP[name] = help
        return run

    return register


def add_site_arguments(parser: argparse.ArgumentParser, *, default: str | None = None, record: bool = False) -> None:
    """``--site NAME`` or ``--lat --lon --tz [--altitude]``.

    With `record` (commands that read a file) ``--tz`` is the file's time zone, which may differ
    from the site's: ``--site lanzhou --tz UTC`` reads a UTC logger at Lanzhou. With
    ``--lat/--lon`` the site's clock is ``--site-tz``, or else the same ``--tz``.
    """
    group = parser.add_argument_group("site", f"a built-in site ({', '.join(sites.names())}) or coordinates")
    group.add_argument("--site", default=None, help=f"built-in site name{f' (default {default})' if default else ''}")
    group.add_argument("--lat", type=real_number, help="latitude, degrees north")
    group.add_argument("--lon", type=real_number, help="longitude, degrees east")
    if record:
        group.add_argument("--tz", help="IANA time zone of the file's naive stamps (or to convert stamps with "
                                        "offsets to), e.g. UTC; with --lat/--lon also the site's clock")
        group.add_argument("--site-tz", help="with --lat/--lon: the site's clock when it differs from the file's --tz")
    else:
        group.add_argument("--tz", help="IANA time zone of the local clock, e.g. Asia/Shanghai")
    group.add_argument("--altitude", type=real_number, help="metres above sea level (with --lat/--lon; default 0)")
    parser.set_defaults(_default_site=default, _record_site=record)


def site_from_arguments(args: argparse.Namespace, *, clock_required: bool = True) -> sites.Site | None:
    """The site the user named, or the one given by coordinates.

    For commands that read a file (`add_site_arguments` with ``record=True``) ``--tz`` is the
    file's zone and goes with ``--site`` too; a site by coordinates takes ``--site-tz`` or
    ``--tz`` as its clock. With `clock_required` false (``check``, which only needs the sun)
    coordinates without a zone get UTC, and no site at all gives None.
    """
    record = getattr(args, "_record_site", False)
    site_tz = getattr(args, "site_tz", None) if record else None
    if args.site is not None:
        given = (args.lat, args.lon, args.altitude, site_tz if record else args.tz)
        if any(value is not None for value in given):
            flags = "--lat/--lon/--altitude" + ("/--site-tz" if record else "/--tz")
            raise HybridtrackError(f"give either --site or {flags}, not both")
        with flag_named("--site"):  # 'unknown site 'atlantis'' had named no flag
            return sites.get(args.site)
    clock = (site_tz or args.tz) if record else args.tz
    if args.lat is not None and args.lon is not None:
        if clock is None and (clock_required or not record):
            raise HybridtrackError("--lat and --lon need the site's clock: --tz ZONE" + (" (or --site-tz)" if record
                                                                                          else ""))
        altitude = 0.0 if args.altitude is None else args.altitude
        # refused by its flag: 'site 'custom': latitude 95.0 is outside ...' had named a site nobody named
        sites.check_place(args.lat, args.lon, altitude, clock or "UTC", {
            "latitude": "--lat", "longitude": "--lon", "altitude": "--altitude",
            "tz": f"{'--site-tz' if site_tz else '--tz'}: "})
        return sites.custom(args.lat, args.lon, clock or "UTC", altitude)
    if args.lat is not None or args.lon is not None or (args.tz is not None and not record):
        together = "--lat, --lon" + ("" if record else " and --tz")
        raise HybridtrackError(f"{together} go together; one of them is missing")
    if site_tz is not None or args.altitude is not None:
        raise HybridtrackError(f"{'--site-tz' if site_tz is not None else '--altitude'} goes with --lat/--lon")
    if args._default_site:
        return sites.get(args._default_site)
    if not clock_required:
        return None
    raise HybridtrackError("no site: give --site NAME or --lat LAT --lon LON --tz TZ")


def add_collector_arguments(parser: argparse.ArgumentParser) -> None:
    """``--collector`` and the geometry flags of each kind."""
    from ..collectors import KINDS

    group = parser.add_argument_group("collector")
    group.add_argument("--collector", choices=KINDS, default="trough-ns", help="collector kind (default trough-ns)")
    group.add_argument("--axis-azimuth", type=real_number, help="trough/Fresnel axis azimuth, degrees from north")
    group.add_argument("--row-distance", type=real_number, default=5.0,
                       help="Fresnel: signed row distance from the receiver line, m, east positive (default 5)")
    group.add_argument("--receiver-height", type=real_number, default=10.0,
                       help="Fresnel: receiver height, m (default 10)")
    group.add_argument("--aim", type=real_number, nargs=3, default=(0.0, 20.0, 100.0), metavar=("E", "N", "U"),
                       help="heliostat: aim point from the mirror centre, m (default 0 20 100)")


def collector_from_arguments(args: argparse.Namespace):
    """The `Collector` the flags describe."""
    from ..collectors import Collector

    return Collector(args.collector, args.axis_azimuth, args.row_distance, args.receiver_height, tuple(args.aim))


def parse_mapping(pairs, flag: str) -> dict[str, str]:
    """``["dni=Direct Normal", "time="]`` -> a dict; ``time=`` (empty) names an unnamed column."""
    mapping: dict[str, str] = {}
    for pair in pairs or []:
        name, sep, value = pair.partition("=")
        name = name.strip()
        if not sep or not name or (not value.strip() and not (flag == "--map" and name == "time")):
            raise HybridtrackError(f"{flag} takes NAME=VALUE, got {pair!r}")
        if name in mapping:
            raise HybridtrackError(f"{flag} names {name} twice ({mapping[name]!r} and {value.strip()!r})")
        mapping[name] = value.strip()
    return mapping


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    """``--map``, ``--units``, ``--format``, date order, ``--decomposition``, ``--strict`` and ``--lenient``."""
    group = parser.add_argument_group("recorded file")
    group.add_argument("--map", action="append", metavar="NAME=COLUMN",
                       help="which file column holds ghi, dni, dhi, wind_speed, temp_air, photocurrent or time "
                            "(repeatable), e.g. --map dni='Direct Normal'; --map time= names an unnamed first column")
    group.add_argument("--units", action="append", metavar="NAME=UNIT", help="unit of a column, e.g. --units ghi=kW/m2")
    group.add_argument("--format", default=None,
                       help="csv, epw, tmy3, tmy2, midc, srml, bsrn, surfrad, crn, solrad (default: from the content)")
    order = group.add_mutually_exclusive_group()
    order.add_argument("--dayfirst", dest="dayfirst", action="store_const", const=True, default=None,
                       help="dates like 05/06/2021 are day first (5 June)")
    order.add_argument("--monthfirst", dest="dayfirst", action="store_const", const=False,
                       help="dates like 05/06/2021 are month first (6 May)")
    group.add_argument("--decomposition", choices=("erbs", "dirint"), default="erbs",
                       help="how DNI and DHI are split from GHI alone (default erbs)")
    group.add_argument("--strict", action="store_true",
                       help="refuse the file at the first thing the checks would repair (default: repair and report)")
    group.add_argument("--lenient", action="store_true",
                       help="warn instead of refusing when the light does not follow the site's sun")
    group.add_argument("--fill-nights", action="store_true",
                       help="put back the nights a logger left out (irradiance 0 with the sun down, wind carried "
                            "across), so that each morning is pre-positioned as a PLC scanning all night would")


def read_record(args: argparse.Namespace, path: str, *, site=None, freq: str | None = None):
    """`read_weather` with the flags of `add_record_arguments` (``--tz`` is the file's zone); with
    ``--fill-nights`` the nights the file leaves out put back (`hybridtrack.io.fill_nights`),
    without it those nights named in the report."""
    from ..io import fill_nights, read_weather
    from ..io.nights import night_gaps

    frame = read_weather(path, columns=parse_mapping(args.map, "--map"), tz=args.tz, format=args.format, site=site,
                         units=parse_mapping(args.units, "--units"), freq=freq, decomposition=args.decomposition,
                         strict=args.strict, dayfirst=args.dayfirst, lenient=args.lenient)
    if args.fill_nights:
        if site is None:
            raise HybridtrackError("--fill-nights needs the site whose sun says when it is night: give --site")
        return fill_nights(frame, site)
    left_out = night_gaps(frame, site) if site is not None and len(frame) > 1 else 0
    if left_out:
        frame.attrs["validation"]["nights_left_out"] = (
            f"{left_out} (no rows from a night into its morning: each such morning's slew from stow is "
            "scored, as no PLC scanning all night would show; --fill-nights puts them back)")
    return frame


def add_force_argument(parser: argparse.ArgumentParser) -> None:
    """``--force``: replace existing output files (and say which); without it they are refused."""
    parser.add_argument("--force", action="store_true",
                        help="replace output files that exist already (default: refuse, naming them)")


@contextlib.contextmanager
def leaving_out(args: argparse.Namespace, paths: Iterable, reason: str) -> Iterator[None]:
    """Within the block a command writes its results without `paths`, files it writes on other
    runs (`reason`: why not on this one, such as ``--no-log``).

    Such a file there already is an earlier run's, and would be read as this run's. Without
    ``--force`` it is refused before the block, as a file to replace is; with it, it is removed
    once the block has written the results (a failed run leaves the earlier run whole), each said
    in one line on standard output, as ``replaced (--force)`` is; so is a folder below ``--out``
    (a left-out run's) that this emptied, then removed. Only regular files are taken: a folder or
    a symbolic link of such a name is none a run wrote, and is left as it is.

    Raises
    ------
    HybridtrackError
        Without ``--force``, if any of `paths` is there; with it, if one cannot be removed.
    """
    import os
    from pathlib import Path

    from ..outputs import earlier_files, remove_earlier

    stale = earlier_files(paths)
    if stale and not args.force:
        some = len(stale) > 1
        raise HybridtrackError(f"would leave {len(stale)} file{'s' if some else ''} of an earlier run beside this "
                               f"run's results: {', '.join(map(str, stale))} (not written: {reason}); give --force "
                               f"to remove {'them' if some else 'it'}, or write elsewhere")
    for path in stale:  # before the run, not after it
        if not os.access(path.parent, os.W_OK | os.X_OK):
            raise HybridtrackError(f"{path}: from an earlier run, and cannot be removed (no permission in "
                                   f"{path.parent}); remove it, or write elsewhere")
    yield
    remove_earlier(stale)  # a save may have removed them already, as the one it writes beside them
    for path in stale:
        print(f"{path}: removed, from an earlier run ({reason})")
    for folder in sorted({path.parent for path in stale} - {Path(args.out or ".")}):  # no --out: no stale files
        with contextlib.suppress(OSError):  # a folder with anything else in it stays
            folder.rmdir()
            print(f"{folder}: removed, emptied of an earlier run's files ({reason})")


#: ``--strategy``'s help: without it the ``--config`` file's strategy runs, not a default over it.
STRATEGY_HELP = "tracking strategy (default: the --config file's controller.strategy, else hybrid)"


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """Collector, strategy, config and output flags shared by simulate, replay and compare."""
    from ..control import STRATEGIES

    add_collector_arguments(parser)
    group = parser.add_argument_group("run")
    group.add_argument("--strategy", choices=STRATEGIES, help=STRATEGY_HELP)
    group.add_argument("--config", help="simulation config (TOML: controller, imperfections, sensor, drive, seed)")
    group.add_argument("--perfect", action="store_true", help="no imperfections: a perfectly built and set-up field")
    group.add_argument("--out", help="folder for log, events.csv, summary.json and report.png")
    add_force_argument(group)


def simulation_config(args: argparse.Namespace, seed: int | None = None):
    """The run's config: the ``--config`` file's (or the defaults), with ``--strategy``,
    ``--perfect`` and `seed` over it where given."""
    import dataclasses

    from ..simulation import SimulationConfig
    from ..world import Imperfections

    config = SimulationConfig.from_toml(args.config) if args.config else SimulationConfig()
    if getattr(args, "strategy", None) is not None:  # the flag over the file; the file's where not given
        config = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy=args.strategy))
    if args.perfect:
        config = dataclasses.replace(config, imperfections=Imperfections.none())
    if seed is not None:
        config = dataclasses.replace(config, seed=seed)
    return config


def add_synthetic_arguments(parser: argparse.ArgumentParser, *, date_required: bool = True,
                            record: bool = False) -> None:
    """Site, dates, weather, step, seed and gusts of synthetic days (`record`: a file may be read too)."""
    add_site_arguments(parser, record=record)
    parser.add_argument("--date", required=date_required, help="first local date, YYYY-MM-DD")
    parser.add_argument("--days", type=whole_number, default=1, help="number of days (default 1)")
    parser.add_argument("--weather", default="mixed",
                        help="sunny, cloudy, overcast, mixed (default), climate, or one per day: sunny,cloudy,...")
    parser.add_argument("--freq", default="1min", help="step (default 1min)")
    parser.add_argument("--seed", type=whole_number,
                        help="random seed of sky and sensor (default: the --config file's seed where the command "
                             "takes one, else 0)")
    parser.add_argument("--gusts-per-day", type=real_number, default=0.0, help="mean gust events a day (default 0)")


def synthetic_span(args: argparse.Namespace):
    """The first and last day of the synthetic run the arguments ask for, with its ``--days``,
    ``--seed``, ``--gusts-per-day``, ``--date``, ``--freq`` and ``--weather`` checked."""
    import datetime as dt

    from ..sky import check_weather
    from ..simulation import run_step
    from ..times import parse_date

    if not 1 <= args.days <= 3660:
        raise HybridtrackError(f"--days must be between 1 and 3660, got {args.days}")
    if args.seed is None:  # a config file's seed is the run's, unless --seed says otherwise
        args.seed = _config_seed(args)
    params.seed(args.seed, "--seed")
    params.number(args.gusts_per_day, "--gusts-per-day", 0, 200)
    with flag_named("--date"):
        first = parse_date(args.date)
    with flag_named("--freq"):
        run_step(args.freq)
    with flag_named("--weather"):
        weather = check_weather(args.weather.split(",") if "," in args.weather else args.weather, args.days)
    args.weather = weather if isinstance(weather, str) else ",".join(weather)  # as read: headings name it so
    return first, first + dt.timedelta(days=args.days - 1)


@contextlib.contextmanager
def flag_named(flag: str) -> Iterator[None]:
    """Within the block, a refusal (`HybridtrackError`) names `flag`, whose value it refused:
    ``--freq: step 'soon' is not a duration ...`` (the API's message after the flag)."""
    try:
        yield
    except HybridtrackError as exc:
        raise HybridtrackError(f"{flag}: {exc}") from None


def _config_seed(args: argparse.Namespace) -> int:
    """The seed of the ``--config`` file, if the command has one and it was given; else 0."""
    from ..simulation import SimulationConfig

    path = getattr(args, "config", None)
    return SimulationConfig.from_toml(path).seed if path else 0


def synthetic_frame(args: argparse.Namespace, site):
    from ..sky import synthetic

    first, last = synthetic_span(args)
    weather = args.weather.split(",") if "," in args.weather else args.weather
    return synthetic(site, first, last, weather=weather, freq=args.freq, seed=args.seed,
                     gusts_per_day=args.gusts_per_day)


def add_dask_arguments(parser, *, default: str) -> None:
    """``--scheduler`` and ``--workers``: where a command's independent runs go (`hybridtrack.cluster`)."""
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help=f"a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: {default})")
    parser.add_argument("--workers", type=whole_number,
                        help="worker processes of a local Dask cluster (default: one per core when a cluster is used)")
