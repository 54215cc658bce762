"""A sweep of site-years on 1 and on 2 Dask workers, in one run.

Run: ``python benchmarks/sweep.py [--runs N]``. The sweep is N site-years (Lanzhou, a trough on
a north-south axis, climate weather, 1-minute steps, 525,600 steps each), one per seed, run by
``hybridtrack.sweep.run_sweep`` on a local cluster of 1 and then of 2 worker processes. Wall time
includes starting the cluster. The tables of the two must be equal, and are checked.
"""

from __future__ import annotations

import argparse
import os
import time

import pandas as pd
from _timing import print_table

from hybridtrack.sweep import Sweep, run_sweep


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=8, help="site-years in the sweep (default 8)")
    args = parser.parse_args()
    sweep = Sweep.from_dict({"base": {"site": "lanzhou", "collector": "trough-ns", "start": "2021-01-01", "days": 365,
                                      "weather": "climate"},
                             "grid": {"seed": list(range(args.runs))}})
    seconds, tables = {}, {}
    load = os.getloadavg()[0]
    for workers in (1, 2):
        start = time.perf_counter()
        tables[workers] = run_sweep(sweep, workers=workers, progress=False)
        seconds[workers] = time.perf_counter() - start
    pd.testing.assert_frame_equal(tables[1], tables[2])
    failed = int(tables[1]["error"].notna().sum())
    rows = [[workers, args.runs, f"{seconds[workers]:.1f}", f"{seconds[workers] / args.runs:.2f}",
             f"{seconds[1] / seconds[workers]:.2f}x"] for workers in (1, 2)]
    print(f"{args.runs} site-years at 1 min, one run each way; tables equal; {failed} failed runs; "
          f"load average {load:.1f} before, {os.getloadavg()[0]:.1f} after, on {os.cpu_count()} cores")
    print_table(["workers", "runs", "wall s", "s per run", "speed-up vs 1"], rows)


if __name__ == "__main__":
    main()
