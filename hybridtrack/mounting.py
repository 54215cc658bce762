"""Where a collector on a (possibly misaligned) mount must point: pure geometry.

Both sides use it: the world with the mount's true errors, the controller with its own
estimate of them (none, or a commissioning fit). Frame: x east, y north, z up.
"""

from __future__ import annotations

import numpy as np

from .collectors import (Collector, across_angle, as_collector, heliostat_normal, normal_angles, receiver_angle,
                         sun_path, sun_vector)
from .errors import HybridtrackError
from .params import number
from .reuse import shared

__all__ = ["mounting_rotation", "mount_targets", "pointing_vectors", "angles_on_mount", "incidence_cosine",
           "geometry_key", "rotate"]


def _about(direction: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation by `angle` radians about the unit vector `direction`."""
    x, y, z = direction
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def mounting_rotation(axis_azimuth_error: float, axis_tilt_error: float, axis_azimuth: float,
                      axis_roll_error: float = 0.0) -> np.ndarray:
    """Rotation taking world vectors into a misaligned mounting's nominal frame (3x3).

    The true axis is the nominal one (at `axis_azimuth`) turned about the vertical by
    `axis_azimuth_error` (clockwise from above), tilted about the horizontal cross-axis
    direction by `axis_tilt_error` (its far end up) and rolled about its own nominal direction
    by `axis_roll_error`, all in degrees. For a single-axis collector a roll is the same as an
    encoder offset; for a heliostat's pedestal the tilt and roll are its two tilt components,
    and the turn is the same as an azimuth encoder offset (Stone 1986).
    """
    given = {"axis_azimuth_error": axis_azimuth_error, "axis_tilt_error": axis_tilt_error,
             "axis_azimuth": axis_azimuth, "axis_roll_error": axis_roll_error}
    # one finite angle each: an array raised numpy's ValueError, None its TypeError, NaN gave NaNs
    radians = {name: np.radians(number(value, f"mounting_rotation: {name} (degrees)")) for name, value in given.items()}
    b = radians["axis_azimuth"]
    turn = _about(np.array([0.0, 0.0, 1.0]), radians["axis_azimuth_error"])
    tilt = _about(np.array([np.cos(b), -np.sin(b), 0.0]), radians["axis_tilt_error"])
    roll = _about(np.array([np.sin(b), np.cos(b), 0.0]), radians["axis_roll_error"])
    return (roll @ tilt @ turn).T  # world -> mounting


def mount_targets(altitude, azimuth, collector: Collector, rotation: np.ndarray | None = None, *,
                  night: bool = False, vectors: np.ndarray | None = None, sun: np.ndarray | None = None) -> np.ndarray:
    """Target angles of a collector on a mount turned by `rotation` (`mounting_rotation`), degrees.

    Returns shape (N, 1) for single-axis collectors (trough convention) and (N, 2) for a
    heliostat (normal azimuth and elevation). NaN while the sun is down, unless `night`:
    then the geometry is followed below the horizon too (to pre-position before sunrise).
    `vectors` are this sun's `pointing_vectors` (with the same `night`) when the caller has them,
    `sun` its unit vectors (a heliostat's, `heliostat_sun`) otherwise.
    """
    alt, az = sun_path(altitude, azimuth, "mount_targets")
    collector = as_collector(collector)
    if rotation is not None and np.shape(rotation) != (3, 3):  # numpy's ValueError, deep in a product
        raise HybridtrackError(f"mount_targets: rotation must be a 3 x 3 matrix (mounting_rotation), got shape "
                               f"{np.shape(rotation)}")
    if night:
        return angles_on_mount(pointing_vectors(alt, az, collector, night=True, sun=sun) if vectors is None
                               else vectors, collector, rotation)
    # only where the sun is up: half a year's scans are nights, where a heliostat's NaN normals cost
    # numpy's slow path (a mirror's targets for a year took 0.13 s, against 0.05 s up only)
    up = ~(alt < 0)
    if vectors is None:
        vectors = pointing_vectors(alt[up], az[up], collector, sun=None if sun is None else sun[up])
    else:
        vectors = vectors[up]
    out = np.full((len(alt), 1 if collector.single_axis else 2), np.nan)
    out[up] = angles_on_mount(vectors, collector, rotation)
    return out


def pointing_vectors(altitude, azimuth, collector: Collector, *, night: bool = False, sun=None) -> np.ndarray:
    """What a collector's angles follow, as unit vectors in the site frame (N, 3): the sun for a
    single-axis collector, a heliostat's wanted mirror normal (with `night`, the normal for the
    sun mirrored above the horizon). Computed once, they serve any number of mounts
    (`angles_on_mount`). `sun`: the sun's unit vectors (`sun_vector`, of the altitude mirrored
    above the horizon with `night`), if computed already (a heliostat field shares them)."""
    alt = np.asarray(altitude, float)
    if collector.kind == "heliostat":
        return heliostat_normal(np.abs(alt) if night else alt, azimuth, collector.aim, sun=sun)
    return sun_vector(alt, np.asarray(azimuth, float))


def heliostat_sun(base: tuple, altitude, azimuth, collector: Collector, *, night: bool = False) -> np.ndarray | None:
    """The sun's unit vectors a heliostat's own geometry starts from (the `sun` of
    `pointing_vectors` and `incidence_cosine`), shared by a field's heliostats under the sun that
    `base` keys; None for another collector, whose pointing vectors are the sun's own and are
    shared whole (`geometry_key`)."""
    if collector.kind != "heliostat":
        return None
    alt = np.asarray(altitude, float)
    return shared((*base, "sun vectors", night),
                  lambda: sun_vector(np.abs(alt) if night else alt, np.asarray(azimuth, float)))


def geometry_key(base: tuple, what: str, collector: Collector) -> tuple | None:
    """A `hybridtrack.reuse.shared` key for `what` of a collector's geometry under the sun that
    `base` keys: what `pointing_vectors`, `incidence_cosine` and the mount fit's derivatives
    (`hybridtrack.control.mountfit.vector_jacobian`) read of a collector, its kind and axis, so
    that a field's rows or troughs on one axis line share them. None for a heliostat: its
    geometry turns on its own aim point, which no other heliostat of its field has, and keeping
    what no other run asks for would only push out what they do."""
    if collector.kind == "heliostat":
        return None
    return (*base, what, collector.kind, collector.axis)


def rotate(vectors: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Each of `vectors` (N, 3) turned by `rotation` (3 × 3): ``vectors @ rotation.T``, summed by
    numpy's einsum rather than BLAS. A year of scans is a tall, thin product that BLAS's threads
    do not speed up, and they spin against other work on the machine: with another process busy
    on one of two cores a site-year's `simulate` took 2.09 s instead of 1.31 s, most of the
    difference in these products."""
    return np.einsum("nc,dc->nd", vectors, rotation)


def angles_on_mount(vectors: np.ndarray, collector: Collector, rotation: np.ndarray | None = None) -> np.ndarray:
    """The collector's angles (N, axes), degrees, that follow `vectors` (`pointing_vectors`) on
    a mount turned by `rotation` (`mounting_rotation`; None: the nominal mount)."""
    rotated = vectors if rotation is None else rotate(vectors, rotation)
    if collector.kind == "heliostat":
        return np.stack(normal_angles(rotated), axis=-1)
    sun = across_angle(rotated, collector.axis)
    if collector.kind == "fresnel":
        sun = 0.5 * (sun + receiver_angle(collector.row_distance, collector.receiver_height))
    return sun[:, None]


def incidence_cosine(altitude, azimuth, collector: Collector, *, sun=None) -> np.ndarray:
    """Cosine of the sun's incidence on a perfectly tracking aperture.

    For a single-axis collector it is the part of the sun vector across the axis; a
    heliostat's is the cosine of half the angle between sun and aim point. Zero at night.
    `sun`: the sun's unit vectors (`sun_vector`), if computed already.
    """
    alt, az = sun_path(altitude, azimuth, "incidence_cosine")
    collector = as_collector(collector)
    s = sun_vector(alt, az) if sun is None else sun
    if collector.kind == "heliostat":
        r = np.asarray(collector.aim, float) / np.linalg.norm(collector.aim)
        cos = np.sqrt(np.clip((1.0 + np.einsum("nc,c->n", s, r)) / 2.0, 0.0, 1.0))
    else:
        b = np.radians(collector.axis)
        along = s[:, 0] * np.sin(b) + s[:, 1] * np.cos(b)
        cos = np.sqrt(np.clip(1.0 - along**2, 0.0, 1.0))
    return np.where(alt > 0, cos, 0.0)
