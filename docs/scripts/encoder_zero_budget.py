"""Where the 1° mount's encoder-zero miss on a winter trough day comes from.

Run: ``python docs/scripts/encoder_zero_budget.py`` (about a minute). Issue 10's acceptance
(``issue10_acceptance.py``) compares the fitted encoder zero with the hardware's (plus the sensor's
bias). The fit has no term for the controller's own sun model or its clock, so what those add to
the trough's angle over a day lands in its zero. This script takes them away one at a time on the
same seeded day and prints the miss and the fit's own 1σ after each step.
"""

from dataclasses import replace

from issue10_acceptance import SET_MOUNT, calibration_misses
from hybridtrack.simulation import SimulationConfig, simulate
from hybridtrack.sky import synthetic

DAYS = (("nanjing", "2013-12-21"), ("nanjing", "2013-06-21"), ("lanzhou", "2021-12-21"), ("lanzhou", "2021-06-21"))
NO_CLOCK_OR_SITE = replace(SET_MOUNT, clock_error=0.0, clock_drift=0.0, latitude_error=0.0, longitude_error=0.0)
#: Each step takes one more source away: (label, the world's imperfections, the controller's sun model).
STEPS = (("as set (PLC sun model)", SET_MOUNT, "plc"),
         ("controller on SPA", SET_MOUNT, "spa"),
         ("and no clock or site error", NO_CLOCK_OR_SITE, "spa"),
         ("and no sensor noise", replace(NO_CLOCK_OR_SITE, sensor_noise=0.0), "spa"))


def miss(site: str, date: str, imperfections, sun_model: str) -> dict:
    """The fitted encoder zero less the truth on the sunny day, trough-ns, hybrid, seed 1."""
    frame = synthetic(site, date, weather="sunny", seed=1)
    config = SimulationConfig(imperfections=imperfections, seed=1)
    config = replace(config, controller=replace(config.controller, sun_model=sun_model))
    result = simulate(frame, site, collector="trough-ns", strategy="hybrid", config=config)
    return calibration_misses(result, imperfections)


def main() -> None:
    for site, date in DAYS:
        for label, imperfections, sun_model in STEPS:
            found = miss(site, date, imperfections, sun_model)
            print(f"{site:8s} {date}  {label:28s} encoder zero miss {found['encoder_offset_miss']:+.3f}° "
                  f"(1σ {found['encoder_offset_std']:.3f}°)")


if __name__ == "__main__":
    main()
