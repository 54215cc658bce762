"""End-to-end simulation speed against pvlib's SPA over the same stamps, in one process.

Run: ``python benchmarks/simulate.py [--repeats N] [--part all|simulate|kernel]``. For one site-year at 1-minute steps
(525,600 steps) and one day at 1-second steps (86,400 steps), the sky is made first. The
timed part runs from the sensor model to the metrics: ``hybridtrack.simulate``, which also
computes the true sun with SPA. It is compared with pvlib's ``spa_python`` alone over the
same stamps. Peak memory is traced with tracemalloc on one extra run. Memory growth over
time is checked too: the traced peak of a year is compared with a month's.

The kernel part runs a site-year on both engines (``SimulationConfig.engine``: the readable
reference loop and the compiled kernel), end to end and the scan loop alone, against SPA in the
same run, and times the kernel's first call in a fresh process: compiling into an empty cache,
then loading what that compile cached.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc

import pvlib
from _timing import median_seconds, print_table

import hybridtrack.simulation as simulation
from hybridtrack import simulate, sites
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic

FIRST_CALL = """
import time
from hybridtrack import simulate
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic
frame = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=1)
start = time.perf_counter()
simulate(frame, "lanzhou", config=SimulationConfig(engine="compiled"))
print(time.perf_counter() - start)
"""


def peak_mib(function) -> float:
    """Peak traced Python memory of one call, MiB."""
    tracemalloc.start()
    function()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


class LoopTimer:
    """Time spent in the scan loop of either engine (`simulation._run`, `simulation.run_compiled`)."""

    def __init__(self):
        self.seconds = 0.0
        for name in ("_run", "run_compiled"):
            setattr(self, name, getattr(simulation, name))
            setattr(simulation, name, self._timed(getattr(simulation, name)))

    def _timed(self, function):
        def timed(*args):
            start = time.perf_counter()
            try:
                return function(*args)
            finally:
                self.seconds += time.perf_counter() - start
        return timed

    def median_loop(self, function, repeats: int) -> float:
        """The median of `repeats` calls' loop time (after one warm-up call)."""
        function()
        samples = []
        for _ in range(repeats):
            self.seconds = 0.0
            function()
            samples.append(self.seconds)
        return sorted(samples)[len(samples) // 2]


def first_calls() -> tuple[float, float]:
    """Seconds of a one-day run in a fresh process: compiling into an empty cache, then cached."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        return tuple(float(subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, capture_output=True,
                                          text=True, check=True).stdout.strip().splitlines()[-1]) for _ in range(2))


def kernel_table(repeats: int) -> None:
    """The compiled kernel against the reference loop on a site-year, with SPA in the same run."""
    site = sites.get("lanzhou")
    frame = synthetic(site, "2021-01-01", "2021-12-31", weather="climate", freq="1min", seed=1, gusts_per_day=1.0)
    spa = median_seconds(lambda: pvlib.solarposition.spa_python(frame.index, site.latitude, site.longitude,
                                                                 site.altitude), repeats)
    timer = LoopTimer()
    rows, runs = [], {}
    for engine in ("reference", "compiled"):
        config = SimulationConfig(engine=engine)
        run = median_seconds(lambda: simulate(frame, site, config=config), repeats)
        loop = timer.median_loop(lambda: simulate(frame, site, config=config), repeats)
        runs[engine] = (run, loop)
        rows.append([engine, f"{run:.2f}", f"{run / spa:.2f}x", f"{loop:.3f}", f"{loop / len(frame) * 1e6:.3f}"])
    print(f"\nthe scan loop: lanzhou site-year at 1 min ({len(frame):,} steps), hybrid, trough-ns; "
          f"SPA alone {spa:.2f} s; median of {repeats} runs")
    print_table(["engine", "simulate s", "simulate/SPA", "loop s", "loop µs/step"], rows)
    (run_ref, loop_ref), (run_kernel, loop_kernel) = runs["reference"], runs["compiled"]
    print(f"compiled against reference: simulate {run_ref / run_kernel:.1f}x faster, "
          f"the loop {loop_ref / loop_kernel:.0f}x faster")
    compiling, cached = first_calls()
    print(f"first call in a fresh process (one day): {compiling:.1f} s compiling, {cached:.1f} s from the cache")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--part", choices=("all", "simulate", "kernel"), default="all")
    args = parser.parse_args()
    if args.part in ("all", "simulate"):
        simulate_table(args.repeats)
    if args.part in ("all", "kernel"):
        kernel_table(args.repeats)


def simulate_table(repeats: int) -> None:
    """A site-year, and a day at 1 s, against SPA; memory per step over a month and a year."""
    rows = []
    cases = [("lanzhou", "2021-01-01", "2021-12-31", "1min", "climate", "site-year, 1 min"),
             ("nanjing", "2013-01-01", "2013-12-31", "1min", "climate", "site-year, 1 min"),
             ("lanzhou", "2021-06-21", None, "1s", "mixed", "one day, 1 s")]
    for name, start, end, freq, weather, label in cases:
        site = sites.get(name)
        frame = synthetic(site, start, end, weather=weather, freq=freq, seed=1, gusts_per_day=1.0)
        spa = median_seconds(lambda: pvlib.solarposition.spa_python(frame.index, site.latitude, site.longitude,
                                                                     site.altitude), repeats)
        run = median_seconds(lambda: simulate(frame, site), repeats)
        memory = peak_mib(lambda: simulate(frame, site))
        rows.append([f"{name} {label}", f"{len(frame):,}", f"{spa:.2f}", f"{run:.2f}", f"{run / spa:.2f}x",
                     f"{memory:,.0f}", f"{run / len(frame) * 1e6:.1f}"])
    print(f"hybrid strategy, trough-ns, default imperfections; median of {repeats} runs")
    print_table(["case", "steps", "SPA alone s", "simulate s", "simulate/SPA", "peak MiB", "µs/step"], rows)

    site = sites.get("lanzhou")
    month = synthetic(site, "2021-06-01", "2021-06-30", weather="climate", seed=2)
    year = synthetic(site, "2021-01-01", "2021-12-31", weather="climate", seed=2)
    per_step = [peak_mib(lambda f=f: simulate(f, site)) / len(f) * 2**20 for f in (month, year)]
    print(f"\nmemory per step: a month {per_step[0]:,.0f} B, a year {per_step[1]:,.0f} B "
          f"(a year / a month = {per_step[1] / per_step[0]:.2f}; flat means no growth with time)")


if __name__ == "__main__":
    main()
