"""Synthetic skies: weather frames for any site, day or year, seeded and reproducible.

A frame holds pvlib's columns ``ghi``, ``dni``, ``dhi`` (W/m²), ``wind_speed`` (m/s) and
``temp_air`` (°C), plus the true sky label per step (``sky``) and the clear-sky irradiance
it was built from (``ghi_clear``, ``dni_clear``, ``dhi_clear``), on a tz-aware index.

How it is built:

* **Clear sky**: pvlib's Ineichen model with the site's altitude and the Linke turbidity
  looked up for the site and month (interpolated through the year), on SPA's apparent zenith.
* **Sky regimes**: each day is ``sunny``, ``cloudy`` or ``overcast``. A ``mixed`` day changes
  regime within the day, in spells of about one to four hours. Multi-day runs take a weather
  per day, a sequence, or ``"climate"``, which draws day types from the site's monthly
  climate (`CLIMATE`).
* **Clouds**: an alternating renewal process in continuous time (lognormal clear gaps and
  cloud passages, minutes to an hour), so the same seed gives the same clouds at any step.
  Under a cloud the beam keeps a fraction τ of the clear DNI, and a share of the lost beam
  reappears as diffuse light. In the clear gaps of a broken sky, light scattered off cloud
  edges raises the diffuse, so GHI can briefly exceed the clear-sky GHI (cloud enhancement).
  Overcast keeps DNI near zero (τ ≤ 0.02) and the diffuse at 20-40 % of the clear GHI.
* **Closure**: ``ghi = dni·cos(apparent zenith) + dhi`` holds exactly, and everything is 0
  while the sun is down.
* **Wind**: a diurnal shape (calm at dawn, strongest mid-afternoon) times a lognormal
  AR(1) fluctuation, plus optional gust events whose peaks can exceed the 17.2 m/s stow
  threshold.
* **Temperature**: the month's mean with a diurnal swing, smaller under overcast.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from . import params
from .budget import check_steps
from .errors import HybridtrackError
from .sites import Site, builtin_here, get
from .smoothing import one_pole
from .times import clock_hours, local_midnight, local_range, parse_freq, stamp_minutes

__all__ = ["synthetic", "check_weather", "weather_name", "clear_sky", "smooth_noise", "MinuteGrid", "Climate", "CLIMATE",
           "DAY_TYPES", "WEATHERS", "RegimeParameters", "REGIMES", "daily_summary"]

DAY_TYPES = ("sunny", "cloudy", "overcast")
#: W/m²: irradiance no sensor reads with the sun below the horizon (twilight gives a few W/m²):
#: more of it at night says the weather is another place's, or its clock another zone's
#: (`hybridtrack.io.suncheck` for files, `hybridtrack.simulate` for frames).
LIGHT_AT_NIGHT = 20.0
WEATHERS = (*DAY_TYPES, "mixed", "climate")


@dataclass(frozen=True)
class RegimeParameters:
    """How clouds come and go in one sky regime.

    Durations are medians of lognormal distributions (minutes); τ is the fraction of the
    clear-sky beam a cloud lets through, drawn uniformly per passage.
    """

    clear_median: float
    cloud_median: float
    spread: float
    tau: tuple[float, float]
    scatter: float  # share of the lost beam that reappears as diffuse
    enhancement: tuple[float, float]  # diffuse boost in clear gaps, fraction of clear DHI


REGIMES = {
    "sunny": RegimeParameters(clear_median=150.0, cloud_median=3.0, spread=0.6, tau=(0.4, 0.85),
                              scatter=0.3, enhancement=(0.0, 0.1)),
    "cloudy": RegimeParameters(clear_median=9.0, cloud_median=14.0, spread=0.8, tau=(0.0, 0.12),
                               scatter=0.35, enhancement=(0.3, 1.3)),
    "overcast": RegimeParameters(clear_median=1e9, cloud_median=1e9, spread=0.0, tau=(0.0, 0.02),
                                 scatter=0.0, enhancement=(0.0, 0.0)),
}


@dataclass(frozen=True)
class Climate:
    """A site's monthly climate for multi-day runs.

    Parameters
    ----------
    sunshine : sequence of 12 floats
        Relative sunshine per month (share of the possible hours with DNI ≥ 120 W/m²).
    temperature : sequence of 12 floats
        Monthly mean air temperature, °C.
    wind : float
        Mean wind speed, m/s.
    source : str
        Where the numbers come from.
    """

    sunshine: tuple[float, ...]
    temperature: tuple[float, ...]
    wind: float
    source: str

    #: Relative sunshine of each day type as this generator makes them (WMO threshold,
    #: DNI ≥ 120 W/m², over the hours the sun is up): the mean of a year of each at both sites
    #: (sunny 0.99 Lanzhou, 0.91 Nanjing; cloudy 0.40, 0.35). A test keeps the climate consistent.
    DAY_SUNSHINE = {"sunny": 0.95, "cloudy": 0.37, "overcast": 0.0}
    #: The share of cloudy days assumed in every month; the sunshine normal sets the rest.
    CLOUDY_SHARE = 0.4

    def day_fractions(self, month: int) -> dict[str, float]:
        """Chance of a sunny, cloudy and overcast day in `month` (1-12).

        A share `CLOUDY_SHARE` of days is cloudy. The sunny/overcast split of the rest is
        solved so that the expected sunshine equals the month's normal, clipped to [0, 1].
        """
        s = self.sunshine[month - 1]
        c = self.CLOUDY_SHARE
        sunny = (s - c * self.DAY_SUNSHINE["cloudy"]) / self.DAY_SUNSHINE["sunny"]
        sunny = float(np.clip(sunny, 0.0, 1.0 - c))
        return {"sunny": sunny, "cloudy": c, "overcast": 1.0 - c - sunny}


_NORMALS = ("Approximate 1991-2020 monthly normals of the China Meteorological Administration "
            "(relative sunshine rounded to 1 %, temperatures to 0.5 °C) as reproduced in public climate "
            "tables; not checked against the station records. Replace with your station's normals "
            "for quantitative work.")

#: Monthly climates of the two sites every feature serves.
CLIMATE = {
    "lanzhou": Climate(
        sunshine=(0.54, 0.53, 0.51, 0.55, 0.55, 0.54, 0.53, 0.54, 0.49, 0.51, 0.55, 0.54),
        temperature=(-4.5, 0.0, 6.5, 13.0, 17.5, 21.0, 23.0, 21.5, 16.5, 10.0, 3.0, -3.0),
        wind=1.3, source=_NORMALS),
    "nanjing": Climate(
        sunshine=(0.41, 0.40, 0.40, 0.45, 0.45, 0.38, 0.46, 0.51, 0.46, 0.49, 0.48, 0.45),
        temperature=(3.0, 5.5, 10.0, 16.0, 21.5, 25.0, 28.5, 28.0, 23.5, 18.0, 11.5, 5.0),
        wind=2.4, source=_NORMALS),
}


def _climate_for(site: Site) -> Climate:
    """The site's monthly normals where it is a built-in site with them (by name and place: a
    custom site that borrows 'lanzhou' at Cape Town had been given Lanzhou's winter in a Cape Town
    summer), else a generic mid-latitude default."""
    known = builtin_here(site.name, site)
    if known is not None and known.name in CLIMATE:
        return CLIMATE[known.name]
    # a site without normals: a mid-latitude default, flagged in the frame's attrs
    return Climate((0.5,) * 12, tuple(15.0 - 10.0 * np.cos(2 * np.pi * (m - 0.5) / 12.0) *
                                      np.sign(site.latitude or 1.0) for m in range(1, 13)),
                   2.5, "generic mid-latitude default (the site has no normals here)")


def _period(site: Site, start, end, freq: str) -> pd.DatetimeIndex:
    """The steps from `start` to `end` on the site's clock; a date alone means its whole day."""
    def stamp(value):
        """A timestamp on the site's clock, or None for a plain date."""
        if isinstance(value, (pd.Timestamp, dt.datetime)) or (isinstance(value, str) and len(value.strip()) > 10):
            moment = pd.Timestamp(value)
            if moment.tz is not None:
                return moment.tz_convert(site.tz)
            try:
                return moment.tz_localize(site.tz)
            except ValueError:  # pandas' nonexistent or ambiguous local time
                raise HybridtrackError(f"{moment} is not one time on {site.tz}'s clock: it is skipped or repeated "
                                       "where the clocks change; give a time with its UTC offset") from None
        return None

    first = stamp(start)
    last = stamp(end) if end is not None else None
    if first is None and last is None:
        return local_range(start, site.tz, end_date=end, freq=freq)
    if first is None:
        first = local_range(start, site.tz, freq=freq)[0]
    if last is None:
        last = local_range(end if end is not None else first.date(), site.tz, freq=freq)[-1]
    if last < first:
        raise HybridtrackError(f"the period ends ({last}) before it starts ({first})")
    check_steps(first, last, parse_freq(freq), what=f"{first} to {last}")
    return pd.date_range(first, last, freq=parse_freq(freq))


#: m/s: the strongest gust a synthetic frame may draw, above the 113 m/s of the strongest gust on
#: record (Barrow Island, 1996; WMO's archive of weather extremes).
STRONGEST_GUST = 120.0


def _gust_peak(peak) -> tuple[float, float]:
    """`synthetic`'s gust peaks: a low and a high within 0 to `STRONGEST_GUST` m/s, low first (a
    reversed pair raised numpy's ValueError, NaN an OverflowError; 1e9 m/s was drawn)."""
    if isinstance(peak, (str, bytes)) or not hasattr(peak, "__len__") or len(peak) != 2:
        raise HybridtrackError(f"gust_peak must be a (low, high) pair of m/s, got {peak!r:.60}")
    low, high = (params.number(v, "gust_peak (m/s)", 0, STRONGEST_GUST) for v in peak)
    if low > high:
        raise HybridtrackError(f"gust_peak ({low:g}, {high:g}): the low peak must not be above the high one")
    return low, high


def weather_name(name):
    """A weather's name as `synthetic` reads it: in lower case, without the spaces around it
    (``"Sunny"``, ``" SUNNY "`` -> ``"sunny"``), as a site's name and a file's sky labels are read;
    anything but text is returned as it is, for `check_weather` to refuse."""
    return name.strip().lower() if isinstance(name, str) else name


def check_weather(weather, days: int) -> str | list[str]:
    """The weather `synthetic` makes for `days` days, its names read by `weather_name`: one name, or
    a per-day list of names. Refused: an unknown name (named as given, with the names known), or a
    per-day list of another length or with a name that is not a day's weather (``climate`` draws
    them)."""
    if isinstance(weather, str):
        if weather_name(weather) not in WEATHERS:
            raise HybridtrackError(f"unknown weather {weather!r}; choose from {', '.join(WEATHERS)} or a per-day list")
        return weather_name(weather)
    weather = list(weather)
    if len(weather) != days:
        raise HybridtrackError(f"{len(weather)} weathers given for {days} days; give one per day")
    for value in weather:
        if weather_name(value) not in WEATHERS or weather_name(value) == "climate":
            raise HybridtrackError(f"unknown day weather {value!r}; choose from sunny, cloudy, overcast, mixed")
    return [weather_name(value) for value in weather]


def _day_types(days: list, weather, climate: Climate, rng: np.random.Generator) -> list[str]:
    weather = check_weather(weather, len(days))
    if weather == "climate":
        out = []
        for day in days:
            fractions = climate.day_fractions(day.month)
            out.append(str(rng.choice(DAY_TYPES, p=[fractions[t] for t in DAY_TYPES])))
        return out
    return [weather] * len(days) if isinstance(weather, str) else list(weather)


def _regime_spells(day_start: pd.Timestamp, day_type: str, rng: np.random.Generator) -> list[tuple]:
    """(start, end, regime) spells covering one local day."""
    day_end = day_start + pd.Timedelta(days=1)
    if day_type != "mixed":
        return [(day_start, day_end, day_type)]
    spells, t = [], day_start + pd.Timedelta(hours=float(rng.uniform(5.0, 9.0)))
    regime = str(rng.choice(DAY_TYPES))
    spells.append((day_start, t, regime))
    while t < day_end:
        regime = str(rng.choice([r for r in DAY_TYPES if r != regime]))
        length = pd.Timedelta(minutes=float(np.clip(rng.lognormal(np.log(120.0), 0.45), 45.0, 300.0)))
        spells.append((t, min(t + length, day_end), regime))
        t += length
    return spells


def _cloud_passages(t0: pd.Timestamp, t1: pd.Timestamp, regime: str, rng: np.random.Generator) -> list[tuple]:
    """(start, end, tau, enhancement) of every cloud passage and clear gap in a spell."""
    p = REGIMES[regime]
    if regime == "overcast":
        return [(t0, t1, float(rng.uniform(*p.tau)), 0.0, True)]
    out, t = [], t0
    in_cloud = bool(rng.random() < p.cloud_median / (p.cloud_median + p.clear_median))
    while t < t1:
        median = p.cloud_median if in_cloud else p.clear_median
        length = pd.Timedelta(minutes=float(np.clip(rng.lognormal(np.log(median), p.spread), 0.5, 600.0)))
        end = min(t + length, t1)
        if in_cloud:
            out.append((t, end, float(rng.uniform(*p.tau)), 0.0, True))
        else:
            out.append((t, end, 1.0, float(rng.uniform(*p.enhancement)), False))
        t, in_cloud = end, not in_cloud
    return out


@dataclass(frozen=True)
class MinuteGrid:
    """The 1-minute grid `smooth_noise` draws its noise on, for an index.

    Attributes
    ----------
    minutes : numpy.ndarray
        Each stamp's minutes since the first.
    knots : int
        Grid points drawn: the span in whole minutes, and two more.
    on_knots : bool
        Every stamp is the next grid point (an index at 1-minute steps): the noise is taken
        as drawn, which is what interpolating it at its own points gives.
    """

    minutes: np.ndarray
    knots: int
    on_knots: bool

    @classmethod
    def of(cls, index: pd.DatetimeIndex) -> MinuteGrid:
        minutes = np.asarray((index - index[0]) / pd.Timedelta(minutes=1), float)
        knots = int(np.ceil(minutes[-1])) + 2 if len(minutes) else 2
        return cls(minutes, knots, bool(np.array_equal(minutes, np.arange(len(minutes)))))

    def place(self, values: np.ndarray) -> np.ndarray:
        """Values on the grid's points, at the index's stamps."""
        if self.on_knots:
            return values[:len(self.minutes)]
        return np.interp(self.minutes, np.arange(self.knots), values)


def smooth_noise(index: pd.DatetimeIndex, rng: np.random.Generator, minutes: float, sigma: float, *,
                 grid: MinuteGrid | None = None) -> np.ndarray:
    """Zero-mean AR(1) noise with time constant `minutes`, on a 1-minute grid, then interpolated
    (`grid`, the index's `MinuteGrid`, if made already)."""
    grid = grid or MinuteGrid.of(index)
    phi = np.exp(-1.0 / minutes)
    shocks = rng.normal(0.0, sigma * np.sqrt(1 - phi**2), grid.knots)
    return grid.place(one_pole(shocks, 1.0, phi))


def clear_sky(index: pd.DatetimeIndex, site: Site, apparent_zenith, *,
              daily_extraterrestrial: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clear-sky GHI, DNI and DHI (W/m², 0 at night): pvlib's Ineichen model with the site's
    altitude and the Linke turbidity looked up for the site and month, computed only where the
    sun is up (below the horizon Ineichen's is zero).

    `daily_extraterrestrial` takes the extraterrestrial beam of each day (pvlib's
    ``get_extra_radiation``), as ``pvlib.location.Location.get_clearsky`` does; otherwise
    Ineichen's default constant.

    No more light reaches the ground than arrives at the top of the atmosphere: the DNI is held
    to the day's extraterrestrial beam and the GHI to that beam on the horizontal, the DHI the
    rest (`_within_top_of_atmosphere`). Ineichen's altitude terms (``cg1 = 5.09e-5 h + 0.868``, the
    beam's ``0.664 + 0.163 / exp(-h / 8000)``) were fitted to sites below about 3,000 m and pass
    both above some 4,000 m: a GHI of 1,371 W/m² at 4,500 m under a sun whose light on the
    horizontal at the top of the atmosphere is 1,305 W/m², and a DNI of 1,501 W/m² at 9,000 m.
    Below those heights nothing is held (the built-in sites' skies are as Ineichen gives them).

    References
    ----------
    Ineichen, P. & Perez, R. (2002). A new airmass independent formulation for the Linke
    turbidity coefficient. *Solar Energy* 73(3), 151-157. doi:10.1016/S0038-092X(02)00045-2
    """
    import pvlib

    apparent_zenith = np.asarray(apparent_zenith, float)
    up = apparent_zenith < 90.0
    irradiance = {name: np.zeros(len(apparent_zenith)) for name in ("ghi", "dni", "dhi")}
    if up.any():
        zenith, times = apparent_zenith[up], index[up]
        airmass = pvlib.atmosphere.get_absolute_airmass(pvlib.atmosphere.get_relative_airmass(zenith),
                                                        pvlib.atmosphere.alt2pres(site.altitude))
        linke = pvlib.clearsky.lookup_linke_turbidity(times, site.latitude, site.longitude).to_numpy(float)
        extra = {"dni_extra": pvlib.irradiance.get_extra_radiation(times).to_numpy(float)} \
            if daily_extraterrestrial else {}
        with np.errstate(divide="ignore", invalid="ignore"):  # pvlib divides by airmass, large at the horizon
            clear = pvlib.clearsky.ineichen(zenith, airmass, linke, altitude=site.altitude, **extra)
        held = _within_top_of_atmosphere(clear, zenith, times)
        for name, values in irradiance.items():
            values[up] = np.nan_to_num(held[name])
    return irradiance["ghi"], irradiance["dni"], irradiance["dhi"]


#: W/m²: the least extraterrestrial beam of the year, at aphelion (the solar constant, 1361 W/m²,
#: Kopp & Lean 2011, over 1.0167²): a clear sky below it on the beam and on the horizontal is
#: within the top of the atmosphere on any day, so only a sky above it is judged day by day.
LEAST_EXTRATERRESTRIAL = 1316.0


def _within_top_of_atmosphere(clear, zenith: np.ndarray, times: pd.DatetimeIndex) -> dict:
    """Ineichen's `clear` sky with its DNI held to the day's extraterrestrial beam (pvlib's
    ``get_extra_radiation``) and its GHI to that beam on the horizontal, the DHI then the GHI less
    the beam on the horizontal; untouched (to the bit) where neither passes its top."""
    import pvlib

    ghi, dni, dhi = (np.asarray(clear[name], float) for name in ("ghi", "dni", "dhi"))
    cos_zenith = np.fmax(np.cos(np.radians(zenith)), 0.0)
    with np.errstate(invalid="ignore"):
        judged = np.flatnonzero((dni > LEAST_EXTRATERRESTRIAL) | (ghi > LEAST_EXTRATERRESTRIAL * cos_zenith))
    if not len(judged):
        return {"ghi": ghi, "dni": dni, "dhi": dhi}
    top = pvlib.irradiance.get_extra_radiation(times[judged]).to_numpy(float)
    ghi, dni, dhi = ghi.copy(), dni.copy(), dhi.copy()
    beam, light = np.minimum(dni[judged], top), np.minimum(ghi[judged], top * cos_zenith[judged])
    over = (beam < dni[judged]) | (light < ghi[judged])
    at = judged[over]
    ghi[at], dni[at] = light[over], beam[over]
    dhi[at] = np.fmax(light[over] - beam[over] * cos_zenith[at], 0.0)
    return {"ghi": ghi, "dni": dni, "dhi": dhi}


def synthetic(site: Site | str, start, end=None, *, weather: str | Sequence[str] = "mixed", freq: str = "1min",
              seed: int = 0, gusts_per_day: float = 0.0, gust_peak: tuple[float, float] = (14.0, 24.0),
              wind_mean: float | None = None, climate: Climate | None = None) -> pd.DataFrame:
    """A synthetic weather frame for `site` from `start` to `end`.

    Parameters
    ----------
    site : Site or str
    start, end : date, str or timestamp
        A date alone means that whole local day; `end` defaults to `start`. Timestamps
        (naive ones on the site's clock) cut the period within a day.
    weather : {"sunny", "cloudy", "overcast", "mixed", "climate"} or sequence of str
        One weather for every day, one per day, or ``"climate"`` to draw each day from the
        site's monthly climate.
    freq : str
        Step, e.g. ``"1min"`` or ``"1s"``.
    seed : int
        Seeds every random draw: the same seed gives the same frame.
    gusts_per_day : float
        Mean number of gust events a day (Poisson), each lasting 2-10 minutes with a peak
        drawn uniformly from `gust_peak` (m/s).
    wind_mean : float, optional
        Mean wind speed (m/s); the climate's by default.
    climate : Climate, optional
        Monthly climate; the site's own (`CLIMATE`) by default.

    Returns
    -------
    pandas.DataFrame
        Columns ``ghi dni dhi wind_speed temp_air sky ghi_clear dni_clear dhi_clear``; attrs
        record the site, seed, weather per day and the climate's source.
    """
    from .sun import solar_position

    site = get(site)
    climate = climate or _climate_for(site)
    index = _period(site, start, end, freq)
    if len(index) < 2:  # nothing downstream can take one stamp: a weather frame needs a step
        raise HybridtrackError(f"step {freq!r} leaves {len(index)} time step{'' if len(index) == 1 else 's'} in the "
                               f"period: a weather frame needs at least two")
    params.number(gusts_per_day, "gusts_per_day", 0, 200)
    gust_peak = _gust_peak(gust_peak)
    seed = params.seed(seed)
    rng = np.random.default_rng(seed)
    local = index.tz_convert(site.tz)
    days = sorted(set(local.date))
    day_types = _day_types(days, weather, climate, rng)

    # regimes and cloud passages in continuous time
    edges, tau, boost, regimes, clouded = [], [], [], [], []
    for day, day_type in zip(days, day_types):
        day_start = local_midnight(day, site.tz)
        for s0, s1, regime in _regime_spells(day_start, day_type, rng):
            for c0, c1, t, e, cloud in _cloud_passages(s0, s1, regime, rng):
                edges.append(c1)
                tau.append(t)
                boost.append(e)
                regimes.append(DAY_TYPES.index(regime))
                clouded.append(cloud)
    which = np.searchsorted(pd.DatetimeIndex(edges).as_unit("ns").asi8, index.as_unit("ns").asi8, side="right")
    which = np.minimum(which, len(edges) - 1)
    step_tau, step_boost = np.asarray(tau)[which], np.asarray(boost)[which]
    step_regime, step_cloud = np.asarray(regimes)[which], np.asarray(clouded)[which]

    position = solar_position(index, site)
    apparent_zenith = position["apparent_zenith"].to_numpy(float)
    ghi_c, dni_c, dhi_c = clear_sky(index, site, apparent_zenith)
    cos_z = np.cos(np.radians(apparent_zenith))
    up = cos_z > 0.0
    beam_c = dni_c * np.where(up, cos_z, 0.0)

    overcast = step_regime == DAY_TYPES.index("overcast")
    scatter = np.array([REGIMES[r].scatter for r in DAY_TYPES])[step_regime]
    dni = dni_c * step_tau
    edge_light = np.minimum(step_boost * dhi_c, 0.25 * ghi_c)  # cloud enhancement, at most +25 % of clear GHI
    dhi = np.where(step_cloud, dhi_c + scatter * (1.0 - step_tau) * beam_c, dhi_c + edge_light)
    overcast_share = np.clip(0.3 + smooth_noise(index, rng, 90.0, 0.05), 0.2, 0.4)
    dhi = np.where(overcast, overcast_share * ghi_c, dhi)
    dni, dhi = np.where(up, dni, 0.0), np.where(up, dhi, 0.0)
    ghi = dni * np.where(up, cos_z, 0.0) + dhi

    hours = clock_hours(local)
    mean_wind = climate.wind if wind_mean is None else params.number(wind_mean, "wind_mean (m/s)", 0, 40)
    diurnal = 1.0 + 0.5 * np.sin(2 * np.pi * (hours - 9.0) / 24.0)
    wind = mean_wind * diurnal * np.exp(smooth_noise(index, rng, 20.0, 0.35) - 0.06)
    wind = np.maximum(wind, 0.0) + _gusts(index, rng, gusts_per_day, gust_peak)

    month_mean = np.asarray(climate.temperature, float)[local.month.to_numpy() - 1]
    swing = np.where(overcast, 2.5, 6.0)
    temp = month_mean + swing * np.sin(2 * np.pi * (hours - 9.0) / 24.0) + smooth_noise(index, rng, 60.0, 0.5)

    frame = pd.DataFrame({
        "ghi": ghi, "dni": dni, "dhi": dhi, "wind_speed": wind, "temp_air": temp,
        "sky": pd.Categorical(np.asarray(DAY_TYPES)[step_regime], categories=list(DAY_TYPES)),
        "ghi_clear": ghi_c, "dni_clear": dni_c, "dhi_clear": dhi_c,
    }, index=index)
    frame.attrs.update(site=site.name, seed=seed, freq=str(freq), source="synthetic",
                       weather={str(d): w for d, w in zip(days, day_types)}, climate_source=climate.source)
    return frame


def _gusts(index: pd.DatetimeIndex, rng: np.random.Generator, per_day: float, peak: tuple[float, float]) -> np.ndarray:
    """Added wind speed of gust events: a rise and fall over 2-10 minutes to a drawn peak."""
    extra = np.zeros(len(index))
    span_days = (index[-1] - index[0]) / pd.Timedelta(days=1) if len(index) > 1 else 0.0
    count = rng.poisson(per_day * max(span_days, 1.0 / 24.0)) if per_day > 0 else 0
    if count == 0:
        return extra
    t = np.asarray((index - index[0]) / pd.Timedelta(minutes=1), float)
    for centre, width, height in zip(rng.uniform(0.0, t[-1] if len(t) > 1 else 1.0, count),
                                     rng.uniform(2.0, 10.0, count), rng.uniform(*peak, count)):
        extra = np.maximum(extra, height * np.clip(1.0 - np.abs(t - centre) / (width / 2.0), 0.0, 1.0))
    return extra


def daily_summary(frame: pd.DataFrame, site: Site | str) -> pd.DataFrame:
    """Per local day: DNI and GHI totals (kWh/m²), clearness index, sunshine share.

    The daily clearness index is the day's GHI over the extraterrestrial irradiance on a
    horizontal plane; the sunshine share is the share of daylight time with DNI ≥ 120 W/m² (the
    WMO's sunshine threshold). Each stamp stands for its own step
    (`hybridtrack.times.stamp_minutes`), in the sums and the shares alike.
    """
    import pvlib

    from .sun import solar_position

    site = get(site)
    position = solar_position(frame.index, site)
    cos_z = np.clip(np.cos(np.radians(position["zenith"].to_numpy(float))), 0.0, None)
    extra = pvlib.irradiance.get_extra_radiation(frame.index).to_numpy(float) * cos_z
    hours = stamp_minutes(frame.index) / 60.0  # each stamp its own step; a gap counts no light
    day = frame.index.tz_convert(site.tz).date
    up = position["altitude"].to_numpy(float) > 0
    dni = frame["dni"].to_numpy(float)
    table = pd.DataFrame({"ghi": frame["ghi"].to_numpy(float) * hours, "dni": dni * hours, "extra": extra * hours,
                          "up": up * hours, "sunshine": (up & (dni >= 120.0)) * hours}, index=day)  # Wh/m², hours
    sums = table.groupby(level=0).sum()
    out = pd.DataFrame({
        "dni_kwh_m2": sums["dni"] / 1000.0,
        "ghi_kwh_m2": sums["ghi"] / 1000.0,
        "clearness_index": sums["ghi"] / sums["extra"],
        "sunshine_share": (sums["sunshine"] / sums["up"]).where(sums["up"] > 0, 0.0),
    })
    out.index.name = "date"
    return out
