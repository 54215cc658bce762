"""Commissioning an open-loop tracker: one clear day tracked on the sun sensor, then a mount fit.

What a field does at start-up: a day of closed-loop tracking on the sensor gives the sun's angle
in encoder coordinates through the day, and a least-squares fit of the mount's errors
(`hybridtrack.control.mountfit`) corrects the computed targets from then on. The day is a
synthetic clear day at the same site, the day before the run starts, in the same world (the
same mount, clock and sensor errors).
"""

from __future__ import annotations

import dataclasses

import pandas as pd

from .collectors import Collector
from .control import MountEstimate
from .control.mountfit import fit_mount
from .world import installed_site

__all__ = ["commission"]


def commission(site, collector: Collector, config, start: pd.Timestamp, *, classifier=None) -> MountEstimate:
    """The mount fitted from a clear day of sensor tracking before `start`.

    Parameters
    ----------
    site : Site
    collector : Collector
    config : SimulationConfig
        The run's config: its world and controller are the ones commissioned.
    start : pandas.Timestamp
        The run's first step; commissioning takes the local day before.
    classifier : FuzzyWeatherClassifier, optional
    """
    from .simulation import simulate
    from .sky import synthetic

    day = (start.tz_convert(site.tz) - pd.Timedelta(days=1)).date()
    frame = synthetic(site, day, weather="sunny", seed=config.seed)
    tracking = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy="sensor"))
    run = simulate(frame, site, collector=collector, config=tracking, classifier=classifier)
    columns = ["sensor_sun"] if collector.single_axis else ["sensor_sun_azimuth", "sensor_sun"]
    clock = run.log.index + pd.Timedelta(seconds=config.imperfections.clock_error)
    mount, _ = fit_mount(clock, run.log[columns].to_numpy(float), installed_site(site, config.imperfections),
                         collector, config.controller)
    return mount
