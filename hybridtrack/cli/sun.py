"""``hybridtrack sun``: where the sun is and where a collector must point over a day."""

from __future__ import annotations

import argparse

import numpy as np
import pandas as pd

from ..outputs import claim, write
from .base import (
    add_collector_arguments,
    add_force_argument,
    add_site_arguments,
    collector_from_arguments,
    command,
    flag_named,
    site_from_arguments,
)


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
    parser.add_argument("--geometric", action="store_true",
                        help="targets on the geometric sun (default: on the sun as it appears, refraction included, "
                             "where the light comes from and the simulated controller aims)")
    parser.add_argument("--csv", metavar="OUT", help="write the table as CSV instead of printing it")
    parser.add_argument("--plot", metavar="PNG", help="also draw the sun path and targets")
    add_force_argument(parser)


def _fastest_rate(rate: pd.Series) -> str:
    """The summary's rate line: the fastest target rate, or why there is none (a rate needs two
    steps in a row with the sun up; nan and numpy's All-NaN warning had been printed)."""
    rates = np.abs(rate.to_numpy(float))
    if not np.isfinite(rates).any():
        return "fastest target rate: needs two steps with the sun up"
    return f"fastest target rate {np.nanmax(rates):.3f} °/min"


@command("sun", "sun position and collector target angles over a day", _sun_arguments)
def _sun(args: argparse.Namespace) -> int:
    from ..collectors import Collector
    from ..sun import solar_position
    from ..times import local_range, parse_clock, parse_date, parse_freq

    site = site_from_arguments(args)
    collector: Collector = collector_from_arguments(args)
    for flag, parse, value in (("--date", parse_date, args.date), ("--start", parse_clock, args.start),
                               ("--end", parse_clock, args.end), ("--freq", parse_freq, args.freq)):
        with flag_named(flag):  # the refusal names the flag: '--end: clock time '25:00' is not HH:MM'
            parse(value)
    times = local_range(args.date, site.tz, start=args.start, end=args.end, freq=args.freq)
    position = solar_position(times, site, args.model, declination=args.declination, equation_of_time=args.eot)
    aimed = position["altitude" if args.geometric else "apparent_altitude"]
    angles = collector.angles(aimed, position["azimuth"])
    table = pd.concat([position[["altitude", "apparent_altitude", "azimuth", "declination",
                                 "hour_angle", "equation_of_time"]], angles], axis=1)
    if args.csv:
        write(claim([args.csv])[0], lambda file: table.to_csv(file, float_format="%.6f", index_label="time"))
        print(f"wrote {len(table)} rows to {args.csv}")
    else:
        shown = table.copy()
        shown.index = shown.index.strftime("%Y-%m-%d %H:%M:%S")
        print(shown.round(3).to_string(na_rep="-"))
    up = aimed > 0
    print(f"\n{site.name} ({site.latitude:.4f}°, {site.longitude:.4f}°) {args.date}, "
          f"model {args.model}, collector {collector.kind}, targets on the "
          f"{'geometric sun' if args.geometric else 'apparent (refracted) sun'}")
    if up.any():
        peak = position["altitude"].idxmax()
        print(f"  sun up in range {up.index[up.to_numpy()][0]:%H:%M}-{up.index[up.to_numpy()][-1]:%H:%M}; "
              f"highest {position['altitude'].max():.3f}° at {peak:%H:%M:%S}")
        if "rate" in angles:
            print(f"  {_fastest_rate(angles['rate'])}")
    else:
        print("  the sun stays below the horizon in this range")
    if args.plot:
        from ..report import plot_sun_path, save_figure

        title = f"{site.name} {args.date}: {collector.kind} ({args.model})"
        print(f"  plot: {save_figure(plot_sun_path(position, angles, title=title), args.plot)}")
    return 0
