"""PLC sun model against pvlib's SPA over a year of 1-minute stamps: speed and accuracy.

Run: ``python benchmarks/sun.py [--repeats N]``. Prints, per site, the median wall time of
each model (same process, same stamps), their ratio, and the PLC model's worst errors against
SPA (trough angle with altitude above 10°, geometric altitude while the sun is up).
"""

from __future__ import annotations

import argparse

import numpy as np
import pandas as pd
from _timing import median_seconds, print_table

from hybridtrack import sites
from hybridtrack.collectors import trough_angle
from hybridtrack.sun import solar_position


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--year", type=int, default=2021)
    args = parser.parse_args()
    rows = []
    for name in ("lanzhou", "nanjing"):
        site = sites.get(name)
        times = pd.date_range(f"{args.year}-01-01", f"{args.year + 1}-01-01", freq="1min", tz=site.tz, inclusive="left")
        spa_time = median_seconds(lambda: solar_position(times, site, "spa"), args.repeats)
        plc_time = median_seconds(lambda: solar_position(times, site, "plc"), args.repeats)
        spa, plc = solar_position(times, site, "spa"), solar_position(times, site, "plc")
        high, up = spa["altitude"] > 10, spa["altitude"] > 0
        rho_error = np.abs(trough_angle(spa.altitude, spa.azimuth) - trough_angle(plc.altitude, plc.azimuth))[high]
        alt_error = np.abs(spa.altitude - plc.altitude)[up]
        rows.append([name, f"{len(times):,}", f"{spa_time:.3f}", f"{plc_time:.3f}", f"{spa_time / plc_time:.1f}x",
                     f"{rho_error.max():.4f}", f"{alt_error.max():.4f}"])
    print(f"one year ({args.year}) of 1-minute stamps, median of {args.repeats} runs")
    print_table(["site", "stamps", "SPA s", "PLC s", "SPA/PLC", "max trough err °", "max altitude err °"], rows)


if __name__ == "__main__":
    main()
