"""Whole fields: wall time and peak memory, each case in its own process.

Run: ``python benchmarks/fields.py [--repeats N] [--heliostats N]``. Every case runs in a fresh Python process
(so its peak resident memory is its own, weather frame included) on the same Lanzhou site-year
at 1-minute steps (525,600 steps, climate weather, seed 1):

* ``SPA site-year``: pvlib's SPA over the year's stamps, the reference of the ratios;
* ``one Fresnel row``: ``simulate`` for one row;
* ``20-row Fresnel field, 1 thread``: ``simulate_field`` of the default 20-row field, metrics only
  (``keep_log=False``), one row after another in the process (``threads=1``), sharing the sky;
* ``20-row Fresnel field``: the same on the default threads (one per core);
* ``20-row Fresnel field, 2 workers``: the same on a local Dask cluster of two worker processes
  (``workers=2``; starting the cluster is timed too);
* ``N heliostats``: a field of ``--heliostats`` mirrors (``HeliostatField.rings``, 100 by
  default) in process on the default threads, metrics only; the table also gives its time per
  mirror and, for fewer than 1,000, what 1,000 would take at that rate (an extrapolation,
  marked as one);
* ``1,000 heliostats, geometry, per mirror``: every mirror's normal, azimuth and elevation for
  the year, one mirror per call, as the per-collector loop does it;
* ``1,000 heliostats, geometry, vectorised``: the same numbers for all mirrors in one call a day
  (``HeliostatField.targets``, 1,440 x 1,000 x 3 at a time).

Medians of `--repeats` runs of each (1 by default: the field-year takes minutes), taken in
rounds: each round runs every case once, so that SPA, the reference of the ratios, is measured
beside the cases through the same hours (this machine's speed drifts by 30 % within an hour:
SPA's site-year took 3.3-4.4 s over one half hour, 2026-11-29). Peak memory
is the largest resident set of the case's process and, for the cases on workers, the parent's
plus each worker's at most (``RUSAGE_CHILDREN`` gives the largest child's).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

from _timing import peak_rss_bytes, print_table

YEAR = ("2021-01-01", "2021-12-31")
#: Mirrors of the heliostat field-year case (``--heliostats``).
HELIOSTATS = int(os.environ.get("HYBRIDTRACK_BENCH_HELIOSTATS", "100"))


def _year():
    from hybridtrack.sky import synthetic

    return synthetic("lanzhou", *YEAR, weather="climate", seed=1, gusts_per_day=1.0)


def _spa(frame):
    import pvlib

    from hybridtrack import sites

    site = sites.get("lanzhou")
    pvlib.solarposition.spa_python(frame.index, site.latitude, site.longitude, site.altitude)


def _one_row(frame):
    from hybridtrack import simulate
    from hybridtrack.collectors import Collector

    simulate(frame, "lanzhou", collector=Collector("fresnel"))


def _fresnel_field_one_thread(frame):
    from hybridtrack import simulate_field
    from hybridtrack.fields import FresnelField

    simulate_field(frame, "lanzhou", FresnelField(), keep_log=False, progress=False, threads=1)


def _fresnel_field(frame):
    from hybridtrack import simulate_field
    from hybridtrack.fields import FresnelField

    simulate_field(frame, "lanzhou", FresnelField(), keep_log=False, progress=False)


def _fresnel_field_on_workers(frame):
    from hybridtrack import simulate_field
    from hybridtrack.fields import FresnelField

    simulate_field(frame, "lanzhou", FresnelField(), keep_log=False, progress=False, workers=2)


def _heliostats(frame):
    from hybridtrack import simulate_field
    from hybridtrack.fields import HeliostatField

    simulate_field(frame, "lanzhou", HeliostatField.rings(HELIOSTATS), keep_log=False, progress=False)


def _sun(frame):
    from hybridtrack.sun import solar_position

    return solar_position(frame.index, "lanzhou", "spa-fast")


def _geometry_per_mirror(sun):
    from hybridtrack.collectors import heliostat_normal, normal_angles
    from hybridtrack.fields import HeliostatField

    field = HeliostatField.rings(1000)
    alt, az = sun["altitude"].to_numpy(), sun["azimuth"].to_numpy()
    for aim in field.relative_aims:
        normal_angles(heliostat_normal(alt, az, aim))


def _geometry_vectorised(sun):
    from hybridtrack.fields import HeliostatField

    field = HeliostatField.rings(1000)
    alt, az = sun["altitude"].to_numpy(), sun["azimuth"].to_numpy()
    for start in range(0, len(alt), 1440):
        field.targets(alt[start:start + 1440], az[start:start + 1440])


CASES = {"SPA site-year": (_year, _spa), "one Fresnel row": (_year, _one_row),
         "20-row Fresnel field, 1 thread": (_year, _fresnel_field_one_thread),
         "20-row Fresnel field": (_year, _fresnel_field),
         "20-row Fresnel field, 2 workers": (_year, _fresnel_field_on_workers),
         "N heliostats": (_year, _heliostats),
         "1,000 heliostats, geometry, per mirror": (lambda: _sun(_year()), _geometry_per_mirror),
         "1,000 heliostats, geometry, vectorised": (lambda: _sun(_year()), _geometry_vectorised)}


def _child(case: str) -> None:
    prepare, run = CASES[case]
    data = prepare()
    start = time.perf_counter()
    run(data)
    seconds = time.perf_counter() - start
    peak = peak_rss_bytes() / 2**20
    if "workers" in case:  # an upper bound: a worker's ru_maxrss starts at its parent's
        peak += 2 * resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(json.dumps({"seconds": seconds, "peak_mib": peak}))


def _run_case(case: str) -> dict:
    done = subprocess.run([sys.executable, __file__, "--case", case], capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _measure(repeats: int) -> dict[str, tuple[float, float]]:
    """Each case's median seconds and largest peak MiB over `repeats` rounds of every case."""
    results = {case: [] for case in CASES}
    for _ in range(repeats):
        for case in CASES:
            results[case].append(_run_case(case))
    return {case: (statistics.median(r["seconds"] for r in runs), max(r["peak_mib"] for r in runs))
            for case, runs in results.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--heliostats", type=int, default=HELIOSTATS, help="mirrors in the heliostat field-year case")
    parser.add_argument("--case", choices=list(CASES), help=argparse.SUPPRESS)
    args = parser.parse_args()
    os.environ["HYBRIDTRACK_BENCH_HELIOSTATS"] = str(args.heliostats)
    if args.case:
        _child(args.case)
        return
    measured = _measure(args.repeats)
    spa = measured["SPA site-year"][0]
    per_mirror = measured["1,000 heliostats, geometry, per mirror"][0]
    rows = [[case, f"{seconds:.2f}", f"{seconds / spa:.2f}x", f"{per_mirror / seconds:.1f}x" if "geometry" in case
             else "", f"{peak:,.0f}"] for case, (seconds, peak) in measured.items()]
    rows = [[case.replace("N heliostats", f"{args.heliostats:,} heliostats"), *rest] for case, *rest in rows]
    mirrors = measured["N heliostats"][0]
    print(f"Lanzhou site-year at 1 min (525,600 steps), median of {args.repeats} run(s) each, one process per case; "
          f"default threads: {_default_threads()}")
    print_table(["case", "wall s", "/ SPA", "per-mirror / this", "peak RSS MiB"], rows)
    line = f"heliostat field-year: {mirrors / args.heliostats:.2f} s a mirror"
    if args.heliostats < 1000:
        line += f"; 1,000 mirrors at that rate (extrapolated, not run): {1000 * mirrors / args.heliostats:.0f} s"
    print(line)


def _default_threads() -> int:
    from hybridtrack.cluster import cores

    return cores()


if __name__ == "__main__":
    main()
