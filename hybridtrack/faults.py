"""A library of fault scenarios users can run, each through one shared safety check.

Every scenario is a seeded day with one thing gone wrong (or a hard case that is not a fault),
injected through `simulate`'s ``faults`` or the weather frame itself. `run_scenario` runs it and
reports whether the controller detected it (the first event whose reason matches the scenario's
pattern after the fault began), how long that took, the worst true pointing error while it was
undetected, the final mode, and every breach of the safety check:

* the true angle stays short of the hard stops (the world holds an axis driven into one there)
  and every target within the software limits;
* a stow begins within one scan of every gust, in every mode, and of every wind reading that is
  missing or no anemometer's (`hybridtrack.control.wind.READABLE`) unless the run tracks through
  missing wind;
* once stowed for wind, the collector does not move until the mode ends (a timed stow move with
  the encoder judged frozen is allowed to finish), and stands at the true stow (the drive's, less
  the encoder's zero error) within the deadband and a count;
* no step is tracked on a sensor judged faulty (stuck, implausible or an invalid reading), and
  no step stays in sensor mode on a sensor invalid for longer than the allowed loss (but for the
  sensor-only tracker, which has no computed sun to hand over to and holds where it is);
* no tracking mode while the collector cannot move (the encoder judged frozen is ``fault``).

``hybridtrack faults list`` and ``hybridtrack faults run NAME`` are the command line.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import sites
from .errors import HybridtrackError

__all__ = ["Scenario", "SCENARIOS", "ScenarioResult", "run_scenario", "safety_breaches"]

FAULTY = ("stuck", "implausible", "invalid reading")
INVALID = ("low light", "out of view", "invalid reading", "outlier", "stuck", "implausible")


@dataclass(frozen=True)
class Scenario:
    """One fault scenario.

    Parameters
    ----------
    name, description : str
    build : callable
        ``build(site) -> (frame, faults, config, onset)``: the weather, the injected faults, the
        run's config changes (a dict of ``SimulationConfig`` replacements) and when the fault
        begins (a local clock time ``"HH:MM"``).
    detected_by : str or None
        A regular expression an event's reason matches when the fault is detected; None for a
        hard case with nothing to detect, which must only stay safe.
    site : str or Site
    collector : str
    """

    name: str
    description: str
    build: Callable
    detected_by: str | None
    site: str | sites.Site = "lanzhou"
    collector: str = "trough-ns"


def _day(site, weather="sunny", seed=1, date=None):
    from .sky import synthetic

    site = sites.get(site)
    default = {"lanzhou": "2021-06-21", "nanjing": "2013-06-21"}.get(site.name, "2021-06-21")
    return synthetic(site, date or default, weather=weather, seed=seed)


def _between(frame, start, end):
    clock = frame.index.tz_convert(frame.index.tz)
    day = str(clock[0].date())
    return np.asarray((clock >= pd.Timestamp(f"{day} {start}", tz=frame.index.tz))
                      & (clock < pd.Timestamp(f"{day} {end}", tz=frame.index.tz)))


def _calm(frame):
    return np.clip(frame["wind_speed"].to_numpy(), 0.0, 11.0)


def _sensor_value(value, start="11:00", end="14:00", noise=0.0):
    def build(site):
        frame = _day(site)
        window = _between(frame, start, end)
        jitter = noise * np.random.default_rng(3).standard_normal(len(frame))
        return frame, {"sensor": np.where(window, value + jitter, np.nan)}, {}, start
    return build


def _ramp(frame, per_hour, start):
    """Degrees growing by `per_hour` from the local clock time `start`, 0 before it."""
    hours = np.asarray((frame.index - frame.index[0]) / pd.Timedelta(hours=1))
    begin = float(start[:2]) + float(start[3:]) / 60.0
    return np.clip((hours - begin) * per_hour, 0.0, None)


def _sensor_drift(per_hour, start="10:00"):
    def build(site):
        frame = _day(site)
        return frame, {"sensor_drift": _ramp(frame, per_hour, start)}, {}, start
    return build


def _encoder_creep(per_hour, start="11:00"):
    def build(site):
        frame = _day(site)
        return frame, {"encoder": _ramp(frame, per_hour, start)}, {}, start
    return build


def _sensor_bias(size, start="12:00"):
    def build(site):
        frame = _day(site)
        return frame, {"sensor_drift": np.where(_between(frame, start, "23:59"), size, 0.0)}, {}, start
    return build


def _mask(name, start, end, weather="sunny"):
    def build(site):
        frame = _day(site, weather)
        return frame, {name: _between(frame, start, end)}, {}, start
    return build


def _encoder(values, start="11:00"):
    def build(site):
        frame = _day(site)
        shift = np.zeros(len(frame))
        at = int(np.flatnonzero(_between(frame, start, "23:59"))[0])
        shift[at:at + len(values)] = values
        return frame, {"encoder": shift}, {}, start
    return build


def _encoder_step(size, start="11:00"):
    def build(site):
        frame = _day(site)
        return frame, {"encoder": np.where(_between(frame, start, "23:59"), size, 0.0)}, {}, start
    return build


def _clock(kind, size, start="12:00"):
    def build(site):
        frame = _day(site)
        after = _between(frame, start, "23:59")
        if kind == "step":
            clock = np.where(after, size, 0.0)
        else:
            scans = np.cumsum(after)
            clock = scans * size
        return frame, {"clock": clock}, {"imperfections": {"clock_drift": 0.0}}, start
    return build


def _wind(kind, start="11:00"):
    def build(site):
        frame = _day(site)
        wind = _calm(frame)
        at = _between(frame, start, "23:59")
        if kind == "gust":
            wind[_between(frame, start, start[:3] + "04")] = 22.0
        elif kind == "storm":
            wind[:] = 28.0 + 2.0 * np.sin(np.arange(len(frame)) / 7.0)
        elif kind == "hover":
            wind[at] = 17.2 + 0.5 * np.sin(np.arange(at.sum()) * 1.3)
        elif kind == "nan":
            wind[_between(frame, start, start[:3] + "30")] = np.nan
        elif kind == "stuck":
            wind[at] = 0.0
        elif kind == "offset":
            wind = np.clip(wind - 0.6, -0.04, None)  # a calm anemometer reading a little below zero
        elif kind == "broken":
            wind[_between(frame, start, start[:3] + "30")] = -5.0  # an open 4-20 mA loop: below any calm
        elif kind == "sunrise":
            wind[_between(frame, "05:10", "05:20")] = 21.0
        onset = {"sunrise": "05:10", "storm": "00:00"}.get(kind, start)
        return frame.assign(wind_speed=wind), {}, {}, onset
    return build


def _frozen_and_gust(site):
    frame = _day(site)
    wind = _calm(frame)
    wind[_between(frame, "14:00", "14:20")] = 29.0
    return frame.assign(wind_speed=wind), {"encoder_frozen": _between(frame, "12:00", "18:00")}, {}, "12:00"


def _frozen_overnight_and_gust(site):
    frame = _day(site)
    wind = _calm(frame)
    wind[_between(frame, "11:00", "11:20")] = 25.0
    return frame.assign(wind_speed=wind), {"encoder_frozen": _between(frame, "05:00", "23:59")}, {}, "05:00"


def _stuck_then_gust(site):
    frame = _day(site)
    wind = _calm(frame)
    wind[_between(frame, "12:30", "12:40")] = 24.0
    faults = {"sensor": np.where(_between(frame, "11:00", "14:00"), 0.2, np.nan)}
    return frame.assign(wind_speed=wind), faults, {}, "11:00"


def _irradiance(kind, start="10:00"):
    def build(site):
        frame = _day(site, "mixed", seed=2)
        dni = frame["dni"].to_numpy().copy()
        window = _between(frame, start, start[:3] + "30")
        dni[window] = np.nan if kind == "nan" else -40.0
        return frame.assign(dni=dni), {}, {}, start
    return build


def _weather(weather, date=None):
    def build(site):
        return _day(site, weather, 4 if date is None else 5, date), {}, {}, "00:00"
    return build


def _no_wind(site):
    frame = _day(site)
    return frame.drop(columns=["wind_speed"]), {}, {}, "00:00"


SCENARIOS: dict[str, Scenario] = {s.name: s for s in [
    Scenario("sensor-dropout", "the sensor gives no reading 11:00-13:00 in full sun",
             _mask("sensor_dropout", "11:00", "13:00"), r"sensor lost \(invalid reading\)"),
    Scenario("sensor-dropout-cloudy", "the sensor gives no reading 11:00-13:00 under a broken sky",
             _mask("sensor_dropout", "11:00", "13:00", "mixed"), None),
    Scenario("sensor-stuck", "the sensor says 'on the sun' (0.000°) from 11:00", _sensor_value(0.0),
             r"sensor lost \(stuck\)"),
    Scenario("sensor-stuck-noisy", "stuck at 0° with 0.001° of electronic noise", _sensor_value(0.0, noise=0.001),
             r"sensor lost \(stuck\)"),
    Scenario("sensor-stuck-offset", "stuck at +0.2° from 11:00", _sensor_value(0.2), r"sensor lost \(stuck\)"),
    Scenario("sensor-wild", "the sensor reads +8° from 11:00", _sensor_value(8.0), r"implausible"),
    Scenario("sensor-drift", "the sensor drifts 0.8° an hour from 10:00", _sensor_drift(0.8),
             r"disagree|implausible"),
    Scenario("sensor-drift-slow", "the sensor drifts 0.3° an hour from 10:00", _sensor_drift(0.3),
             r"disagree|implausible"),
    Scenario("sensor-bias", "the sensor takes on +1.5° at noon", _sensor_bias(1.5), r"disagree|implausible"),
    Scenario("sensor-bias-small", "the sensor takes on +0.5° at noon", _sensor_bias(0.5), r"disagree|implausible"),
    Scenario("sensor-stuck-then-gust", "a stuck sensor, then a gust at 12:30", _stuck_then_gust,
             r"sensor lost \(stuck\)"),
    Scenario("encoder-glitch", "one wild count (+5.6°) at 11:00", _encoder([5.625]), r"encoder glitch"),
    Scenario("encoder-glitch-burst", "two wild counts in a row at 11:00", _encoder([5.625, 5.625]),
             r"encoder glitch"),
    Scenario("encoder-step", "the encoder reads 1.4° more from 11:00 on (slipped coupling)",
             _encoder_step(1.40625), r"held for|encoder glitch"),
    Scenario("encoder-creep", "the encoder reads 1° an hour more from 11:00 (a coupling slipping)",
             _encoder_creep(1.0), r"held beyond the plausibility bound"),
    Scenario("encoder-frozen", "the encoder freezes 12:00-18:00", _mask("encoder_frozen", "12:00", "18:00"),
             r"encoder frozen"),
    Scenario("encoder-frozen-gust", "frozen encoder, then 29 m/s at 14:00", _frozen_and_gust, r"encoder frozen"),
    Scenario("encoder-frozen-overnight-gust", "the encoder freezes at stow overnight, misses the first move, "
             "then 25 m/s at 11:00", _frozen_overnight_and_gust, r"encoder frozen"),
    Scenario("clock-step-forward", "the clock jumps 10 min forward at noon", _clock("step", 600.0),
             r"clock stepped"),
    Scenario("clock-step-back", "the clock jumps 10 min back at noon", _clock("step", -600.0), r"clock stepped"),
    Scenario("clock-creep", "the clock gains 4 s every scan from noon (under the step detector)",
             _clock("creep", 4.0), r"clock creeping"),
    Scenario("clock-creep-slow", "the clock gains 0.5 s every scan from noon", _clock("creep", 0.5),
             r"clock creeping"),
    Scenario("wind-gust", "22 m/s for 4 minutes at 11:00", _wind("gust"), r"wind .* m/s >"),
    Scenario("wind-storm", "28-30 m/s all day", _wind("storm"), r"wind .* m/s >"),
    Scenario("wind-hover", "wind hovering around the 17.2 m/s threshold from 11:00", _wind("hover"),
             r"wind .* m/s >"),
    Scenario("wind-nan", "the anemometer gives no number 11:00-11:30", _wind("nan"), r"wind reading missing"),
    Scenario("wind-broken", "the anemometer reads -5 m/s 11:00-11:30 (an open signal loop)", _wind("broken"),
             r"no wind \(an anemometer reads"),
    Scenario("wind-stuck", "the anemometer sticks at 0.0 from 11:00", _wind("stuck"), r"anemometer stuck"),
    Scenario("wind-negative-calm", "a calm anemometer reading -0.04 m/s at times (a zero offset)",
             _wind("offset"), None),
    Scenario("wind-at-sunrise", "a gust while pre-positioning before sunrise", _wind("sunrise"),
             r"wind .* m/s >"),
    Scenario("wind-missing", "no anemometer at all (a live controller stows)", _no_wind, r"wind reading missing"),
    Scenario("dni-nan", "the irradiance is NaN 10:00-10:30", _irradiance("nan"), None),
    Scenario("dni-negative", "the irradiance reads -40 W/m² 10:00-10:30", _irradiance("negative"), None),
    Scenario("overcast-day", "no direct sun all day", _weather("overcast"), None),
    Scenario("broken-cloud-day", "a broken sky all day (cloud pull on the sensor)", _weather("cloudy"), None),
    Scenario("polar-day", "the sun never sets (Tromsø, June)", _weather("sunny", "2022-06-21"), None,
             site=sites.custom(69.65, 18.96, "Europe/Oslo", name="tromso")),
    Scenario("polar-night", "the sun never rises (Tromsø, December)", _weather("sunny", "2022-12-21"), None,
             site=sites.custom(69.65, 18.96, "Europe/Oslo", name="tromso")),
    Scenario("dst-day", "the clocks go forward (Seville, last Sunday of March)", _weather("sunny", "2022-03-27"),
             None, site=sites.custom(37.39, -5.98, "Europe/Madrid", name="seville")),
    Scenario("southern-hemisphere", "Cape Town at the December solstice", _weather("sunny", "2022-12-21"), None,
             site=sites.custom(-33.92, 18.42, "Africa/Johannesburg", name="cape-town")),
    Scenario("heliostat-wrap", "a heliostat whose normal crosses north (azimuth wraps)",
             _weather("sunny"), None, site="delingha", collector="heliostat"),
]}


@dataclass
class ScenarioResult:
    """What happened in one scenario."""

    scenario: Scenario
    detected: bool | None
    time_to_detect: pd.Timedelta | None
    worst_error: float | None
    final_mode: str
    breaches: list
    result: object

    @property
    def safe(self) -> bool:
        """No breach of the safety check."""
        return not self.breaches

    def row(self) -> dict:
        """One row of the fault table."""
        return {"scenario": self.scenario.name,
                "detected": "-" if self.detected is None else ("yes" if self.detected else "NO"),
                "time to detect": "-" if self.time_to_detect is None
                else f"{self.time_to_detect / pd.Timedelta(minutes=1):.0f} min",
                "worst error while undetected (°)": "-" if self.worst_error is None else f"{self.worst_error:.2f}",
                "final mode": self.final_mode, "safe": "yes" if self.safe else "NO: " + "; ".join(self.breaches)}


def safety_breaches(result) -> list[str]:
    """Every way a run broke the shared safety check (empty: safe)."""
    from .control.wind import WindGuard
    from .world import HARD_STOP_MARGIN

    log, breaches = result.log, []
    single = result.collector.single_axis
    low, high = result.config.drive.limits if single else (0.0, 90.0)
    stops = log["angle"].to_numpy(float)  # the world holds the axis at its hard stop: a collector driven into it
    hit = ~((stops > low - HARD_STOP_MARGIN + 1e-9) & (stops < high + HARD_STOP_MARGIN - 1e-9))
    if hit.any():
        breaches.append(f"driven into a hard stop ({log.index[np.flatnonzero(hit)[0]]})")
    if not log["target"].between(low - 1e-9, high + 1e-9).all():
        breaches.append("target beyond the limits")
    mode = log["mode"].astype(str).to_numpy()
    controller = result.config.controller  # a gust as the wind guard judges one: missing or unreadable wind too
    guard = WindGuard(controller.wind_stow, controller.wind_release, controller.minutes("wind_hold"),
                      controller.wind_missing)
    late = guard.gusts(log["wind_speed"].to_numpy(float)) & (mode != "stow_wind")
    if late.any():
        breaches.append(f"no stow at a gust ({log.index[np.flatnonzero(late)[0]]})")
    angle = log["angle"].to_numpy()
    stowed_at = _true_stow(result)
    for start in np.flatnonzero((mode == "stow_wind") & (np.roll(mode, 1) != "stow_wind")):
        end = start
        while end + 1 < len(mode) and mode[end + 1] == "stow_wind":
            end += 1
        settled = start + 5  # at stow speed a stow (or a timed stow move) ends within a few scans
        if end > settled and np.ptp(angle[settled:end + 1]) > 0:
            breaches.append(f"moved while stowed for wind ({log.index[settled]})")
        if end > settled and not abs(angle[end] - stowed_at[0]) <= stowed_at[1]:
            breaches.append(f"stowed for wind but {angle[end]:.2f}° where the stow is {stowed_at[0]:.2f}° "
                            f"({log.index[end]})")
    status = log["sensor_status"].astype(str).to_numpy()
    faulty_tracked = (mode == "sensor") & np.isin(status, FAULTY) & np.roll(np.isin(status, FAULTY), 1)
    if faulty_tracked.any():
        breaches.append(f"tracked a sensor judged faulty ({log.index[np.flatnonzero(faulty_tracked)[0]]})")
    if result.config.controller.sensor_only:  # no computed sun to hand over to: it holds, by design
        return breaches
    loss = int(result.config.controller.minutes("sensor_loss"))
    run = 0
    invalid = np.isin(status, INVALID)
    for i in range(len(log)):
        run = run + 1 if invalid[i] else 0
        if mode[i] == "sensor" and run > loss + 1:
            breaches.append(f"stayed on an invalid sensor past the loss time ({log.index[i]})")
            break
    return breaches


def _true_stow(result) -> tuple[float, float]:
    """Where the logged axis truly stands when stowed (its encoder's stow less the encoder's zero
    error), and how far from it a stowed axis may stand: the deadband and one count."""
    drive = result.config.drive if result.collector.single_axis else result.config.heliostat_drive
    stow = drive.stow if result.collector.single_axis else 90.0  # a heliostat's logged axis: elevation
    return stow - result.config.imperfections.encoder_offset, drive.deadband + drive.resolution + 1e-9


def run_scenario(name: str, site: str | None = None) -> ScenarioResult:
    """Run one scenario (at its own site, or `site`) and judge it."""
    from .simulation import SimulationConfig, simulate

    if name not in SCENARIOS:
        import difflib

        near = difflib.get_close_matches(str(name).lower(), SCENARIOS, n=1)
        hint = f"did you mean {near[0]!r}? " if near else ""
        raise HybridtrackError(f"unknown fault scenario {name!r}; {hint}`hybridtrack faults list` shows them")
    scenario = SCENARIOS[name]
    place = site or scenario.site
    frame, faults, changes, onset = scenario.build(place)
    config = SimulationConfig()
    for part, values in changes.items():
        config = dataclasses.replace(config, **{part: dataclasses.replace(getattr(config, part), **values)})
    result = simulate(frame, place, collector=scenario.collector, config=config, faults=faults or None)
    start = pd.Timestamp(f"{frame.index[0].tz_convert(frame.index.tz).date()} {onset}", tz=frame.index.tz)
    detected = time_to_detect = None
    undetected = result.log.index >= start
    if scenario.detected_by is not None:
        events = result.events
        hits = events[(events["time"] >= start) & events["reason"].str.contains(scenario.detected_by, regex=True,
                                                                                  flags=re.IGNORECASE)]
        detected = len(hits) > 0
        if detected:
            time_to_detect = hits["time"].iloc[0] - start
            undetected &= result.log.index < hits["time"].iloc[0]
    log = result.log[undetected]
    tracking = log["mode"].isin(["sensor", "astronomical", "search"]) & log["target_true"].notna()
    worst = float(log.loc[tracking, "error"].abs().max()) if tracking.any() else None
    return ScenarioResult(scenario, detected, time_to_detect, worst, str(result.log["mode"].iloc[-1]),
                          safety_breaches(result), result)
