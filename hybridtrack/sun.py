"""Where the sun is: the cheap model field PLCs run, and NREL SPA as the reference.

Both models return the same columns (degrees unless said otherwise):

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
``model="plc"`` is the closed-form model of ``domain.md`` §2 (Bourges' declination refit by
Wang & Liu, their equation of time), with Cooper's declination and Lamm's equation of time
selectable.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import pandas as pd

from .errors import HybridtrackError
from .sites import Site, get
from .times import clock_hours

__all__ = [
    "solar_position",
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
    return index


def _plc(
    index: pd.DatetimeIndex, site: Site, declination: str, equation_of_time: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    local = index.tz_convert(site.tz)
    utc_naive = index.tz_convert("UTC").tz_localize(None)
    zone_hours = np.asarray((local.tz_localize(None) - utc_naive) / pd.Timedelta(hours=1), float)
    day, year = np.asarray(local.day_of_year, float), np.asarray(local.year, float)
    dec = DECLINATION_MODELS[declination](day, year)
    if equation_of_time == "lamm":
        eot = lamm_equation_of_time(index)
    else:
        eot = plc_equation_of_time(day, year)
    # true solar time: clock + (longitude - zone meridian)/15 + Et/60
    solar_time = clock_hours(local) + (site.longitude - 15.0 * zone_hours) / 15.0 + eot / 60.0
    hour_angle = (15.0 * (solar_time - 12.0) + 180.0) % 360.0 - 180.0
    return dec, hour_angle, eot


def solar_position(
    times,
    site: Site | str,
    model: Literal["spa", "plc"] = "spa",
    *,
    declination: str = "wang-liu",
    equation_of_time: str = "wang-liu",
    temperature: float = 12.0,
) -> pd.DataFrame:
    """The sun's position at each time, from SPA or from the PLC model.

    Parameters
    ----------
    times : pandas.DatetimeIndex or array_like of tz-aware timestamps
        Naive times are refused. The PLC model reads them on the site's clock.
    site : Site or str
        A `Site` or a built-in site name.
    model : {"spa", "plc"}
        ``"spa"``: NREL SPA through pvlib, the reference. ``"plc"``: the closed-form model
        field controllers run (``domain.md`` §2).
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
    pressure = float(pvlib.atmosphere.alt2pres(site.altitude))  # Pa
    if model == "spa":
        spa = pvlib.solarposition.spa_python(
            index, site.latitude, site.longitude, altitude=site.altitude,
            pressure=pressure, temperature=temperature,
        )
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
        raise HybridtrackError(f"unknown sun model {model!r}; choose 'spa' or 'plc'")
    return pd.DataFrame(
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
