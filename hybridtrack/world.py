"""The world the controller lives in (the plant): the true sun, the true mounting, the sensor's
physics, the encoder and the actuator.

Metrics are scored against this world; the controller never sees it. Each scan the world
fills an `Observation` with what the controller's instruments read, the controller decides,
and the world moves (`World.observe`, `World.move`). Every imperfection here is something the
controller does not know about:

* the collector's true axis is turned by `axis_azimuth_error` and tilted by
  `axis_tilt_error` from the nominal one (a rotation of the mounting frame);
* the encoder's zero is off by `encoder_offset`, so its readings are shifted;
* the controller's clock runs `clock_error` seconds ahead (negative: behind);
* its site coordinates are off by `latitude_error` and `longitude_error`;
* the sun sensor is mounted `sensor_bias` off the collector's axis, and its reading has
  `sensor_noise` (1σ at 1000 W/m² in view, growing as the light falls).

The defaults are the size found in commissioned fields: a few tenths of a degree of axis
misalignment, an encoder zero three counts off (0.26°), a PLC clock 45 s behind, site
coordinates from a map (about 1 km), a sensor bracket aligned to about 1 mrad (0.06°), and
a fine sensor's noise of 0.03° at full sun (commercial fine sun sensors quote < 0.1°).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from . import sites
from .collectors import Collector
from .control.modes import UNKNOWN, sky_code
from .control.observation import Observation
from .drive import Drive, encoder_reading
from .errors import HybridtrackError
from .params import _finite
from .mounting import (geometry_key, heliostat_sun, incidence_cosine, mount_targets, mounting_rotation,
                       pointing_vectors)
from .reuse import Same, shared
from .sensor import (RECORDED_COLUMN, RECORDED_POINTING, SceneLight, SensorModel, coarse_offset, read_photocurrent,
                     read_pointing, scene_light, sensor_frame, sensor_scene)
from .sun import solar_position
from .times import HOUR_NS, plus_seconds

__all__ = ["Imperfections", "World", "HARD_STOP_MARGIN", "installed_site", "controller_clock", "scan_timer",
           "true_sun"]

#: Degrees the mechanism's hard stops lie beyond the drive's software limits.
HARD_STOP_MARGIN = 1.0


#: The largest size of each imperfection (degrees; seconds; seconds a day; days).
IMPERFECTION_LIMITS = {"axis_azimuth_error": 10.0, "axis_tilt_error": 10.0, "encoder_offset": 10.0,
                       "clock_error": 3600.0, "clock_drift": 100.0, "commissioned_days_ago": 3660.0,
                       "latitude_error": 1.0, "longitude_error": 1.0, "sensor_bias": 2.0, "sensor_noise": 2.0,
                       "axis_roll_error": 10.0}


@dataclass(frozen=True)
class Imperfections:
    """What is wrong with the real installation, unknown to the controller.

    Parameters
    ----------
    axis_azimuth_error, axis_tilt_error : float
        Degrees the true axis is turned (counterclockwise seen from above: its azimuth is the
        nominal one minus this) and tilted (its far end up) from the nominal axis.
    encoder_offset : float
        Degrees the encoder's zero is off; the reading is the true angle plus this.
    clock_error : float
        Seconds the controller's clock ran ahead of true time when it was set, at commissioning.
    clock_drift : float
        Seconds a day the controller's clock gains (negative: loses). A PLC's real-time clock runs
        on an uncompensated watch crystal; Siemens gives ±60 s a month at 25 °C for the S7-1200
        (±2 s a day). The default is half that bound.
    commissioned_days_ago : float
        Days between commissioning (when the clock was set and an open loop's mount was fitted)
        and the start of the run: the clock has drifted for that long.
    latitude_error, longitude_error : float
        Degrees the controller's site coordinates are off.
    sensor_bias : float
        Degrees the sun sensor is mounted off the collector's axis.
    sensor_noise : float
        Degrees, 1σ of the sensor's reading at 1000 W/m² in view.
    axis_roll_error : float
        Degrees the mount is rolled about its nominal axis direction
        (`hybridtrack.mounting.mounting_rotation`): a heliostat pedestal's tilt about the
        north-south line, beside `axis_tilt_error` about the east-west line. For a single-axis
        collector a roll about its own axis is an encoder offset.
    """

    axis_azimuth_error: float = 0.3
    axis_tilt_error: float = 0.2
    encoder_offset: float = 0.26
    clock_error: float = -45.0
    clock_drift: float = 1.0
    commissioned_days_ago: float = 30.0
    latitude_error: float = 0.008
    longitude_error: float = 0.01
    sensor_bias: float = 0.06
    sensor_noise: float = 0.03
    axis_roll_error: float = 0.0

    def __post_init__(self) -> None:
        limits = IMPERFECTION_LIMITS
        for f in fields(self):  # numpy's numbers too, kept as floats (a float32 had been refused)
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not _finite(value):
                raise HybridtrackError(f"imperfections: {f.name} must be a finite number, got {value!r:.60}")
            if abs(value) > limits[f.name]:
                raise HybridtrackError(f"imperfections: {f.name} = {value} is beyond ±{limits[f.name]:g}")
            object.__setattr__(self, f.name, float(value))
        if self.sensor_noise < 0 or self.commissioned_days_ago < 0:
            raise HybridtrackError("imperfections: sensor_noise and commissioned_days_ago must not be negative")

    @classmethod
    def none(cls) -> Imperfections:
        """A perfect installation."""
        return cls(**{f.name: 0.0 for f in fields(cls)})




def installed_site(site: sites.Site, imperfections: Imperfections) -> sites.Site:
    """The site as the installer told the controller: off by the coordinate errors."""
    latitude = float(np.clip(site.latitude + imperfections.latitude_error, -90, 90))
    longitude = float((site.longitude + imperfections.longitude_error + 180) % 360 - 180)
    return sites.Site(site.name, latitude, longitude, site.altitude, site.tz)


def scan_timer(index: pd.DatetimeIndex) -> np.ndarray:
    """The controller's scan timer at each scan: minutes since the run began. Computed once for
    the world and the controller of every run of a field under one frame (`hybridtrack.reuse`;
    handed out read-only there)."""
    return shared(("scan timer", Same(index)), lambda: np.asarray((index - index[0]) / pd.Timedelta(minutes=1), float))


def controller_clock(index: pd.DatetimeIndex, imperfections: Imperfections, faults: dict) -> pd.DatetimeIndex:
    """What the controller's clock shows at each scan of `index`: true time plus its error, its
    drift since it was set, and any clock fault (``faults["clock"]``, seconds per scan). The same
    for every collector of a field controller (`hybridtrack.reuse`)."""
    imp = imperfections

    def reading(fault_seconds):
        age = imp.commissioned_days_ago + np.asarray((index - index[0]) / pd.Timedelta(days=1), float)
        return plus_seconds(index, imp.clock_error + imp.clock_drift * age + fault_seconds)

    if "clock" in faults:
        return reading(np.nan_to_num(np.asarray(faults["clock"], float)))
    key = ("controller clock", Same(index), imp.clock_error, imp.clock_drift, imp.commissioned_days_ago)
    return shared(key, lambda: reading(np.zeros(len(index))))


def true_sun(index: pd.DatetimeIndex, site: sites.Site, model: str) -> tuple[np.ndarray, np.ndarray]:
    """The true sun's apparent altitude and azimuth at each stamp, degrees: `model`'s (SPA) where
    the sun can be up (a cheap model finds where), the sun far below (-90°) elsewhere. Computed
    once for the runs of a field and its table (`hybridtrack.reuse`), and handed to each as
    read-only arrays.

    The altitude is the apparent one, refraction included (SPA's, at the site's pressure and
    12 °C): the light comes from where the sun appears, and that is where a sensor sees it and
    a collector must point. The geometric sun had been the truth, so a controller that leaves
    refraction out was scored as tracking perfectly at a low sun, 0.48° below the true one at the
    horizon and 0.09° at 10° at sea level (docs/world.md, "Refraction")."""
    return shared(("true sun", Same(index), site, model), lambda: _sun_where_up(index, site, model))


def _sun_where_up(index: pd.DatetimeIndex, site: sites.Site, model: str) -> tuple[np.ndarray, np.ndarray]:
    candidate = _sun_may_be_up(index, site)
    altitude, azimuth = np.full(len(index), -90.0), np.zeros(len(index))
    if candidate.any():
        spa = solar_position(index[candidate], site, model)
        altitude[candidate], azimuth[candidate] = spa["apparent_altitude"].to_numpy(), spa["azimuth"].to_numpy()
    return altitude, azimuth


def _sun_may_be_up(index: pd.DatetimeIndex, site: sites.Site) -> np.ndarray:
    """Stamps where the sun may be above -3°, as the cheap PLC model sees it at a knot every
    hour: each stamp is judged by its nearest knot, half an hour away at most, in which the
    sun's altitude moves 7.5° at most (the earth turns 0.25° a minute), and by 0.5° more for
    the model's declination and equation of time, held for each calendar day."""
    stamps = np.asarray(index.as_unit("ns").asi8)
    if not len(stamps):
        return np.zeros(0, bool)
    first = stamps.min() // HOUR_NS
    knots = pd.DatetimeIndex(np.arange(first, stamps.max() // HOUR_NS + 2) * HOUR_NS).tz_localize("UTC")
    altitude = solar_position(knots, site, "plc")["altitude"].to_numpy()
    return altitude[(stamps + HOUR_NS // 2) // HOUR_NS - first] > -3.0 - 7.5 - 0.5


class World:
    """The plant one collector lives in, over one weather frame.

    Parameters
    ----------
    frame : pandas.DataFrame
        The weather (``dni``, ``dhi``, ``wind_speed``; a recorded ``photocurrent``, and a
        recorded pointing signal ``pointing`` (and ``pointing_2`` for a heliostat's elevation),
        degrees, NaN where the sensor had no reading, are used as recorded; a ``sky`` column is
        the true sky, for the oracle policy only).
    site : Site
    collector : Collector
    imperfections : Imperfections
    sensor : SensorModel
        The sensor's physics; its `bias` and `noise` are taken from `imperfections`.
    drives : list of Drive
    seed : int
    faults : dict
        Injected faults, one array per step (see ``hybridtrack.simulation.FAULTS``).
    truth : {"spa-fast", "spa"}
        The true sun's model (``hybridtrack.sun.solar_position``).

    Attributes
    ----------
    truth : numpy.ndarray
        (N, axes) the true targets on the true mount, degrees (NaN with the sun down);
        ``truth_axes`` the same per axis, (axes, N), with 0 for NaN, as the scans read it.
    scene : tuple of numpy.ndarray
        The sensor's scene (`hybridtrack.sensor.SensorScene`): beam, aureole, patch, the patch's
        offset per axis (2, N) and the diffuse light.
    noise, current_noise, coarse_noise : numpy.ndarray
        Standard normal draws: the fine cells' (axes, N), the photocurrent's (N,), the coarse
        cells' (axes, N).
    angles : numpy.ndarray
        (axes, N) the angle each axis stood at after each scan, filled as the run goes.
    """

    def __init__(self, frame: pd.DataFrame, site: sites.Site, collector: Collector, imperfections: Imperfections,
                 sensor: SensorModel, drives: list[Drive], seed: int, faults: dict, truth: str = "spa-fast"):
        index = frame.index
        self.n, self.axes = len(index), len(drives)
        self.index, self.site, self.collector, self.imperfections = index, site, collector, imperfections
        self.sensor = dataclasses.replace(sensor, bias=imperfections.sensor_bias, noise=imperfections.sensor_noise)
        self.drives = drives
        self.faults = faults
        rng = np.random.default_rng(seed)
        self._sun_model = truth
        self._sun_key = (Same(index), site, truth)  # what the true sun turns on, in every shared key of it
        self.altitude, self.azimuth = self._true_sun()
        rotation = mounting_rotation(imperfections.axis_azimuth_error, imperfections.axis_tilt_error, collector.axis,
                                     imperfections.axis_roll_error)
        key = geometry_key(self._sun_key, "pointing", collector)  # None: a heliostat's are its own
        vectors = None if key is None else shared(key, lambda: pointing_vectors(self.altitude, self.azimuth, collector))
        self.truth = mount_targets(self.altitude, self.azimuth, collector, rotation, vectors=vectors,
                                   sun=self._heliostat_sun())
        weather = frame if "dhi" in frame.columns else frame.assign(dhi=0.0)
        light = shared(("scene light", Same(frame), *self._sun_key, self.sensor.view_share),
                       lambda: self._scene_light(weather))
        scene = sensor_scene(weather, None, self.sensor, rng=rng, light=light)
        self.scene = (scene.beam, scene.aureole, scene.patch, np.ascontiguousarray(scene.patch_offset.T), scene.diffuse)
        self.truth_axes = np.ascontiguousarray(np.nan_to_num(self.truth[:, :self.axes].T))
        self.noise = rng.standard_normal((self.axes, self.n))  # axis by axis, as one draw each made them
        self.current_noise = rng.standard_normal(self.n)
        self.coarse_noise = rng.standard_normal((self.axes, self.n))
        self.recorded_current = frame[RECORDED_COLUMN].to_numpy(float) if RECORDED_COLUMN in frame.columns else None
        self.recorded_pointing = self._recorded_pointing_columns(frame)
        self.frame_dni = frame["dni"].to_numpy(float)
        self.wind = frame["wind_speed"].to_numpy(float) if "wind_speed" in frame.columns else np.full(self.n, np.nan)
        self.true_sky = shared(("true sky", Same(frame)), lambda: self._true_sky(frame))
        self.minutes = scan_timer(index)
        self.circular = [d.limits[1] - d.limits[0] >= 360.0 for d in drives]
        self.actual = [d.stow - imperfections.encoder_offset for d in drives]  # parked where stow reads
        self.angles = np.full((self.axes, self.n), np.nan)
        self.last_encoder = [math.nan] * self.axes
        self._scans = None

    def _listed(self) -> dict:
        """The frame-wide arrays as Python lists, which the reference loop reads one value at a
        time (a list gives a Python float about three times faster than an array does); made
        on the first scan, so the compiled kernel, which reads the arrays, never pays for them."""
        if self._scans is None:
            def listed(values):
                return None if values is None else np.asarray(values).tolist()

            self._scans = {"scene": [listed(v) for v in self.scene], "truth": listed(self.truth_axes),
                           "noise": listed(self.noise), "current_noise": listed(self.current_noise),
                           "coarse_noise": listed(self.coarse_noise), "recorded": listed(self.recorded_current),
                           "pointing": listed(self.recorded_pointing), "wind": listed(self.wind),
                           "minutes": listed(self.minutes), "sky": listed(self.true_sky),
                           "faults": {name: listed(np.asarray(v).T) for name, v in self.faults.items()
                                      if name != "clock"}}
        return self._scans

    # -- set up ----------------------------------------------------------------------------------

    def _recorded_pointing_columns(self, frame: pd.DataFrame) -> list | None:
        """The sensor's recorded pointing signal per axis (NaN: no reading), or None without one."""
        names = RECORDED_POINTING[:self.axes]
        present = [name for name in names if name in frame.columns]
        if not present:
            return None
        if len(present) < len(names):
            raise HybridtrackError(f"a recorded pointing signal needs a column per axis: {', '.join(names)}; "
                                   f"the frame has {', '.join(present)}")
        return np.array([frame[name].to_numpy(float) for name in names])

    def _true_sun(self) -> tuple[np.ndarray, np.ndarray]:
        return true_sun(self.index, self.site, self._sun_model)

    def _clear_sky(self, frame: pd.DataFrame, position: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
        """The frame's clear-sky DNI and DHI, or Ineichen's under the true sun (`position`, its zenith)."""
        if "dni_clear" in frame.columns and "dhi_clear" in frame.columns:
            return frame["dni_clear"].to_numpy(float), frame["dhi_clear"].to_numpy(float)
        from .sky import clear_sky

        return clear_sky(self.index, self.site, position["zenith"].to_numpy(float))[1:]

    def _scene_light(self, weather: pd.DataFrame) -> SceneLight:
        """The light in the sensor's view from the weather and the true sun: the same for every
        collector under them."""
        position = pd.DataFrame({"azimuth": self.azimuth, "zenith": 90.0 - self.altitude}, index=self.index)
        clear_dni, clear_dhi = self._clear_sky(weather, position)
        return scene_light(weather, position, self.sensor, clear_dni=clear_dni, clear_dhi=clear_dhi)

    @staticmethod
    def _true_sky(frame: pd.DataFrame) -> np.ndarray | None:
        """The frame's true sky as `SKY_CODES` codes (anything else: unknown), or None."""
        if "sky" not in frame.columns:
            return None
        found, names = pd.factorize(frame["sky"])  # -1 for a missing label: the table's last entry
        return np.array([sky_code(name, UNKNOWN) for name in names] + [UNKNOWN], np.int64)[found]

    def incidence(self) -> np.ndarray:
        """Cosine of the true sun's incidence on a perfectly tracking aperture at each scan
        (`hybridtrack.mounting.incidence_cosine`), for the scoring; shared by a field's
        collectors of one geometry (`hybridtrack.mounting.geometry_key`)."""
        return shared(geometry_key(self._sun_key, "incidence", self.collector, aperture=True),
                      lambda: incidence_cosine(self.altitude, self.azimuth, self.collector, sun=heliostat_sun(
                          self._sun_key, self.altitude, self.azimuth, self.collector, aperture=True)))

    def _heliostat_sun(self) -> np.ndarray | None:
        return heliostat_sun(self._sun_key, self.altitude, self.azimuth, self.collector)

    # -- each scan -------------------------------------------------------------------------------

    def _miss(self, truth: list, a: int, i: int) -> float:
        """Degrees axis `a` stands short of its true target (a turning axis's the short way round);
        a single axis or a heliostat's azimuth axis (0)."""
        difference = truth[a][i] - self.actual[a]
        if self.circular[a]:
            difference = (difference + 180.0) % 360.0 - 180.0
        return difference

    def _offsets(self, truth: list, i: int) -> list:
        """Degrees from the sensor's axis to the true sun per axis, in the sensor's own frame (the
        mounting bias included): a single axis's miss as it is, a heliostat's as its sensor on the
        mirror sees it (`hybridtrack.sensor.sensor_frame`; axis 0 azimuth, 1 elevation)."""
        azimuth_miss = self._miss(truth, 0, i)
        misses = [azimuth_miss] if self.axes == 1 else sensor_frame(azimuth_miss, truth[1][i], self.actual[1])
        return [miss + self.sensor.bias for miss in misses]

    def _encoder(self, faults: dict, a: int, i: int) -> float:
        if "encoder_frozen" in faults and faults["encoder_frozen"][i] and not math.isnan(self.last_encoder[a]):
            return self.last_encoder[a]
        value = encoder_reading(self.actual[a] + self.imperfections.encoder_offset, self.drives[a].resolution)
        if "encoder" in faults:
            value += faults["encoder"][a][i]
        self.last_encoder[a] = value
        return value

    def observe(self, i: int, obs: Observation) -> None:
        """Fill `obs` with what the controller's instruments read at scan `i`."""
        scans = self._listed()
        beam, aureole, patch, patch_offset, diffuse = scans["scene"]
        offsets = self._offsets(scans["truth"], i)
        noise = [scans["noise"][a][i] for a in range(self.axes)]
        if scans["pointing"] is not None:  # as recorded: what the logger's sensor said
            reported = [scans["pointing"][a][i] for a in range(self.axes)]
            valid = not any(math.isnan(value) for value in reported)
        else:
            reported, valid = read_pointing(offsets, beam[i], aureole[i], patch[i],
                                            [patch_offset[a][i] for a in range(self.axes)], noise, self.sensor)
        obs.valid = valid
        self._sensor_faults(scans["faults"], i, reported, obs)
        obs.i, obs.t, obs.wind = i, scans["minutes"][i], scans["wind"][i]
        for a in range(self.axes):
            obs.encoder[a] = self._encoder(scans["faults"], a, i)
            obs.coarse[a] = coarse_offset(offsets[a], beam[i], scans["coarse_noise"][a][i], self.sensor)
        worst = max(abs(o) for o in offsets)
        obs.intensity = scans["recorded"][i] if scans["recorded"] is not None else \
            read_photocurrent(worst, beam[i], diffuse[i], scans["current_noise"][i], self.sensor)
        obs.true_sky = scans["sky"][i] if scans["sky"] is not None else -1

    def _sensor_faults(self, faults: dict, i: int, reported: list, obs: Observation) -> None:
        """The sensor's reading after any injected fault: a wrong value (the sensor still says it
        sees the sun), a drift, or a dropout (no number at all)."""
        for a in range(self.axes):
            value = reported[a]
            if "sensor" in faults and not math.isnan(faults["sensor"][a][i]):
                value = faults["sensor"][a][i]
                obs.valid = True  # a faulty sensor still says it sees the sun
            if "sensor_drift" in faults:
                value += faults["sensor_drift"][i]
            if "sensor_dropout" in faults and faults["sensor_dropout"][i]:
                value = math.nan
            obs.offset[a] = value

    def move(self, i: int, moves: list) -> None:
        """Drive each axis by the commanded move; the hard stops hold it. Record the angle at `i`."""
        for a, drive in enumerate(self.drives):
            low, high = drive.limits
            self.actual[a] = min(max(self.actual[a] + moves[a], low - HARD_STOP_MARGIN), high + HARD_STOP_MARGIN)
            self.angles[a, i] = self.actual[a]

    def rest(self, i: int, j: int) -> None:
        """Scans `i` to `j` - 1 with nothing moving."""
        for a in range(self.axes):
            self.angles[a, i:j] = self.actual[a]
