"""End-to-end simulation speed against pvlib's SPA over the same stamps, in one process.

Run: ``python benchmarks/simulate.py [--repeats N]``. For one site-year at 1-minute steps
(525,600 steps) and one day at 1-second steps (86,400 steps), the sky is made first. The
timed part runs from the sensor model to the metrics: ``hybridtrack.simulate``, which also
computes the true sun with SPA. It is compared with pvlib's ``spa_python`` alone over the
same stamps. Peak memory is traced with tracemalloc on one extra run. Memory growth over
time is checked too: the traced peak of a year is compared with a month's.
"""

from __future__ import annotations

import argparse
import tracemalloc

import pvlib
from _timing import median_seconds, print_table

from hybridtrack import simulate, sites
from hybridtrack.sky import synthetic


def peak_mib(function) -> float:
    """Peak traced Python memory of one call, MiB."""
    tracemalloc.start()
    function()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = []
    cases = [("lanzhou", "2021-01-01", "2021-12-31", "1min", "climate", "site-year, 1 min"),
             ("nanjing", "2013-01-01", "2013-12-31", "1min", "climate", "site-year, 1 min"),
             ("lanzhou", "2021-06-21", None, "1s", "mixed", "one day, 1 s")]
    for name, start, end, freq, weather, label in cases:
        site = sites.get(name)
        frame = synthetic(site, start, end, weather=weather, freq=freq, seed=1, gusts_per_day=1.0)
        spa = median_seconds(lambda: pvlib.solarposition.spa_python(frame.index, site.latitude, site.longitude,
                                                                     site.altitude), args.repeats)
        run = median_seconds(lambda: simulate(frame, site), args.repeats)
        memory = peak_mib(lambda: simulate(frame, site))
        rows.append([f"{name} {label}", f"{len(frame):,}", f"{spa:.2f}", f"{run:.2f}", f"{run / spa:.2f}x",
                     f"{memory:,.0f}", f"{run / len(frame) * 1e6:.1f}"])
    print(f"hybrid strategy, trough-ns, default imperfections; median of {args.repeats} runs")
    print_table(["case", "steps", "SPA alone s", "simulate s", "simulate/SPA", "peak MiB", "µs/step"], rows)

    site = sites.get("lanzhou")
    month = synthetic(site, "2021-06-01", "2021-06-30", weather="climate", seed=2)
    year = synthetic(site, "2021-01-01", "2021-12-31", weather="climate", seed=2)
    per_step = [peak_mib(lambda f=f: simulate(f, site)) / len(f) * 2**20 for f in (month, year)]
    print(f"\nmemory per step: a month {per_step[0]:,.0f} B, a year {per_step[1]:,.0f} B "
          f"(a year / a month = {per_step[1] / per_step[0]:.2f}; flat means no growth with time)")


if __name__ == "__main__":
    main()
