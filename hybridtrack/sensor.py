"""The photoelectric sun sensor: what it reads from the sky, and where it says the sun is.

Two signals come from one sensor head on the collector:

* **Intensity**: the photocurrent in mA, the dark current plus the responsivity times the
  light the cells see. That light is the direct beam (when the sun is inside the field of
  view, weighted by the cosine of the pointing offset) plus a share of the diffuse light.
  The defaults put a clear noon at Lanzhou in June near 300 mA, a clear Nanjing noon near
  250 mA (the published sunny reading is 246 mA), bright overcast near 80-110 mA and night
  at the 30 mA dark current: the field range 30-300 mA of ``domain.md`` §4.
  A recorded ``photocurrent`` column is used as it is.
* **Variation**: how much the intensity moved over a trailing window (the range max − min),
  the classifier's second input. The default window, 20 minutes, was chosen by measurement.
  Synthetic sunny, cloudy and overcast days at Lanzhou and Nanjing (solstices, two seeds,
  sun above 10°) were classified with windows of 5-30 minutes. The share of steps in their
  own class was, for sunny / cloudy / overcast: 5 min 0.91 / 0.27 / 1.00; 10 min 0.89 / 0.53 /
  1.00; 20 min 0.85 / 0.79 / 1.00; 30 min 0.81 / 0.89 / 1.00. Cloud passages last longer than
  a short window, so under one the light looks steady and dim (overcast). The price of
  20 minutes is that a sky stays "cloudy" for up to 20 minutes after the clouds go, which
  is the cautious side for a tracker.
* **Pointing**: the angular offset between the collector's aim and the sun, as the
  quadrant cells measure it, with noise and bias. It is valid only above a direct-light
  threshold and inside the field of view. The default threshold, 120 W/m², is the WMO's
  threshold for sunshine: below it the sun casts no distinct shadow, so the quadrants cannot
  resolve its direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .errors import HybridtrackError

__all__ = ["SensorModel", "sensor_view", "RECORDED_COLUMN"]

#: A weather frame column holding a recorded photocurrent (mA), used instead of the model.
RECORDED_COLUMN = "photocurrent"


@dataclass(frozen=True)
class SensorModel:
    """Parameters of the photoelectric sun sensor.

    Parameters
    ----------
    dark_current : float
        Photocurrent with no light, mA.
    responsivity : float
        mA per W/m² of light on the cells.
    diffuse_share : float
        Share of the diffuse irradiance the cells see (0-1).
    window : str
        Trailing window for the variation, e.g. ``"20min"``.
    current_noise : float
        Standard deviation of the photocurrent noise, mA.
    direct_threshold : float
        DNI below which the pointing signal is invalid, W/m².
    field_of_view : float
        Half-angle inside which the sensor sees the sun, degrees.
    noise : float
        Standard deviation of the measured pointing offset, degrees.
    bias : float
        Constant error of the measured pointing offset, degrees.
    """

    dark_current: float = 30.0
    responsivity: float = 0.271
    diffuse_share: float = 0.5
    window: str = "20min"
    current_noise: float = 0.5
    direct_threshold: float = 120.0
    field_of_view: float = 10.0
    noise: float = 0.03
    bias: float = 0.0

    def __post_init__(self) -> None:
        checks = [("dark_current", self.dark_current >= 0), ("responsivity", self.responsivity > 0),
                  ("diffuse_share", 0 <= self.diffuse_share <= 1), ("current_noise", self.current_noise >= 0),
                  ("direct_threshold", self.direct_threshold >= 0), ("field_of_view", 0 < self.field_of_view <= 90),
                  ("noise", self.noise >= 0)]
        for name, ok in checks:
            if not ok:
                raise HybridtrackError(f"sensor: {name} = {getattr(self, name)!r} is out of range")
        try:
            if pd.Timedelta(self.window) <= pd.Timedelta(0):
                raise ValueError
        except ValueError:
            raise HybridtrackError(f"sensor: window {self.window!r} is not a positive duration such as '20min'") from None

    def direct_response(self, offset) -> np.ndarray:
        """Share of the direct beam the cells collect at a pointing offset (degrees)."""
        off = np.abs(np.asarray(offset, float))
        return np.where(off <= self.field_of_view, np.cos(np.radians(off)), 0.0)

    def photocurrent(self, frame: pd.DataFrame, *, offset=None, rng: np.random.Generator | None = None) -> pd.Series:
        """Photocurrent (mA) for each step of a weather frame.

        A recorded ``photocurrent`` column is returned as it is. Otherwise the model is used,
        with `offset` (degrees, default 0: the sensor faces the sun) and noise from `rng`.
        """
        if RECORDED_COLUMN in frame.columns:
            return frame[RECORDED_COLUMN].astype(float).rename("intensity_ma")
        for column in ("dni", "dhi"):
            if column not in frame.columns:
                raise HybridtrackError(f"the weather frame has no {column!r} column for the sensor model")
        response = self.direct_response(0.0 if offset is None else offset)
        light = frame["dni"].to_numpy(float) * response + self.diffuse_share * frame["dhi"].to_numpy(float)
        current = self.dark_current + self.responsivity * light
        if rng is not None and self.current_noise > 0:
            current = current + rng.normal(0.0, self.current_noise, len(current))
        return pd.Series(np.maximum(current, 0.0), index=frame.index, name="intensity_ma")

    def variation(self, intensity: pd.Series) -> pd.Series:
        """Range (max − min) of the intensity over the trailing window, mA; NaN readings skipped."""
        if not isinstance(intensity.index, pd.DatetimeIndex):
            raise HybridtrackError("the variation needs readings on a DatetimeIndex")
        rolling = intensity.rolling(pd.Timedelta(self.window), min_periods=1)
        return (rolling.max() - rolling.min()).rename("variation_ma")

    def pointing(self, offset, dni, *, rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The measured pointing offset (degrees) and whether it is valid.

        Valid where DNI is at least `direct_threshold` and the true offset is inside the
        field of view (and both are finite); invalid readings are NaN.
        """
        true = np.asarray(offset, float)
        beam = np.asarray(dni, float)
        valid = np.isfinite(true) & np.isfinite(beam) & (beam >= self.direct_threshold) \
            & (np.abs(true) <= self.field_of_view)
        measured = true + self.bias
        if rng is not None and self.noise > 0:
            measured = measured + rng.normal(0.0, self.noise, np.shape(true))
        return np.where(valid, measured, np.nan), valid


def sensor_view(frame: pd.DataFrame, model: SensorModel | None = None, *, seed: int = 0) -> pd.DataFrame:
    """The frame with the sensor's ``intensity_ma`` and ``variation_ma`` columns added.

    The sensor is taken to face the sun (a collector tracking within its field of view);
    the controller adds its own pointing offset when it steps through time.
    """
    model = model or SensorModel()
    rng = np.random.default_rng(seed)
    out = frame.copy()
    out["intensity_ma"] = model.photocurrent(frame, rng=rng)
    out["variation_ma"] = model.variation(out["intensity_ma"])
    out.attrs = dict(frame.attrs)
    out.attrs["intensity_source"] = "recorded" if RECORDED_COLUMN in frame.columns else "sensor model"
    return out
