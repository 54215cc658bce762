"""A controller that has been running before the run begins: commissioning and warm calibration.

Every real field commissions its open-loop trackers once, and a hybrid controller that has run
for a while carries its calibration into the next day. Both come from the same place here: a
synthetic clear day at the same site in the same world (the same mount, clock and sensor
errors), run through the same controller:

* `commission`: the clear day at commissioning (`Imperfections.commissioned_days_ago` before the
  run, when the clock was set) tracked on the sensor whenever it reads valid, with the same online
  mount estimator the hybrid runs (`hybridtrack.control.mountfit`); the mount it ends the day
  with is frozen for the run (``astronomical-commissioned``).
* `warm_memory`: the clear day before the run, run with the calibrating strategy itself; its mount fit and offsets
  at the end of the day are where the run starts (``hybrid``, ``hybrid-always``,
  ``hybrid-oracle``), so no policy is judged on a first morning it would never see in the field.
"""

from __future__ import annotations

import dataclasses
import datetime as dt

import pandas as pd

from .collectors import Collector
from .control import MountEstimate
from .control.mountfit import parameter_names
from .errors import HybridtrackError
from .times import FIRST_DATE

__all__ = ["commission", "warm_memory", "clear_day"]


def clear_day(site, collector: Collector, config, start: pd.Timestamp, strategy: str, days_before: float,
              classifier=None, sky_seed: int | None = None):
    """The run of `strategy` over a clear day at `site`, `days_before` local days before `start`,
    with the controller's clock as it was then, tracked but not scored (`simulation.Tracked`: only
    its memory is wanted).

    The day's sky is drawn from `sky_seed` (by default the config's seed, which also seeds the
    world's own draws: the sensor's noise). A field's collectors stood under one sky the day
    before as they do in the run: the field gives them its seed, and they share the day's frame
    and what follows from it alone (its sun and its light; `hybridtrack.reuse`)."""
    from .reuse import same_object
    from .simulation import track
    from .sky import synthetic

    day = _day_before(start.tz_convert(site.tz), days_before)
    seed = config.seed if sky_seed is None else sky_seed
    frame = same_object(("clear day", site, day, seed), lambda: synthetic(site, day, weather="sunny", seed=seed))
    age = max(config.imperfections.commissioned_days_ago - days_before, 0.0)
    setup = dataclasses.replace(config, controller=dataclasses.replace(config.controller, strategy=strategy),
                                imperfections=dataclasses.replace(config.imperfections, commissioned_days_ago=age))
    return track(frame, site, collector=collector, config=setup, classifier=classifier, warm_start=False)


def _day_before(start: pd.Timestamp, days: float) -> dt.date:
    """The local date `days` before `start`, refused with the reason where it is before the first
    date a run can cover (a run early in that span, commissioned long before)."""
    try:
        day = (start - pd.Timedelta(days=days)).date()
    except (OverflowError, pd.errors.OutOfBoundsDatetime):  # before pandas' first timestamp
        day = start.date() - dt.timedelta(days=days)
    if day < FIRST_DATE:
        raise HybridtrackError(f"the run starts on {start.date()}; its clear day {days:g} days before ({day}, "
                               f"for warm start or commissioning, imperfections.commissioned_days_ago) is before "
                               f"{FIRST_DATE}, the first date a run can cover: start later or commission it more "
                               "recently")
    return day


def commission(site, collector: Collector, config, start: pd.Timestamp, *, classifier=None,
               sky_seed: int | None = None) -> MountEstimate:
    """The mount fitted online over a clear day of sensor tracking at commissioning, then frozen.

    Parameters
    ----------
    site : Site
    collector : Collector
    config : SimulationConfig
        The run's config: its world and controller are the ones commissioned.
    start : pandas.Timestamp
        The run's first step.
    classifier : FuzzyWeatherClassifier, optional
    sky_seed : int, optional
        Seeds the day's sky (`clear_day`); by default the config's seed.
    """
    days = max(config.imperfections.commissioned_days_ago, 1.0)
    run = clear_day(site, collector, config, start, "hybrid-always", days, classifier, sky_seed)
    return MountEstimate.from_parameters(parameter_names(collector), run.memory()["theta"])


def warm_memory(site, collector: Collector, config, start: pd.Timestamp, *, classifier=None,
                sky_seed: int | None = None) -> dict:
    """What the run's own strategy carries out of the clear day before (`Controller.memory`): its
    mount fit and offsets. Not the clock watch's readings: the run's watch starts afresh. The
    day's sky is drawn from `sky_seed` (`clear_day`)."""
    memory = clear_day(site, collector, config, start, config.controller.strategy, 1.0, classifier,
                       sky_seed).memory()
    return {key: value for key, value in memory.items() if key != "clock"}
