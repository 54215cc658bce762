"""Where each collector must point: pure functions over arrays.

Frame: x east, y north, z up; the sun's unit vector from altitude α and azimuth γ (from
north) is ``s = (cos α sin γ, cos α cos γ, sin α)``. Every angle is in degrees. Tracking
angles are NaN while the sun is below the horizon (altitude < 0).

Single-axis collectors (trough, Fresnel row) share one convention, the literature's: the
angle is measured in the plane across the axis from the horizon at azimuth
``axis_azimuth + 90°`` (east for a north-south axis) through the zenith (90°, the stow
position) to the opposite horizon (180°).

Every function broadcasts its sun position against its collector parameters (row distances,
receiver heights, axis azimuths, aim points) by numpy's rules, as pvlib's functions do: equal
shapes go element by element, and a sun path with a trailing axis against N collectors gives a
(T, N) table in one call, e.g. ``fresnel_angle(alt[:, None], az[:, None], d, h)`` with ``d`` of
shape (N,). A pandas Series comes back as a Series when the result has its shape. A value
that is one number for scalar input (an angle, a loss) is a numpy.float64, as numpy's and
pvlib's are, and one vector in gives one vector out: `heliostat_normal` of one sun position and
one aim point is (3,), `normal_angles` of one normal two numpy.float64, `jack_heights` (K,).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from . import mountpass
from .errors import HybridtrackError
from .params import finite_array, number

__all__ = [
    "Collector",
    "as_collector",
    "KINDS",
    "trough_kind",
    "sun_vector",
    "across_angle",
    "trough_angle",
    "tracking_rate",
    "fresnel_angle",
    "fresnel_end_loss",
    "heliostat_normal",
    "normal_angles",
    "jack_heights",
    "THREE_POINT_SUPPORT",
    "AXIS_AZIMUTH",
]

#: Named horizontal axes: the angle's 0° faces east for "ns" and north for "ew" (an east-west
#: axis tracks north-south with y in place of x).
AXIS_AZIMUTH = {"ns": 0.0, "ew": 270.0}

#: The published three-jack layout under a heliostat mirror, (x, y) in metres.
THREE_POINT_SUPPORT = np.array([[0.0, 1.0], [-0.707, -0.707], [0.707, -0.707]])


def _like(template, values: np.ndarray, name: str | None = None):
    """Return `values` as a Series on the template's index when the template is a Series of its
    shape, else as `_scalar` does."""
    if isinstance(template, pd.Series) and np.shape(values) == template.shape:
        return pd.Series(values, index=template.index, name=name)
    return _scalar(values)


def _scalar(values):
    """`values`, a numpy.float64 where it is one number (a 0-d array): the one type every function
    of this module gives for scalar input, as numpy's and pvlib's do (they had given a 0-d array,
    a numpy.float64 or a Python float by function). Arrays stay arrays."""
    return values[()] if np.ndim(values) == 0 else values


def _broadcast(function: str, **arrays) -> None:
    """Refuse parameters of shapes that do not broadcast together, naming each: numpy's error
    named no parameter and was no `HybridtrackError`."""
    shapes = {name: np.shape(value) for name, value in arrays.items()}
    try:
        np.broadcast_shapes(*shapes.values())
    except ValueError:
        listed = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        hint = (" (a sun position of shape (T, 1) against collectors' (N,) gives every collector at every step)"
                if "altitude" in shapes else "")
        raise HybridtrackError(f"{function}: the shapes {listed} do not broadcast together{hint}") from None


def checked_sun(altitude, azimuth, function: str) -> tuple[np.ndarray, np.ndarray]:
    """A sun position as float arrays, refused by `function`'s name unless it is numbers: an
    altitude within [-90, 90] degrees and a finite azimuth, or NaN where there is no sun. Two
    Series must share their index (numpy pairs them by position, and the answer carried the
    altitude's labels). Text, None, complex numbers and True had been read, or raised numpy's
    errors."""
    if isinstance(altitude, pd.Series) and isinstance(azimuth, pd.Series) and not altitude.index.equals(azimuth.index):
        raise HybridtrackError(f"{function}: altitude and azimuth are Series on different indexes; align them first "
                               "(numpy would pair them by position)")
    alt, az = _degrees(altitude, "altitude", function), _degrees(azimuth, "azimuth", function)
    with np.errstate(invalid="ignore"):
        if np.any(np.abs(alt) > 90.0):
            raise HybridtrackError(f"{function}: altitude must be within [-90, 90] degrees (NaN where there is no "
                                   f"sun), got {float(alt[np.abs(alt) > 90.0].flat[0]):g}")
    return alt, az


def sun_path(altitude, azimuth, function: str) -> tuple[np.ndarray, np.ndarray]:
    """A sun path as two 1-D float arrays of one value a step (`checked_sun`'s): one position is a
    path of one step; a path is one value a step, of the same length in both, refused by
    `function`'s name otherwise (a length-1 azimuth had been reused against a longer altitude,
    and a scalar or a column raised numpy's IndexError)."""
    alt, az = checked_sun(altitude, azimuth, function)
    alt, az = np.atleast_1d(alt), np.atleast_1d(az)
    if alt.ndim != 1 or alt.shape != az.shape:
        raise HybridtrackError(f"{function} takes a sun path: altitude and azimuth of one value a step, the same "
                               f"length; got shapes {alt.shape} and {az.shape}")
    return alt, az


def _degrees(values, name: str, function: str) -> np.ndarray:
    """`values` as a float array of angles: real numbers (NaN allowed), never infinite."""
    return finite_array(values, not_numbers=f"{function}: {name} must be numbers (degrees)",
                        infinite=f"{function}: {name} must be finite degrees (NaN where there is no sun)")


def _vectors(function: str, values, name: str) -> np.ndarray:
    """`values` as float vectors ``(..., 3)`` of their own shape (one vector is (3,)), refused with
    their shape unless they are; NaN stands for no sun, an infinite component for no direction (it
    had given angles and heights)."""
    return checked_vectors(finite_array(values, not_numbers=f"{function}: {name} must be (east, north, up) vectors "
                                        "of numbers", infinite=f"{function}: {name} must be finite (NaN where there "
                                        "is no sun)"), function, name)


def checked_vectors(values, function: str, name: str, shape: tuple | None = None) -> np.ndarray:
    """`values` as an array of (east, north, up) vectors, ``(..., 3)`` or exactly `shape`, refused
    by `function`'s and the argument's `name` with the shape expected and got (a wrong shape had
    raised numpy's IndexError or ValueError deep in a product). Only O(1) checks of the shape and
    type, for vectors a caller computed already (a year's sun); `_vectors` checks each value."""
    try:
        array = np.asarray(values)
    except ValueError:  # a ragged list
        array = np.asarray(None)
    expected = "(..., 3)" if shape is None else str(tuple(shape))
    if array.dtype.kind not in "fiu":
        raise HybridtrackError(f"{function}: {name} must be (east, north, up) vectors of numbers, shape {expected}; "
                               f"got {values!r:.60}")
    if array.shape[-1:] != (3,) or (shape is not None and array.shape != tuple(shape)):
        raise HybridtrackError(f"{function}: {name} must be (east, north, up) vectors, shape {expected}; got shape "
                               f"{array.shape}")
    return array


def sun_vector(altitude, azimuth) -> np.ndarray:
    """Unit vectors towards the sun, shape ``(..., 3)`` in (east, north, up)."""
    alt, az = checked_sun(altitude, azimuth, "sun_vector")
    _broadcast("sun_vector", altitude=alt, azimuth=az)
    return direction_vectors(alt, az)


def direction_vectors(altitude: np.ndarray, azimuth: np.ndarray) -> np.ndarray:
    """Unit vectors ``(..., 3)`` in (east, north, up) at `altitude` above the horizon and `azimuth`
    from north (float arrays, degrees), without `sun_vector`'s checks: for a sun position checked
    already, or an axis's angles, which may stand past the zenith (a heliostat's elevation axis
    parked at 90° with its encoder's offset stood at 90.01°, and a 1,000-mirror field's scoring
    had refused it as no sun)."""
    a, g = np.broadcast_arrays(np.radians(altitude), np.radians(azimuth))  # one altitude, many azimuths too
    return np.stack([np.cos(a) * np.sin(g), np.cos(a) * np.cos(g), np.sin(a)], axis=-1)


def within_turn(angle: np.ndarray) -> np.ndarray:
    """`angle` % 360 (degrees, a float array), bit for bit, without numpy's float remainder on
    every element: that takes ~45 ns an angle below zero and ~110 ns a NaN (0.06 s for a
    year's azimuths with its nights), against ~10 ns for the add below. Angles within a turn of
    zero (-360 to 360) add 360 where negative, as the remainder itself does; the rest take it.
    A number or a list is taken as well (a float had raised an AttributeError, a list a TypeError)."""
    array = np.asarray(angle)
    if array.dtype.kind not in "fiu":  # text, None, True and False are no angle
        raise HybridtrackError(f"within_turn: angles must be numbers (degrees), got {angle!r:.60}")
    angle = array.astype(float, copy=False)
    within = np.where(angle < 0.0, angle + 360.0, angle + 0.0)  # + 0.0: -0.0 % 360 is 0.0
    beyond = (angle < -360.0) | (angle >= 360.0)
    if beyond.any():
        with np.errstate(invalid="ignore"):  # an infinite angle is NaN, as numpy's remainder gives it
            within[beyond] = angle[beyond] % 360.0
    return _scalar(within)


def across_angle(vectors: np.ndarray, axis_azimuth) -> np.ndarray:
    """Angle (degrees) of vectors ``(..., 3)`` projected on the plane across a horizontal axis.

    Measured from the horizontal direction at ``axis_azimuth + 90°`` through the zenith, the
    single-axis convention of this module, within [-90, 270) so that a direction just below
    either horizon stays next to 0 or 180. A vector on the horizon along the axis has no part
    across it and gives 90°, the limit of a vector above the horizon along the axis, however its
    direction was rounded. `axis_azimuth` (degrees) broadcasts against ``vectors[..., 0]``. A
    zero vector has no direction and is refused (it had given 0°).
    """
    vectors = _vectors("across_angle", vectors, "vectors")
    b = np.radians(_finite(axis_azimuth, "axis azimuth"))
    _broadcast("across_angle", **{"vectors without their x, y, z axis": vectors[..., 0]}, axis_azimuth=b)
    across = vectors[..., 0] * np.cos(b) - vectors[..., 1] * np.sin(b)  # horizontal, at azimuth b + 90°
    angle = np.degrees(np.arctan2(vectors[..., 2], across))
    angle = np.where(angle < -90.0, angle + 360.0, angle)  # [-90, 270): continuous through both horizons
    level = vectors[..., 2] == 0.0  # a year's check in ~1 ms; the rest only for a vector on the horizon
    return _scalar(_level_along_axis(vectors, b, across, angle, level) if level.any() else angle)


#: How small a horizontal vector's part across an axis may be, as a share of its part along the
#: axis, and still lie along it: sin 360° is -2.4e-16 in floating point, not 0, and such rounding
#: of an azimuth written a few turns either way stays below 1e-14; an azimuth 1e-12° off the axis
#: gives 1.7e-14.
ALONG_AXIS = 1e-13


def _level_along_axis(vectors: np.ndarray, b: np.ndarray, across: np.ndarray, angle: np.ndarray,
                      level: np.ndarray) -> np.ndarray:
    """`across_angle`'s `angle` with 90° where a vector on the horizon (`level`) lies along the
    axis: it has no part across the axis, and the rounding of its azimuth had given 0° or 180° by
    how the azimuth was written (0 or 360, 180 or -180). 90° is the limit of a vector above the
    horizon along the axis. A zero vector has no direction and is refused (it had given 0°)."""
    if np.any(level & (vectors[..., 0] == 0.0) & (vectors[..., 1] == 0.0)):
        raise HybridtrackError("across_angle: a zero vector has no direction")
    along = vectors[..., 0] * np.sin(b) + vectors[..., 1] * np.cos(b)
    return np.where(level & (np.abs(across) <= ALONG_AXIS * np.abs(along)), 90.0, angle)


def _cross_axis_angle(altitude, azimuth, axis_azimuth) -> np.ndarray:
    """Angle of the sun's projection on the plane across a horizontal axis (0-180°)."""
    angle = across_angle(direction_vectors(altitude, azimuth), axis_azimuth)
    return np.where(np.asarray(altitude, float) >= 0.0, angle, np.nan)


def trough_angle(altitude, azimuth, axis_azimuth=0.0):
    """Rotation angle of a parabolic trough on a horizontal axis.

    Parameters
    ----------
    altitude, azimuth : array_like or pandas.Series
        Sun altitude and azimuth (from north), degrees.
    axis_azimuth : float, array_like or {"ns", "ew"}
        Azimuth of the axis, degrees from north; 0 is a north-south axis tracking east-west.
        An array gives one axis per collector, broadcast against the sun position.

    Returns
    -------
    numpy.float64, ndarray or pandas.Series
        ρ in 0-180°: 0 faces the horizon at ``axis_azimuth + 90°`` (east for a north-south
        axis), 90 the zenith (stow), 180 the opposite horizon. NaN while the sun is down.
        For a north-south axis ρ = atan2(tan α, sin γ), i.e. 90° + pvlib's
        ``tracking.singleaxis`` tracker_theta with axis_azimuth 180 and no backtracking.
        A sun on the horizon (α = 0) exactly along the axis has no projection across it:
        ρ is 90° there, however the azimuth is written (0 or 360, 180 or -180), the limit of
        a sun just above the horizon along the axis (where pvlib's tracker_theta is 0).

    References
    ----------
    .. [1] W. F. Marion and A. P. Dobos, "Rotation angle for the optimum tracking of one-axis
       trackers", NREL/TP-6A20-58891, 2013.
    .. [2] W. F. Holmgren, C. W. Hansen and M. A. Mikofski, "pvlib python: a python package for
       modeling solar energy systems", Journal of Open Source Software 3(29), 884, 2018,
       doi:10.21105/joss.00884 (``pvlib.tracking.singleaxis``).
    """
    if isinstance(axis_azimuth, str):
        if axis_azimuth not in AXIS_AZIMUTH:
            raise HybridtrackError(f"unknown axis {axis_azimuth!r}; use 'ns', 'ew' or degrees")
        axis_azimuth = AXIS_AZIMUTH[axis_azimuth]
    axis = _finite(axis_azimuth, "axis azimuth")
    alt, az = checked_sun(altitude, azimuth, "trough_angle")
    _broadcast("trough_angle", altitude=alt, azimuth=az, axis_azimuth=axis)
    return _like(altitude, _cross_axis_angle(alt, az, axis), "trough_angle")


def tracking_rate(angle):
    """Rate of change of tracking angles, degrees per minute.

    Central differences on the time index (one-sided at the ends), so any regular or
    irregular sampling works; use a fine step where the peak rate matters. A DataFrame (one
    column per collector) gives each column's rate.

    Parameters
    ----------
    angle : pandas.Series or pandas.DataFrame
        Angles (degrees) on a DatetimeIndex.

    Returns
    -------
    pandas.Series or pandas.DataFrame
        Of the input's shape; a Series is named ``rate``.
    """
    if not isinstance(angle, (pd.Series, pd.DataFrame)) or not isinstance(angle.index, pd.DatetimeIndex):
        raise HybridtrackError("tracking_rate needs a Series or DataFrame on a DatetimeIndex")
    if angle.index.tz is None:  # a local clock's naive stamps across a change of summer time give wrong rates
        raise HybridtrackError("tracking_rate needs a tz-aware time index; localise it (index.tz_localize(...))")
    if len(angle) < 2:
        raise HybridtrackError("tracking_rate needs at least two samples")
    if angle.index.hasnans or not angle.index.is_monotonic_increasing or not angle.index.is_unique:
        # a step back or a repeat gave wrong rates or infinities without a word
        raise HybridtrackError("tracking_rate needs time stamps that increase, without repeats or NaT; sort them "
                               "and drop the repeats first")
    columns = angle.to_frame() if isinstance(angle, pd.Series) else angle
    if not all(kind.kind in "fiu" for kind in columns.dtypes):
        raise HybridtrackError("tracking_rate needs angles as numbers (degrees)")
    minutes = np.asarray((angle.index - angle.index[0]) / pd.Timedelta(minutes=1), float)
    rate = np.gradient(angle.to_numpy(float), minutes, axis=0)
    if isinstance(angle, pd.DataFrame):
        return pd.DataFrame(rate, index=angle.index, columns=angle.columns)
    return pd.Series(rate, index=angle.index, name="rate")


def fresnel_angle(altitude, azimuth, d, h, axis_azimuth=0.0):
    """Tracking angle of a linear Fresnel mirror row.

    The mirror normal bisects the directions to the sun and to the receiver, in the plane
    across the row's axis.

    Parameters
    ----------
    altitude, azimuth : array_like or pandas.Series
        Sun position, degrees.
    d : float or array_like
        Signed lateral distance of the row from the receiver line, metres, positive for a
        row on the ``axis_azimuth + 90°`` side (east of the receiver for a north-south field).
    h : float or array_like
        Height of the receiver above the row's pivot, metres (> 0).
    axis_azimuth : float or array_like
        Azimuth of the row axis, degrees from north.

    Returns
    -------
    numpy.float64, ndarray or pandas.Series
        Angle of the mirror normal in the trough convention (90° = mirror horizontal, facing
        the zenith; below 90° tilted towards the ``axis_azimuth + 90°`` side). NaN at night.
    """
    receiver = receiver_angle(d, h)
    axis = _finite(axis_azimuth, "axis azimuth")
    alt, az = checked_sun(altitude, azimuth, "fresnel_angle")
    _broadcast("fresnel_angle", altitude=alt, azimuth=az, d=d, h=h, axis_azimuth=axis)
    sun = _cross_axis_angle(alt, az, axis)
    return _like(altitude, 0.5 * (sun + receiver), "fresnel_angle")


def receiver_angle(d, h):
    """Direction (trough convention, degrees) from a Fresnel row at lateral distance `d` to its receiver.

    A numpy.float64 for scalar `d` and `h`, else an array of their broadcast shape.
    """
    d, h = _distance(d, "row distance d"), _distance(h, "receiver height h")
    _broadcast("receiver_angle", d=d, h=h)
    if not np.all(h > 0):
        raise HybridtrackError(f"receiver height h must be positive, got {h.tolist()!r} m")
    return _scalar(np.degrees(np.arctan2(h, -d)))


def _finite(values, name: str) -> np.ndarray:
    """`values` as a float array, refused with its name unless every element is a finite number
    (text and True had been read as numbers: "5" as 5 m)."""
    array = finite_array(values, not_numbers=f"{name} must be numbers", infinite=f"{name} must be finite")
    if not np.all(np.isfinite(array)):
        raise HybridtrackError(f"{name} must be finite, got {array.tolist()!r}")
    return array


def _distance(values, name: str) -> np.ndarray:
    """`_finite` metres no farther than `MAX_DISTANCE` (a row 1e308 m out had overflowed to an
    infinite end loss with numpy's RuntimeWarning)."""
    array = _finite(values, name)
    if np.any(np.abs(array) > MAX_DISTANCE):
        raise HybridtrackError(f"{name} must be within {MAX_DISTANCE:g} m, the farthest a row or receiver lies from "
                               f"a collector; got {array.tolist()!r:.60}")
    return array


#: The sun vector's part across a Fresnel row's axis at or below which its ray runs along the row:
#: sin 180° rounds to 1.2e-16, not 0, and a sun on the horizon straight down the row had been given
#: a finite end loss of 8.5e16 m. Four units in the last place of 1, far below any sun that is not
#: exactly on the axis's line at the horizon (1e-15 rad is 6e-14°).
PARALLEL = 4.0 * np.finfo(float).eps


def fresnel_end_loss(altitude, azimuth, d, h, axis_azimuth=0.0):
    """End loss of a Fresnel row: how far the reflected light runs past the receiver's end.

    The mirror's normal lies across the row's axis, so the reflected ray keeps the sun's part
    along the axis; it travels ``f = sqrt(d² + h²)`` across the axis to the receiver and so runs
    ``L_end = -f s_a / sqrt(1 - s_a²)`` along it, ``s_a = cos α cos(γ - β)`` the sun vector's part
    along the axis (β the axis azimuth), i.e. ``f`` times the tangent of the sun's angle out of
    the plane across the axis. For a north-south row (β = 0) this is
    ``f cos α cos γ_s / sqrt(cos²α sin²γ_s + sin²α)``, γ_s the azimuth from south, and at solar
    noon ``f cot α``.

    Parameters
    ----------
    altitude, azimuth : array_like or pandas.Series
        Sun position, degrees (azimuth from north).
    d, h : float or array_like
        Row's lateral distance from the receiver line and the receiver's height, metres; arrays
        give one row each, broadcast against the sun position (``altitude[:, None]`` against
        ``d`` of shape (N,) gives (T, N)).
    axis_azimuth : float or array_like
        Azimuth of the row's axis, degrees from north (0: a north-south row); broadcast too.

    Returns
    -------
    numpy.float64, ndarray or pandas.Series
        Metres; positive means the light is lost past the row's end at `axis_azimuth` (the
        north end of a north-south row), negative past the other end; infinite with the sun on
        the horizon straight along the row (its ray never reaches the receiver). NaN while the
        sun is down.
    """
    d, h = _distance(d, "row distance d"), _distance(h, "receiver height h")
    if not np.all(h > 0):  # the hypotenuse would hide the sign: -10 m gave +10 m's loss
        raise HybridtrackError(f"receiver height h must be positive, got {h.tolist()!r} m")
    axis = _finite(axis_azimuth, "axis azimuth")
    alt, az = checked_sun(altitude, azimuth, "fresnel_end_loss")
    _broadcast("fresnel_end_loss", altitude=alt, azimuth=az, d=d, h=h, axis_azimuth=axis)
    a = np.radians(alt)
    g = np.radians(az - axis)  # the sun's azimuth from the axis
    f = np.hypot(d, h)
    along, across = -f * np.cos(a) * np.cos(g), np.sqrt((np.cos(a) * np.sin(g)) ** 2 + np.sin(a) ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        loss = np.where(across > PARALLEL, along / across, np.copysign(np.inf, along))
    return _like(altitude, np.where(a >= 0.0, loss, np.nan), "end_loss")  # a sun on the horizon is up, as elsewhere


def heliostat_normal(altitude, azimuth, aim, *, sun=None) -> np.ndarray:
    """Unit mirror normals of a heliostat reflecting the sun onto an aim point.

    Law of reflection: ``n = (s + r) / |s + r|`` with ``r`` the unit vector from the mirror
    centre to the aim point.

    Parameters
    ----------
    altitude, azimuth : array_like
        Sun position, degrees.
    aim : array_like, shape (3,) or (..., 3)
        Aim point relative to the mirror centre, (east, north, up) metres; one per mirror with
        shape (M, 3), broadcast against the sun position.

    Returns
    -------
    ndarray, shape (..., 3)
        Unit normals in (east, north, up), of the broadcast shape of the sun position and the
        aim points (one position and one aim point give (3,)); NaN while the sun is down.
        Altitudes of shape (T, 1) against aim points (M, 3) give all M mirrors at T steps,
        (T, M, 3).

    Other Parameters
    ----------------
    sun : numpy.ndarray, optional
        ``sun_vector(altitude, azimuth)``, if computed already (a field's heliostats share it):
        of the sun position's shape and (3,); another is refused.
    """
    unit = aim_unit(aim)
    alt, az = checked_sun(altitude, azimuth, "heliostat_normal")
    _broadcast("heliostat_normal", altitude=alt, azimuth=az, **{"aim_points without their x, y, z axis": unit[..., 0]})
    if sun is None:
        s = direction_vectors(alt, az)
    else:
        s = checked_vectors(sun, "heliostat_normal", "sun", np.broadcast_shapes(alt.shape, az.shape) + (3,))
    fast = mountpass.heliostat_normals(s, unit, alt)  # a sun path and one aim point: one compiled pass, same bits
    if fast is not None:
        return fast
    bisector = s + unit
    n = bisector / np.linalg.norm(bisector, axis=-1, keepdims=True)
    return np.where((alt < 0.0)[..., None], np.nan, n)


def aim_unit(aim) -> np.ndarray:
    """Unit vectors from a mirror centre towards its aim points: the ``r`` of the law of
    reflection in `heliostat_normal`.

    Parameters
    ----------
    aim : array_like, shape (3,) or (..., 3)
        Aim points relative to the mirror centre, (east, north, up) metres.

    Returns
    -------
    ndarray, shape of `aim`
        Each aim point over its length. Anything but three finite coordinates, not all zero,
        is refused by name (`HybridtrackError`).
    """
    try:
        target = finite_array(aim, not_numbers="aim point", infinite="aim point")
    except HybridtrackError:  # text and ragged lists are no point ("0", "20", "100" had been read as one)
        target = np.zeros(0)
    norm = np.linalg.norm(target, axis=-1, keepdims=True) if target.ndim else np.zeros(1)
    if target.ndim == 0 or target.shape[-1] != 3 or not np.all(np.isfinite(target)) or not np.all(norm > 0):
        raise HybridtrackError(f"aim point must be three finite coordinates (east, north, up), not all zero, shape "
                               f"(3,) or (..., 3); got {_described(aim)}")
    return target / norm


def normal_angles(normals) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (from north, 0-360) and elevation of normals ``(..., 3)``, degrees, shape ``(...)``
    (two numpy.float64 for one normal).

    The normals need not be unit vectors: the elevation is the angle above the horizontal plane
    (``arctan2(up, horizontal length)``), so a normal of any length gives its direction's angles
    (the arcsine of ``up`` alone had given 90° for ``(0, 3, 2)``), and a normal near the zenith
    keeps its precision. A zero vector has no direction and is refused."""
    n = _vectors("normal_angles", normals, "normals")
    horizontal = np.hypot(n[..., 0], n[..., 1])
    if np.any((horizontal == 0.0) & (n[..., 2] == 0.0)):
        raise HybridtrackError("normal_angles: a zero vector has no direction")
    azimuth = within_turn(np.degrees(np.arctan2(n[..., 0], n[..., 1])))
    elevation = np.degrees(np.arctan2(n[..., 2], horizontal))
    return azimuth, _scalar(elevation)


def jack_heights(normals, supports=THREE_POINT_SUPPORT) -> np.ndarray:
    """Heights of the jacks of a multi-point support that set a mirror to each normal.

    The mirror plane passes through the centre (height 0), so a jack at horizontal position
    ``(x_i, y_i)`` stands at ``z_i = -(n_x x_i + n_y y_i) / n_z``.

    Parameters
    ----------
    normals : array_like, shape (..., 3)
        Unit mirror normals in (east, north, up), with n_z > 0.
    supports : array_like, shape (K, 2)
        Horizontal jack positions (east, north), metres; the published three-jack layout by
        default.

    Returns
    -------
    ndarray, shape (..., K)
        Jack heights in metres relative to the mirror centre.
    """
    n = _vectors("jack_heights", normals, "normals")
    with np.errstate(invalid="ignore"):
        if np.any(n[..., 2] <= 0):  # a mirror facing the horizon or down has no jack heights (inf and nan)
            raise HybridtrackError("jack_heights: normals must point up (n_z > 0); NaN where there is no sun")
    xy = _finite(supports, "supports")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise HybridtrackError(f"supports must be (x, y) pairs, got shape {xy.shape}")
    with np.errstate(invalid="ignore", divide="ignore"):
        return -(n[..., :1] * xy[:, 0] + n[..., 1:2] * xy[:, 1]) / n[..., 2:3]


def _aim_point(aim) -> tuple[float, float, float]:
    """A heliostat's aim point as three floats, each checked (None and 5.0 had raised a TypeError)."""
    try:
        values = tuple(aim)
    except TypeError:
        values = ()
    if len(values) != 3:
        raise HybridtrackError(f"collector: aim (m) must be three numbers (east, north, up), got {aim!r:.60}")
    return tuple(number(value, "collector: aim (m)", -MAX_DISTANCE, MAX_DISTANCE) for value in values)


#: The collector kinds the project serves: "trough" is a trough on any horizontal axis (its
#: `axis_azimuth` given), "trough-ns" and "trough-ew" the two usual axes by name.
KINDS = ("trough-ns", "trough-ew", "trough", "fresnel", "heliostat")

#: The axis line each named trough kind stands for, as its axis azimuth modulo 180 degrees.
NAMED_TROUGHS = {"trough-ns": AXIS_AZIMUTH["ns"] % 180.0, "trough-ew": AXIS_AZIMUTH["ew"] % 180.0}


def trough_kind(axis_azimuth: float) -> str:
    """The kind of a trough on a horizontal axis, named so that it never names another axis.

    Parameters
    ----------
    axis_azimuth : float
        Azimuth of the axis, degrees from north, finite.

    Returns
    -------
    str
        "trough-ns" on exactly a north-south line (0 or 180, a turn either way too), "trough-ew"
        on exactly an east-west one (90 or 270), "trough" on any other (`Collector` carries its
        axis azimuth).

    References
    ----------
    .. [1] W. F. Marion and A. P. Dobos, "Rotation angle for the optimum tracking of one-axis
       trackers", NREL/TP-6A20-58891, 2013 (horizontal single axes at any azimuth).
    """
    line = number(axis_azimuth, "trough_kind: axis_azimuth (degrees from north)") % 180.0
    return next((kind for kind, named in NAMED_TROUGHS.items() if line == named), "trough")


#: Metres: the farthest a row, receiver or aim point may lie from a collector (a large tower
#: field's outer heliostats are about 1.5 km from the tower).
MAX_DISTANCE = 5_000.0
#: Metres: the lowest a Fresnel receiver may stand above its rows. Built rows' mirrors are 0.5 m
#: wide and more (Zhu et al. 2014, doi:10.1016/j.solener.2013.05.021) and their receivers stand
#: metres above them; 1e-300 m had been taken, its row right below the receiver scored on a
#: receiver lying on the mirror, and 0.01 (kilometres for metres) would have been too. Well below
#: any built receiver, so that no real layout is refused.
MIN_RECEIVER_HEIGHT = 0.1


#: The kinds of collector each geometry field of `Collector` describes.
GEOMETRY_KINDS = {"axis_azimuth": ("trough-ns", "trough-ew", "trough", "fresnel"), "row_distance": ("fresnel",),
                  "receiver_height": ("fresnel",), "aim": ("heliostat",)}


@dataclass(frozen=True)
class Collector:
    """A collector's kind and geometry: everything needed to turn a sun position into targets.

    Parameters
    ----------
    kind : {"trough-ns", "trough-ew", "trough", "fresnel", "heliostat"}
        Parabolic trough on a north-south or east-west horizontal axis, or on any other
        horizontal axis ("trough", its `axis_azimuth` required), a linear Fresnel mirror row, or
        a two-axis heliostat.
    axis_azimuth : float, optional
        Trough or Fresnel axis azimuth in degrees from north; by default the kind's own
        (0 for "trough-ns" and "fresnel", 270 for "trough-ew", see `AXIS_AZIMUTH`). A named
        trough takes only its own line: 0 or 180 for "trough-ns", 90 or 270 for "trough-ew"
        (a turn either way too); see `trough_kind`.
    row_distance, receiver_height : float
        Fresnel row: signed lateral distance from the receiver line and receiver height (m).
    aim : tuple of float
        Heliostat aim point relative to the mirror centre, (east, north, up) metres; the
        published tower case by default.
    """

    kind: str = "trough-ns"
    axis_azimuth: float | None = None
    row_distance: float = 5.0
    receiver_height: float = 10.0
    aim: tuple[float, float, float] = (0.0, 20.0, 100.0)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise HybridtrackError(f"unknown collector {self.kind!r}; choose from {', '.join(KINDS)}")
        if self.axis_azimuth is not None:
            number(self.axis_azimuth, "collector: axis_azimuth (degrees from north)", -360, 360)
        number(self.row_distance, "collector: row_distance (m)", -MAX_DISTANCE, MAX_DISTANCE)
        number(self.receiver_height, "collector: receiver_height (m)", 0, MAX_DISTANCE, above=True)
        object.__setattr__(self, "aim", _aim_point(self.aim))  # a tuple: a list or an array made it unhashable
        self._refuse_other_kinds_geometry()
        if self.receiver_height < MIN_RECEIVER_HEIGHT:  # a Fresnel row's: another kind's was refused above
            raise HybridtrackError(f"collector: receiver_height (m) must be at least {MIN_RECEIVER_HEIGHT:g} m above "
                                   f"the rows (mirrors are 0.5 m wide and more), got {self.receiver_height:g}")
        self._refuse_untruthful_axis()
        if self.kind == "heliostat":
            heliostat_normal(45.0, 180.0, self.aim)  # validates the aim point
            if not self.aim[2] >= MIN_RECEIVER_HEIGHT:  # as a field's aim points and a Fresnel receiver
                raise HybridtrackError(f"collector: aim (m): the aim point must be above the mirror, at least "
                                       f"{MIN_RECEIVER_HEIGHT:g} m, got {self.aim[2]:g} m up: a heliostat reflects "
                                       "the sun up to its receiver")

    def _refuse_other_kinds_geometry(self) -> None:
        """Refuse geometry this kind has no use for (a trough's row distance, a heliostat's axis),
        set away from its default: it would be ignored without a word."""
        for f in fields(self):
            kinds = GEOMETRY_KINDS.get(f.name)
            value = getattr(self, f.name)
            if kinds is None or self.kind in kinds or value is None or np.array_equal(np.asarray(value, float),
                                                                     np.asarray(f.default, float)):
                continue
            raise HybridtrackError(f"collector: {f.name} describes a {' or '.join(kinds)} collector, "
                                   f"not a {self.kind}; it would be ignored")

    def _refuse_untruthful_axis(self) -> None:
        """Refuse a trough whose kind would misname its axis: a "trough-ns" on a 45° axis had been
        taken and reported as north-south; and a "trough" without the axis it stands for."""
        if self.kind == "trough" and self.axis_azimuth is None:
            raise HybridtrackError("collector: a trough needs its axis_azimuth (degrees from north); trough-ns and "
                                   "trough-ew name the north-south and east-west axes")
        if self.kind in NAMED_TROUGHS and self.axis_azimuth is not None and trough_kind(self.axis) != self.kind:
            raise HybridtrackError(f"collector: axis_azimuth {self.axis:g} is no {self.kind} axis (a {self.kind} lies "
                                   f"at {NAMED_TROUGHS[self.kind]:g} or {NAMED_TROUGHS[self.kind] + 180:g} degrees); "
                                   f"it is a {trough_kind(self.axis)} collector")

    @property
    def single_axis(self) -> bool:
        """True for troughs and Fresnel rows, whose target is one angle."""
        return self.kind != "heliostat"

    @property
    def axis(self) -> float:
        """The axis azimuth in effect, degrees from north."""
        if self.axis_azimuth is not None:
            return float(self.axis_azimuth)
        return AXIS_AZIMUTH["ew"] if self.kind == "trough-ew" else AXIS_AZIMUTH["ns"]

    def angles(self, altitude: pd.Series, azimuth: pd.Series) -> pd.DataFrame:
        """Target angles for a sun path, as a frame on the path's index.

        Single-axis kinds give ``angle`` (degrees, trough convention) and ``rate`` (°/min);
        a Fresnel row adds ``end_loss`` (m, `fresnel_end_loss`); a heliostat gives
        ``normal_azimuth``, ``normal_elevation`` and the three ``jack_1..3`` heights (m) of the
        published support.
        """
        if not (isinstance(altitude, pd.Series) and isinstance(azimuth, pd.Series)):
            raise HybridtrackError("Collector.angles takes the sun path as two Series on its time index (the columns "
                                   f"of solar_position), got {type(altitude).__name__} and {type(azimuth).__name__}")
        out = pd.DataFrame(index=altitude.index)
        if self.kind == "heliostat":
            normals = heliostat_normal(altitude.to_numpy(float), azimuth.to_numpy(float), self.aim)
            out["normal_azimuth"], out["normal_elevation"] = normal_angles(normals)
            for i, column in enumerate(jack_heights(normals).T, start=1):
                out[f"jack_{i}"] = column
            return out
        if self.kind == "fresnel":
            out["angle"] = fresnel_angle(altitude, azimuth, self.row_distance, self.receiver_height, self.axis)
        else:
            out["angle"] = trough_angle(altitude, azimuth, self.axis)
        if len(out) > 1:
            out["rate"] = tracking_rate(out["angle"])
        if self.kind == "fresnel":
            out["end_loss"] = fresnel_end_loss(altitude, azimuth, self.row_distance, self.receiver_height, self.axis)
        return out


def _described(value) -> str:
    """A value as one short line: an array by its shape (a thousand aim points had been printed),
    anything else as its repr."""
    shape = getattr(value, "shape", None)
    if shape is not None and np.size(value) > 3:
        return f"an array of shape {tuple(shape)}"
    text = repr(value)
    if len(text) <= 80 and "\n" not in text:
        return text
    return f"a {type(value).__name__}" + (f" of length {len(value)}" if hasattr(value, "__len__") else "")


def as_collector(value) -> Collector:
    """A `Collector` from its kind's name, or the `Collector` itself; anything else is refused
    (a number had raised an AttributeError deep in a run)."""
    if isinstance(value, str):
        return Collector(value)
    if not isinstance(value, Collector):
        raise HybridtrackError(f"collector must be a kind's name ({', '.join(KINDS)}) or a Collector, got {value!r:.60}")
    return value
