"""Reading a site-year of 1-minute records: read_weather against plain pandas, in one process.

Run: ``python benchmarks/records.py [--repeats N]``. A year at Lanzhou (525,600 rows) is written
in three shapes (ISO stamps with offsets, dd/mm/yyyy naive stamps, Campbell TOA5) and read with
`read_weather` at the site (every check, the sun check included) and with ``pandas.read_csv``
plus ``pandas.to_datetime`` (no checks: the reference floor). Both must give the same values.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
from _timing import median_seconds, print_table

from hybridtrack.io import read_weather
from hybridtrack.sky import synthetic

COLUMNS = ["ghi", "dni", "dhi", "wind_speed", "temp_air"]


def write_shapes(folder: Path) -> dict[str, tuple[Path, dict, str]]:
    frame = synthetic("lanzhou", "2021-01-01", "2021-12-31", weather="climate", freq="1min", seed=1)[COLUMNS].round(2)
    local = frame.index.tz_convert("Asia/Shanghai")
    iso, dmy, toa5 = folder / "iso.csv", folder / "dmy.csv", folder / "toa5.dat"
    frame.set_axis(local.strftime("%Y-%m-%dT%H:%M:%S+08:00"), axis=0).to_csv(iso, index_label="time")
    frame.set_axis(local.strftime("%d/%m/%Y %H:%M"), axis=0).to_csv(dmy, index_label="Timestamp")
    body = frame.set_axis(local.strftime("%Y-%m-%d %H:%M:%S"), axis=0)
    body.columns = ["GHI_Avg", "DNI_Avg", "DHI_Avg", "WS_ms_Avg", "AirTC_Avg"]
    head = ('"TOA5","LZ","CR1000","1","x","y","1","Min"\n"TIMESTAMP","GHI_Avg","DNI_Avg","DHI_Avg","WS_ms_Avg",'
            '"AirTC_Avg"\n"TS","W/m^2","W/m^2","W/m^2","meters/second","Deg C"\n"","Avg","Avg","Avg","Avg","Avg"\n')
    toa5.write_text(head + body.to_csv(header=False))
    return {"ISO with offsets": (iso, {}, "%Y-%m-%dT%H:%M:%S%z"),
            "dd/mm/yyyy, naive": (dmy, {"tz": "Asia/Shanghai"}, "%d/%m/%Y %H:%M"),
            "Campbell TOA5": (toa5, {"tz": "Asia/Shanghai"}, "%Y-%m-%d %H:%M:%S")}


def pandas_floor(path: Path, fmt: str) -> pd.DataFrame:
    skip = [0, 2, 3] if path.suffix == ".dat" else None
    raw = pd.read_csv(path, skiprows=skip, index_col=0)
    raw.index = pd.to_datetime(raw.index, format=fmt)
    return raw


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, (path, kwargs, fmt) in write_shapes(Path(folder)).items():
            ours = median_seconds(lambda: read_weather(path, site="lanzhou", **kwargs), args.repeats)
            floor = median_seconds(lambda: pandas_floor(path, fmt), args.repeats)
            same = np.allclose(read_weather(path, site="lanzhou", **kwargs)["ghi"].to_numpy(),
                               pandas_floor(path, fmt).iloc[:, 0].clip(lower=0).to_numpy(), equal_nan=True)
            rows.append([name, f"{ours:.2f}", f"{floor:.2f}", f"{ours / floor:.1f}x", "yes" if same else "NO"])
    print("a site-year at 1-minute steps (525,600 rows), median of", args.repeats)
    print_table(["shape", "read_weather (s)", "pandas read_csv (s)", "ratio", "same GHI"], rows)


if __name__ == "__main__":
    main()
