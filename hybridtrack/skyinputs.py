"""What the sky classifier reads: inputs that mean the same at any site, sensor and step.

The published classifier reads the sensor's photocurrent in mA and its range over a
trailing 20-minute window. Both tie it to one sensor, one climate and one sampling step.
`sky_inputs` offers a second reading of the same sensor, chosen by `SkyInputConfig`:

* **Relative intensity** (``mode = "relative"``): the light the cells see over the light
  they would see under a clear sky at that time and place, ``k = (I - I0) / (Ic - I0)``,
  with ``I0`` the dark current and ``Ic`` the photocurrent the sensor model gives for
  pvlib's Ineichen clear sky with the Linke turbidity looked up for the site and month.
  ``k`` is capped at 1 (a sky brighter than the model's clear sky is clear) and put back
  on the classifier's mA scale, ``lo + (hi - lo) (k - k0) / (1 - k0)`` (clipped) with the
  config's intensity ``raw_range`` and ``k0 = relative_floor``, so one fuzzy config serves
  both modes: a clear sky reads as the top of the published range whatever the sun's
  height, site or sensor, and overcast light (``k`` below ``k0``) as its bottom.
* **Variation per unit time**: the readings are first averaged over a trailing
  ``smoothing`` period (1 min by default), then the range (max - min) is taken over the
  trailing ``window`` (20 min). Both are durations, not sample counts: the variation is
  the 20-minute range of 1-minute means, whatever the logger's step up to a minute (1 s,
  10 s or 1 min read the same). A coarser record (5 min) cannot be refined; its labels
  agree with those of the same sky at 1 min on about 90 % of samples (measured,
  ``docs/sky-validation.md``). In relative mode the range is that of ``k``, with a swing
  of ``full_variation`` at the top of the variation's ``raw_range``: the clear-sky
  morning ramp is not a variation.
* **Low sun**: below ``min_altitude`` the expected clear-sky light is small and the
  clear-sky model least certain, so the ratio is unstable and overcast diffuse light can
  read as a large share of it. There the absolute photocurrent is used instead
  (``low_sun = "absolute"``, the default, which leans to "overcast", the cautious side),
  or the sky is left ``unknown`` (``low_sun = "unknown"``). The default 5° was measured.
* **Rule table**: ``rules = "published"`` (the four published rules, `FuzzyConfig.default`,
  the default: it measured better than the complete table in relative mode) or
  ``"complete"`` (six rules, ``data/fuzzy-complete.toml``).

`SkyInputConfig.published` is the published system: absolute mA, raw samples, the four
rules, no low-sun rule. The default is what measured best on real records
(``docs/sky-validation.md``).

References
----------
Ineichen, P. and Perez, R. (2002). A new airmass independent formulation for the Linke
turbidity coefficient. Solar Energy 73(3), 151-157. doi:10.1016/S0038-092X(02)00045-2

Remund, J., Wald, L., Lefèvre, M., Ranchin, T. and Page, J. (2003). Worldwide Linke
turbidity information. Proc. ISES Solar World Congress, Göteborg.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import HybridtrackError
from .params import duration
from .rolling import trailing_range
from .sensor import SensorModel
from .sites import Site, get
from .sky import clear_sky as ineichen_clear_sky

__all__ = ["SkyInputConfig", "MODES", "RULES", "LOW_SUN", "clear_sky", "clear_sky_photocurrent", "sky_inputs",
           "photocurrent_range", "classify_sky", "fuzzy_config"]

MODES = ("relative", "absolute")
RULES = ("complete", "published")
LOW_SUN = ("absolute", "unknown")

#: The complete six-rule table shipped with the project.
COMPLETE_RULES = Path(__file__).resolve().parent.parent / "data" / "fuzzy-complete.toml"


@dataclass(frozen=True)
class SkyInputConfig:
    """How the sensor's light becomes the classifier's two inputs.

    Parameters
    ----------
    mode : {"relative", "absolute"}
        Intensity relative to the clear-sky photocurrent, or the photocurrent in mA.
    rules : {"complete", "published"}
        The six-rule table or the four published rules.
    window : str
        Trailing window of the variation (range), e.g. ``"20min"``.
    smoothing : str or None
        Trailing mean applied before the range, e.g. ``"5min"``; None uses raw samples.
    min_altitude : float
        Degrees of apparent sun altitude below which the low-sun rule applies (relative mode).
    low_sun : {"absolute", "unknown"}
        Below `min_altitude`: absolute inputs, or no label.
    full_variation : float
        Relative mode: the swing of the clear-sky ratio (0-1) that reads as the top of the
        variation's ``raw_range``. The published ranges make it 180/270 = 0.67 of the
        intensity span; 0.3 puts the sunny/cloudy boundary under bright light at a swing of
        0.15, about where thin cloud takes the beam ratio below 0.7 (measured,
        ``docs/sky-validation.md``).
    relative_floor : float
        Relative mode: the clear-sky ratio read as the bottom of the intensity ``raw_range``.
        0.3: on real records 95 % of samples whose beam was hidden for the whole window read
        below 0.27 (median 0.12), so overcast light is "weak" and the "medium" term's centre
        lands at 0.65, in the thin-cloud range (median 0.64 for "cloudy").
    """

    mode: str = "relative"
    rules: str = "published"
    window: str = "20min"
    smoothing: str | None = "1min"
    min_altitude: float = 5.0
    low_sun: str = "absolute"
    full_variation: float = 0.3
    relative_floor: float = 0.3

    def __post_init__(self) -> None:
        if isinstance(self.smoothing, str) and self.smoothing.lower() == "none":
            object.__setattr__(self, "smoothing", None)
        for name, allowed in (("mode", MODES), ("rules", RULES), ("low_sun", LOW_SUN)):
            if getattr(self, name) not in allowed:
                raise HybridtrackError(f"sky inputs: {name} {getattr(self, name)!r} is not one of {', '.join(allowed)}")
        duration(self.window, "sky inputs: window")
        if self.smoothing is not None:
            duration(self.smoothing, "sky inputs: smoothing")
        if isinstance(self.min_altitude, bool) or not isinstance(self.min_altitude, (int, float)) \
                or not math.isfinite(self.min_altitude) or not -5.0 <= self.min_altitude <= 45.0:
            raise HybridtrackError(f"sky inputs: min_altitude {self.min_altitude!r} must be a number of degrees "
                                   "within [-5, 45]")
        for name, low, high in (("full_variation", 0.05, 2.0), ("relative_floor", 0.0, 0.9)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or not low <= value <= high:
                raise HybridtrackError(f"sky inputs: {name} {value!r} must be a number within [{low:g}, {high:g}]")

    @classmethod
    def published(cls) -> SkyInputConfig:
        """The published system: absolute mA, raw samples, four rules, no low-sun rule."""
        return cls(mode="absolute", rules="published", window="20min", smoothing=None, min_altitude=-5.0)

    def to_dict(self) -> dict:
        """Plain values; ``smoothing = None`` is written as ``"none"`` (TOML has no null)."""
        data = asdict(self)
        data["smoothing"] = "none" if self.smoothing is None else self.smoothing
        return data

    @classmethod
    def from_dict(cls, data, *, source: str = "sky inputs") -> SkyInputConfig:
        """Build from a mapping such as a TOML ``[sky]`` table; unknown keys are refused."""
        if not isinstance(data, dict):
            raise HybridtrackError(f"{source}: the sky inputs must be a table, got {type(data).__name__}")
        allowed = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise HybridtrackError(f"{source}: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(allowed))}")
        values = dict(data)
        for key in ("mode", "rules", "window", "smoothing", "low_sun"):
            if key in values and not isinstance(values[key], str):
                raise HybridtrackError(f"{source}: {key} must be a string, got {values[key]!r}")
        if str(values.get("smoothing", "")).lower() == "none":
            values["smoothing"] = None
        try:
            return cls(**values)
        except HybridtrackError as exc:
            raise HybridtrackError(f"{source}: {exc}") from None

    @classmethod
    def from_toml(cls, path) -> SkyInputConfig:
        """Read a TOML file: its ``[sky]`` table, or the whole file if it has none."""
        from .io import read_toml

        data = read_toml(path)
        return cls.from_dict(data.get("sky", data), source=str(path))

    def to_toml(self, path) -> Path:
        """Write the config as a TOML file with a ``[sky]`` table."""
        from .io import write_toml

        return write_toml({"sky": self.to_dict()}, path)


def fuzzy_config(config: SkyInputConfig):
    """The `FuzzyConfig` of the chosen rule table."""
    from .fuzzy import FuzzyConfig

    return FuzzyConfig.from_toml(COMPLETE_RULES) if config.rules == "complete" else FuzzyConfig.default()


def clear_sky(index: pd.DatetimeIndex, site: Site | str, position: pd.DataFrame | None = None) -> pd.DataFrame:
    """Sun altitude and Ineichen clear-sky irradiance at each stamp.

    Parameters
    ----------
    index : pandas.DatetimeIndex
    site : Site or str
    position : pandas.DataFrame, optional
        The sun's ``apparent_altitude`` (degrees) at each stamp, e.g. from a controller's own sun
        model (``hybridtrack.sun.solar_position``); pvlib's SPA by default.

    Returns
    -------
    pandas.DataFrame
        ``apparent_elevation`` (degrees) and ``ghi``, ``dni``, ``dhi`` (W/m²) of pvlib's
        Ineichen-Perez clear sky with the Linke turbidity looked up for the site and month.

    References
    ----------
    Ineichen, P. and Perez, R. (2002). A new airmass independent formulation for the Linke
    turbidity coefficient. Solar Energy 73(3), 151-157. doi:10.1016/S0038-092X(02)00045-2
    """
    import pvlib

    site = get(site)
    if not isinstance(index, pd.DatetimeIndex) or index.tz is None:
        raise HybridtrackError("the clear sky needs a time-zone-aware DatetimeIndex")
    if position is None:
        location = pvlib.location.Location(site.latitude, site.longitude, altitude=site.altitude)
        elevation = location.get_solarposition(index)["apparent_elevation"].to_numpy(float)
    else:
        elevation = np.asarray(position["apparent_altitude"], float)
    ghi, dni, dhi = ineichen_clear_sky(index, site, 90.0 - elevation, daily_extraterrestrial=True)
    return pd.DataFrame({"apparent_elevation": elevation, "ghi": ghi, "dni": dni, "dhi": dhi}, index=index)


def clear_sky_photocurrent(clear: pd.DataFrame, sensor: SensorModel) -> pd.Series:
    """The photocurrent (mA) the sensor model gives under the clear sky, without noise."""
    current = sensor.photocurrent(clear[["dni", "dhi"]])
    return current.rename("clear_intensity_ma")


def _smoothed(values: pd.Series, smoothing: str | None) -> pd.Series:
    if smoothing is None:
        return values
    return values.rolling(pd.Timedelta(smoothing), min_periods=1).mean()


def photocurrent_range(current: pd.Series, config: SkyInputConfig | None = None) -> tuple[pd.Series, pd.Series]:
    """The photocurrent as the sky watch reads it and its trailing range, both in mA.

    Parameters
    ----------
    current : pandas.Series
        The sensor's photocurrent (mA) on a time index.
    config : SkyInputConfig, optional
        Its ``smoothing`` (the trailing mean taken first, if any) and ``window`` (the range's
        span); the default when omitted.

    Returns
    -------
    (pandas.Series, pandas.Series)
        The smoothed photocurrent and its range (max - min) over the trailing ``window``: the
        classifier's inputs in absolute mode, and what relative mode divides by the clear sky.
    """
    config = config or SkyInputConfig()
    absolute = _smoothed(current.astype(float), config.smoothing)
    return absolute, trailing_range(absolute, config.window)


def sky_inputs(frame: pd.DataFrame, site: Site | str, sensor: SensorModel | None = None,
               config: SkyInputConfig | None = None, *, intensity: pd.Series | None = None,
               clear: pd.DataFrame | None = None) -> tuple[pd.Series, pd.Series]:
    """The classifier's two inputs, on the mA scale of its config, for every stamp.

    Parameters
    ----------
    frame : pandas.DataFrame
        Weather frame on a tz-aware index with ``dni`` and ``dhi`` (or ``photocurrent``).
    site : Site or str
    sensor : SensorModel, optional
        The sensor; the default model when omitted.
    config : SkyInputConfig, optional
        The input choices; the default (measured best) when omitted.
    intensity : pandas.Series, optional
        The sensor's photocurrent (mA) if already computed (e.g. with noise); else the
        noise-free model (or the recorded ``photocurrent`` column).
    clear : pandas.DataFrame, optional
        `clear_sky` for the frame's index, if already computed.

    Returns
    -------
    (pandas.Series, pandas.Series)
        ``intensity_input`` and ``variation_input``, to be given to
        ``FuzzyWeatherClassifier.score``; NaN where the low-sun rule says ``unknown``.

    References
    ----------
    Ineichen, P. and Perez, R. (2002). A new airmass independent formulation for the Linke
    turbidity coefficient. Solar Energy 73(3), 151-157. doi:10.1016/S0038-092X(02)00045-2
    """
    sensor = sensor or SensorModel()
    config = config or SkyInputConfig()
    if not isinstance(frame.index, pd.DatetimeIndex) or frame.index.tz is None:
        raise HybridtrackError("the sky inputs need a weather frame on a time-zone-aware DatetimeIndex")
    current = sensor.photocurrent(frame) if intensity is None else intensity
    absolute, absolute_variation = photocurrent_range(current, config)
    if config.mode == "absolute":
        return absolute.rename("intensity_input"), absolute_variation.rename("variation_input")
    fuzzy = fuzzy_config(config)
    lo, hi = fuzzy.inputs[0].raw_range
    vlo, vhi = fuzzy.inputs[1].raw_range
    clear = clear_sky(frame.index, site) if clear is None else clear
    expected = clear_sky_photocurrent(clear, sensor) - sensor.dark_current
    low = (clear["apparent_elevation"] < config.min_altitude).to_numpy() | ~(expected.to_numpy() > 0)
    # a sky brighter than the model's clear sky is clear: the excess is the model's error
    # (Linke turbidity looked up, not measured), and its ramp must not read as variation
    relative = ((absolute - sensor.dark_current) / expected.where(~low)).clip(upper=1.0)
    relative_variation = trailing_range(relative, config.window)
    floor = config.relative_floor
    intensity_input = lo + (hi - lo) * ((relative - floor) / (1.0 - floor)).clip(0.0, 1.0)
    variation_input = vlo + (vhi - vlo) * relative_variation / config.full_variation
    fallback = (absolute, absolute_variation) if config.low_sun == "absolute" else (np.nan, np.nan)
    intensity_input = intensity_input.where(~low, fallback[0])
    variation_input = variation_input.where(~low, fallback[1])
    return intensity_input.rename("intensity_input"), variation_input.rename("variation_input")


def classify_sky(frame: pd.DataFrame, site: Site | str, sensor: SensorModel | None = None,
                 config: SkyInputConfig | None = None, *, classifier=None, intensity: pd.Series | None = None,
                 clear: pd.DataFrame | None = None) -> pd.DataFrame:
    """Sky score and label for every stamp of a weather frame.

    Parameters
    ----------
    frame, site, sensor, config, intensity, clear
        As for `sky_inputs`.
    classifier : FuzzyWeatherClassifier, optional
        Overrides the rule table `config.rules` picks (e.g. a tuned config).

    Returns
    -------
    pandas.DataFrame
        ``intensity_input``, ``variation_input``, ``sky_score`` and ``sky`` (label).
    """
    from .fuzzy import FuzzyWeatherClassifier

    config = config or SkyInputConfig()
    clf = classifier or FuzzyWeatherClassifier(fuzzy_config(config))
    intensity_input, variation_input = sky_inputs(frame, site, sensor, config, intensity=intensity, clear=clear)
    score = clf.score(intensity_input, variation_input)
    return pd.DataFrame({"intensity_input": intensity_input, "variation_input": variation_input,
                         "sky_score": score, "sky": clf.label(score)}, index=frame.index)

