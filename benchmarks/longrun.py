"""A year at 1-second steps in bounded memory: the streamed run's wall time and peak memory.

Run: ``python benchmarks/longrun.py [--days N] [--month-days N] [--repeats N]``. One north-south
trough at Lanzhou, hybrid strategy, synthetic climate weather made a day at a time
(`hybridtrack.streaming.synthetic_days`), 1-second steps: a year (365 days, 31.5 M steps) and a
month (30 days) are each run by `hybridtrack.streaming.stream` in a fresh subprocess, which
reports its wall time (weather made, run, log written) and its peak resident memory
(`_timing.peak_rss_bytes`, the whole process: Python, numpy, the kernel).
If memory does not grow with the span, the year's peak is the month's.

The same-run reference is pvlib's ``spa_python`` over one day's 1-second stamps (the median of
`--repeats` calls), so the ratios say how many SPA-days of time a step of the streamed run costs
on this machine today.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

import pandas as pd
import pvlib
from _timing import median_seconds, print_table

from hybridtrack import sites

CHILD = """
import json, sys, time
from _timing import peak_rss_bytes
start = time.perf_counter()
from hybridtrack.streaming import stream, synthetic_days
days = synthetic_days("lanzhou", "2021-01-01", sys.argv[2], weather="climate", freq="1s", seed=1)
result = stream(days, sys.argv[1], collector="trough-ns", strategy="hybrid")
wall = time.perf_counter() - start
peak = peak_rss_bytes()
s = result.summary
print(json.dumps({"wall": wall, "peak": peak, "steps": s["steps"], "rms": s["tracking_error_deg"]["rms"],
                  "p95": s["tracking_error_deg"]["p95"], "energy": s["energy_capture"], "clock": s["clock"],
                  "log_bytes": result.files["log"].stat().st_size}))
"""


def streamed(days: int) -> dict:
    """Run `days` days from 2021-01-01 in a fresh process; its wall time, peak RSS and summary."""
    end = (pd.Timestamp("2021-01-01") + pd.Timedelta(days=days - 1)).date().isoformat()
    with tempfile.TemporaryDirectory() as folder:
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([os.getcwd(), os.path.dirname(os.path.abspath(__file__)),
                                                     os.environ.get("PYTHONPATH", "")])}
        done = subprocess.run([sys.executable, "-c", CHILD, folder, end], capture_output=True, text=True, env=env,
                              check=False)
    if done.returncode != 0:
        raise SystemExit(f"the {days}-day run failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", type=int, default=365, help="days of the long run (default 365)")
    parser.add_argument("--month-days", type=int, default=30, help="days of the shorter run (default 30)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats of the SPA reference (default 3)")
    args = parser.parse_args()
    site = sites.get("lanzhou")
    stamps = pd.date_range("2021-06-21", periods=86_400, freq="1s", tz=site.tz)
    spa = median_seconds(lambda: pvlib.solarposition.spa_python(stamps, site.latitude, site.longitude,
                                                                 site.altitude), args.repeats)
    runs = {f"{args.month_days} days": streamed(args.month_days), f"{args.days} days": streamed(args.days)}
    rows = [["pvlib spa_python, one day's 1-s stamps", "86,400", f"{spa:.2f}", "1.0", "-", "-", "-", "-"]]
    for name, run in runs.items():
        rows.append([f"stream {name} at 1 s", f"{run['steps']:,}", f"{run['wall']:.0f}", f"{run['wall'] / spa:.0f}",
                     f"{run['wall'] / run['steps'] * 1e6:.1f}", f"{run['peak'] / 2**30:.2f}",
                     f"{run['log_bytes'] / run['steps']:.1f}", f"{run['rms']:.4f} / {run['energy']:.4f}"])
    print(f"Lanzhou, trough-ns, hybrid, synthetic climate weather, 1-s steps; {os.cpu_count()} cores")
    print_table(["case", "steps", "wall s", "x SPA-day", "µs/step", "peak RSS GiB", "log B/step", "RMS ° / energy"],
                rows)
    month, year = runs.values()
    print(f"\npeak RSS, {args.days} days over {args.month_days} days: {year['peak'] / month['peak']:.2f}x "
          f"(the span is {args.days / args.month_days:.1f}x); wall: {year['wall'] / month['wall']:.1f}x")
    print(f"clock watch at the end of {args.days} days: {year['clock']}")


if __name__ == "__main__":
    main()
