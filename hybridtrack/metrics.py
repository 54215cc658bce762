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

from . import params
from .errors import HybridtrackError
from .times import check_tz, stamp_minutes

__all__ = ["summarize", "score", "RunningSummary", "offered_light", "daily", "shares", "share_counts", "event_counts", "moved_axes",
           "weighted_quantile", "acceptance", "held_error", "ACCEPTANCE_HALF_ANGLE", "TRACKING_MODES",
           "HISTOGRAM_RESOLUTION"]

TRACKING_MODES = ("sensor", "astronomical", "search")
ACCEPTANCE_HALF_ANGLE = {"trough-ns": 1.0, "trough-ew": 1.0, "trough": 1.0, "fresnel": 0.8, "heliostat": 0.25}


def acceptance(error, half_angle: float) -> np.ndarray:
    """Share of the direct light an aperture intercepts at a pointing error (degrees)."""
    ratio = np.asarray(error, float) / half_angle
    squared = ratio * ratio  # squared twice: numpy's general power is ten times slower
    return 1.0 / (1.0 + squared * squared)


def weighted_quantile(values, weights, q: float) -> float:
    """The `q` quantile of `values` with `weights` (step interpolation on the weighted CDF)."""
    v = np.asarray(values, float)
    w = np.asarray(weights, float)
    if v.size == 0 or not np.sum(w) > 0:
        return float("nan")
    order = np.argsort(v)
    cdf = np.cumsum(w[order]) / np.sum(w)
    return float(v[order][min(np.searchsorted(cdf, q), len(v) - 1)])


def offered_light(dni, sun_up, incidence) -> np.ndarray:
    """Direct light a perfect tracker would catch at each step (W/m², 0 with the sun down or no
    DNI): the weight of energy capture, and of a collector in a field's figures."""
    dni = np.nan_to_num(np.asarray(dni, float))
    return np.where(np.asarray(sun_up, bool) & (dni > 0), dni * np.asarray(incidence, float), 0.0)


def _half_angle(collector: str) -> float:
    """The acceptance half-angle of a kind of collector, refused by name for another kind."""
    if collector not in ACCEPTANCE_HALF_ANGLE:
        raise HybridtrackError(f"collector {collector!r}: choose {', '.join(ACCEPTANCE_HALF_ANGLE)}")
    return ACCEPTANCE_HALF_ANGLE[collector]


#: The log columns every metric reads.
SCORED_COLUMNS = ("dni", "error", "mode")


def _check_log(log: pd.DataFrame, sun_up, incidence) -> None:
    """Refuse a log without the columns the metrics read, or per-step arrays of another length
    (a KeyError and numpy's broadcast error had come from deep inside)."""
    missing = [c for c in SCORED_COLUMNS if c not in log.columns]
    if missing:
        raise HybridtrackError(f"the log has no {', '.join(map(repr, missing))} column; a run's log has "
                               f"{', '.join(SCORED_COLUMNS)}")
    for name, values in (("sun_up", sun_up), ("incidence", incidence)):
        if np.shape(values) != (len(log),):
            raise HybridtrackError(f"{name} needs one value per step of the log ({len(log)}), got shape "
                                   f"{np.shape(values)}")


def _steps(log: pd.DataFrame, collector: str, sun_up: np.ndarray, incidence: np.ndarray) -> pd.DataFrame:
    """Per-step terms every metric is built from, so the run summary and the daily table agree.

    Columns: ``weight`` (direct light on the aperture where the error is scored, else 0),
    ``error``, ``offered`` (direct light a perfect tracker would catch), ``captured`` (what this
    one caught through the acceptance model), the light in W min/m² over each stamp's own step
    (`hybridtrack.times.stamp_minutes`: a frame of mixed steps weighs a minute alike in each).
    Not the moves (`moved_axes`): only the daily table counts them by step, and the summary's
    come from the drive (8 ms of a Fresnel row-year's scoring, which never read them).
    """
    half_angle = _half_angle(collector)
    _check_log(log, sun_up, incidence)
    dni = np.nan_to_num(log["dni"].to_numpy(float))
    error = log["error"].to_numpy(float)
    beam = dni * np.asarray(incidence, float)  # direct light on the aperture
    tracking = _in_modes(log["mode"], TRACKING_MODES) & (beam > 0) & np.isfinite(error)
    minutes = stamp_minutes(log.index)  # light over the stamp's own step, so mixed steps weigh alike
    offered = offered_light(dni, sun_up, incidence) * minutes
    captured = np.zeros(len(log))
    captured[tracking] = offered[tracking] * acceptance(error[tracking], half_angle)
    return pd.DataFrame({"weight": np.where(tracking, beam * minutes, 0.0), "error": np.where(tracking, error, np.nan),
                         "offered": offered, "captured": captured}, index=log.index,
                        copy=False)


def _in_modes(mode: pd.Series, modes: tuple) -> np.ndarray:
    """Whether each step's mode is one of `modes`: a run's categorical column by its codes (pandas'
    own ``isin`` took 7 ms over a year's steps, this well under one)."""
    if isinstance(mode.dtype, pd.CategoricalDtype):
        return np.isin(mode.cat.codes.to_numpy(), np.flatnonzero(mode.cat.categories.isin(modes)))
    return mode.isin(modes).to_numpy()


def moved_axes(log: pd.DataFrame) -> np.ndarray:
    """Drive axes that moved at each step, from the logged angles (a heliostat has two).

    The drive counts a move at every step in which it turns an axis. The log holds no angle from
    before its first step, so a move made at that step (from where the run found the collector,
    stowed) is not seen here: the sum over a run is the run's ``moves`` less any made at its
    first step (a noon-to-1 pm frame: 29 here, 30 in the summary).
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


def held_error(log: pd.DataFrame) -> pd.Series:
    """The pointing error just before each next scan, degrees: the collector where this scan's
    move left it (``angle``, and a heliostat's ``angle_azimuth``) against the true target where
    the next scan finds the sun (``target_true``, ``target_true_azimuth``). NaN at the last scan
    and wherever either target is NaN.

    The run's ``error`` (and every score built on it) is taken at each scan after its move: the
    error of a drive that keeps up with the sun between scans, as a PLC scanning every few
    seconds does. A run at coarse steps (30 minutes) models such a PLC coarsely; were the drive
    to move only at the run's scans, its error would grow over each step from ``error`` to this.
    The gap between the two is what the coarse step leaves unscored (``docs/robustness.md``,
    "Coarse steps"). A single axis' error is signed (angle less target, within ±180°, as
    ``error`` is); a heliostat's is the angle between its mirror normal and the one it needs.
    """
    missing = [c for c in ("angle", "target_true") if c not in log.columns]
    if missing:
        raise HybridtrackError(f"held_error: the log has no {', '.join(map(repr, missing))} column; a run's log has "
                               "angle and target_true")
    angle = log["angle"].to_numpy(float)
    wanted = np.append(log["target_true"].to_numpy(float)[1:], np.nan)
    if "target_true_azimuth" not in log.columns:  # one axis
        with np.errstate(invalid="ignore"):
            error = (angle - wanted + 180.0) % 360.0 - 180.0
        return pd.Series(error, index=log.index, name="held_error")
    azimuth = np.radians(log["angle_azimuth"].to_numpy(float))
    wanted_azimuth = np.radians(np.append(log["target_true_azimuth"].to_numpy(float)[1:], np.nan))
    e, w = np.radians(angle), np.radians(wanted)
    # the angle between two directions given as (elevation, azimuth): the haversine form keeps
    # its precision at small angles, where the arccos of a dot product loses it
    half = np.sin((w - e) / 2.0) ** 2 + np.cos(e) * np.cos(w) * np.sin((wanted_azimuth - azimuth) / 2.0) ** 2
    error = np.degrees(2.0 * np.arcsin(np.sqrt(np.clip(half, 0.0, 1.0))))
    return pd.Series(error, index=log.index, name="held_error")


def _scored_errors(steps: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scored steps' (weight above zero) weights, errors and |errors|."""
    w = steps["weight"].to_numpy()
    scored = w > 0
    e = steps["error"].to_numpy()[scored]
    return w[scored], e, np.abs(e)


def _error_sums(steps: pd.DataFrame) -> dict:
    """The running sums the error metrics are made of, over the scored steps (weight above zero):
    ``weight`` Σw, ``squared`` Σw·e², ``first`` Σw·e, ``within`` Σw where |e| ≤ 0.5°, ``max``
    max |e|. Sums of two spans add (``max`` takes the larger), so a streamed run keeps only these."""
    return _sums(*_scored_errors(steps))


def _sums(w: np.ndarray, e: np.ndarray, magnitude: np.ndarray) -> dict:
    """`_error_sums` of the scored weights, errors and |errors| (`_scored_errors`)."""
    return {"weight": float(w.sum()), "squared": float(np.sum(w * e * e)), "first": float(np.sum(w * e)),
            "within": float(np.sum(w[magnitude <= 0.5])), "max": float(np.max(magnitude)) if e.size else 0.0}


def _error_from_sums(sums: dict, p95) -> tuple[dict, float | None]:
    """The error metrics (RMS, p95, max, mean) and the share within 0.5° from `_error_sums`."""
    total = sums["weight"]
    if not total > 0:
        return {"rms": None, "p95": None, "max": None, "mean": None}, None
    stats = {"rms": float(np.sqrt(sums["squared"] / total)), "p95": p95, "max": sums["max"],
             "mean": float(sums["first"] / total)}
    return stats, float(sums["within"] / total)


def _error_stats(steps: pd.DataFrame) -> tuple[dict, float | None]:
    w, e, magnitude = _scored_errors(steps)  # once for the sums and the p95
    return _error_from_sums(_sums(w, e, magnitude), weighted_quantile(magnitude, w, 0.95))


def share_counts(log: pd.DataFrame, sun_up: np.ndarray) -> tuple[dict, dict]:
    """Steps in each mode and each sky (``night`` while the true sun is down): what `shares`
    divides by the steps; counts of two spans add."""
    from .control import MODES, SKY_CODES

    up = np.asarray(sun_up, bool)
    modes = log["mode"].value_counts()  # by category, without making a string per step
    sky = log["sky"][up].value_counts()
    night = int(sky.get("night", 0)) + int((~up).sum())
    return ({m: int(modes.get(m, 0)) for m in MODES},
            {k: night if k == "night" else int(sky.get(k, 0)) for k in (*SKY_CODES, "night")})


def _shares_from_counts(modes: dict, sky: dict, steps: int) -> tuple[dict, dict]:
    n = max(steps, 1)
    return ({m: round(float(c) / n, 5) for m, c in modes.items()}, {k: round(float(c) / n, 5) for k, c in sky.items()})


def shares(log: pd.DataFrame, sun_up: np.ndarray) -> tuple[dict, dict]:
    """Mode shares and sky shares, both over every step of the run (the same base).

    The sky share counts the steps with the true sun down as ``night``, so each set of shares
    sums to one and ``stow_night`` can be read beside ``night``.
    """
    return _shares_from_counts(*share_counts(log, sun_up), len(log))


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
    scored = score(log, collector=collector, moves=moves, travel=travel, events=events, sun_up=sun_up,
                   incidence=incidence)
    return _compose(site=site, collector=collector, strategy=strategy, steps=len(log), start=log.index[0],
                    end=log.index[-1], scores=scored, shares=shares(log, sun_up))


def score(log: pd.DataFrame, *, collector: str, moves: int, travel: float, events: pd.DataFrame,
          sun_up: np.ndarray, incidence: np.ndarray) -> dict:
    """The summary's scores of a run, without its mode and sky shares: its pointing error
    (``tracking_error_deg``, ``within_0_5_deg``), ``energy_capture``, ``moves``, ``travel_deg``
    and its `event_counts`. The log needs only its ``dni``, ``error`` and ``mode`` columns (a
    field's collector that keeps no log is scored from those alone)."""
    steps = _steps(log, collector, sun_up, incidence)
    stats, within = _error_stats(steps)
    return {**_scores(stats=stats, within=within, captured=float(steps["captured"].sum()),
                      offered=float(steps["offered"].sum()), moves=moves, travel=travel),
            **event_counts(events)}


def _scores(*, stats, within, captured, offered, moves, travel) -> dict:
    """The error, energy and drive keys of a summary, rounded as it gives them."""
    return {
        "tracking_error_deg": {k: _rounded(v) for k, v in stats.items()},
        "within_0_5_deg": _rounded(within),
        "energy_capture": round(float(captured / offered), 5) if offered > 0 else None,
        "moves": int(moves), "travel_deg": round(float(travel), 3),
    }


def _compose(*, site, collector, strategy, steps, start, end, scores, shares) -> dict:
    """The summary's keys, in order, from its parts (`summarize` and `RunningSummary` both): the
    run's scores (`score`; its event counts last) and its shares."""
    mode_share, sky_share = shares
    events = {k: v for k, v in scores.items() if k not in _SCORE_KEYS}
    return {
        "site": site, "collector": collector, "strategy": strategy, "steps": int(steps),
        "start": start.isoformat(), "end": end.isoformat(),
        **{k: scores[k] for k in _SCORE_KEYS},
        "share_base": "every step of the run; sky 'night' while the true sun is down",
        "mode_share": mode_share, "sky_share": sky_share,
        **events,
    }


#: The keys of `_scores`, in the summary's order.
_SCORE_KEYS = ("tracking_error_deg", "within_0_5_deg", "energy_capture", "moves", "travel_deg")


#: Degrees: the width of `RunningSummary`'s error histogram bins (its p95 is within half of it).
HISTOGRAM_RESOLUTION = 0.001
#: Degrees: the histogram's range, 0 to this; a larger error counts in the last bin (max stays exact).
HISTOGRAM_SPAN = 180.0
#: The most bins the histogram may have (8 MB of counts): at 1e-9° a span of 180° asked numpy for
#: 1.3 TiB and died with MemoryError. A finer p95 would resolve no tracker's pointing either.
HISTOGRAM_BINS = 1_000_000


class RunningSummary:
    """`summarize` over a run that arrives in consecutive parts, in memory that does not grow with it.

    Each part (`add`) contributes running sums: the error's weighted sums (`_error_sums`), the
    energy offered and captured, mode and sky counts (`share_counts`), event counts
    (`event_counts`), moves and travel. They add exactly (up to floating-point summation order,
    about 1e-12 relative), so `summary` equals `summarize` over the whole run in every key but
    the p95. The p95 comes from a fixed-bin histogram of |error| weighted as the metrics weight
    it: bins of `resolution` degrees from 0 to `span`; the reported p95 is the centre of the bin
    where the weighted CDF first reaches 0.95, within ``resolution / 2`` of the exact weighted
    quantile (`weighted_quantile`). The histogram takes ``8 · span / resolution`` bytes (1.4 MB
    at the defaults).

    Parameters
    ----------
    site, collector, strategy : str
        As `summarize` takes them.
    resolution : float
        Degrees, the histogram's bin width.
    span : float
        Degrees, the histogram's upper end.
    """

    def __init__(self, *, site: str, collector: str, strategy: str, resolution: float = HISTOGRAM_RESOLUTION,
                 span: float = HISTOGRAM_SPAN):
        span = params.number(span, "span", 0.0, 180.0, above=True)
        resolution = params.number(resolution, "resolution", span / HISTOGRAM_BINS, min(1.0, span))  # degrees
        _half_angle(collector)
        self.site, self.collector, self.strategy = site, collector, strategy
        self.resolution, self.span = float(resolution), float(span)
        self.histogram = np.zeros(int(np.ceil(span / resolution)))
        self.sums = {"weight": 0.0, "squared": 0.0, "first": 0.0, "within": 0.0, "max": 0.0}
        self.captured = self.offered = self.travel = 0.0
        self.steps = self.moves = 0
        self.modes: dict = {}
        self.sky: dict = {}
        self.events: dict = {}
        self.start = self.end = None

    def add(self, log: pd.DataFrame, *, moves: int, travel: float, events: pd.DataFrame, sun_up: np.ndarray,
            incidence: np.ndarray) -> None:
        """Count the next part of the run (the arguments of `summarize` for that part)."""
        if not len(log):
            return
        steps = _steps(log, self.collector, sun_up, incidence)
        sums = _error_sums(steps)
        for key in ("weight", "squared", "first", "within"):
            self.sums[key] += sums[key]
        self.sums["max"] = max(self.sums["max"], sums["max"])
        w = steps["weight"].to_numpy()
        scored = w > 0
        bins = np.minimum((np.abs(steps["error"].to_numpy()[scored]) / self.resolution).astype(np.int64),
                          len(self.histogram) - 1)
        self.histogram += np.bincount(bins, weights=w[scored], minlength=len(self.histogram))
        self.captured += float(steps["captured"].sum())
        self.offered += float(steps["offered"].sum())
        self.moves += int(moves)
        self.travel += float(travel)
        self.steps += len(log)
        for total, counts in zip((self.modes, self.sky), share_counts(log, sun_up)):
            for key, count in counts.items():
                total[key] = total.get(key, 0) + count
        for key, count in event_counts(events).items():
            self.events[key] = self.events.get(key, 0) + count
        self.start = log.index[0] if self.start is None else self.start
        self.end = log.index[-1]

    def p95(self) -> float | None:
        """The weighted p95 of |error| from the histogram: its bin's centre (degrees)."""
        total = self.histogram.sum()
        if not total > 0:
            return None
        cdf = np.cumsum(self.histogram) / total
        k = min(int(np.searchsorted(cdf, 0.95)), len(self.histogram) - 1)
        return float((k + 0.5) * self.resolution)

    def summary(self) -> dict:
        """The summary so far, in `summarize`'s keys (its p95 from the histogram)."""
        if self.start is None:
            raise HybridtrackError("the running summary has no part of the run yet: add() one first")
        stats, within = _error_from_sums(self.sums, self.p95())
        scores = {**_scores(stats=stats, within=within, captured=self.captured, offered=self.offered,
                            moves=self.moves, travel=self.travel), **self.events}
        return _compose(site=self.site, collector=self.collector, strategy=self.strategy, steps=self.steps,
                        start=self.start, end=self.end, scores=scores,
                        shares=_shares_from_counts(self.modes, self.sky, self.steps))


#: The log columns the daily table reads besides the scored ones (`SCORED_COLUMNS`): a heliostat's
#: ``angle_azimuth`` too, where the log has it (`moved_axes`).
DAILY_COLUMNS = ("sky", "wind_speed", "angle")
#: The columns of those that hold numbers.
_NUMBER_COLUMNS = ("dni", "error", "wind_speed", "angle")


def _check_daily_log(log) -> None:
    """Refuse what `daily` cannot make days of, by name: a log that is no frame on a tz-aware,
    increasing time index, has no steps, lacks a column it reads (without ``angle`` every day's
    moves had been 0), names one twice, or holds text where numbers belong (pandas' KeyError,
    TypeError and ValueError had come out; a reversed log gave NaN energy capture each day)."""
    if not isinstance(log, pd.DataFrame) or not isinstance(log.index, pd.DatetimeIndex):
        raise HybridtrackError(f"daily: the log must be a run's log, a DataFrame on a DatetimeIndex; got "
                               f"{type(log).__name__}")
    if not len(log):
        raise HybridtrackError("daily: the log has no steps, so no day to count")
    if log.index.tz is None or not log.index.is_monotonic_increasing:
        raise HybridtrackError("daily: the log's index must be tz-aware and increasing, as a run's is")
    missing = [c for c in (*SCORED_COLUMNS, *DAILY_COLUMNS) if c not in log.columns]
    if missing:
        raise HybridtrackError(f"daily: the log has no {', '.join(map(repr, missing))} column; a run's log has "
                               f"{', '.join((*SCORED_COLUMNS, *DAILY_COLUMNS))}")
    repeated = log.columns[log.columns.duplicated()]
    if len(repeated):
        raise HybridtrackError(f"daily: the log has the column {repeated[0]!r} more than once")
    for column in _NUMBER_COLUMNS:
        if not params.real_numbers(log[column].dtype):
            raise HybridtrackError(f"daily: the log's column {column!r} must hold numbers, got dtype {log[column].dtype}")


def _highest(values: np.ndarray) -> float:
    """The largest of `values` that is a number, NaN where none is (without numpy's warning of an
    all-NaN slice, which a day without a wind reading had shown the user)."""
    numbers = values[~np.isnan(values)]
    return float(numbers.max()) if numbers.size else np.nan


def daily(log: pd.DataFrame, *, collector: str, tz, sun_up: np.ndarray, incidence: np.ndarray) -> pd.DataFrame:
    """One row per local day, with the run summary's definitions applied to that day.

    Columns: ``energy_capture``, ``rms``/``p95``/``max`` (degrees, DNI-weighted), ``moves``,
    ``stow_wind_min`` and ``stow_night_min`` (minutes in each mode), ``dni_kwh_m2`` (direct
    normal irradiation), ``max_wind`` (m/s; NaN for a day without a reading) and the sky shares
    (``sky_sunny`` ... ``sky_night``, over the day's steps). The days' ``moves`` are counted from
    the logged angles (`moved_axes`): they add up to the run's less any made at its first step.
    """
    _check_daily_log(log)
    steps = _steps(log, collector, sun_up, incidence)
    local = log.index.tz_convert(check_tz(tz))
    day = pd.Index(local.date, name="date")
    minutes = stamp_minutes(log.index)  # each stamp its own step: a gap is not time in a mode
    moved = moved_axes(log)
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
            "moves": int(moved[idx].sum()),
            "stow_wind_min": float(minutes[idx][mode == "stow_wind"].sum()),
            "stow_night_min": float(minutes[idx][mode == "stow_night"].sum()),
            "dni_kwh_m2": float(np.nansum(log["dni"].to_numpy(float)[idx] * minutes[idx]) / 60e3),
            "max_wind": _highest(log["wind_speed"].to_numpy(float)[idx]),
            **{f"sky_{k}": float(counts.get(k, 0.0)) for k in ("sunny", "cloudy", "overcast", "unknown", "night")},
        })
    return pd.DataFrame(rows).set_index("date").astype(float).astype({"moves": int})
