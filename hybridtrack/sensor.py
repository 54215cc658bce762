"""The photoelectric sun sensor: what it reads from the sky, and where it says the sun is.

Two signals come from one sensor head on the collector:

* **Intensity**: the photocurrent in mA, the dark current plus the responsivity times the
  light the cells see. That light is the direct beam (when the sun is inside the field of
  view, weighted by the cosine of the pointing offset) plus a share of the diffuse light.
  The defaults put a clear noon at Lanzhou at 314-333 mA (above the published classifier's
  30-300 mA range, where its intensity input saturates), a clear Nanjing noon at 264-270 mA (the
  published sunny reading is 246 mA), bright overcast near 80-110 mA and night at the 30 mA dark
  current (docs/physics.md §4).
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
* **Pointing**: a four-quadrant (or shadow-band) cell balances the light on its quadrants, so
  it reports the brightness-weighted centre of what falls in its field of view, not the sun
  (`SensorScene`, `read_pointing`). Under a clear sky the beam outweighs everything else in a
  few degrees and the centre is the sun. Under broken cloud a bright, sunlit cloud edge near a
  veiled sun pulls the centre toward it, and a closed loop follows. The light in view is the
  beam, the symmetric circumsolar aureole and that bright patch, apportioned with the Perez
  all-weather model's circumsolar brightening (Perez et al. 1990), from the frame's own DNI and
  DHI, so a pull appears only where the frame's light says a cloud is near the sun. The
  reading's noise grows as the light in view falls (an amplifier's noise against a smaller
  signal). It is valid only with enough light in view: the sensor's own "sun present" output,
  not the DNI, which it cannot know. A coarse, wide-angle stage tells roughly where the sun is.

References
----------
Perez, R., Ineichen, P., Seals, R., Michalsky, J. & Stewart, R. (1990). Modeling daylight
availability and irradiance components from direct and global irradiance. *Solar Energy* 44(5),
271-289. doi:10.1016/0038-092X(90)90055-H

Buie, D., Monger, A. G. & Dey, C. J. (2003). Sunshape distributions for terrestrial solar
simulations. *Solar Energy* 74(2), 113-122. doi:10.1016/S0038-092X(03)00125-7
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .errors import HybridtrackError
from .params import duration, number
from .sky import MinuteGrid, smooth_noise
from .smoothing import one_pole

__all__ = ["SensorModel", "sensor_view", "RECORDED_COLUMN", "RECORDED_POINTING", "SensorScene", "SceneLight",
           "scene_light", "sensor_scene", "circumsolar_light", "sensor_frame", "read_pointing", "read_photocurrent",
           "coarse_offset"]

#: A weather frame column holding a recorded photocurrent (mA), used instead of the model.
RECORDED_COLUMN = "photocurrent"
#: Weather frame columns holding the sensor's recorded pointing signal, degrees, one per axis it
#: serves (a single axis; a heliostat's azimuth and elevation), used instead of the model.
RECORDED_POINTING = ("pointing", "pointing_2")


#: The least responsivity a sun sensor can have, mA per W/m² (`SensorModel.responsivity`).
MIN_RESPONSIVITY = 0.001


@dataclass(frozen=True)
class SensorModel:
    """Parameters of the photoelectric sun sensor.

    Parameters
    ----------
    dark_current : float
        Photocurrent with no light, mA.
    responsivity : float
        mA per W/m² of light on the cells, from `MIN_RESPONSIVITY` to 10: below that the full
        sun's photocurrent (1 mA at 1000 W/m²) is within twice the default noise, no signal to
        track or classify by (1e-300 had broken the mount fit's numbers mid-run).
    diffuse_share : float
        Share of the diffuse irradiance the cells see (0-1).
    window : str
        Trailing window for the variation, e.g. ``"20min"``.
    current_noise : float
        Standard deviation of the photocurrent noise, mA.
    direct_threshold : float
        W/m² of light in the fine cells' view below which the sensor says it sees no sun
        (the WMO's sunshine threshold, 120 W/m², applied to what the cells see).
    field_of_view : float
        Half-angle of the fine (pointing) cells' view, degrees.
    coarse_field_of_view : float
        Half-angle of the wide-angle acquisition cells, degrees: commercial trackers' coarse
        cells look east and west down to the horizon, so the sun is found from any angle.
    coarse_accuracy : float
        Degrees, 1σ of the acquisition cells' estimate of the sun's offset (the ratio of two
        cosine cells facing either way, good to a few degrees).
    noise : float
        Standard deviation of the measured pointing offset at 1000 W/m² in view, degrees;
        it grows as 1000 W/m² over the light in view.
    bias : float
        Sensor-to-axis mounting error: a constant offset of the reading, degrees.
    patch_distance : tuple of float
        Degrees: the bright cloud patch's centroid lies this far from the sun (a cloud edge
        inside the view that a cloud veiling or about to veil the sun presents).
    view_share : float
        Share of the Perez circumsolar light that falls inside the fine view. For an aureole
        whose radiance falls as the inverse square of the angle from the sun (Buie et al.
        2003 measure slopes of about -2), the share within 10° of Perez's 25° circumsolar
        region is ln(10/0.27)/ln(25/0.27) ≈ 0.8.
    """

    dark_current: float = 30.0
    responsivity: float = 0.271
    diffuse_share: float = 0.5
    window: str = "20min"
    current_noise: float = 0.5
    direct_threshold: float = 120.0
    field_of_view: float = 10.0
    coarse_field_of_view: float = 90.0
    noise: float = 0.03
    bias: float = 0.0
    coarse_accuracy: float = 2.0
    patch_distance: tuple[float, float] = (2.0, 6.0)
    view_share: float = 0.8

    def __post_init__(self) -> None:
        # (name, low, high, low excluded): mA, mA per W/m², shares, W/m², degrees
        ranges = [("dark_current", 0, 1000, False), ("responsivity", MIN_RESPONSIVITY, 10, False),
                  ("diffuse_share", 0, 1, False),
                  ("current_noise", 0, 100, False), ("direct_threshold", 0, 1500, True),
                  ("field_of_view", 0, 90, True), ("coarse_field_of_view", self.field_of_view, 90, False),
                  ("coarse_accuracy", 0, 45, False), ("noise", 0, 5, False), ("bias", -5, 5, False),
                  ("view_share", 0, 1, False)]
        for name, low, high, above in ranges:
            number(getattr(self, name), f"sensor: {name}", low, high, above=above)
        patch = tuple(self.patch_distance)
        if len(patch) != 2 or not number(patch[0], "sensor: patch_distance", 0, 30) \
                <= number(patch[1], "sensor: patch_distance", 0, 30):
            raise HybridtrackError(f"sensor: patch_distance {list(patch)} must be [low, high] within 0-30 degrees")
        object.__setattr__(self, "patch_distance", tuple(float(v) for v in patch))
        duration(self.window, "sensor: window")

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


@dataclass
class SensorScene:
    """The light a sensor facing the sun would have in view, per step (world side).

    Attributes
    ----------
    beam : numpy.ndarray
        DNI, W/m².
    aureole : numpy.ndarray
        Symmetric circumsolar light inside the fine view, W/m² on a sun-facing plane.
    patch : numpy.ndarray
        The bright cloud patch's light inside the fine view, W/m² on a sun-facing plane.
    patch_offset : numpy.ndarray
        (N, 2) degrees from the sun to the patch's centroid, in the sensor's two axes; 0 where
        the patch has no light (``patch`` 0), where its place changes no reading.
    diffuse : numpy.ndarray
        DHI, W/m² (for the photocurrent).
    """

    beam: np.ndarray
    aureole: np.ndarray
    patch: np.ndarray
    patch_offset: np.ndarray
    diffuse: np.ndarray


def circumsolar_light(frame: pd.DataFrame, position: pd.DataFrame) -> np.ndarray:
    """Perez's circumsolar diffuse on a plane facing the sun, W/m² (0 with the sun down).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``dni`` and ``dhi``, W/m²; a missing or negative value counts as no light.
    position : pandas.DataFrame
        The true sun (``zenith``, ``azimuth``) on the same index.

    Returns
    -------
    numpy.ndarray

    References
    ----------
    Perez, R., Ineichen, P., Seals, R., Michalsky, J. and Stewart, R. (1990). Modeling daylight
    availability and irradiance components from direct and global irradiance. Solar Energy 44(5),
    271-289. doi:10.1016/0038-092X(90)90055-H
    """
    import pvlib

    zenith = position["zenith"].to_numpy(float)
    up = zenith < 90.0
    out = np.zeros(len(frame))
    if not up.any():
        return out
    index = frame.index[up]
    dhi = np.nan_to_num(np.clip(frame["dhi"].to_numpy(float)[up], 0.0, None))
    dni = np.nan_to_num(np.clip(frame["dni"].to_numpy(float)[up], 0.0, None))
    azimuth = position["azimuth"].to_numpy(float)[up]
    airmass = pvlib.atmosphere.get_relative_airmass(zenith[up])
    extra = pvlib.irradiance.get_extra_radiation(index).to_numpy(float)
    parts = pvlib.irradiance.perez(zenith[up], azimuth, dhi, dni, extra, zenith[up], azimuth, airmass,
                                   return_components=True)
    out[up] = np.nan_to_num(np.asarray(parts["poa_circumsolar"], float))
    return np.maximum(out, 0.0)


@dataclass
class SceneLight:
    """What a sun-facing sensor has in view that follows from the weather and the sun alone, the
    same for every collector under them (a field's collectors share it): `SensorScene`'s light,
    and the unsigned cloud-edge pattern the patch's side follows (`sensor_scene`)."""

    beam: np.ndarray
    aureole: np.ndarray
    patch: np.ndarray
    diffuse: np.ndarray
    edges: np.ndarray | None  # the side at the first cloud edge taken as +1; None for fewer than 2 stamps
    grid: MinuteGrid


def scene_light(frame: pd.DataFrame, position: pd.DataFrame, model: SensorModel, *, clear_dni, clear_dhi,
                circumsolar=None) -> SceneLight:
    """The weather's and the sun's part of `sensor_scene` (its parameters); `model` gives only its
    ``view_share``."""
    dni = np.clip(frame["dni"].to_numpy(float), 0.0, None)  # NaN stays NaN: light nobody knows
    dhi = np.clip(frame["dhi"].to_numpy(float), 0.0, None)
    clear_dni = np.nan_to_num(np.asarray(clear_dni, float))
    clear_dhi = np.nan_to_num(np.asarray(clear_dhi, float))
    if circumsolar is None:
        circumsolar = circumsolar_light(frame, position)
    circumsolar = np.asarray(circumsolar, float) * model.view_share
    cloud_share = np.divide(np.clip(np.nan_to_num(dhi) - clear_dhi, 0.0, None), dhi, out=np.zeros_like(dhi),
                            where=np.nan_to_num(dhi) > 0)
    clearness = np.clip(np.divide(np.nan_to_num(dni), np.maximum(clear_dni, 50.0)), 0.0, 1.2)
    grid = MinuteGrid.of(frame.index)
    return SceneLight(beam=dni, aureole=circumsolar * (1.0 - cloud_share), patch=circumsolar * cloud_share,
                      diffuse=dhi, edges=_cloud_edges(grid.minutes, clearness), grid=grid)


def _cloud_edges(minutes: np.ndarray, clearness: np.ndarray) -> np.ndarray | None:
    """Which side of the sun the bright cloud light is on, -1 to 1, continuous in time, taking the
    first side as +1 (None for fewer than two stamps: no side).

    The side flips at every cloud passage's edge, where the beam's clearness (DNI over clear-sky
    DNI) crosses one half: the nearest sunlit edge moves from one side of the sun to the other
    as the cloud crosses it. The flip is smoothed with a 2-minute time constant so the patch
    moves through the sun rather than jumping. A collector's patch takes a random first side:
    this times -1 or 1, which is the filter of the flipped steps exactly (the filter is linear,
    and a sign change is exact in floating point).
    """
    if len(minutes) < 2:
        return None
    clear = clearness >= 0.5
    crossings = np.concatenate([[0], np.cumsum(clear[1:] != clear[:-1])])
    sign = np.where(crossings % 2 == 0, 1.0, -1.0)
    keep = np.exp(-float(np.median(np.diff(minutes))) / 2.0)
    return one_pole(sign, 1.0 - keep, keep, keep * sign[0])


def sensor_scene(frame: pd.DataFrame, position: pd.DataFrame | None, model: SensorModel, *, clear_dni=None,
                 clear_dhi=None, rng: np.random.Generator, circumsolar=None,
                 light: SceneLight | None = None) -> SensorScene:
    """What a sun-facing sensor has in view at each step of a weather frame (world side).

    Parameters
    ----------
    frame : pandas.DataFrame
        ``dni`` and ``dhi`` (recorded or synthetic).
    position : pandas.DataFrame or None
        The true sun (``zenith``, ``azimuth``) on the same index; not read where `light` is given.
    model : SensorModel
    clear_dni, clear_dhi : array-like
        Clear-sky DNI and DHI on the same index (a synthetic frame's ``dni_clear`` and
        ``dhi_clear``; pvlib's Ineichen model for a recorded one).
    rng : numpy.random.Generator
        Seeds the patch's distance from the sun and its direction.
    circumsolar : array-like, optional
        `circumsolar_light` for this frame and sun, if computed already; computed here otherwise.
    light : SceneLight, optional
        `scene_light` for this frame, sun and model, if computed already (a field's collectors
        share it); then the clear sky and `circumsolar` are not needed.

    Notes
    -----
    The diffuse light above what the clear sky would give (DHI − clear DHI) is cloud light;
    its circumsolar share (Perez et al. 1990) is the patch, off the sun. The rest of the
    circumsolar light is the aureole, centred on the sun. The patch sits `patch_distance` from
    the sun (a seeded AR(1) between the bounds, time constant 30 min) in a direction that turns
    as the clouds move (AR(1), 20 min), on the side `_cloud_edges` says.
    """
    if light is None:
        light = scene_light(frame, position, model, clear_dni=clear_dni, clear_dhi=clear_dhi, circumsolar=circumsolar)
    index, grid = frame.index, light.grid
    side = np.zeros(len(index)) if light.edges is None else rng.choice([-1.0, 1.0]) * light.edges
    low, high = model.patch_distance
    wander = smooth_noise(index, rng, 30.0, 1.0, grid=grid)  # drawn over every step, as the seed's stream runs
    heading = rng.uniform(0.0, 2.0 * np.pi)
    turn = smooth_noise(index, rng, 20.0, 1.0, grid=grid)
    # placed only where the patch shines (half a year's steps): elsewhere its place changes no
    # reading, and the trigonometry over every step was 15 ms of a Fresnel row-year
    lit = np.flatnonzero(light.patch)
    distance = low + (high - low) * 0.5 * (1.0 + np.tanh(wander[lit]))
    direction = heading + 0.5 * turn[lit]
    reach = side[lit] * distance
    offset = np.zeros((2, len(index)))  # each axis's offsets in a row of their own, as the world reads them
    offset[0, lit] = np.cos(direction) * reach
    offset[1, lit] = np.sin(direction) * reach
    return SensorScene(beam=light.beam, aureole=light.aureole, patch=light.patch, patch_offset=offset.T,
                       diffuse=light.diffuse)


def sensor_frame(azimuth_miss: float, target_elevation: float, elevation: float) -> tuple[float, float]:
    """Where a heliostat's sensor, on the mirror, sees its target: degrees across its face and
    along it, from axis misses.

    Parameters
    ----------
    azimuth_miss : float
        Degrees the target's azimuth lies from the azimuth axis's angle (wrapped to a half turn).
    target_elevation : float
        The target's elevation on the mount, degrees.
    elevation : float
        The elevation axis's angle, degrees.

    Returns
    -------
    (float, float)
        The angle across the sensor's face (out of the plane the elevation axis turns the
        sensor's axis in), ``asin(cos e · sin Δaz)``, and the angle along it (in that plane),
        ``atan2(sin e, cos e · cos Δaz) - elevation``: the target's cross-elevation and
        elevation errors in the sensor's own frame (docs/world.md, "The sensor's frame"). Near
        the zenith a large azimuth miss is a small angle across the face: at 89° a 26.7° miss
        is 0.45°.
    """
    d, e = math.radians(azimuth_miss), math.radians(target_elevation)
    across = math.degrees(math.asin(math.cos(e) * math.sin(d)))
    along = math.degrees(math.atan2(math.sin(e), math.cos(e) * math.cos(d))) - elevation
    return across, (along + 180.0) % 360.0 - 180.0


def read_pointing(offsets, beam: float, aureole: float, patch: float, patch_offset, noise, model: SensorModel):
    """What the fine cells report for one scan: the offset per axis and whether they see a sun.

    Parameters
    ----------
    offsets : sequence of float
        Degrees from the sensor's axis to the true sun, per axis, in the sensor's own frame (a
        heliostat's: `sensor_frame`; the mounting bias included).
    beam, aureole, patch : float
        The scene's light (`SensorScene`) at this scan, W/m².
    patch_offset : sequence of float
        Degrees from the sun to the patch, per axis.
    noise : sequence of float
        Standard normal draws, per axis.
    model : SensorModel

    Returns
    -------
    (list of float, bool)
        The reported offsets (NaN when nothing is in view) and the "sun present" output.
    """
    fov = model.field_of_view
    worst = abs(offsets[0]) if len(offsets) == 1 else max(abs(offsets[0]), abs(offsets[1]))
    spot = [o + p for o, p in zip(offsets, patch_offset)]
    spread = abs(spot[0]) if len(spot) == 1 else max(abs(spot[0]), abs(spot[1]))
    sun_light = beam * math.cos(math.radians(worst)) + aureole if worst <= fov else 0.0
    patch_light = patch if spread <= fov else 0.0
    light = sun_light + patch_light
    if not light >= model.direct_threshold:
        return [math.nan] * len(offsets), False
    sigma = model.noise * 1000.0 / light
    return [(sun_light * o + patch_light * s) / light + sigma * z for o, s, z in zip(offsets, spot, noise)], True


def read_photocurrent(offset: float, beam: float, diffuse: float, noise: float, model: SensorModel) -> float:
    """The photocurrent (mA) for one scan, with the sensor `offset` degrees off the sun."""
    off = abs(offset)
    direct = beam * math.cos(math.radians(off)) if off <= model.coarse_field_of_view else 0.0
    current = model.dark_current + model.responsivity * (direct + model.diffuse_share * diffuse)
    return max(current + model.current_noise * noise, 0.0)


def coarse_offset(offset: float, beam: float, noise: float, model: SensorModel) -> float:
    """The acquisition cells' estimate of the sun's offset, degrees (NaN if they see no sun)."""
    if beam >= model.direct_threshold and abs(offset) <= model.coarse_field_of_view:
        return offset + model.coarse_accuracy * noise
    return math.nan
