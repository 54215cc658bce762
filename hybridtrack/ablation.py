"""What the classifier is worth: every policy over a seeded set of days, on the same world.

Each day (site × season × weather × seed × collector) is one synthetic frame; every policy runs
on it with the same world (mount, clock, sensor errors and noise draws) and the same drive.
The policies that bracket the classifier:

* ``hybrid-always`` removes it (the sensor is tracked whenever it reads valid);
* ``hybrid-oracle`` replaces it with the truth (the frame's own sky label);
* ``hybrid`` is the fuzzy switch between them. The share of the RMS gap between the first two
  that the hybrid recovers is what the classifier is worth.

Beside them: ``hybrid-nocal`` (no calibration), ``astronomical`` (open loop as installed),
``astronomical-commissioned`` (open loop after a commissioning fit) and ``sensor`` (closed loop
as sold). Per run the table also says why a closed loop lost energy: the share of the direct
energy it failed to intercept (through the acceptance model of `hybridtrack.metrics`) while
following the sensor as it read (cloud pull: the sensor saw light, and it was not the sun's
alone; the readings the Kalman gate rejected as outliers count here, since a pulled reading is
rejected once the pull has dragged the filter), and the share while searching or while the sensor
saw too little light or no sun in view (a lost sun). Running the same days in a world without
pull (``[sensor] patch_distance = [0, 0]``: the bright patch sits on the sun) is the ablation
that shows the first share is caused by the pull (docs/world.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .control import STRATEGIES
from .control.modes import LOW_LIGHT, OK, OUT_OF_VIEW, OUTLIER, SENSOR_STATUS
from .errors import HybridtrackError

__all__ = ["AblationPlan", "AblationResult", "ablate", "run_days", "SEASONS", "SITE_YEARS"]

#: The typical days of each season (month-day) and the year each site's days are taken from.
SEASONS = {"spring": "03-20", "summer": "06-21", "autumn": "09-23", "winter": "12-21"}
SITE_YEARS = {"lanzhou": 2021, "nanjing": 2013}


@dataclass(frozen=True)
class AblationPlan:
    """Which days and policies to run: every combination of the fields.

    The default is 2 sites × 4 seasons × 5 seeds of mixed skies (40 days) on two collectors.
    """

    sites: tuple[str, ...] = ("lanzhou", "nanjing")
    seasons: tuple[str, ...] = tuple(SEASONS)
    weather: tuple[str, ...] = ("mixed",)
    seeds: tuple[int, ...] = (1, 2, 3, 4, 5)
    collectors: tuple[str, ...] = ("trough-ns", "fresnel")
    policies: tuple[str, ...] = STRATEGIES

    def __post_init__(self) -> None:
        for name in PLAN_FIELDS:
            object.__setattr__(self, name, checked_values(name, getattr(self, name), "ablate"))

    def days(self) -> list[dict]:
        """One dict per day: site, date, weather, seed, collector."""
        out = []
        for site in self.sites:
            year = SITE_YEARS.get(site, 2021)
            for season in self.seasons:
                for weather in self.weather:
                    for seed in self.seeds:
                        for collector in self.collectors:
                            out.append({"site": site, "season": season, "date": f"{year}-{SEASONS[season]}",
                                        "weather": weather, "seed": int(seed), "collector": collector})
        return out


#: The fields of an `AblationPlan` that list what to run.
PLAN_FIELDS = ("sites", "seasons", "weather", "seeds", "collectors", "policies")


def checked_values(name: str, values, label: str) -> tuple:
    """An `AblationPlan` field (`PLAN_FIELDS`) as the plan keeps it: a tuple of known values,
    none twice, the built-in sites by their own names; refused with `label` first (``ablate``
    from Python, the flag on the command line)."""
    from . import params
    from . import sites as known_sites
    from .collectors import KINDS
    from .sky import DAY_TYPES, weather_name

    # a text had been run a letter a value ("unknown site 'l'"); a number raised TypeError
    if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
        raise HybridtrackError(f"{label}: {name} must be a list, such as ({values!r},), got {values!r:.60}")
    values = tuple(values)
    if not values:
        raise HybridtrackError(f"{label}: no {name} to run")
    if name == "sites":  # a built-in site by its own name: 'Nanjing' had taken the days of 2021, 'nanjing' 2013
        try:
            values = tuple(site if isinstance(site, known_sites.Site) else known_sites.get(site).name
                           for site in values)
        except HybridtrackError as exc:
            raise HybridtrackError(f"{label}: {exc}") from None
    elif name == "seeds":
        values = tuple(params.seed(seed, f"{label}: seed") for seed in values)
    else:
        what, known = {"seasons": ("season", tuple(SEASONS)), "weather": ("weather", (*DAY_TYPES, "mixed")),
                       "collectors": ("collector", KINDS), "policies": ("policy", STRATEGIES)}[name]
        # a weather as synthetic reads it ('Sunny' is sunny), as a site by its own name
        read = tuple(map(weather_name, values)) if name == "weather" else values
        unknown = next((given for given, value in zip(values, read) if value not in known), None)
        if unknown is not None:
            raise HybridtrackError(f"{label}: unknown {what} {unknown!r}; choose from {', '.join(known)}")
        values = read
    twice = next((value for k, value in enumerate(values) if value in values[:k]), None)
    if twice is not None:  # the same days run twice, and counted twice in the table's means
        raise HybridtrackError(f"{label}: {name} names {twice!r} twice")
    return values


def _day(day: dict, policies: tuple[str, ...], config) -> list[dict]:
    """Every policy on one day; a row each."""
    from .simulation import SimulationConfig, simulate
    from .sky import synthetic

    frame = synthetic(day["site"], day["date"], weather=day["weather"], seed=day["seed"])
    base = dataclasses.replace(config or SimulationConfig(), seed=day["seed"])
    rows = []
    for policy in policies:
        result = simulate(frame, day["site"], collector=day["collector"], strategy=policy, config=base)
        rows.append({**day, "policy": policy, **_metrics(result)})
    return rows


#: Sensor statuses under which the sensor read a pointing signal (followed, or gated out as an outlier).
READ = tuple(SENSOR_STATUS[k] for k in (OK, OUTLIER))
#: Sensor statuses under which it had none: too little light, or the sun outside its view.
UNSEEN = tuple(SENSOR_STATUS[k] for k in (LOW_LIGHT, OUT_OF_VIEW))


def _metrics(result) -> dict:
    """The headline numbers of a run and why a closed loop lost: shares of the energy it lost."""
    from .metrics import ACCEPTANCE_HALF_ANGLE, acceptance

    summary, log = result.summary, result.log
    error = summary["tracking_error_deg"]
    beam = np.nan_to_num(log["dni"].to_numpy(float))
    mode = log["mode"].astype(str).to_numpy()
    on_sensor = mode == "sensor"
    status = log["sensor_status"].astype(str).to_numpy()
    read = np.isin(status, READ)
    unseen = np.isin(status, UNSEEN)
    gained = acceptance(np.nan_to_num(log["error"].to_numpy(float), nan=np.inf),
                        ACCEPTANCE_HALF_ANGLE[result.collector.kind])
    lost_energy = beam * (1.0 - gained) * np.isin(mode, ["sensor", "astronomical", "search"])
    total = lost_energy.sum()
    hours = np.diff(log.index.as_unit("ns").asi8).mean() / 3.6e12 if len(log) > 1 else 0.0

    def share(mask):
        return float(lost_energy[mask].sum() / total) if total > 0 else float("nan")

    return {"rms": error["rms"], "p95": error["p95"], "energy": summary["energy_capture"],
            "sensor_share": summary["mode_share"]["sensor"], "pull_loss_share": share(on_sensor & read),
            "lost_sun_loss_share": share((mode == "search") | (on_sensor & unseen)),
            "lost_kwh": float(total * hours / 1000.0)}


def _pooled(shares: np.ndarray, lost: np.ndarray) -> float:
    """Shares of each run's lost energy pooled over the runs: the share of all the energy lost."""
    known = np.isfinite(shares) & (lost > 0)
    return float((shares[known] * lost[known]).sum() / lost[known].sum()) if known.any() else float("nan")


def _interval(values: np.ndarray, rng: np.random.Generator, draws: int = 2000) -> tuple[float, float]:
    """A 95 % bootstrap interval of the mean."""
    values = values[np.isfinite(values)]
    if len(values) < 2:
        return float("nan"), float("nan")
    means = rng.choice(values, size=(draws, len(values)), replace=True).mean(axis=1)
    return float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


@dataclass
class AblationResult:
    """Every run (`runs`, one row per day and policy) and the table per policy (`table`)."""

    runs: pd.DataFrame
    plan: AblationPlan = field(default_factory=AblationPlan)

    @property
    def table(self) -> pd.DataFrame:
        """Per policy: mean, 95 % interval of the mean and worst of RMS, p95 and energy capture, and
        of all the direct energy the policy lost while tracking, the shares lost to pull and to a
        lost sun."""
        rng = np.random.default_rng(0)
        rows = {}
        for policy, runs in self.runs.groupby("policy", sort=False):
            row = {}
            for metric, worst in (("rms", np.max), ("p95", np.max), ("energy", np.min)):
                values = runs[metric].to_numpy(float)
                low, high = _interval(values, rng)
                row.update({f"{metric} mean": np.nanmean(values), f"{metric} 95% low": low,
                            f"{metric} 95% high": high, f"{metric} worst": worst(values)})
            lost = runs["lost_kwh"].to_numpy(float)
            for name, column in (("pull loss share", "pull_loss_share"), ("lost-sun loss share", "lost_sun_loss_share")):
                row[name] = _pooled(runs[column].to_numpy(float), lost)
            rows[policy] = row
        return pd.DataFrame(rows).T

    def gap_recovered(self) -> float:
        """Share of the mean-RMS gap between ``hybrid-always`` and ``hybrid-oracle`` the hybrid recovers."""
        mean = self.runs.groupby("policy")["rms"].mean()
        if not {"hybrid", "hybrid-always", "hybrid-oracle"} <= set(mean.index):
            return float("nan")
        gap = mean["hybrid-always"] - mean["hybrid-oracle"]
        return float((mean["hybrid-always"] - mean["hybrid"]) / gap) if gap != 0 else float("nan")

    def gap_note(self) -> str:
        """`gap_recovered` in words, or why there is no share to give (a policy missing, no gap)."""
        share = self.gap_recovered()
        if not math.isnan(share):
            return f"hybrid recovers {share:.0%} of the always→oracle RMS gap"
        policies = set(self.runs["policy"])
        if not {"hybrid", "hybrid-always", "hybrid-oracle"} <= policies:
            return "no always→oracle gap: run hybrid, hybrid-always and hybrid-oracle to measure it"
        return "no always→oracle gap: the true sky label changes nothing on these days"

    def __repr__(self) -> str:
        days = len(self.runs) // max(self.runs["policy"].nunique(), 1)
        return (f"AblationResult({days} day-runs × {self.runs['policy'].nunique()} policies; "
                f"{self.gap_note()})\n"
                + self.table.to_string(float_format=lambda v: f"{v:.4f}"))

    def _repr_html_(self) -> str:
        return (f"<p>{self.gap_note()}</p>"
                + self.table.to_html(float_format=lambda v: f"{v:.4f}"))

    def plot(self):
        """RMS and energy capture of every day, per policy, with each mean (a matplotlib Figure)."""
        from matplotlib.figure import Figure

        policies = list(dict.fromkeys(self.runs["policy"]))
        figure = Figure(figsize=(11, 4.8), layout="constrained")
        axes = figure.subplots(1, 2)
        rng = np.random.default_rng(0)
        for ax, metric, label in ((axes[0], "rms", "pointing error RMS (°)"), (axes[1], "energy", "energy capture")):
            for k, policy in enumerate(policies):
                values = self.runs.loc[self.runs["policy"] == policy, metric].to_numpy(float)
                ax.scatter(k + rng.uniform(-0.18, 0.18, len(values)), values, s=9, alpha=0.45, color=f"C{k}")
                ax.hlines(np.nanmean(values), k - 0.3, k + 0.3, color="black", linewidth=2)
            ax.set_xticks(range(len(policies)), policies, rotation=30, ha="right")
            ax.set_ylabel(label)
            ax.grid(axis="y", alpha=0.3)
        axes[0].set_yscale("log")
        days = len(self.runs) // max(len(policies), 1)
        figure.suptitle(f"Every policy on the same {days} seeded day-runs (bar: mean); {self.gap_note()}")
        return figure


def ablate(plan: AblationPlan | None = None, *, config=None, workers: int = 1, progress=None) -> AblationResult:
    """Run every policy of `plan` on every day of it.

    Parameters
    ----------
    plan : AblationPlan, optional
    config : SimulationConfig, optional
        The world, controller and drive every policy shares (its seed is replaced by each day's).
    workers : int
        Processes to run days in; every day is seeded, so the table is the same for any number.
    progress : callable, optional
        Called with 1 after each day.
    """
    plan = plan or AblationPlan()
    return AblationResult(pd.DataFrame(run_days(_day, plan.days(), (plan.policies, config), workers, progress)), plan)


def run_days(run, days: list[dict], arguments: tuple, workers: int, progress=None) -> list[dict]:
    """``run(day, *arguments)`` (a list of rows) for every day, in `workers` processes; the rows in
    the days' order."""
    if not 1 <= workers <= 64:
        raise HybridtrackError(f"workers must be 1-64, got {workers}")
    if workers == 1:
        results = []
        for day in days:
            results.append(run(day, *arguments))
            if progress is not None:
                progress(1)
    else:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(workers) as pool:
            futures = [pool.submit(run, day, *arguments) for day in days]
            results = []
            for future in futures:
                results.append(future.result())
                if progress is not None:
                    progress(1)
    return [row for rows in results for row in rows]
