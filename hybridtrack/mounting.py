"""Where a collector on a (possibly misaligned) mount must point: pure geometry.

Both sides use it: the world with the mount's true errors, the controller with its own
estimate of them (none, or a commissioning fit). Frame: x east, y north, z up.

What broadcasts: `mounting_rotation` over its angles by numpy's rules (arrays give one rotation
each, ``(..., 3, 3)``), `rotate` rotations ``(..., 3, 3)`` against vectors ``(..., 3)``, and
`angles_on_mount` its vectors against its rotation. `mount_targets`, `pointing_vectors` and
`incidence_cosine` take one `Collector` and a sun path (one value a step): the collector's kind
chooses the geometry, and a simulation runs one collector at a time; a field of many uses the
broadcasting functions of `hybridtrack.collectors` (`hybridtrack.fields`).
"""

from __future__ import annotations

import math

import numpy as np

from . import mountpass
from .collectors import (Collector, _broadcast, _finite, across_angle, aim_unit, as_collector, checked_sun,
                         checked_vectors, heliostat_normal, normal_angles, receiver_angle, sun_path, sun_vector)
from .errors import HybridtrackError
from .reuse import shared

__all__ = ["mounting_rotation", "mount_targets", "pointing_vectors", "angles_on_mount", "incidence_cosine",
           "geometry_key", "rotate"]


def _about(x, y, z, angle: np.ndarray) -> np.ndarray:
    """Rodrigues' rotations ``(..., 3, 3)`` by `angle` radians about the unit vectors (x, y, z),
    each an array broadcast against the others."""
    k = np.zeros(np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(z), np.shape(angle)) + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -z, y, -x
    k[..., 1, 0], k[..., 2, 0], k[..., 2, 1] = z, -y, x
    sine, versine = np.sin(angle), 1.0 - np.cos(angle)
    return np.eye(3) + sine[..., None, None] * k + versine[..., None, None] * (k @ k)


def mounting_rotation(axis_azimuth_error, axis_tilt_error, axis_azimuth, axis_roll_error=0.0) -> np.ndarray:
    """Rotation taking world vectors into a misaligned mounting's nominal frame.

    The true axis is the nominal one (at `axis_azimuth`) turned about the vertical by
    `axis_azimuth_error` (counterclockwise seen from above: the true axis's azimuth is
    ``axis_azimuth - axis_azimuth_error``), tilted about the horizontal cross-axis
    direction by `axis_tilt_error` (its far end up) and rolled about its own nominal direction
    by `axis_roll_error`. For a single-axis collector a roll is the same as an encoder offset;
    for a heliostat's pedestal the tilt and roll are its two tilt components, and the turn is
    the same as an azimuth encoder offset [1]_.

    Parameters
    ----------
    axis_azimuth_error, axis_tilt_error, axis_azimuth, axis_roll_error : float or array_like
        Degrees, finite; arrays (one mount each) broadcast together by numpy's rules.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        One rotation matrix per element of the parameters' broadcast shape: (3, 3) for
        numbers. Apply it with `rotate`.

    References
    ----------
    .. [1] K. W. Stone, "Automatic heliostat track alignment method", US Patent 4,564,275, 1986.
    """
    given = {"axis_azimuth_error": axis_azimuth_error, "axis_tilt_error": axis_tilt_error,
             "axis_azimuth": axis_azimuth, "axis_roll_error": axis_roll_error}
    # finite angles: None had raised numpy's TypeError, NaN given NaNs
    radians = {name: np.radians(_finite(value, f"mounting_rotation: {name} (degrees)"))
               for name, value in given.items()}
    _broadcast("mounting_rotation", **radians)
    b = radians["axis_azimuth"]
    turn = _about(0.0, 0.0, 1.0, radians["axis_azimuth_error"])
    tilt = _about(np.cos(b), -np.sin(b), 0.0, radians["axis_tilt_error"])
    roll = _about(np.sin(b), np.cos(b), 0.0, radians["axis_roll_error"])
    return np.swapaxes(roll @ tilt @ turn, -1, -2)  # world -> mounting


def mount_targets(altitude, azimuth, collector: Collector, rotation: np.ndarray | None = None, *,
                  night: bool = False, vectors: np.ndarray | None = None, sun: np.ndarray | None = None,
                  engine: str = "auto") -> np.ndarray:
    """Target angles of one collector on a mount turned by `rotation` (`mounting_rotation`), degrees.

    Returns shape (N, 1) for single-axis collectors (trough convention) and (N, 2) for a
    heliostat (normal azimuth and elevation), N the steps of the sun path (one position is a
    path of one step). NaN while the sun is down, unless `night`: then the geometry is followed
    below the horizon too (to pre-position before sunrise). `vectors` are this sun's
    `pointing_vectors` (with the same `night`) when the caller has them, `sun` its unit vectors
    (a heliostat's, `heliostat_sun`) otherwise: each (N, 3), refused by name otherwise (they had
    raised numpy's IndexError). One collector and one (3, 3) rotation: `angles_on_mount`
    broadcasts over rotations. `engine` as `angles_on_mount`'s.
    """
    alt, az = sun_path(altitude, azimuth, "mount_targets")
    collector = as_collector(collector)
    mountpass.check_engine(engine, "mount_targets")
    if rotation is not None and np.shape(rotation) != (3, 3):  # numpy's ValueError, deep in a product
        raise HybridtrackError(f"mount_targets: rotation must be a 3 x 3 matrix (mounting_rotation), got shape "
                               f"{np.shape(rotation)}")
    vectors = _path_vectors(vectors, "mount_targets", "vectors", len(alt))
    sun = _path_vectors(sun, "mount_targets", "sun", len(alt))
    if night:
        return angles_on_mount(pointing_vectors(alt, az, collector, night=True, sun=sun) if vectors is None
                               else vectors, collector, rotation, engine=engine)
    # only where the sun is up: half a year's scans are nights, where a heliostat's NaN normals cost
    # numpy's slow path (a mirror's targets for a year took 0.13 s, against 0.05 s up only)
    if engine != "numpy":  # one compiled pass, NaN where the sun is down
        if vectors is not None:
            fast = _compiled_angles(vectors, collector, rotation, engine, altitude=alt)
        elif sun is not None and collector.kind == "heliostat":  # its normals made in the pass
            fast = mountpass.heliostat_sun_angles(sun, aim_unit(collector.aim), rotation, alt)
        else:
            fast = None
        if fast is not None:
            return fast
    up = ~(alt < 0)
    if vectors is None:
        vectors = pointing_vectors(alt[up], az[up], collector, sun=None if sun is None else sun[up])
    else:
        vectors = vectors[up]
    out = np.full((len(alt), 1 if collector.single_axis else 2), np.nan)
    out[up] = angles_on_mount(vectors, collector, rotation, engine=engine)
    return out


def _path_vectors(given, function: str, name: str, steps: int) -> np.ndarray | None:
    """None, or `given` as a sun path's vectors, (steps, 3), refused by `function`'s and `name`'s
    name otherwise: one vector (3,) is a path of one step, as one sun position is."""
    if given is None:
        return None
    try:
        one = steps == 1 and np.shape(given) == (3,)
    except ValueError:  # a ragged list, which checked_vectors refuses
        one = False
    return checked_vectors(np.reshape(given, (1, 3)) if one else given, function, name, (steps, 3))


def pointing_vectors(altitude, azimuth, collector: Collector, *, night: bool = False, sun=None) -> np.ndarray:
    """What a collector's angles follow, as unit vectors in the site frame (N, 3): the sun for a
    single-axis collector, a heliostat's wanted mirror normal (with `night`, the normal for the
    sun mirrored above the horizon). Computed once, they serve any number of mounts
    (`angles_on_mount`). `sun`: the sun's unit vectors (`sun_vector`, of the altitude mirrored
    above the horizon with `night`), if computed already (a heliostat field shares them)."""
    collector = as_collector(collector)
    if collector.kind != "heliostat":
        return sun_vector(altitude, azimuth)
    alt, az = checked_sun(altitude, azimuth, "pointing_vectors")  # text had raised numpy's ValueError
    return heliostat_normal(np.abs(alt) if night else alt, az, collector.aim, sun=sun)


def heliostat_sun(base: tuple, altitude, azimuth, collector: Collector, *, night: bool = False,
                  aperture: bool = False) -> np.ndarray | None:
    """The sun's unit vectors a heliostat's own geometry starts from (the `sun` of
    `pointing_vectors` and `incidence_cosine`), shared by a field's heliostats under the sun that
    `base` keys; with `aperture`, a Fresnel row's too, whose incidence turns on its own place
    under the receiver (`incidence_cosine`). None for another collector, whose pointing vectors
    are the sun's own and are shared whole (`geometry_key`)."""
    if not _its_own(collector, aperture):
        return None
    alt = np.asarray(altitude, float)
    return shared((*base, "sun vectors", night),
                  lambda: sun_vector(np.abs(alt) if night else alt, np.asarray(azimuth, float)))


def geometry_key(base: tuple, what: str, collector: Collector, *, aperture: bool = False) -> tuple | None:
    """A `hybridtrack.reuse.shared` key for `what` of a collector's geometry under the sun that
    `base` keys: what `pointing_vectors` and the mount fit's derivatives
    (`hybridtrack.control.mountfit.vector_jacobian`) read of a collector, its kind and axis, so
    that a field's rows or troughs on one axis line share them. None for a heliostat: its
    geometry turns on its own aim point, which no other heliostat of its field has, and keeping
    what no other run asks for would only push out what they do; so too for what a Fresnel row's
    `aperture` reads (`incidence_cosine`), which turns on its own place under the receiver."""
    if _its_own(collector, aperture):
        return None
    return (*base, what, collector.kind, collector.axis)


def _its_own(collector: Collector, aperture: bool) -> bool:
    """Whether a collector's geometry (its `aperture`'s, if asked) turns on what no other collector
    of its field shares: a heliostat's aim point, a Fresnel row's place under the receiver."""
    return collector.kind == "heliostat" or (aperture and collector.kind == "fresnel")


def rotate(vectors, rotation) -> np.ndarray:
    """`vectors` ``(..., 3)`` turned by `rotation` ``(..., 3, 3)``, broadcast by numpy's rules.

    ``vectors @ rotation.T`` for one rotation, summed term by term in the order x, y, z rather
    than by BLAS or einsum. A year of scans is a tall, thin product that BLAS's threads do not
    speed up, and they spin against other work on the machine: with another process busy on
    one of two cores a site-year's `simulate` took 2.09 s instead of 1.31 s, most of the
    difference in these products. einsum's order of summation follows the machine's SIMD width;
    this one is the same everywhere, and is the compiled pass's (`hybridtrack.mountpass`).

    Parameters
    ----------
    vectors : array_like, shape (..., 3)
    rotation : array_like, shape (..., 3, 3)
        `mounting_rotation`'s; one per vector, or one for all.

    Returns
    -------
    ndarray, shape (..., 3)
        The leading shapes of the vectors and the rotations broadcast: one vector (3,) for one
        vector and one rotation, (T, N, 3) for vectors (T, 1, 3) and rotations (N, 3, 3).
    """
    vectors = checked_vectors(vectors, "rotate", "vectors")
    try:
        matrices = np.asarray(rotation)
    except ValueError:  # a ragged list
        matrices = np.asarray(None)
    if matrices.dtype.kind not in "fiu" or matrices.shape[-2:] != (3, 3):
        got = f"shape {matrices.shape}" if matrices.dtype.kind in "fiu" else f"{rotation!r:.60}"
        raise HybridtrackError(f"rotate: rotation must be 3 x 3 matrices of numbers (mounting_rotation), shape "
                               f"(..., 3, 3); got {got}")
    _broadcast("rotate", **{"vectors without their x, y, z axis": vectors[..., 0],
                            "rotations without their 3 x 3": matrices[..., 0, 0]})
    x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    out = np.empty(np.broadcast_shapes(x.shape, matrices.shape[:-2]) + (3,))
    for d in range(3):
        out[..., d] = x * matrices[..., d, 0] + y * matrices[..., d, 1] + z * matrices[..., d, 2]
    return out


def angles_on_mount(vectors, collector: Collector, rotation=None, *, engine: str = "auto") -> np.ndarray:
    """The collector's angles ``(..., axes)``, degrees, that follow `vectors` ``(..., 3)``
    (`pointing_vectors`) on a mount turned by `rotation` (`mounting_rotation`, ``(..., 3, 3)``
    broadcast against the vectors as `rotate` does; None: the nominal mount). One vector gives
    one row of angles, (axes,); a wrong shape is refused by name (one vector had raised numpy's
    IndexError).

    `engine`: ``numpy`` the reference path below; ``compiled`` (where numba is installed) a path
    of vectors (N, 3) under one rotation in one pass (`hybridtrack.mountpass`), the same bits;
    ``auto`` compiled where it applies. Either takes the reference path for what the pass
    leaves to it (other shapes, a vector on the horizon, a refusal)."""
    vectors, collector = checked_vectors(vectors, "angles_on_mount", "vectors"), as_collector(collector)
    mountpass.check_engine(engine, "angles_on_mount")
    if engine != "numpy":
        fast = _compiled_angles(vectors, collector, rotation, engine)
        if fast is not None:
            return fast
    rotated = vectors if rotation is None else rotate(vectors, rotation)
    if collector.kind == "heliostat":
        return np.stack(normal_angles(rotated), axis=-1)
    sun = across_angle(rotated, collector.axis)
    if collector.kind == "fresnel":
        sun = 0.5 * (sun + receiver_angle(collector.row_distance, collector.receiver_height))
    return np.asarray(sun)[..., None]


def _compiled_angles(vectors: np.ndarray, collector: Collector, rotation, engine: str, altitude=None):
    """`angles_on_mount` in one compiled pass (`hybridtrack.mountpass`), NaN where `altitude`
    (if given) is below zero; None where the pass does not apply."""
    if not mountpass.available():
        return None
    if collector.kind == "heliostat":
        return mountpass.heliostat_angles(vectors, rotation, altitude)
    b = np.radians(_finite(collector.axis, "axis azimuth"))  # the axis's trigonometry as across_angle's
    receiver = receiver_angle(collector.row_distance, collector.receiver_height) \
        if collector.kind == "fresnel" else None
    return mountpass.single_axis_angles(vectors, rotation, np.cos(b), np.sin(b), receiver, altitude)


def incidence_cosine(altitude, azimuth, collector: Collector, *, sun=None) -> np.ndarray:
    """Cosine of the sun's incidence on one collector's perfectly tracking aperture, (N,) for a
    sun path of N steps.

    For a trough it is the part of the sun vector across the axis. A Fresnel row's mirror turns
    its normal halfway between the sun and the receiver in the plane across the axis, so its
    cosine is that part times the cosine of half the angle, in that plane, between the sun and
    the receiver as the row sees it (`row_distance`, `receiver_height`): rows far from the
    receiver line catch less of the beam. A heliostat's is the cosine of half the angle between
    sun and aim point. Zero at night. `sun`: the sun's unit vectors (`sun_vector`), (N, 3), if
    computed already; another shape is refused by name (it had raised numpy's errors).

    References
    ----------
    Duffie, J. A. & Beckman, W. A. (2013). *Solar Engineering of Thermal Processes*, 4th ed.,
    Wiley, §1.9 (angle of incidence on tracking surfaces). doi:10.1002/9781118671603
    """
    alt, az = sun_path(altitude, azimuth, "incidence_cosine")
    collector = as_collector(collector)
    s = sun_vector(alt, az) if sun is None else _path_vectors(sun, "incidence_cosine", "sun", len(alt))
    if collector.kind == "heliostat":
        r = np.asarray(collector.aim, float) / np.linalg.norm(collector.aim)
        cos = np.sqrt(np.clip((1.0 + np.einsum("nc,c->n", s, r)) / 2.0, 0.0, 1.0))
    else:
        b = np.radians(collector.axis)
        along = s[:, 0] * np.sin(b) + s[:, 1] * np.cos(b)
        cos = np.sqrt(np.clip(1.0 - along**2, 0.0, 1.0))
        if collector.kind == "fresnel":
            cos = cos * _half_turn_to_receiver(s, b, cos, collector)
    return np.where(alt > 0, cos, 0.0)


def _half_turn_to_receiver(s: np.ndarray, b: float, across_part: np.ndarray, collector: Collector) -> np.ndarray:
    """cos(δ/2) for a Fresnel row, δ the angle in the plane across the axis (unit vectors
    across, towards ``axis + 90°``, and up) between the sun's part there (of length
    `across_part`) and the direction from the row to the receiver, ``(-d, h)``."""
    across = s[:, 0] * np.cos(b) - s[:, 1] * np.sin(b)
    reach = math.hypot(collector.row_distance, collector.receiver_height)
    to_receiver = (-collector.row_distance * across + collector.receiver_height * s[:, 2]) / reach
    with np.errstate(invalid="ignore", divide="ignore"):  # a sun along the axis has no part across it
        cos_delta = np.where(across_part > 0, to_receiver / across_part, 1.0)
    return np.sqrt(np.clip((1.0 + cos_delta) / 2.0, 0.0, 1.0))
