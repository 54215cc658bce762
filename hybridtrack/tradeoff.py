"""The drive's deadband and the scan period against pointing error and wear: what each move buys.

An intermittent drive moves when the target and the encoder differ by more than its deadband, and
looks once a scan period (`hybridtrack.drive`). A wider deadband or a longer period moves less
often (less wear, less energy for the motor) and points worse. `tradeoff` runs one policy over a
grid of deadbands and periods on the same seeded days, and reports pointing error (RMS and p95,
DNI-weighted, `hybridtrack.metrics`) against moves a day. The period is the weather frame's step:
the controller scans once a step.

Each day is one synthetic frame at each period (`hybridtrack.sky.synthetic`, the same seed: the
same sky, sampled at that step); every deadband runs on it with the same world.

A run's log holds the error at each scan, just after that scan's move: at a long period it never
sees the sun running away from a collector that stands still until the next scan. So beside the
run's own RMS and p95 the table has the *held* error: between two scans the collector stands
where the first left it while the true target moves on (linearly between the scans' true
targets), sampled `SUBSTEPS` times an interval, weighted by the direct light on the aperture as
the run's metrics are (`hybridtrack.metrics`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .ablation import SEASONS, SITE_YEARS, run_days
from .errors import HybridtrackError

__all__ = ["TradeoffPlan", "TradeoffResult", "tradeoff", "held_error", "SUBSTEPS"]

#: Samples of the held error in each interval between scans.
SUBSTEPS = 8


@dataclass(frozen=True)
class TradeoffPlan:
    """Which deadbands, periods and days to run: every combination.

    Parameters
    ----------
    deadbands : tuple of float
        Degrees (the drive's of a single axis; a heliostat's drive for a heliostat).
    periods : tuple of str
        Scan periods (pandas frequencies: ``"1min"``, ``"5min"``).
    sites, seasons, weather, seeds, collectors : tuple
        The days, as in `hybridtrack.ablation.AblationPlan`.
    policy : str
    """

    deadbands: tuple[float, ...] = (0.1, 0.2, 0.4, 0.8)
    periods: tuple[str, ...] = ("1min",)
    sites: tuple[str, ...] = ("lanzhou", "nanjing")
    seasons: tuple[str, ...] = ("summer", "winter")
    weather: tuple[str, ...] = ("sunny",)
    seeds: tuple[int, ...] = (1,)
    collectors: tuple[str, ...] = ("trough-ns",)
    policy: str = "hybrid"

    def __post_init__(self) -> None:
        from .ablation import AblationPlan

        for name in ("deadbands", "periods"):
            object.__setattr__(self, name, checked_grid(name, getattr(self, name), "tradeoff"))
        days = AblationPlan(self.sites, self.seasons, self.weather, self.seeds, self.collectors, (self.policy,))
        for name in ("sites", "seasons", "weather", "seeds", "collectors"):  # as the plan names them: 'Nanjing'
            object.__setattr__(self, name, getattr(days, name))  # had taken 2021's days, not SITE_YEARS' 2013

    def days(self) -> list[dict]:
        """One dict per day and period: site, date, weather, seed, collector, period."""
        return [{"site": site, "date": f"{SITE_YEARS.get(site, 2021)}-{SEASONS[season]}", "weather": weather,
                 "seed": int(seed), "collector": collector, "period": period}
                for site in self.sites for season in self.seasons for weather in self.weather for seed in self.seeds
                for collector in self.collectors for period in self.periods]


def checked_grid(name: str, values, label: str) -> tuple:
    """A `TradeoffPlan` grid field, ``deadbands`` or ``periods``, as the plan keeps it: a tuple
    of distinct deadbands the drive takes (0-10°) or scan periods of 10 s to 30 min; refused with
    `label` first (``tradeoff`` from Python, the flag on the command line, which had named none:
    ``tradeoff: period '0' is not a step``)."""
    from .drive import Drive
    from .times import parse_freq

    example = "of degrees such as (0.1, 0.4)" if name == "deadbands" else "of steps such as ('1min', '5min')"
    # a text was run a letter a period, a number raised TypeError: each is a list of values
    if not isinstance(values, (tuple, list)):
        raise HybridtrackError(f"{label}: {name} must be a list {example}, got {values!r:.60}")
    values = tuple(values)
    if not values:
        raise HybridtrackError(f"{label}: no {name} to run")
    if name == "deadbands":
        for k, deadband in enumerate(values):
            try:
                Drive(deadband=deadband)  # refuses a deadband outside 0-10°
            except HybridtrackError as exc:
                raise HybridtrackError(f"{label}: {exc}") from None
            if deadband in values[:k]:  # the same days run twice, and counted twice in the table's means
                raise HybridtrackError(f"{label}: deadband {deadband!r} is given twice")
        return values
    steps = {}
    for period in values:
        if not isinstance(period, str):  # a number would be nanoseconds to pandas
            raise HybridtrackError(f"{label}: period {period!r:.60} is not a step such as '1min' or '10s'")
        try:
            step = parse_freq(period)  # as the synthetic sky reads it
        except HybridtrackError:
            raise HybridtrackError(f"{label}: period {period!r} is not a step such as '1min' or '10s'") from None
        if not pd.Timedelta(seconds=10) <= step <= pd.Timedelta(minutes=30):
            raise HybridtrackError(f"{label}: period {period!r} is outside 10 s to 30 min")
        if step in steps:  # the same days run twice, and counted twice in the table's means
            raise HybridtrackError(f"{label}: period {period!r} is given twice (as {steps[step]!r} and {period!r})")
        steps[step] = period
    return values


def _day(day: dict, plan: TradeoffPlan, config) -> list[dict]:
    """Every deadband on one day at one period; a row each."""
    from .simulation import SimulationConfig, simulate
    from .sky import synthetic

    frame = synthetic(day["site"], day["date"], weather=day["weather"], seed=day["seed"], freq=day["period"])
    days = (frame.index[-1] - frame.index[0] + (frame.index[1] - frame.index[0])) / pd.Timedelta(days=1)
    base = dataclasses.replace(config or SimulationConfig(), seed=day["seed"])
    rows = []
    for deadband in plan.deadbands:
        drives = {"drive": dataclasses.replace(base.drive, deadband=deadband),
                  "heliostat_drive": dataclasses.replace(base.heliostat_drive, deadband=deadband)}
        result = simulate(frame, day["site"], collector=day["collector"], strategy=plan.policy,
                          config=dataclasses.replace(base, **drives))
        summary = result.summary
        held_rms, held_p95 = held_error(result)
        rows.append({**day, "deadband": deadband, "rms": summary["tracking_error_deg"]["rms"],
                     "p95": summary["tracking_error_deg"]["p95"], "held_rms": held_rms, "held_p95": held_p95,
                     "energy": summary["energy_capture"], "moves_per_day": summary["moves"] / days})
    return rows


def held_error(result) -> tuple[float, float]:
    """DNI-weighted RMS and p95 of the pointing error between scans, degrees: from each scan to the
    next the collector holds its angle while the true target moves on (see the module's notes)."""
    from .collectors import direction_vectors
    from .metrics import TRACKING_MODES, weighted_quantile
    from .report import true_sun_terms

    log = result.log
    beam = np.nan_to_num(log["dni"].to_numpy(float)) * true_sun_terms(result)[1]  # as the run scored it
    single = result.collector.single_axis
    columns = ("",) if single else ("", "_azimuth")
    truth = [log[f"target_true{c}"].to_numpy(float) for c in columns]
    held = [log[f"angle{c}"].to_numpy(float)[:-1] for c in columns]
    fraction = np.arange(SUBSTEPS) / SUBSTEPS
    wanted = []
    for k, series in enumerate(truth):
        change = np.diff(series)
        if not single and k == 1:  # the azimuth axis turns the short way round
            change = (change + 180.0) % 360.0 - 180.0
        wanted.append(series[:-1, None] + change[:, None] * fraction)
    if single:
        error = np.abs(held[0][:, None] - wanted[0])
    else:  # the angle between the held and the wanted mirror normal
        actual = direction_vectors(np.repeat(held[0], SUBSTEPS), np.repeat(held[1], SUBSTEPS))  # past the zenith too
        target = direction_vectors(wanted[0].ravel(), wanted[1].ravel())
        error = np.degrees(np.arccos(np.clip(np.sum(actual * target, axis=1), -1.0, 1.0))).reshape(-1, SUBSTEPS)
    scored = (log["mode"].isin(TRACKING_MODES).to_numpy()[:-1] & (beam[:-1] > 0)
              & np.isfinite(error).all(axis=1))
    weight = np.repeat(beam[:-1][scored], SUBSTEPS)
    error = error[scored].ravel()
    if not weight.sum() > 0:
        return float("nan"), float("nan")
    return float(np.sqrt(np.sum(weight * error**2) / weight.sum())), weighted_quantile(error, weight, 0.95)


@dataclass
class TradeoffResult:
    """Every run (`runs`: a row per day, period and deadband) and the means per period and deadband (`table`)."""

    runs: pd.DataFrame
    plan: TradeoffPlan = field(default_factory=TradeoffPlan)

    @property
    def table(self) -> pd.DataFrame:
        """Per period and deadband: mean RMS and worst p95 at the scans and held between them, mean
        energy capture and mean moves a day."""
        return self.runs.groupby(["period", "deadband"], sort=False).agg(
            rms=("rms", "mean"), p95_worst=("p95", "max"), held_rms=("held_rms", "mean"),
            held_p95_worst=("held_p95", "max"), energy=("energy", "mean"), moves_per_day=("moves_per_day", "mean"))

    def __repr__(self) -> str:
        return f"TradeoffResult({len(self.runs)} runs)\n" + self.table.to_string(float_format=lambda v: f"{v:.4g}")

    def plot(self):
        """Pointing error held between scans (RMS and worst p95) against moves a day, one line per
        period, each point labelled with its deadband (a matplotlib Figure)."""
        from matplotlib.figure import Figure

        table = self.table.reset_index()
        figure = Figure(figsize=(11, 4.8), layout="constrained")
        axes = figure.subplots(1, 2, sharex=True)
        for k, (period, rows) in enumerate(table.groupby("period", sort=False)):
            for ax, metric in zip(axes, ("held_rms", "held_p95_worst")):
                ax.plot(rows["moves_per_day"], rows[metric], marker="o", color=f"C{k}", label=f"scan {period}",
                        gid=f"{metric}:{period}")
                for _, row in rows.iterrows():
                    ax.annotate(f"{row['deadband']:g}°", (row["moves_per_day"], row[metric]), fontsize="x-small",
                                xytext=(3, 3), textcoords="offset points")
        for ax, label in zip(axes, ("pointing error held between scans, RMS (°, mean over days)",
                                    "held between scans, p95 (°, worst day)")):
            ax.set_xscale("log")
            ax.set_xlabel("moves a day (mean, log scale)")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        axes[0].legend(fontsize="small")
        days = self.runs.groupby(["site", "date", "weather", "seed", "collector"]).ngroups
        figure.suptitle(f"{self.plan.policy}: the drive's deadband (labels) and scan period against pointing error, "
                        f"over {days} day(s)")
        return figure


def tradeoff(plan: TradeoffPlan | None = None, *, config=None, workers: int = 1, progress=None) -> TradeoffResult:
    """Run `plan`'s policy over its grid of deadbands and periods on every day of it.

    Parameters
    ----------
    plan : TradeoffPlan, optional
    config : SimulationConfig, optional
        The world, controller and drive every run shares (its seed is each day's, its deadband
        each run's).
    workers : int
        Processes to run days in; every day is seeded, so the table is the same for any number.
    progress : callable, optional
        Called with 1 after each day and period.
    """
    plan = plan or TradeoffPlan()
    rows = run_days(_day, plan.days(), (plan, config), workers, progress)
    return TradeoffResult(pd.DataFrame(rows), plan)
