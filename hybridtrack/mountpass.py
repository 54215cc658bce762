"""A collector's angles along a path of pointing vectors in one compiled pass (numba).

`hybridtrack.mounting.angles_on_mount` turns a year of pointing vectors into axis angles with
numpy: the rotation onto the mount, then the angle across a single axis (or a heliostat normal's
azimuth and elevation), each step a year-long temporary array. A field's run does this twice a
collector, for its world's true targets and its plan's targets: about 35 ms a Fresnel row-year
each. The passes here compute each scan's angles from its vector alone, in the same order of
operations as numpy does (rotation ``x·m[d,0] + y·m[d,1] + z·m[d,2]``, then the same libm
``atan2`` and ``hypot``, degrees as ``x · 180/π``), so they give the same bits; a test holds the
two equal bit for bit. The trigonometry of the axis (its cosine and sine) and the receiver's
angle stay numpy's, computed once by the caller.

A pass declines (returns False) where a scan needs what only the reference path does: a vector
on the horizon (an up component of exactly zero, whose angle across an axis the reference
rounds to the axis's own direction), an infinite component (which the reference refuses by
name) or a zero heliostat normal (refused too). The caller then runs the reference path on the
whole path. Without numba there is no pass (`available` is False).
"""

from __future__ import annotations

import math

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the reference path is tested by asking for it
    numba = None

__all__ = ["available", "single_axis_angles", "heliostat_angles"]

ENGINES = ("auto", "compiled", "numpy")


def available() -> bool:
    """Whether the compiled passes can run here."""
    return numba is not None


def _compiled(function):
    return function if numba is None else numba.njit(cache=True, nogil=True, error_model="numpy")(function)


@_compiled
def _rotated(vectors, rotation, i, d):
    """Component `d` of vector `i` turned by `rotation` (None: not turned), summed as numpy's
    einsum sums it."""
    if rotation is None:
        return vectors[i, d]
    return vectors[i, 0] * rotation[d, 0] + vectors[i, 1] * rotation[d, 1] + vectors[i, 2] * rotation[d, 2]


@_compiled
def _single_axis_pass(vectors, rotation, cos_axis, sin_axis, receiver, fresnel, altitude, out):
    """`out[i, 0]`: the angle across the axis of vector `i` turned by `rotation`, within
    [-90, 270) (halved towards the `receiver` angle for a Fresnel row); NaN where `altitude` (if
    given) is below zero. False at the first vector the reference path must take instead."""
    for i in range(vectors.shape[0]):
        if altitude is not None and altitude[i] < 0.0:
            out[i, 0] = np.nan
            continue
        x, y, z = _rotated(vectors, rotation, i, 0), _rotated(vectors, rotation, i, 1), _rotated(vectors, rotation, i, 2)
        if math.isinf(x) or math.isinf(y) or math.isinf(z) or z == 0.0:
            return False
        angle = math.degrees(math.atan2(z, x * cos_axis - y * sin_axis))
        if angle < -90.0:
            angle = angle + 360.0
        out[i, 0] = 0.5 * (angle + receiver) if fresnel else angle
    return True


@_compiled
def _heliostat_pass(vectors, rotation, altitude, out):
    """`out[i]`: azimuth (0-360) and elevation of normal `i` turned by `rotation`; NaN where
    `altitude` (if given) is below zero. False at the first normal the reference must take."""
    for i in range(vectors.shape[0]):
        if altitude is not None and altitude[i] < 0.0:
            out[i, 0] = out[i, 1] = np.nan
            continue
        x, y, z = _rotated(vectors, rotation, i, 0), _rotated(vectors, rotation, i, 1), _rotated(vectors, rotation, i, 2)
        if math.isinf(x) or math.isinf(y) or math.isinf(z):
            return False
        horizontal = math.hypot(x, y)
        if horizontal == 0.0 and z == 0.0:
            return False
        azimuth = math.degrees(math.atan2(x, y))
        if azimuth < 0.0:  # hybridtrack.collectors.within_turn: within a turn of zero, + 360 below it
            azimuth = azimuth + 360.0
        elif azimuth >= 360.0:
            azimuth = azimuth % 360.0
        out[i, 0] = azimuth + 0.0
        out[i, 1] = math.degrees(math.atan2(z, horizontal))
    return True


def _ready(vectors: np.ndarray, rotation, altitude) -> tuple | None:
    """The pass's arguments as it takes them, or None where it does not apply (not a path of
    float vectors (N, 3) under one rotation)."""
    if numba is None or vectors.ndim != 2 or vectors.dtype != np.float64:
        return None
    if rotation is not None:
        rotation = np.asarray(rotation)
        if rotation.shape != (3, 3) or rotation.dtype != np.float64:
            return None
        rotation = np.ascontiguousarray(rotation)
    if altitude is not None:
        altitude = np.ascontiguousarray(altitude, dtype=float)
        if altitude.shape != vectors.shape[:1]:
            return None
    return np.ascontiguousarray(vectors), rotation, altitude


def single_axis_angles(vectors: np.ndarray, rotation, cos_axis: float, sin_axis: float, receiver: float | None,
                       altitude: np.ndarray | None = None) -> np.ndarray | None:
    """A single-axis collector's angles (N, 1) along `vectors` (N, 3) on a mount turned by
    `rotation` ((3, 3) or None), as `hybridtrack.mounting.angles_on_mount` gives them; the axis
    by its azimuth's cosine and sine, `receiver` a Fresnel row's receiver angle (None for a
    trough). NaN where `altitude` is below zero, if given. None where the pass does not apply
    or declines (the module's text)."""
    ready = _ready(vectors, rotation, altitude)
    if ready is None:
        return None
    out = np.empty((len(vectors), 1))
    fresnel = receiver is not None
    if not _single_axis_pass(ready[0], ready[1], float(cos_axis), float(sin_axis),
                             float(receiver) if fresnel else 0.0, fresnel, ready[2], out):
        return None
    return out


def heliostat_angles(vectors: np.ndarray, rotation, altitude: np.ndarray | None = None) -> np.ndarray | None:
    """A heliostat's azimuth and elevation (N, 2) along its normals `vectors` (N, 3) on a mount
    turned by `rotation`, as `hybridtrack.mounting.angles_on_mount` gives them; NaN where
    `altitude` is below zero, if given. None where the pass does not apply or declines."""
    ready = _ready(vectors, rotation, altitude)
    if ready is None:
        return None
    out = np.empty((len(vectors), 2))
    return out if _heliostat_pass(*ready, out) else None
