"""Regenerate the typical-day weather records in data/, byte for byte.

Run from the repository root: ``python data/make_typical_days.py [--out data]``.
Each file holds one site's four typical days (docs/physics.md §1) under one weather type, over
the controller's working hours 05:00-20:00 local time, at 1-minute steps.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from hybridtrack.sky import synthetic

TYPICAL_DAYS = {
    "lanzhou": ("2021-03-20", "2021-06-21", "2021-09-23", "2021-12-21"),
    "nanjing": ("2013-03-20", "2013-06-21", "2013-09-23", "2013-12-22"),
}
WEATHERS = ("sunny", "cloudy", "overcast")
COLUMNS = {"ghi": 1, "dni": 1, "dhi": 1, "wind_speed": 2, "temp_air": 1}  # decimals kept


def make(site: str, weather: str) -> str:
    """The CSV text of one site's typical days under one weather."""
    days = []
    for number, day in enumerate(TYPICAL_DAYS[site]):
        seed = 1000 * (1 + list(TYPICAL_DAYS).index(site)) + 10 * WEATHERS.index(weather) + number
        frame = synthetic(site, f"{day} 05:00", f"{day} 20:00", weather=weather, seed=seed, gusts_per_day=1.0)
        days.append(frame)
    frame = pd.concat(days)
    table = pd.DataFrame({name: frame[name].round(decimals) for name, decimals in COLUMNS.items()})
    table["sky"] = frame["sky"].astype(str)
    table.index = frame.index.strftime("%Y-%m-%dT%H:%M:%S%z").str.replace(r"(\d{2})(\d{2})$", r"\1:\2", regex=True)
    return table.to_csv(index_label="time", lineterminator="\n")


def file_name(site: str, weather: str) -> str:
    """``lanzhou-2021-sunny.csv``."""
    return f"{site}-{TYPICAL_DAYS[site][0][:4]}-{weather}.csv"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).parent), help="folder to write into (default: data/)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for site in TYPICAL_DAYS:
        for weather in WEATHERS:
            path = out / file_name(site, weather)
            path.write_text(make(site, weather), encoding="utf-8")
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
