"""Weather frames: ``check`` a recorded file, make a synthetic ``sky``."""

from __future__ import annotations

import argparse

import pandas as pd

from ..outputs import claim, write
from .base import (
    add_force_argument,
    add_record_arguments,
    add_site_arguments,
    add_synthetic_arguments,
    command,
    flag_named,
    read_record,
    site_from_arguments,
    synthetic_frame,
)


def _check_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="recorded weather file")
    add_site_arguments(parser, record=True)
    add_record_arguments(parser)
    parser.add_argument("--freq", help="resample to this step, e.g. 1min (1h at most: the longest step a replay runs)")
    parser.add_argument("--out", metavar="FILE", help="write the checked (cleaned) frame: Parquet for a .parquet "
                                                      "name, else CSV")
    add_force_argument(parser)


@command("check", "read a recorded weather file and print its validation summary; with a site (--site or "
                  "--lat/--lon) also check it against the sun", _check_arguments)
def _check(args: argparse.Namespace) -> int:
    from ..io import validation_report

    site = site_from_arguments(args, clock_required=False)
    if args.freq is not None:
        from ..simulation import run_step

        # before the file is read, naming the flag; a step no run takes (1d: 300 minutes in one row,
        # called clean) is refused as replay refuses it, since the checked file is for replays
        with flag_named("--freq"):
            run_step(args.freq)
    if args.out:  # before the file is read, not after its report: an --out there already had been refused last
        _refuse_other_formats(args.out)
        claim([args.out])
    frame = read_record(args, args.file, site=site, freq=args.freq)
    print(validation_report(frame))
    if args.out:
        write_frame(frame, args.out)
        print(f"wrote {len(frame)} rows to {args.out}")
    return 0


#: Names of files `write_frame` cannot write: it writes Parquet or CSV text, and had written CSV
#: under a .parquet name (which a streamed replay then could not open).
_NOT_CSV = (".xlsx", ".xls", ".json", ".nc", ".feather", ".h5", ".pkl")


def _refuse_other_formats(path: str) -> None:
    from pathlib import Path

    from ..errors import HybridtrackError

    if Path(path).suffix.lower() in _NOT_CSV:
        raise HybridtrackError(f"{path}: --out writes CSV or Parquet; name the file .csv or .parquet")


def write_frame(frame: pd.DataFrame, path: str) -> None:
    """Write a weather frame as Parquet or CSV.

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame on a tz-aware index.
    path : str
        A ``.parquet`` name: Parquet, its tz-aware index kept (what a streamed replay reads
        fastest); any other: CSV of ISO stamps with their UTC offset, which `read_weather` reads
        back, with microseconds where a stamp has a fraction of a second (written to the whole
        second, half-second stamps had read back as repeated ones, half the rows dropped).
    """
    from pathlib import Path

    from ..errors import HybridtrackError

    target = Path(path)
    if target.is_dir():
        raise HybridtrackError(f"{path}: is a folder; --out takes a file name")
    _refuse_other_formats(path)
    claim([target])
    if target.suffix.lower() == ".parquet":
        write(target, lambda file: frame.rename_axis("time").to_parquet(file))
        return
    out = frame.copy()
    fraction = ".%f" if (out.index.as_unit("ns").asi8 % 1_000_000_000).any() else ""
    out.index = out.index.strftime(f"%Y-%m-%dT%H:%M:%S{fraction}%z").str.replace(r"(\d{2})(\d{2})$", r"\1:\2",
                                                                                 regex=True)
    write(target, lambda file: out.to_csv(file, index_label="time", float_format="%.6g"))


def _sky_arguments(parser: argparse.ArgumentParser) -> None:
    add_synthetic_arguments(parser)
    parser.add_argument("--out", help="write the weather frame (with sensor readings) as CSV")
    parser.add_argument("--plot", metavar="PNG", help="draw irradiance, sensor readings and wind")
    add_force_argument(parser)


@command("sky", "make a synthetic weather frame and show its sensor's view", _sky_arguments)
def _sky(args: argparse.Namespace) -> int:
    from ..sensor import sensor_view

    site = site_from_arguments(args)
    frame = sensor_view(synthetic_frame(args, site), seed=args.seed)
    print(_sky_table(frame, site).to_string(float_format=lambda v: f"{v:.2f}"))
    if args.out:
        write(claim([args.out])[0], lambda file: frame.to_csv(file, float_format="%.3f", index_label="time"))
        print(f"wrote {len(frame)} rows to {args.out}")
    if args.plot:
        from ..report import plot_sky, save_figure

        print(f"plot: {save_figure(plot_sky(frame, site), args.plot)}")
    return 0


def _sky_table(frame: pd.DataFrame, site) -> pd.DataFrame:
    """Per day: weather, DNI, clearness index, sunshine, and the classifier's share of each label."""
    from ..fuzzy import FuzzyWeatherClassifier
    from ..sky import daily_summary
    from ..sun import solar_position

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
