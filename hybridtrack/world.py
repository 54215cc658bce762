"""The world the controller lives in: the true sun, the true mounting, the imperfections.

Metrics are scored against this world; the controller never sees it. The controller
knows only its clock, its site coordinates, its sun model, its sensor and its encoder.
Every imperfection here is something it does not know about:

* the collector's true axis is turned by `axis_azimuth_error` and tilted by
  `axis_tilt_error` from the nominal one (a rotation of the mounting frame);
* the encoder's zero is off by `encoder_offset`, so its readings are shifted;
* the controller's clock runs `clock_error` seconds ahead (negative: behind);
* its site coordinates are off by `latitude_error` and `longitude_error`;
* the sun sensor reads the pointing offset with `sensor_bias` and `sensor_noise`.

The defaults are the size found in commissioned fields: a few tenths of a degree of axis
misalignment, an encoder zero three counts off (0.26°), a PLC clock 45 s behind, site
coordinates from a map (about 1 km).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .collectors import Collector, across_angle, heliostat_normal, normal_angles, receiver_angle, sun_vector
from .errors import HybridtrackError

__all__ = ["Imperfections", "mounting_rotation", "true_targets", "incidence_cosine"]


@dataclass(frozen=True)
class Imperfections:
    """What is wrong with the real installation, unknown to the controller.

    Parameters
    ----------
    axis_azimuth_error, axis_tilt_error : float
        Degrees the true axis is turned (clockwise from above) and tilted (its far end up)
        from the nominal axis.
    encoder_offset : float
        Degrees the encoder's zero is off; the reading is the true angle plus this.
    clock_error : float
        Seconds the controller's clock runs ahead of true time.
    latitude_error, longitude_error : float
        Degrees the controller's site coordinates are off.
    sensor_bias, sensor_noise : float
        Degrees: constant error and standard deviation of the sun sensor's pointing offset.
    """

    axis_azimuth_error: float = 0.3
    axis_tilt_error: float = 0.2
    encoder_offset: float = 0.26
    clock_error: float = -45.0
    latitude_error: float = 0.008
    longitude_error: float = 0.01
    sensor_bias: float = 0.02
    sensor_noise: float = 0.03

    def __post_init__(self) -> None:
        limits = {"axis_azimuth_error": 10.0, "axis_tilt_error": 10.0, "encoder_offset": 10.0, "clock_error": 3600.0,
                  "latitude_error": 1.0, "longitude_error": 1.0, "sensor_bias": 2.0, "sensor_noise": 2.0}
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not np.isfinite(value):
                raise HybridtrackError(f"imperfections: {f.name} must be a number, got {value!r}")
            if abs(value) > limits[f.name]:
                raise HybridtrackError(f"imperfections: {f.name} = {value} is beyond ±{limits[f.name]:g}")
        if self.sensor_noise < 0:
            raise HybridtrackError("imperfections: sensor_noise must not be negative")

    @classmethod
    def none(cls) -> Imperfections:
        """A perfect installation."""
        return cls(**{f.name: 0.0 for f in fields(cls)})


def mounting_rotation(imperfections: Imperfections, axis_azimuth: float) -> np.ndarray:
    """Rotation taking world vectors into the true mounting's nominal frame (3x3).

    The true axis is the nominal one turned about the vertical by the azimuth error and
    tilted about the horizontal cross-axis direction by the tilt error.
    """
    turn = np.radians(imperfections.axis_azimuth_error)
    tilt = np.radians(imperfections.axis_tilt_error)
    b = np.radians(axis_azimuth)
    # about z (clockwise from above, as azimuth grows)
    rz = np.array([[np.cos(turn), -np.sin(turn), 0.0], [np.sin(turn), np.cos(turn), 0.0], [0.0, 0.0, 1.0]])
    across = np.array([np.cos(b), -np.sin(b), 0.0])  # horizontal, perpendicular to the nominal axis
    k = np.array([[0, -across[2], across[1]], [across[2], 0, -across[0]], [-across[1], across[0], 0]])
    rt = np.eye(3) + np.sin(tilt) * k + (1 - np.cos(tilt)) * (k @ k)  # Rodrigues: tilt about `across`
    return (rt @ rz).T  # world -> mounting


def true_targets(altitude, azimuth, collector: Collector, rotation: np.ndarray | None = None, *,
                 night: bool = False) -> np.ndarray:
    """Target angles of a collector, in its own (possibly misaligned) frame.

    Returns shape (N, 1) for single-axis collectors (trough convention) and (N, 2) for a
    heliostat (normal azimuth and elevation). NaN while the sun is down, unless `night`:
    then the geometry is followed below the horizon too (to pre-position before sunrise).
    """
    alt = np.asarray(altitude, float)
    s = sun_vector(alt, np.asarray(azimuth, float))
    rot = np.eye(3) if rotation is None else rotation
    if collector.kind == "heliostat":
        normals = heliostat_normal(np.abs(alt) if night else alt, azimuth, collector.aim) @ rot.T
        az, el = normal_angles(normals)
        out = np.stack([az, el], axis=-1)
    else:
        sun = across_angle(s @ rot.T, collector.axis)
        if collector.kind == "fresnel":
            sun = 0.5 * (sun + receiver_angle(collector.row_distance, collector.receiver_height))
        out = sun[:, None]
    if not night:
        out[alt < 0] = np.nan
    return out


def incidence_cosine(altitude, azimuth, collector: Collector) -> np.ndarray:
    """Cosine of the sun's incidence on a perfectly tracking aperture.

    For a single-axis collector it is the part of the sun vector across the axis; a
    heliostat's is the cosine of half the angle between sun and aim point. Zero at night.
    """
    alt = np.asarray(altitude, float)
    s = sun_vector(alt, np.asarray(azimuth, float))
    if collector.kind == "heliostat":
        r = np.asarray(collector.aim, float) / np.linalg.norm(collector.aim)
        cos = np.sqrt(np.clip((1.0 + s @ r) / 2.0, 0.0, 1.0))
    else:
        b = np.radians(collector.axis)
        along = s[:, 0] * np.sin(b) + s[:, 1] * np.cos(b)
        cos = np.sqrt(np.clip(1.0 - along**2, 0.0, 1.0))
    return np.where(alt > 0, cos, 0.0)
