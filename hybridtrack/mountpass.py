"""A collector's angles along a path of pointing vectors, and the mount fit's derivatives of
them, each in one compiled pass (numba).

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

`derivatives` is `hybridtrack.control.mountfit.vector_jacobian` in one pass: the angle's
gradient dotted with the vector turned by each pedestal term's rotation derivative, summed in
the order x, y, z as that function's numpy path sums it, NaN as 0 and an infinity as the largest
float (numpy's ``nan_to_num``). A heliostat-year's took 0.28 s on numpy, 0.08 s here.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import HybridtrackError

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the reference path is tested by asking for it
    numba = None

__all__ = ["available", "check_engine", "single_axis_angles", "heliostat_angles", "heliostat_normals",
           "heliostat_sun_angles", "derivatives", "normal_errors"]

ENGINES = ("auto", "compiled", "numpy")


def available() -> bool:
    """Whether the compiled passes can run here."""
    return numba is not None


def check_engine(engine, function: str) -> None:
    """Refuse an `engine` other than `ENGINES`, or ``compiled`` without numba, by `function`'s name."""
    if engine not in ENGINES:
        raise HybridtrackError(f"{function}: unknown engine {engine!r}; choose {', '.join(ENGINES)}")
    if engine == "compiled" and not available():
        raise HybridtrackError(f"{function}: the compiled engine needs numba, which is not installed here")


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
def _put_normal_angles(x, y, z, out, i):
    """`out[i]`: azimuth (0-360) and elevation of the normal (x, y, z) as
    `hybridtrack.collectors.normal_angles` gives them; False for one it refuses or leaves."""
    if math.isinf(x) or math.isinf(y) or math.isinf(z):
        return False
    horizontal = math.hypot(x, y)
    if horizontal == 0.0 and z == 0.0:
        return False
    azimuth = math.degrees(math.atan2(x, y))
    if azimuth < 0.0:  # hybridtrack.collectors.within_turn: within a turn of zero, + 360 below it
        azimuth = azimuth + 360.0
    out[i, 0] = azimuth + 0.0
    out[i, 1] = math.degrees(math.atan2(z, horizontal))
    return True


@_compiled
def _heliostat_pass(vectors, rotation, altitude, out):
    """`out[i]`: azimuth and elevation of normal `i` turned by `rotation`; NaN where `altitude`
    (if given) is below zero. False at the first normal the reference must take."""
    for i in range(vectors.shape[0]):
        if altitude is not None and altitude[i] < 0.0:
            out[i, 0] = out[i, 1] = np.nan
            continue
        x, y, z = _rotated(vectors, rotation, i, 0), _rotated(vectors, rotation, i, 1), _rotated(vectors, rotation, i, 2)
        if not _put_normal_angles(x, y, z, out, i):
            return False
    return True


@_compiled
def _normal(sun, i, aim):
    """`hybridtrack.collectors.heliostat_normal` at scan `i`: the sun's unit vector plus the unit
    vector to the aim point, over its length."""
    x, y, z = sun[i, 0] + aim[0], sun[i, 1] + aim[1], sun[i, 2] + aim[2]
    length = math.sqrt(x * x + y * y + z * z)
    return x / length, y / length, z / length


@_compiled
def _normal_pass(sun, aim, altitude, out):
    """`out[i]`: the mirror normal under sun vector `i`; NaN where `altitude` is below zero."""
    for i in range(sun.shape[0]):
        if altitude[i] < 0.0:
            out[i, 0] = out[i, 1] = out[i, 2] = np.nan
        else:
            out[i, 0], out[i, 1], out[i, 2] = _normal(sun, i, aim)


@_compiled
def _heliostat_sun_pass(sun, aim, rotation, altitude, out):
    """`_heliostat_pass` of the normals `_normal_pass` gives, without keeping them."""
    normal = np.empty((1, 3))
    for i in range(sun.shape[0]):
        if altitude[i] < 0.0:
            out[i, 0] = out[i, 1] = np.nan
            continue
        normal[0, 0], normal[0, 1], normal[0, 2] = _normal(sun, i, aim)
        x, y, z = _rotated(normal, rotation, 0, 0), _rotated(normal, rotation, 0, 1), _rotated(normal, rotation, 0, 2)
        if not _put_normal_angles(x, y, z, out, i):
            return False
    return True


def heliostat_normals(sun: np.ndarray, aim: np.ndarray, altitude: np.ndarray) -> np.ndarray | None:
    """`hybridtrack.collectors.heliostat_normal` under the sun's unit vectors `sun` (N, 3) for
    one unit vector to the aim point `aim` (3,), NaN where `altitude` (N,) is below zero, in
    one pass; None where it does not apply (without numba, or other shapes)."""
    if numba is None or sun.ndim != 2 or sun.shape[1:] != (3,) or np.shape(altitude) != sun.shape[:1] \
            or np.shape(aim) != (3,) or sun.dtype != np.float64:
        return None
    out = np.empty(sun.shape)
    _normal_pass(np.ascontiguousarray(sun), np.asarray(aim, float), np.ascontiguousarray(altitude, dtype=float), out)
    return out


def heliostat_sun_angles(sun: np.ndarray, aim: np.ndarray, rotation, altitude: np.ndarray) -> np.ndarray | None:
    """A heliostat's azimuth and elevation (N, 2) on a mount turned by `rotation`, from the sun's
    unit vectors `sun` (N, 3) and the unit vector to its aim point `aim` (3,): `heliostat_angles`
    of `heliostat_normals` without the normals kept; NaN where `altitude` is below zero. None
    where it does not apply or declines."""
    ready = _ready(sun, rotation, altitude)
    if ready is None or altitude is None or np.shape(aim) != (3,):
        return None
    out = np.empty((len(sun), 2))
    return out if _heliostat_sun_pass(ready[0], np.asarray(aim, float), ready[1], ready[2], out) else None


@_compiled
def _finite_or_extreme(value):
    """numpy's nan_to_num of one number: NaN 0, an infinity the largest float of its sign."""
    if value != value:
        return 0.0
    if math.isinf(value):
        return np.finfo(np.float64).max if value > 0.0 else -np.finfo(np.float64).max
    return value


@_compiled
def _turned_dot(g0, g1, g2, turn, x, y, z):
    """The angle gradient (g0, g1, g2) dotted with the vector turned by `turn`, as einsum sums it."""
    t0 = x * turn[0, 0] + y * turn[0, 1] + z * turn[0, 2]
    t1 = x * turn[1, 0] + y * turn[1, 1] + z * turn[1, 2]
    t2 = x * turn[2, 0] + y * turn[2, 1] + z * turn[2, 2]
    return g0 * t0 + g1 * t1 + g2 * t2


@_compiled
def _single_axis_derivatives(x, y, z, turns, cos_axis, sin_axis, scale, row):
    """`row` (1, 3): a single axis's angle by the two pedestal terms and its encoder zero."""
    across = x * cos_axis - y * sin_axis
    span = across * across + z * z
    d_across, d_z = -z / span, across / span
    g0, g1, g2 = scale * (d_across * cos_axis), scale * (-d_across * sin_axis), scale * d_z
    for k in range(2):
        row[0, k] = _turned_dot(g0, g1, g2, turns[k], x, y, z)
    row[0, 2] = 1.0


@_compiled
def _heliostat_derivatives(x, y, z, turns, degrees, floor, row):
    """`row` (2, 5): a heliostat's azimuth and elevation by its two pedestal terms, its encoder
    zeros and its sensor's collimation (sec e of azimuth)."""
    flat = x * x + y * y
    squared = z * z
    squared = 0.0 if squared < 0.0 else (1.0 if squared > 1.0 else squared)
    g00, g01, g02 = degrees * (y / flat), degrees * (-x / flat), degrees * 0.0
    g10, g11, g12 = degrees * 0.0, degrees * 0.0, degrees * (1.0 / math.sqrt(1.0 - squared))
    for k in range(2):
        row[0, k] = _turned_dot(g00, g01, g02, turns[k], x, y, z)
        row[1, k] = _turned_dot(g10, g11, g12, turns[k], x, y, z)
    row[0, 2] = row[1, 3] = 1.0
    clipped = -1.0 if z < -1.0 else (1.0 if z > 1.0 else z)
    cosine = math.cos(math.radians(math.degrees(math.asin(clipped))))
    row[0, 4] = 1.0 / (min(cosine, -floor) if cosine < 0.0 else (cosine if cosine != cosine else max(cosine, floor)))


@_compiled
def _derivative_pass(vectors, lit, turns, cos_axis, sin_axis, scale, degrees, floor, heliostat, out):
    """`out` (N, axes, parameters), zero beforehand: each lit scan's derivatives, NaN as 0 and an
    infinity as the largest float (numpy's nan_to_num)."""
    for i in range(vectors.shape[0]):
        if not lit[i]:
            continue
        x, y, z = vectors[i, 0], vectors[i, 1], vectors[i, 2]
        row = out[i]
        if heliostat:
            _heliostat_derivatives(x, y, z, turns, degrees, floor, row)
        else:
            _single_axis_derivatives(x, y, z, turns, cos_axis, sin_axis, scale, row)
        for a in range(row.shape[0]):
            for k in range(row.shape[1]):
                row[a, k] = _finite_or_extreme(row[a, k])


def derivatives(vectors: np.ndarray, lit: np.ndarray, turns: np.ndarray, heliostat: bool, cos_axis: float,
                sin_axis: float, scale: float, degrees: float, floor: float) -> np.ndarray | None:
    """The mount fit's derivatives of the targets (`hybridtrack.control.mountfit.vector_jacobian`)
    at the `lit` scans of `vectors` (N, 3), zero elsewhere, in one pass: `turns` the rotation's
    derivatives by the two pedestal terms (2, 3, 3); a single axis's by its axis's cosine and
    sine and `scale` (degrees, halved for a Fresnel row), a heliostat's by `degrees` and the
    collimation's cosine `floor`. None without numba, for a path that is not (N, 3) floats or a
    `lit` that is not one bool a scan."""
    if numba is None or vectors.ndim != 2 or vectors.shape[1:] != (3,) or vectors.dtype != np.float64 \
            or np.shape(lit) != vectors.shape[:1] or np.asarray(lit).dtype != np.bool_:
        return None
    out = np.zeros((len(vectors), 2 if heliostat else 1, 5 if heliostat else 3))
    _derivative_pass(np.ascontiguousarray(vectors), np.ascontiguousarray(lit, dtype=np.bool_),
                     np.ascontiguousarray(turns, dtype=float), float(cos_axis), float(sin_axis), float(scale),
                     float(degrees), float(floor), bool(heliostat), out)
    return out


@_compiled
def _direction(elevation, azimuth):
    """`hybridtrack.collectors.direction_vectors` of one direction, degrees."""
    a, g = math.radians(elevation), math.radians(azimuth)
    return math.cos(a) * math.sin(g), math.cos(a) * math.cos(g), math.sin(a)


@_compiled
def _normal_error_pass(angles, truth, out):
    """`out[i]`: degrees between a heliostat's normal at its `angles[:, i]` (azimuth, elevation)
    and its true normal at `truth[i]`; NaN where the truth is (the sun down)."""
    for i in range(truth.shape[0]):
        if truth[i, 0] != truth[i, 0] or truth[i, 1] != truth[i, 1]:
            out[i] = np.nan
            continue
        x, y, z = _direction(angles[1, i], angles[0, i])
        u, v, w = _direction(truth[i, 1], truth[i, 0])
        dot = x * u + y * v + z * w
        dot = -1.0 if dot < -1.0 else (1.0 if dot > 1.0 else dot)
        out[i] = math.degrees(math.acos(dot))


def normal_errors(angles: np.ndarray, truth: np.ndarray) -> np.ndarray | None:
    """A heliostat's pointing error at each scan, degrees: the angle between the normal its
    axes stood at (`angles`, (2, N): azimuth, elevation) and its true normal (`truth`, (N, 2)),
    NaN where the truth is, as `hybridtrack.simulation`'s numpy path computes it (the
    directions, their dot product clipped to ±1, its arccosine). None without numba or for other
    shapes or types (float32: numpy's path keeps it)."""
    if numba is None or truth.ndim != 2 or truth.shape[1:] != (2,) or np.shape(angles) != (2, truth.shape[0]) \
            or truth.dtype != np.float64 or np.asarray(angles).dtype != np.float64:
        return None
    out = np.empty(truth.shape[0])
    _normal_error_pass(np.ascontiguousarray(angles, dtype=float), np.ascontiguousarray(truth, dtype=float), out)
    return out


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
