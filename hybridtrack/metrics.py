"""How well a run tracked: DNI-weighted pointing error, energy, moves, modes.

Error metrics are scored against the true sun, over the steps where the collector should be
tracking (mode sensor, astronomical or search) and direct light is above zero. Each step is
weighted by the direct light on the aperture, DNI times the cosine of incidence on a perfectly
tracking aperture: an error under a bright sun costs more than one under a thin one. The
cosine matters little for a north-south trough, but an east-west trough at an equinox sunrise
sees the sun nearly along its axis, where its angle swings wildly and it collects nothing.

Energy capture is the direct energy the collector intercepts over what a perfect tracker
would, counted whenever the true sun is up with DNI above zero. Stowing for wind or night
while the sun shines is a loss. The optical acceptance model is smooth,
``η(e) = 1 / (1 + (e/θ½)⁴)``: flat near zero and half at the half-power angle θ½.
θ½ is 1.0° for a parabolic trough (a 70 mm receiver at about 1.7 m focal length), 0.8°
for a Fresnel row, and 0.25° of mirror-normal error for a heliostat (the reflected beam
moves twice as far).

Counts and shares have one definition each, used by the summary, the daily table and the
reports (see ``docs/metrics.md``): mode and sky shares are both over every step of the run,
the sky counting ``night`` while the true sun is down; every row of ``events.csv`` is either a
mode switch (``from`` differs from ``to``) or an alarm (they are equal); ``moves`` counts the
steps in which the drive turned an axis.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["summarize", "daily", "shares", "event_counts", "moved_axes", "weighted_quantile", "acceptance",
           "ACCEPTANCE_HALF_ANGLE", "TRACKING_MODES"]

TRACKING_MODES = ("sensor", "astronomical", "search")
ACCEPTANCE_HALF_ANGLE = {"trough-ns": 1.0, "trough-ew": 1.0, "fresnel": 0.8, "heliostat": 0.25}


def acceptance(error, half_angle: float) -> np.ndarray:
    """Share of the direct light an aperture intercepts at a pointing error (degrees)."""
    e = np.asarray(error, float)
    return 1.0 / (1.0 + (e / half_angle) ** 4)


def weighted_quantile(values, weights, q: float) -> float:
    """The `q` quantile of `values` with `weights` (step interpolation on the weighted CDF)."""
    v = np.asarray(values, float)
    w = np.asarray(weights, float)
    if v.size == 0 or not np.sum(w) > 0:
        return float("nan")
    order = np.argsort(v)
    cdf = np.cumsum(w[order]) / np.sum(w)
    return float(v[order][min(np.searchsorted(cdf, q), len(v) - 1)])


def _steps(log: pd.DataFrame, collector: str, sun_up: np.ndarray, incidence: np.ndarray) -> pd.DataFrame:
    """Per-step terms every metric is built from, so the run summary and the daily table agree.

    Columns: ``weight`` (direct light on the aperture where the error is scored, else 0),
    ``error``, ``offered`` (direct light a perfect tracker would catch), ``captured`` (what this
    one caught through the acceptance model) and ``moved`` (drive axes that moved this step).
    """
    dni = np.nan_to_num(log["dni"].to_numpy(float))
    error = log["error"].to_numpy(float)
    beam = dni * np.asarray(incidence, float)  # direct light on the aperture
    tracking = log["mode"].isin(TRACKING_MODES).to_numpy() & (beam > 0) & np.isfinite(error)
    offered = np.where(np.asarray(sun_up, bool) & (dni > 0), beam, 0.0)
    gained = acceptance(np.where(tracking, error, np.inf), ACCEPTANCE_HALF_ANGLE[collector])
    return pd.DataFrame({"weight": np.where(tracking, beam, 0.0), "error": np.where(tracking, error, np.nan),
                         "offered": offered, "captured": np.where(tracking, offered * gained, 0.0),
                         "moved": moved_axes(log)}, index=log.index)


def moved_axes(log: pd.DataFrame) -> np.ndarray:
    """Drive axes that moved at each step, from the logged angles (a heliostat has two).

    The drive counts a move at every step in which it turns an axis, so the sum over a run is
    the run's ``moves``.
    """
    moved = np.zeros(len(log), int)
    for column in ("angle", "angle_azimuth"):
        if column in log.columns:
            angle = log[column].to_numpy(float)
            change = np.abs(np.diff(angle, prepend=angle[:1]))
            if column == "angle_azimuth":  # logged modulo 360
                change = np.minimum(change, 360.0 - change)
            moved += (change > 1e-9).astype(int)
    return moved


def _error_stats(steps: pd.DataFrame) -> tuple[dict, float | None]:
    w = steps["weight"].to_numpy()
    e = steps["error"].to_numpy()
    scored = w > 0
    w, e = w[scored], e[scored]
    total = w.sum()
    if not total > 0:
        return {"rms": None, "p95": None, "max": None, "mean": None}, None
    stats = {"rms": float(np.sqrt(np.sum(w * e * e) / total)), "p95": weighted_quantile(np.abs(e), w, 0.95),
             "max": float(np.max(np.abs(e))), "mean": float(np.sum(w * e) / total)}
    return stats, float(np.sum(w[np.abs(e) <= 0.5]) / total)


def shares(log: pd.DataFrame, sun_up: np.ndarray) -> tuple[dict, dict]:
    """Mode shares and sky shares, both over every step of the run (the same base).

    The sky share counts the steps with the true sun down as ``night``, so each set of shares
    sums to one and ``stow_night`` can be read beside ``night``.
    """
    from .control import MODES, SKY_CODES

    n = max(len(log), 1)
    up = np.asarray(sun_up, bool)
    modes = log["mode"].value_counts()  # by category, without making a string per step
    sky = log["sky"][up].value_counts()
    night = float(sky.get("night", 0)) + float((~up).sum())
    return ({m: round(float(modes.get(m, 0)) / n, 5) for m in MODES},
            {k: round((night if k == "night" else float(sky.get(k, 0))) / n, 5) for k in (*SKY_CODES, "night")})


def event_counts(events: pd.DataFrame) -> dict:
    """Counts of `events` rows: every row of ``events.csv`` is a mode switch or an alarm.

    ``mode_switches``: rows whose ``from`` differs from ``to`` (every change of mode, stows
    included). ``tracking_switches``: those between two tracking modes (sensor, astronomical,
    search), where a flickering sky would show. ``alarms``: rows with ``from`` equal to ``to``
    (a guard fired without a change of mode). ``stow_events``/``faults``: switches into
    ``stow_wind``/``fault``. ``mode_switches + alarms`` is the number of rows.
    """
    if not len(events):
        return {"mode_switches": 0, "tracking_switches": 0, "stow_events": 0, "faults": 0, "alarms": 0}
    change = (events["from"] != events["to"]).to_numpy()
    tracking = events["from"].isin(TRACKING_MODES).to_numpy() & events["to"].isin(TRACKING_MODES).to_numpy()
    return {"mode_switches": int(change.sum()), "tracking_switches": int((change & tracking).sum()),
            "stow_events": int((change & (events["to"] == "stow_wind").to_numpy()).sum()),
            "faults": int((change & (events["to"] == "fault").to_numpy()).sum()), "alarms": int((~change).sum())}


def _rounded(value, digits: int = 5):
    return None if value is None else round(value, digits)


def summarize(log: pd.DataFrame, *, site: str, collector: str, strategy: str, moves: int, travel: float,
              events: pd.DataFrame, sun_up: np.ndarray, incidence: np.ndarray) -> dict:
    """The summary of a run (the keys of ``summary.json``); every count and share is defined here."""
    steps = _steps(log, collector, sun_up, incidence)
    stats, within = _error_stats(steps)
    ideal = steps["offered"].sum()
    mode_share, sky_share = shares(log, sun_up)
    return {
        "site": site, "collector": collector, "strategy": strategy, "steps": int(len(log)),
        "start": log.index[0].isoformat(), "end": log.index[-1].isoformat(),
        "tracking_error_deg": {k: _rounded(v) for k, v in stats.items()},
        "within_0_5_deg": _rounded(within),
        "energy_capture": round(float(steps["captured"].sum() / ideal), 5) if ideal > 0 else None,
        "moves": int(moves), "travel_deg": round(float(travel), 3),
        "share_base": "every step of the run; sky 'night' while the true sun is down",
        "mode_share": mode_share, "sky_share": sky_share,
        **event_counts(events),
    }


def daily(log: pd.DataFrame, *, collector: str, tz, sun_up: np.ndarray, incidence: np.ndarray) -> pd.DataFrame:
    """One row per local day, with the run summary's definitions applied to that day.

    Columns: ``energy_capture``, ``rms``/``p95``/``max`` (degrees, DNI-weighted), ``moves``,
    ``stow_wind_min`` and ``stow_night_min`` (minutes in each mode), ``dni_kwh_m2`` (direct
    normal irradiation), ``max_wind`` (m/s) and the sky shares (``sky_sunny`` ... ``sky_night``,
    over the day's steps).
    """
    steps = _steps(log, collector, sun_up, incidence)
    local = log.index.tz_convert(tz)
    day = pd.Index(local.date, name="date")
    elapsed = np.asarray((log.index - log.index[0]) / pd.Timedelta(minutes=1), float)  # any index unit
    minutes = np.diff(elapsed, append=elapsed[-1])
    if len(minutes) > 1:
        minutes[-1] = minutes[-2]
    minutes = np.minimum(minutes, np.median(minutes) if len(minutes) else 1.0)  # a gap is not time in a mode
    rows = []
    sky = log["sky"].astype(str).where(np.asarray(sun_up, bool), "night")
    for date, where in pd.Series(np.arange(len(log)), index=day).groupby(level=0):
        idx = where.to_numpy()
        part = steps.iloc[idx]
        stats, within = _error_stats(part)
        offered = part["offered"].sum()
        mode = log["mode"].astype(str).to_numpy()[idx]
        counts = sky.iloc[idx].value_counts(normalize=True)
        rows.append({
            "date": date, "energy_capture": part["captured"].sum() / offered if offered > 0 else np.nan,
            "rms": stats["rms"], "p95": stats["p95"], "max": stats["max"], "within_0_5": within,
            "moves": int(part["moved"].sum()),
            "stow_wind_min": float(minutes[idx][mode == "stow_wind"].sum()),
            "stow_night_min": float(minutes[idx][mode == "stow_night"].sum()),
            "dni_kwh_m2": float(np.nansum(log["dni"].to_numpy(float)[idx] * minutes[idx]) / 60e3),
            "max_wind": float(np.nanmax(log["wind_speed"].to_numpy(float)[idx])) if len(idx) else np.nan,
            **{f"sky_{k}": float(counts.get(k, 0.0)) for k in ("sunny", "cloudy", "overcast", "unknown", "night")},
        })
    return pd.DataFrame(rows).set_index("date").astype(float).astype({"moves": int})
