"""Where the sun is: the cheap model field PLCs run, NREL SPA as the reference, and SPA at a
fraction of its cost for the true sun of long runs.

Every model returns the same columns (degrees unless said otherwise):

``altitude``
    geometric (unrefracted) altitude above the horizon;
``apparent_altitude``
    altitude with atmospheric refraction added (what a sensor sees);
``zenith`` / ``apparent_zenith``
    90° minus the two altitudes above (pvlib's names);
``azimuth``
    clockwise from north, 0-360;
``declination``, ``hour_angle``
    hour angle negative in the morning, within [-180, 180);
``equation_of_time``
    minutes, positive when the sundial runs ahead of mean solar time.

``model="spa"`` is pvlib's NREL SPA (``spa_python``, ±0.0003°). Its declination and hour angle
are the topocentric ones, converted exactly from SPA's own topocentric altitude and azimuth.
``model="spa-fast"`` is the same SPA with its costly part, the Earth's heliocentric series and
the nutation, evaluated on an hourly grid and interpolated (`spa_fast`); it stays within
1e-5° of ``"spa"`` (2.1e-6° measured over a year at Lanzhou and Nanjing, see ``docs/fields.md``)
at about a tenth of its time.
``model="plc"`` is the closed-form model field controllers run (Bourges' declination refit by
Wang & Liu, their equation of time), with Cooper's declination and Lamm's equation of time
selectable.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Literal

import numpy as np
import pandas as pd

from . import params
from .errors import HybridtrackError
from .sites import Site, get
from .times import DAY_NS, FIRST_DATE, LAST_DATE, clock_nanoseconds, day_of_year

__all__ = [
    "solar_position",
    "spa_fast",
    "reuse_positions",
    "SUN_MODELS",
    "SPA_FAST_ERROR",
    "altitude_azimuth",
    "refraction",
    "plc_declination",
    "plc_equation_of_time",
    "cooper_declination",
    "lamm_equation_of_time",
    "DECLINATION_MODELS",
    "EQUATION_OF_TIME_MODELS",
    "COLUMNS",
]

COLUMNS = (
    "altitude",
    "apparent_altitude",
    "zenith",
    "apparent_zenith",
    "azimuth",
    "declination",
    "hour_angle",
    "equation_of_time",
)

_TROPICAL_YEAR = 365.2422


def _day_angle(day_of_year: np.ndarray, year: np.ndarray) -> np.ndarray:
    """Bourges' day angle θ (radians) for integer day of year N and year Y."""
    n0 = 79.6764 + 0.2422 * (year - 1985) - np.floor((year - 1985) / 4.0)
    return 2.0 * np.pi * (day_of_year - n0) / _TROPICAL_YEAR


def plc_declination(day_of_year, year) -> np.ndarray:
    """Declination (degrees), Bourges' series as refit by Wang & Liu (1991).

    Parameters
    ----------
    day_of_year : array_like
        N, 1 on 1 January.
    year : array_like
        Calendar year Y.
    """
    t = _day_angle(np.asarray(day_of_year, float), np.asarray(year, float))
    return (
        0.3723
        + 23.2567 * np.sin(t)
        + 0.1149 * np.sin(2 * t)
        - 0.1712 * np.sin(3 * t)
        - 0.758 * np.cos(t)
        + 0.3656 * np.cos(2 * t)
        + 0.0201 * np.cos(3 * t)
    )


def plc_equation_of_time(day_of_year, year) -> np.ndarray:
    """Equation of time (minutes), the Wang & Liu series on Bourges' day angle."""
    t = _day_angle(np.asarray(day_of_year, float), np.asarray(year, float))
    return 0.0028 - 1.9857 * np.sin(t) + 9.9059 * np.sin(2 * t) - 7.0924 * np.cos(t) - 0.6882 * np.cos(2 * t)


def cooper_declination(day_of_year, year=None) -> np.ndarray:
    """Cooper's (1969) declination, ``23.45 sin(360 (284 + n) / 365)`` degrees."""
    n = np.asarray(day_of_year, float)
    return 23.45 * np.sin(np.radians(360.0 * (284.0 + n) / 365.0))


_LAMM_A = np.array([2.0870e-4, 9.2869e-3, -5.2258e-2, -1.3077e-3, -2.1867e-3, -1.5100e-4])
_LAMM_B = np.array([0.0, -1.2229e-1, -1.5698e-1, -5.1602e-3, -2.9823e-3, -2.3463e-4])


def lamm_equation_of_time(times_utc: pd.DatetimeIndex) -> np.ndarray:
    """Lamm's (1981) equation of time (minutes), a six-term Fourier series.

    Its day count runs continuously through the four-year leap cycle: N = 0.5 plus the days
    since 0 h UT on 1 January of the last leap year (so N = 1.0 at 12:00 UT that day).
    """
    utc = pd.DatetimeIndex(times_utc).tz_convert("UTC")
    leap_year = utc.year - utc.year % 4
    cycle_start = pd.to_datetime({"year": leap_year, "month": 1, "day": 1}).dt.tz_localize("UTC")
    days = (utc - pd.DatetimeIndex(cycle_start)) / pd.Timedelta(days=1)
    n = 0.5 + np.asarray(days, float)
    k = np.arange(6)
    phase = 2.0 * np.pi * np.outer(n, k) / 365.25
    hours = np.cos(phase) @ _LAMM_A + np.sin(phase) @ _LAMM_B
    return 60.0 * hours


DECLINATION_MODELS = {"wang-liu": plc_declination, "cooper": cooper_declination}
EQUATION_OF_TIME_MODELS = ("wang-liu", "lamm")


def altitude_azimuth(declination, hour_angle, latitude) -> tuple[np.ndarray, np.ndarray]:
    """Geometric altitude and azimuth (from north, clockwise, 0-360) of the sun, degrees.

    Parameters
    ----------
    declination, hour_angle : array_like
        Degrees; hour angle negative in the morning.
    latitude : float or array_like
        Degrees, north positive.
    """
    d = np.radians(np.asarray(declination, float))
    w = np.radians(np.asarray(hour_angle, float))
    p = np.radians(np.asarray(latitude, float))
    sin_alt = np.sin(d) * np.sin(p) + np.cos(d) * np.cos(p) * np.cos(w)
    altitude = np.degrees(np.arcsin(np.clip(sin_alt, -1.0, 1.0)))
    # atan2 of the east and north components keeps every quadrant
    east = -np.cos(d) * np.sin(w)
    north = np.sin(d) * np.cos(p) - np.cos(d) * np.sin(p) * np.cos(w)
    azimuth = np.degrees(np.arctan2(east, north)) % 360.0
    return altitude, azimuth


def _declination_hour_angle(altitude, azimuth, latitude) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of `altitude_azimuth`: declination and hour angle (degrees) of a sun direction."""
    a = np.radians(np.asarray(altitude, float))
    g = np.radians(np.asarray(azimuth, float))
    p = np.radians(latitude)
    sin_dec = np.sin(p) * np.sin(a) + np.cos(p) * np.cos(a) * np.cos(g)
    declination = np.degrees(np.arcsin(np.clip(sin_dec, -1.0, 1.0)))
    west = -np.cos(a) * np.sin(g)
    up = np.sin(a) * np.cos(p) - np.cos(a) * np.sin(p) * np.cos(g)
    hour_angle = np.degrees(np.arctan2(west, up))
    return declination, hour_angle


def refraction(altitude, pressure: float = 1010.0, temperature: float = 10.0) -> np.ndarray:
    """Atmospheric refraction (degrees) to add to a geometric altitude.

    The Bennett/Sæmundsson form SPA uses, scaled for pressure (hPa) and temperature (°C);
    zero once the sun is more than 0.8333° below the horizon.
    """
    e0 = np.asarray(altitude, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = (pressure / 1010.0) * (283.0 / (273.0 + temperature)) * 1.02 / (
            60.0 * np.tan(np.radians(e0 + 10.3 / (e0 + 5.11)))
        )
    return np.where(e0 >= -(0.26667 + 0.5667), r, 0.0)


def _check_times(times) -> pd.DatetimeIndex:
    try:
        index = pd.DatetimeIndex(times)
    except (TypeError, ValueError) as exc:
        raise HybridtrackError(f"times are not timestamps: {exc}") from None
    if index.tz is None:
        raise HybridtrackError(
            "times are naive (no time zone); localise them first, e.g. "
            "index.tz_localize('Asia/Shanghai')"
        )
    try:  # a year past 2262 (pandas keeps other units than nanoseconds) raised OutOfBoundsDatetime later
        index.as_unit("ns")
    except (OverflowError, ValueError):  # pandas' OutOfBoundsDatetime is a ValueError
        raise HybridtrackError(f"times must lie within {FIRST_DATE} to {LAST_DATE}, got {index.min()} to "
                               f"{index.max()}") from None
    return index


def _plc(
    index: pd.DatetimeIndex, site: Site, declination: str, equation_of_time: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    wall = clock_nanoseconds(index.tz_convert(site.tz))
    zone_hours = (wall - np.asarray(index.as_unit("ns").asi8)) / 3.6e12
    # the series are of the calendar day: computed once a day, looked up at each scan
    missing = np.asarray(index.isna())  # NaT: its integer is no time at all
    day_number = wall // DAY_NS
    days = day_number[~missing]
    first, last = (int(days.min()), int(days.max())) if len(days) else (0, 0)
    calendar = day_of_year(np.arange(first, last + 1))
    on_day = np.where(missing, 0, day_number - first)
    dec = DECLINATION_MODELS[declination](*calendar)[on_day]
    if equation_of_time == "lamm":
        eot = lamm_equation_of_time(index)
    else:
        eot = plc_equation_of_time(*calendar)[on_day]
    # true solar time: clock + (longitude - zone meridian)/15 + Et/60
    solar_time = (wall % DAY_NS) / 3.6e12 + (site.longitude - 15.0 * zone_hours) / 15.0 + eot / 60.0
    hour_angle = (15.0 * (solar_time - 12.0) + 180.0) % 360.0 - 180.0
    if missing.any():
        dec, hour_angle, eot = (np.where(missing, np.nan, values) for values in (dec, hour_angle, eot))
    return dec, hour_angle, eot


#: The sun models `solar_position` knows.
SUN_MODELS = ("spa", "spa-fast", "plc")
#: Stated bound (degrees) of ``model="spa-fast"`` against ``model="spa"`` on altitude, apparent
#: altitude and the sun's direction; measured 2.1e-6° over a year at 1-minute steps at both sites.
SPA_FAST_ERROR = 1e-5
#: Knot spacing (seconds) of the interpolated SPA quantities.
SPA_FAST_KNOT = 3600.0
#: ΔT = TT - UT (s) that ``spa_python`` assumes by default, and so both SPA paths here.
_DELTA_T = 67.0
#: SPA's refraction at the horizon (degrees), pvlib's default ``atmos_refract``.
_ATMOS_REFRACT = 0.5667


def _unix_seconds(index: pd.DatetimeIndex) -> np.ndarray:
    utc = index.tz_convert("UTC").tz_localize(None)
    return np.asarray((utc - pd.Timestamp("1970-01-01")) / pd.Timedelta(seconds=1), float)


def _spa_geocentric(unixtime: np.ndarray) -> dict[str, np.ndarray]:
    """SPA's slow, site-free quantities at each time: Earth-sun distance, the sun's geocentric
    right ascension and declination, the nutation in right ascension and the equation of time."""
    from pvlib import spa

    jd = spa.julian_day(unixtime)
    jce = spa.julian_ephemeris_century(spa.julian_ephemeris_day(jd, _DELTA_T))
    jme = spa.julian_ephemeris_millennium(jce)
    radius = spa.heliocentric_radius_vector(jme)
    theta = spa.geocentric_longitude(spa.heliocentric_longitude(jme))
    beta = spa.geocentric_latitude(spa.heliocentric_latitude(jme))
    arguments = [f(jce) for f in (spa.mean_elongation, spa.mean_anomaly_sun, spa.mean_anomaly_moon,
                                  spa.moon_argument_latitude, spa.moon_ascending_longitude)]
    nutation = np.empty((2, len(jd)))
    spa.longitude_obliquity_nutation(jce, *arguments, nutation)
    epsilon = spa.true_ecliptic_obliquity(spa.mean_ecliptic_obliquity(jme), nutation[1])
    lamda = spa.apparent_sun_longitude(theta, nutation[0], spa.aberration_correction(radius))
    alpha = spa.geocentric_sun_right_ascension(lamda, epsilon, beta)
    return {
        "radius": radius,
        "right_ascension": np.degrees(np.unwrap(np.radians(alpha))),  # continuous, to interpolate
        "declination": spa.geocentric_sun_declination(lamda, epsilon, beta),
        "nutation_ra": nutation[0] * np.cos(np.radians(epsilon)),
        "equation_of_time": spa.equation_of_time(spa.sun_mean_longitude(jme), alpha, nutation[0], epsilon),
    }


def spa_fast(times, latitude: float, longitude: float, altitude: float = 0.0, pressure: float = 101325.0,
             temperature: float = 12.0, *, knot: float = SPA_FAST_KNOT) -> pd.DataFrame:
    """NREL SPA with its site-free part interpolated from a coarse grid.

    SPA spends nearly all its time on the Earth's heliocentric series and the nutation, which
    vary slowly. They are evaluated by pvlib's SPA functions on knots `knot` seconds apart
    (UTC), turned into the sun's geocentric right ascension and declination, the Earth-sun
    distance, the nutation in right ascension and the equation of time, and interpolated
    linearly to each stamp. The fast parts, the apparent sidereal time, the topocentric
    parallax, the altitude, azimuth and refraction, are evaluated at each stamp exactly as in
    SPA. Linear interpolation errs by at most ``h² max|f''| / 8`` on knots ``h`` apart; with
    hourly knots that is about 2e-6° (measured 2.1e-6° over a year, well inside SPA's own
    ±0.0003°). Where there are fewer than four stamps per knot the reference SPA runs instead.

    Parameters
    ----------
    times : pandas.DatetimeIndex
        Tz-aware times, in any order.
    latitude, longitude : float
        Degrees, north and east positive.
    altitude : float
        Metres above sea level.
    pressure : float
        Pa, for the refraction.
    temperature : float
        °C, for the refraction.
    knot : float
        Seconds between knots.

    Returns
    -------
    pandas.DataFrame
        pvlib's ``spa_python`` columns: ``elevation``, ``apparent_elevation``, ``zenith``,
        ``apparent_zenith``, ``azimuth``, ``equation_of_time``.

    References
    ----------
    Reda, I. and Andreas, A. (2004). Solar position algorithm for solar radiation applications.
    Solar Energy 76(5), 577-589. https://doi.org/10.1016/j.solener.2003.12.003
    """
    import pvlib
    from pvlib import spa

    index = _check_times(times)
    unixtime = _unix_seconds(index)
    if not (np.isfinite(knot) and knot > 0):
        raise HybridtrackError(f"spa_fast: knot must be a positive number of seconds, got {knot!r}")
    finite = unixtime[np.isfinite(unixtime)]
    first, last = (np.floor(finite.min() / knot) - 1, np.ceil(finite.max() / knot) + 1) if finite.size else (0, 0)
    if spa.USE_NUMBA or 4 * (last - first + 1) > len(index):  # compiled SPA has no array API; few stamps
        return pvlib.solarposition.spa_python(index, latitude, longitude, altitude=altitude, pressure=pressure,
                                              temperature=temperature, delta_t=_DELTA_T)
    knots = np.arange(first, last + 1) * knot
    slow = {name: np.interp(unixtime, knots, values) for name, values in _spa_geocentric(knots).items()}
    jd = spa.julian_day(unixtime)
    sidereal = spa.mean_sidereal_time(jd, spa.julian_century(jd)) + slow["nutation_ra"]
    hour_angle = spa.local_hour_angle(sidereal, longitude, slow["right_ascension"] % 360.0)
    xi = spa.equatorial_horizontal_parallax(slow["radius"])
    u = spa.uterm(latitude)
    x, y = spa.xterm(u, latitude, altitude), spa.yterm(u, latitude, altitude)
    delta_alpha = spa.parallax_sun_right_ascension(x, xi, hour_angle, slow["declination"])
    declination = spa.topocentric_sun_declination(slow["declination"], x, y, xi, delta_alpha, hour_angle)
    topocentric_hour_angle = spa.topocentric_local_hour_angle(hour_angle, delta_alpha)
    e0 = spa.topocentric_elevation_angle_without_atmosphere(latitude, declination, topocentric_hour_angle)
    e = spa.topocentric_elevation_angle(
        e0, spa.atmospheric_refraction_correction(pressure / 100.0, temperature, e0, _ATMOS_REFRACT))
    azimuth = spa.topocentric_azimuth_angle(
        spa.topocentric_astronomers_azimuth(topocentric_hour_angle, declination, latitude))
    return pd.DataFrame({"apparent_zenith": 90.0 - e, "zenith": 90.0 - e0, "apparent_elevation": e,
                         "elevation": e0, "azimuth": azimuth, "equation_of_time": slow["equation_of_time"]},
                        index=index)


#: Stamps from which `reuse_positions` keeps an answer: a smaller one costs milliseconds to compute
#: again, and would push out of the memory the long answers that are worth keeping.
REMEMBERED_FROM = 10_000
#: The answers `reuse_positions` keeps: (capacity, [(key, frame), ...] oldest first), or None outside it.
_REUSE: ContextVar[tuple[int, list] | None] = ContextVar("hybridtrack_sun_reuse", default=None)
_REUSE_LOCK = threading.Lock()


@contextmanager
def reuse_positions(entries: int = 8) -> Iterator[None]:
    """Within this block, `solar_position` answers a request it has answered before from memory.

    A request is answered from memory when it asks for the same model, site and options as an
    earlier one and every one of its times was among that one's; the rows are the same numbers
    the model gives (every model here computes each stamp on its own). Runs of many collectors
    on one frame ask for the same sun again and again; this is how they share it without
    passing it around. The memory holds the last `entries` answers, for this thread or task and
    the threads it hands a copy of its context (a field's threads). A block inside another shares
    the outer block's memory.
    """
    if _REUSE.get() is not None:
        yield
        return
    token = _REUSE.set((max(int(entries), 1), []))
    try:
        yield
    finally:
        _REUSE.reset(token)


def _remembered(key: tuple, index: pd.DatetimeIndex) -> pd.DataFrame | None:
    with _REUSE_LOCK:  # the threads of a field share the memory
        return _recalled(key, index)


def _recalled(key: tuple, index: pd.DatetimeIndex) -> pd.DataFrame | None:
    capacity, memory = _REUSE.get() or (0, [])
    for k, entry in enumerate(memory):
        if entry[0] != key:
            continue
        if entry[1].index.equals(index):
            rows = entry[1]
        else:
            where = _positions(entry[1].index, index)
            if where is None:
                continue
            rows = entry[1].iloc[where]
        memory.append(memory.pop(k))  # most recently used last (by place: entries' frames do not compare)
        return rows.set_axis(index).copy()
    return None


def _positions(known: pd.DatetimeIndex, index: pd.DatetimeIndex) -> np.ndarray | None:
    """Where each of `index`'s times is in `known`, or None if any is not there. Both increasing
    (a frame's index and the subsets runs ask for): a binary search, without building a hash
    table of a year's stamps."""
    if not (known.is_monotonic_increasing and index.is_monotonic_increasing):
        where = known.get_indexer(index)
        return None if (where < 0).any() else where
    stamps, wanted = known.as_unit("ns").asi8, index.as_unit("ns").asi8
    where = np.searchsorted(stamps, wanted)
    if len(where) and (where[-1] >= len(stamps) or not np.array_equal(stamps[np.minimum(where, len(stamps) - 1)],
                                                                       wanted)):
        return None
    return where


def _remember(key: tuple, frame: pd.DataFrame) -> None:
    capacity, memory = _REUSE.get() or (0, None)
    if memory is None or not frame.index.is_unique or len(frame) < REMEMBERED_FROM:
        return
    with _REUSE_LOCK:
        memory.append((key, frame))
        del memory[:-capacity]  # keep the newest


def _check_plc_options(model: str, declination, equation_of_time) -> None:
    """Refuse the PLC model's series given by other than their names, or given to another model,
    which would not use them (a list had raised a TypeError; another model ignored them)."""
    for name, value, default in (("declination", declination, "wang-liu"),
                                 ("equation_of_time", equation_of_time, "wang-liu")):
        if not isinstance(value, str):
            raise HybridtrackError(f"{name} must be a model's name, got {value!r:.60}")
        if model != "plc" and value != default:
            raise HybridtrackError(f"{name} applies to the PLC model (model 'plc') only; model {model!r} would not "
                                   f"use {value!r}")


def solar_position(
    times,
    site: Site | str,
    model: Literal["spa", "spa-fast", "plc"] = "spa",
    *,
    declination: str = "wang-liu",
    equation_of_time: str = "wang-liu",
    temperature: float = 12.0,
) -> pd.DataFrame:
    """The sun's position at each time, from SPA, its interpolated fast form, or the PLC model.

    Parameters
    ----------
    times : pandas.DatetimeIndex or array_like of tz-aware timestamps
        Naive times are refused. The PLC model reads them on the site's clock.
    site : Site or str
        A `Site` or a built-in site name.
    model : {"spa", "spa-fast", "plc"}
        ``"spa"``: NREL SPA through pvlib, the reference. ``"spa-fast"``: the same SPA with its
        slow series interpolated from hourly knots (`spa_fast`), within `SPA_FAST_ERROR` of
        ``"spa"`` at about a tenth of its time. ``"plc"``: the closed-form model field
        controllers run.
    declination : {"wang-liu", "cooper"}
        PLC model only: the declination series.
    equation_of_time : {"wang-liu", "lamm"}
        PLC model only: the equation-of-time series.
    temperature : float
        Air temperature (°C) for the refraction in ``apparent_altitude``; the pressure comes
        from the site's altitude.

    Returns
    -------
    pandas.DataFrame
        Indexed by `times`, with the columns listed in the module docstring.
    """
    import pvlib

    site = get(site)
    index = _check_times(times)
    # the air's extremes on record, -89.2 °C (Vostok, 1983) and 56.7 °C (Death Valley, 1913), within
    # round bounds: -273.15 °C had given an apparent altitude of -537°, and text pvlib's TypeError
    temperature = params.number(temperature, "temperature (°C)", -90.0, 60.0)
    _check_plc_options(model, declination, equation_of_time)
    key = (model, site, temperature) + ((declination, equation_of_time) if model == "plc" else ())
    remembered = _remembered(key, index)
    if remembered is not None:
        return remembered
    pressure = float(pvlib.atmosphere.alt2pres(site.altitude))  # Pa
    if model in ("spa", "spa-fast"):
        arguments = dict(altitude=site.altitude, pressure=pressure, temperature=temperature)
        if model == "spa":
            spa = pvlib.solarposition.spa_python(index, site.latitude, site.longitude, delta_t=_DELTA_T, **arguments)
        else:
            spa = spa_fast(index, site.latitude, site.longitude, **arguments)
        altitude = spa["elevation"].to_numpy(float)
        apparent = spa["apparent_elevation"].to_numpy(float)
        azimuth = spa["azimuth"].to_numpy(float)
        eot = spa["equation_of_time"].to_numpy(float)
        dec, hour_angle = _declination_hour_angle(altitude, azimuth, site.latitude)
    elif model == "plc":
        if declination not in DECLINATION_MODELS:
            raise HybridtrackError(
                f"unknown declination model {declination!r}; choose from {', '.join(DECLINATION_MODELS)}"
            )
        if equation_of_time not in EQUATION_OF_TIME_MODELS:
            raise HybridtrackError(
                f"unknown equation-of-time model {equation_of_time!r}; "
                f"choose from {', '.join(EQUATION_OF_TIME_MODELS)}"
            )
        dec, hour_angle, eot = _plc(index, site, declination, equation_of_time)
        altitude, azimuth = altitude_azimuth(dec, hour_angle, site.latitude)
        apparent = altitude + refraction(altitude, pressure / 100.0, temperature)
    else:
        raise HybridtrackError(f"unknown sun model {model!r}; choose from {', '.join(SUN_MODELS)}")
    frame = pd.DataFrame(
        {
            "altitude": altitude,
            "apparent_altitude": apparent,
            "zenith": 90.0 - altitude,
            "apparent_zenith": 90.0 - apparent,
            "azimuth": azimuth,
            "declination": dec,
            "hour_angle": hour_angle,
            "equation_of_time": eot,
        },
        index=index,
    )
    _remember(key, frame)
    return frame
