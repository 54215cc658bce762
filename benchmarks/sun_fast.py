"""The fast SPA truth (``model="spa-fast"``) against pvlib's SPA over a site-year, in one process.

Run: ``python benchmarks/sun_fast.py [--repeats N]``. For each site, a year of 1-minute stamps:
the median wall time of ``solar_position(..., "spa")`` (pvlib's ``spa_python``) and of
``solar_position(..., "spa-fast")``, their ratio, and the fast path's worst errors against SPA
over the year: geometric altitude, the angle between the two sun directions, and the
equation of time.
"""

from __future__ import annotations

import argparse

import numpy as np
import pandas as pd
from _timing import median_seconds, print_table

from hybridtrack import sites
from hybridtrack.sun import solar_position


def separation(a: pd.DataFrame, b: pd.DataFrame) -> np.ndarray:
    """Angle between the sun directions of two position frames, degrees."""
    a1, a2 = np.radians(a["altitude"]), np.radians(b["altitude"])
    cos = np.sin(a1) * np.sin(a2) + np.cos(a1) * np.cos(a2) * np.cos(np.radians(a["azimuth"] - b["azimuth"]))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--year", type=int, default=2021)
    args = parser.parse_args()
    rows = []
    for name in ("lanzhou", "nanjing"):
        site = sites.get(name)
        times = pd.date_range(f"{args.year}-01-01", f"{args.year + 1}-01-01", freq="1min", tz=site.tz,
                              inclusive="left")
        spa_time = median_seconds(lambda: solar_position(times, site, "spa"), args.repeats)
        fast_time = median_seconds(lambda: solar_position(times, site, "spa-fast"), args.repeats)
        spa, fast = solar_position(times, site, "spa"), solar_position(times, site, "spa-fast")
        rows.append([name, f"{len(times):,}", f"{spa_time:.2f}", f"{fast_time:.3f}", f"{fast_time / spa_time:.3f}",
                     f"{np.abs(fast.altitude - spa.altitude).max():.1e}", f"{separation(fast, spa).max():.1e}",
                     f"{np.abs(fast.equation_of_time - spa.equation_of_time).max() * 60:.1e}"])
    print(f"one year ({args.year}) of 1-minute stamps, median of {args.repeats} runs")
    print_table(["site", "stamps", "SPA s", "spa-fast s", "fast/SPA", "max altitude err °", "max direction err °",
                 "max EoT err s"], rows)


if __name__ == "__main__":
    main()
