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
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["summarize", "weighted_quantile", "acceptance", "ACCEPTANCE_HALF_ANGLE", "TRACKING_MODES"]

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


def summarize(log: pd.DataFrame, *, site: str, collector: str, strategy: str, moves: int, travel: float,
              events: pd.DataFrame, sun_up: np.ndarray, incidence: np.ndarray) -> dict:
    """The summary of a run (the keys of ``summary.json``)."""
    dni = np.nan_to_num(log["dni"].to_numpy(float))
    error = log["error"].to_numpy(float)
    beam = dni * incidence  # direct light on the aperture
    tracking = log["mode"].isin(TRACKING_MODES).to_numpy() & (beam > 0) & np.isfinite(error)
    w, e = beam[tracking], error[tracking]
    total = w.sum()
    if total > 0:
        stats = {"rms": float(np.sqrt(np.sum(w * e * e) / total)), "p95": weighted_quantile(np.abs(e), w, 0.95),
                 "max": float(np.max(np.abs(e))), "mean": float(np.sum(w * e) / total)}
        within = float(np.sum(w[np.abs(e) <= 0.5]) / total)
    else:
        stats = {"rms": None, "p95": None, "max": None, "mean": None}
        within = None
    offered = sun_up & (dni > 0)
    ideal = np.sum(dni[offered] * incidence[offered])
    gained = acceptance(np.where(tracking, error, np.inf), ACCEPTANCE_HALF_ANGLE[collector])
    captured = np.sum((dni * incidence * gained)[offered & tracking])
    modes = log["mode"].value_counts(normalize=True)
    sky_up = log.loc[sun_up, "sky"].value_counts(normalize=True) if sun_up.any() else pd.Series(dtype=float)
    tracking_events = events[events["from"].isin(TRACKING_MODES) & events["to"].isin(TRACKING_MODES)
                             & (events["from"] != events["to"])] if len(events) else events
    return {
        "site": site, "collector": collector, "strategy": strategy, "steps": int(len(log)),
        "start": log.index[0].isoformat(), "end": log.index[-1].isoformat(),
        "tracking_error_deg": {k: (None if v is None else round(v, 5)) for k, v in stats.items()},
        "within_0_5_deg": None if within is None else round(within, 5),
        "energy_capture": round(float(captured / ideal), 5) if ideal > 0 else None,
        "moves": int(moves), "travel_deg": round(float(travel), 3),
        "mode_share": {m: round(float(modes.get(m, 0.0)), 5) for m in
                       ("sensor", "astronomical", "search", "stow_wind", "stow_night", "fault")},
        "sky_share": {k: round(float(sky_up.get(k, 0.0)), 5) for k in ("sunny", "cloudy", "overcast", "unknown")},
        "mode_switches": int(len(tracking_events)),
        "stow_events": int(((events["to"] == "stow_wind") & (events["from"] != "stow_wind")).sum()) if len(events) else 0,
        "faults": int(((events["to"] == "fault") & (events["from"] != "fault")).sum()) if len(events) else 0,
        "alarms": int((events["from"] == events["to"]).sum()) if len(events) else 0,
    }
