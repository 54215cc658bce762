"""Whole collector fields: a linear Fresnel field, a trough loop, a heliostat field.

A field is a list of collectors at positions (metres east, north, up from the field's origin),
each with its own imperfections drawn from seeded distributions (`ImperfectionSpread`):
no two rows of a real field are aligned alike. `simulate_field` runs the controller for every
collector on the same weather and site and scores each one and the field. It runs
`hybridtrack.simulate` once per collector (with the compiled kernel where the engine takes it),
on threads of this process by default, with what every collector's run shares computed once:
the sun positions and the sky they stand under, the field controller's clock and its plan's sun
(`hybridtrack.reuse.reuse_work`).

The field geometry itself is vectorised over collectors: `FresnelField.targets`,
`TroughLoop.targets` and `HeliostatField.targets` give every collector's nominal target at
every step in one call of the broadcasting functions of `hybridtrack.collectors`.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import math
import numbers
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import params, sites
from .budget import BYTES_PER_STEP, check_steps
from .cluster import MAX_WORKERS, check_where, cores
from .collectors import (
    MAX_DISTANCE,
    MIN_RECEIVER_HEIGHT,
    Collector,
    fresnel_angle,
    fresnel_end_loss,
    heliostat_normal,
    normal_angles,
    sun_path,
    trough_angle,
    trough_kind,
)
from .errors import HybridtrackError
from .mounting import geometry_key
from .outputs import claim, output_folder, remove_earlier, removing_empty_folders, strict_json, together, write
from .times import stamp_minutes
from .world import IMPERFECTION_LIMITS, Imperfections

__all__ = ["ImperfectionSpread", "FresnelField", "TroughLoop", "HeliostatField", "FieldResult", "simulate_field",
           "collector_columns", "FIELD_KINDS", "LOG_VARIABLES", "COLLECTOR_METRICS"]

#: The per-collector log columns kept in `FieldResult.dataset` (collector × time).
LOG_VARIABLES = ("target_true", "target", "angle", "error", "mode", "sky", "sensor_status", "intensity_ma",
                 "calibration")
#: Log columns every collector shares (the weather and the sky class); kept once, over time.
SHARED_VARIABLES = ("dni", "wind_speed")
#: The dataset's units (UDUNITS names, as CF asks), by variable; a heliostat's ``*_azimuth`` twins too.
UNITS = {"target_true": "degree", "target": "degree", "angle": "degree", "error": "degree", "calibration": "degree",
         "intensity_ma": "mA", "dni": "W m-2", "wind_speed": "m s-1"}
#: Bytes a kept log takes per collector and step, at most (a heliostat's two axes).
LOG_BYTES = 80
#: The closest `HeliostatField.rings` places mirrors, metres: heliostats are built from about 1 m² up
#: (Pfahl et al. 2017's review; docs/fields.md), so centres closer than 1 m would overlap mirrors.
MIN_SPACING = 1.0
#: The closest two Fresnel rows' centres may lie, metres: built primary mirrors are 0.5 m wide and
#: more (Zhu et al. 2014's review of linear Fresnel collectors, doi:10.1016/j.solener.2013.05.021),
#: so rows this close would share their mirrors: a typo (rows 0.1 µm apart had been taken). Well
#: below any built width, so that no real layout is refused.
MIN_ROW_SPACING = 0.1
#: The shortest `TroughLoop.collector_length`, metres: the loop's collectors stand this far apart
#: centre to centre, so shorter ones would overlap or share a place (1e-300 m put two at one
#: point). Built troughs come in modules of a few metres and more (a EuroTrough module is 12 m,
#: small process-heat troughs some 2 to 6 m), so 1 m refuses no real loop.
MIN_COLLECTOR_LENGTH = 1.0
#: The shortest `FresnelField.row_length`, metres, for the same reason: built rows run tens to
#: hundreds of metres; a row of 1e-300 m had been taken and lost all its light off its end.
MIN_ROW_LENGTH = 1.0
#: Metres two collectors may fall short of the least spacing and still be taken: positions written
#: as decimals differ in binary floating point by a little less than they read (-7.2 - -8.2 is
#: 0.9999999999999991), and "1 m apart: closer than 1 m" had refused layouts exactly at the limit.
#: A nanometre lies far below any survey.
SPACING_TOLERANCE = 1e-9
#: The most heliostats a field (one tower) may have, as `HeliostatField.rings` takes: Ivanpah's
#: 173,500 heliostats serve three towers, some 58,000 each.
MAX_HELIOSTATS = 100_000
#: A positions table's columns that give each heliostat its own aim point (`hybridtrack field --positions`).
AIM_COLUMNS = ("aim_east", "aim_north", "aim_up")
#: A heliostat field's aim point when none is given: 100 m above the tower's foot, a tower of the
#: size the rings' default 60 m first radius serves.
DEFAULT_AIM = (0.0, 0.0, 100.0)


@dataclass(frozen=True)
class ImperfectionSpread:
    """Standard deviations of the per-collector imperfections around the config's values.

    Each collector's `Imperfections` field is drawn from a normal distribution centred on the
    run config's value with the standard deviation given here (same units: degrees, seconds).
    ``sensor_noise``, a standard deviation itself, is folded at zero (its absolute value).
    The defaults spread what differs from collector to collector in a commissioned field
    (each row is set up and surveyed on its own: a few tenths of a degree of axis and encoder
    error, a few hundredths of sensor bias) and keep what one field controller shares (its
    clock, its drift and its site coordinates, and the day the field was commissioned) equal for
    all.
    """

    axis_azimuth_error: float = 0.2
    axis_tilt_error: float = 0.15
    encoder_offset: float = 0.2
    clock_error: float = 0.0
    latitude_error: float = 0.0
    longitude_error: float = 0.0
    sensor_bias: float = 0.02
    sensor_noise: float = 0.0
    clock_drift: float = 0.0
    commissioned_days_ago: float = 0.0
    axis_roll_error: float = 0.0

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)  # numpy's scalars are numbers too (they had been refused)
            number = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
            if not number or not value >= 0 or value == math.inf:  # NaN is not >= 0; 10**400 is beyond the limit
                raise HybridtrackError(f"imperfection spread: {f.name} must be a finite number >= 0, got {value!r:.40}")
            if value > IMPERFECTION_LIMITS[f.name]:
                raise HybridtrackError(f"imperfection spread: {f.name} = {value!r:.40} is beyond the imperfection's "
                                       f"own limit of {IMPERFECTION_LIMITS[f.name]:g}")
            object.__setattr__(self, f.name, float(value))

    @classmethod
    def none(cls) -> ImperfectionSpread:
        """Every collector gets the config's imperfections exactly."""
        return cls(**{f.name: 0.0 for f in dataclasses.fields(cls)})

    def draw(self, mean: Imperfections, count: int, seed: int, names: list[str] | None = None) -> list[Imperfections]:
        """`count` imperfection records; collector ``i``'s draw depends only on `seed` and ``i``.
        A draw beyond an imperfection's limits is refused naming the collector (by `names`, as the
        field's table does; else by its number from 1)."""
        records = []
        for i in range(count):
            rng = np.random.default_rng([seed, i])
            values = {f.name: getattr(mean, f.name) + getattr(self, f.name) * rng.standard_normal()
                      for f in dataclasses.fields(Imperfections)}
            values["sensor_noise"] = abs(values["sensor_noise"])
            try:
                records.append(Imperfections(**values))
            except HybridtrackError as exc:
                name = names[i] if names is not None else f"collector {i + 1}"
                raise HybridtrackError(f"{name}: the drawn {exc}; narrow the spread") from None
        return records


def _sun_columns(altitude, azimuth) -> tuple[np.ndarray, np.ndarray]:
    """Sun path (`sun_path`) as (T, 1) columns that broadcast against N collectors."""
    alt, az = sun_path(altitude, azimuth, "a field's geometry")
    return alt[:, None], az[:, None]


def _along_axis(offsets: np.ndarray, axis_azimuth: float) -> np.ndarray:
    """Positions (N, 3) at `offsets` metres along a horizontal axis through the origin."""
    b = np.radians(axis_azimuth)
    xyz = np.stack([offsets * np.sin(b), offsets * np.cos(b), np.zeros_like(offsets)], axis=-1)
    return np.round(xyz, 9) + 0.0  # no 1e-16 m (or -0.0) from the sine of a right angle


def _across_axis(offsets: np.ndarray, axis_azimuth: float) -> np.ndarray:
    """Positions (N, 3) at `offsets` metres across a horizontal axis (towards ``axis_azimuth + 90°``)."""
    return _along_axis(offsets, axis_azimuth + 90.0)


def _as_numbers(values) -> np.ndarray | None:
    """`values` as a float array if they are numbers (not text, not True/False, not even one among
    numbers, which numpy would read as 1 or 0), else None."""
    try:
        raw = np.asarray(values)
    except (TypeError, ValueError):  # ragged
        return None
    if raw.dtype.kind not in "iuf":
        return None
    if not isinstance(values, np.ndarray) and any(isinstance(v, (bool, np.bool_))
                                                  for v in np.asarray(values, dtype=object).ravel()):
        return None
    return raw.astype(float)


def _brief(values) -> str:
    """`values` as one short line for a message (a frame's or an array's repr runs over lines)."""
    text = " ".join(repr(values).split())
    return text if len(text) <= 80 else text[:77] + "..."


def _finite_vector(values, name: str, *, positive: bool = False, bound: float = MAX_DISTANCE) -> np.ndarray:
    """`values` as a 1-D float array, refused unless numbers, finite, within ±`bound` (and positive)."""
    array = _as_numbers(values)
    if array is None:
        raise HybridtrackError(f"{name} must be numbers, got {_brief(values)}")
    array = np.atleast_1d(array)
    if array.ndim != 1 or array.size == 0:
        raise HybridtrackError(f"{name} must be a non-empty list of numbers, got shape {array.shape}")
    if not np.all(np.isfinite(array)) or (positive and not np.all(array > 0)):
        raise HybridtrackError(f"{name} must be finite{' and positive' if positive else ''}, got {array.tolist()}")
    if np.any(np.abs(array) > bound):
        raise HybridtrackError(f"{name} must be within ±{bound:g}, got {array.tolist()}")
    return array


def _distinct(points: np.ndarray, what: str, unit: str) -> None:
    """Refuse two collectors at one place (a typo in a layout: two mirrors cannot share it),
    naming both by their 1-based numbers."""
    rows = points.reshape(len(points), -1)
    _, first, group = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    earlier = first[group.ravel()]  # each collector's first at its place
    repeats = np.flatnonzero(earlier != np.arange(len(rows)))
    if len(repeats):
        again, before = int(repeats[0]), int(earlier[repeats[0]])
        place = ", ".join(f"{v:g}" for v in rows[again])
        raise HybridtrackError(f"{what} {before + 1} and {again + 1} are both at {place} {unit}: two collectors "
                               "cannot share a place")


def _aim_of(aim, aims) -> bool:
    """Whether `aim` is the mean of `aims`, as a field made before stores it: `dataclasses.replace`
    hands both back, and that is no second aim point."""
    one, each = _as_numbers(aim), _as_numbers(aims)
    return (one is not None and each is not None and one.shape == (3,) and each.ndim == 2 and each.shape[1:] == (3,)
            and len(each) > 0 and bool(np.allclose(each.mean(axis=0), one, rtol=0.0, atol=1e-9)))


def _refuse_rows_too_close(distances: np.ndarray) -> None:
    """Refuse Fresnel rows closer than `MIN_ROW_SPACING`, naming the first such pair."""
    order = np.argsort(distances)
    gaps = np.diff(distances[order])
    if len(gaps) and gaps.min() < MIN_ROW_SPACING - SPACING_TOLERANCE:
        k = int(np.argmin(gaps))
        i, j = sorted((int(order[k]), int(order[k + 1])))
        raise HybridtrackError(f"rows {i + 1} and {j + 1} are {gaps[k]:.12g} m apart: closer than {MIN_ROW_SPACING:g} "
                               "m, their mirrors would overlap")


def _refuse_overlapping(xyz: np.ndarray) -> None:
    """Refuse heliostats whose centres are closer than `MIN_SPACING`, as `HeliostatField.rings`
    does: their mirrors would overlap (a positions file 0.5 m apart was taken)."""
    from scipy.spatial import cKDTree

    pairs = cKDTree(xyz).query_pairs(MIN_SPACING, output_type="ndarray")
    apart = np.linalg.norm(xyz[pairs[:, 0]] - xyz[pairs[:, 1]], axis=1) if len(pairs) else np.empty(0)
    close = pairs[apart < MIN_SPACING - SPACING_TOLERANCE]
    if len(close):
        i, j = sorted(min(close.tolist()))
        raise HybridtrackError(f"heliostats {i + 1} and {j + 1} are {np.linalg.norm(xyz[i] - xyz[j]):.12g} m apart: "
                               f"closer than {MIN_SPACING:g} m, their mirrors would overlap (heliostats are built from "
                               "about 1 m² up)")


def _finite_number(value, name: str, *, positive: bool = False, bound: float = MAX_DISTANCE) -> float:
    """`value` as one finite number (`_finite_vector`'s checks); a list or an array of several is
    refused as not one number (it had been told it must be "a non-empty list")."""
    number = _as_numbers(value)
    if number is not None and number.size != 1:
        raise HybridtrackError(f"{name} must be one number for the whole field, got {_brief(value)}")
    return float(_finite_vector(number.ravel() if number is not None else [value], name, positive=positive,
                                bound=bound)[0])


@dataclass(frozen=True)
class FresnelField:
    """A linear Fresnel field: parallel mirror rows under one receiver line.

    Parameters
    ----------
    row_distances : sequence of float
        Each row's signed lateral distance from the receiver line, metres, positive towards
        ``axis_azimuth + 90°`` (east for a north-south field).
    receiver_height : float
        Height of the receiver above the rows' pivots, metres, at least
        `hybridtrack.collectors.MIN_RECEIVER_HEIGHT` (0.1 m).
    row_length : float
        Length of every row, metres, at least `MIN_ROW_LENGTH` (1 m); the end loss is counted
        against it.
    axis_azimuth : float
        Azimuth of the rows' axis, degrees from north (0: north-south rows).
    spread : ImperfectionSpread
        How each row's imperfections scatter around the config's.
    """

    row_distances: tuple[float, ...] = tuple(np.arange(-9.5, 10.0, 1.0))
    receiver_height: float = 10.0
    row_length: float = 100.0
    axis_azimuth: float = 0.0
    spread: ImperfectionSpread = field(default_factory=ImperfectionSpread)

    kind = "fresnel"

    def __post_init__(self) -> None:
        _spread_of(self)
        distances = _finite_vector(self.row_distances, "row distances")
        _distinct(distances, "rows", "m from the receiver line")
        _refuse_rows_too_close(distances)
        object.__setattr__(self, "row_distances", tuple(distances.tolist()))
        for name, least in (("receiver_height", MIN_RECEIVER_HEIGHT), ("row_length", MIN_ROW_LENGTH)):
            value = _finite_number(getattr(self, name), name.replace("_", " "), positive=True)
            if value < least:
                raise HybridtrackError(f"fresnel field: {name.replace('_', ' ')} must be at least {least:g} m, "
                                       f"got {value:g}")
            object.__setattr__(self, name, value)
        object.__setattr__(self, "axis_azimuth", _finite_number(self.axis_azimuth, "axis azimuth", bound=360.0))

    @property
    def names(self) -> list[str]:
        return [f"row {i + 1}" for i in range(len(self.row_distances))]

    @property
    def positions(self) -> np.ndarray:
        """Row centres (N, 3), metres east, north, up from the receiver line's middle."""
        return _across_axis(np.asarray(self.row_distances), self.axis_azimuth)

    def collectors(self) -> list[Collector]:
        return [Collector("fresnel", self.axis_azimuth, d, self.receiver_height) for d in self.row_distances]

    def targets(self, altitude, azimuth) -> np.ndarray:
        """Every row's nominal tracking angle (T, N), degrees; NaN at night."""
        alt, az = _sun_columns(altitude, azimuth)
        return fresnel_angle(alt, az, np.asarray(self.row_distances), self.receiver_height, self.axis_azimuth)

    def end_loss(self, altitude, azimuth) -> np.ndarray:
        """Every row's end loss (T, N), metres, positive past the rows' end at `axis_azimuth`
        (see `fresnel_end_loss`); NaN at night."""
        alt, az = _sun_columns(altitude, azimuth)
        return fresnel_end_loss(alt, az, np.asarray(self.row_distances), self.receiver_height, self.axis_azimuth)


@dataclass(frozen=True)
class TroughLoop:
    """A loop of parabolic trough collectors in a line on one horizontal axis.

    Parameters
    ----------
    count : int
        Number of collectors (solar collector assemblies), each with its own drive.
    collector_length : float
        Length of one collector along the axis, metres (their centres are this far apart), at
        least `MIN_COLLECTOR_LENGTH` (1 m).
    axis_azimuth : float
        Azimuth of the axis, degrees from north (0: north-south, 270: east-west).
    spread : ImperfectionSpread
    """

    count: int = 12
    collector_length: float = 150.0
    axis_azimuth: float = 0.0
    spread: ImperfectionSpread = field(default_factory=ImperfectionSpread)

    def __post_init__(self) -> None:
        _spread_of(self)
        whole = isinstance(self.count, (int, np.integer)) and not isinstance(self.count, bool)
        if not whole or not 1 <= self.count <= 100_000:
            raise HybridtrackError(f"trough loop: count must be a whole number from 1 to 100000, got {self.count!r}")
        object.__setattr__(self, "collector_length",
                           _finite_number(self.collector_length, "collector length", positive=True))
        if self.collector_length < MIN_COLLECTOR_LENGTH:
            raise HybridtrackError(f"trough loop: collector length must be at least {MIN_COLLECTOR_LENGTH:g} m (the "
                                   f"collectors stand one length apart: shorter, they would overlap), got "
                                   f"{self.collector_length:g}")
        object.__setattr__(self, "axis_azimuth", _finite_number(self.axis_azimuth, "axis azimuth", bound=360.0))
        if (self.count - 1) * self.collector_length > MAX_DISTANCE:  # each length was bounded, not the line
            raise HybridtrackError(f"trough loop: {self.count} collectors of {self.collector_length:g} m reach "
                                   f"{(self.count - 1) * self.collector_length:g} m along the axis, beyond "
                                   f"{MAX_DISTANCE:g} m")

    @property
    def kind(self) -> str:
        """The loop's collector kind, which names its axis (`hybridtrack.collectors.trough_kind`)."""
        return trough_kind(self.axis_azimuth)

    @property
    def names(self) -> list[str]:
        return [f"SCA {i + 1}" for i in range(self.count)]

    @property
    def positions(self) -> np.ndarray:
        """Collector centres (N, 3) along the axis, the first at the origin."""
        return _along_axis(np.arange(self.count) * self.collector_length, self.axis_azimuth)

    def collectors(self) -> list[Collector]:
        return [Collector(self.kind, self.axis_azimuth)] * self.count

    def targets(self, altitude, azimuth) -> np.ndarray:
        """Every collector's nominal rotation angle (T, N), degrees; NaN at night."""
        alt, az = _sun_columns(altitude, azimuth)  # a writable array of its own, as the other fields' targets
        return np.repeat(trough_angle(alt, az, self.axis_azimuth), self.count, axis=1)


@dataclass(frozen=True, eq=False)
class HeliostatField:
    """Heliostats around a tower, all aiming at one point unless given their own.

    Parameters
    ----------
    positions : array_like, shape (N, 2) or (N, 3), or pandas.DataFrame
        Mirror centres, metres east, north (and up; 0 when left out) from the tower's foot; a
        table's columns ``east``, ``north`` (and ``up``) are taken by name.
    aim : tuple of float, optional
        The receiver's aim point, (east, north, up) metres from the tower's foot; (0, 0, 100)
        when neither it nor `aims` is given. With `aims`, it is their mean (where the map draws
        the receiver).
    aims : array_like, shape (N, 3), or pandas.DataFrame, optional
        One aim point per heliostat, (east, north, up) metres from the tower's foot (aim-point
        strategies spread the flux on the receiver); a table's columns ``aim_east``,
        ``aim_north``, ``aim_up`` (or ``east``, ``north``, ``up``) are taken by name. Refused
        beside `aim`, which one of the two would not be used. None (kept so) when every
        heliostat aims at `aim`.
    spread : ImperfectionSpread
    """

    positions: np.ndarray = field(default_factory=lambda: np.array([[0.0, -100.0], [50.0, -90.0], [-50.0, -90.0]]))
    aim: tuple[float, float, float] | None = None
    aims: np.ndarray | None = None
    spread: ImperfectionSpread = field(default_factory=ImperfectionSpread)

    kind = "heliostat"

    def __post_init__(self) -> None:
        _spread_of(self)
        xyz = _as_numbers(_by_name(self.positions))
        if xyz is not None and xyz.size == 0:  # numbers, but none of them: no field
            raise HybridtrackError("heliostat positions are empty: a field needs at least one mirror")
        if xyz is None or xyz.ndim != 2 or xyz.shape[1] not in (2, 3):
            raise HybridtrackError(f"heliostat positions must be numbers, (N, 2) or (N, 3) metres, got {_brief(self.positions)}")
        if xyz.shape[1] == 2:
            xyz = np.column_stack([xyz, np.zeros(len(xyz))])
        if not np.all(np.isfinite(xyz)):
            raise HybridtrackError(f"heliostat {int(np.flatnonzero(~np.isfinite(xyz).all(1))[0]) + 1}: "
                                   "position is not finite")
        if len(xyz) > MAX_HELIOSTATS:
            raise HybridtrackError(f"a heliostat field has at most {MAX_HELIOSTATS:,} mirrors, got {len(xyz):,}")
        _refuse_far(np.abs(xyz) > MAX_DISTANCE)  # first: the overlap check squares them (1e200 m overflowed)
        _distinct(xyz, "heliostats", "m (east, north, up)")
        _refuse_overlapping(xyz)
        xyz.setflags(write=False)  # a frozen field: a mirror moved in place had escaped every check above
        object.__setattr__(self, "positions", xyz)
        given = _aims_by_name(self.aims)
        if self.aim is not None and self.aims is not None and not _aim_of(self.aim, given):
            raise HybridtrackError("heliostat field: give aim (one point for every heliostat) or aims (one each), "
                                   "not both; a field's aim is its aims' mean, so to give a field new aims with "
                                   "dataclasses.replace, give aim=None beside them")
        if self.aims is None:
            aim = _as_numbers(DEFAULT_AIM if self.aim is None else self.aim)
            if aim is None or aim.shape != (3,):
                raise HybridtrackError(f"heliostat aim must be three numbers (east, north, up), m, got "
                                       f"{_brief(self.aim)}")
            aims = np.broadcast_to(aim, xyz.shape)
        else:
            aims = _as_numbers(given)
        if aims is None or aims.shape != xyz.shape:
            got = f"shape {aims.shape}" if aims is not None else _brief(self.aims)
            raise HybridtrackError(f"heliostat aim points must be one (east, north, up) per heliostat, shape "
                                   f"{xyz.shape}; got {got}")
        _refuse_far(np.abs(aims) > MAX_DISTANCE)
        aim = aims[0] if self.aims is None else aims.mean(axis=0)  # once near: a mean of 1e308s overflows
        relative = aims - xyz
        bad = ~np.isfinite(relative).all(axis=1) | (np.linalg.norm(relative, axis=1) == 0)
        if bad.any():
            raise HybridtrackError(f"heliostat {int(np.flatnonzero(bad)[0]) + 1}: its aim point is not finite or is "
                                   "the mirror itself")
        _refuse_unreachable_aims(relative)
        object.__setattr__(self, "aim", tuple(aim.tolist()))
        # one shared point stays one: `dataclasses.replace` then moves it, or the mirrors, alone
        if self.aims is not None:
            aims = np.array(aims, float)  # its own, read-only as the positions are
            aims.setflags(write=False)
        object.__setattr__(self, "aims", None if self.aims is None else aims)

    def __reduce__(self):
        """Pickled (and copied) by its parameters, built again: its arrays come back read-only, and
        checked, where numpy's own pickle had given them back writable."""
        return type(self), (self.positions, self.aim, self.aims, self.spread)

    @classmethod
    def rings(cls, count: int = 12, *, first_radius: float = 60.0, spacing: float = 12.0,
              aim: tuple[float, float, float] = DEFAULT_AIM, spread: ImperfectionSpread | None = None
              ) -> HeliostatField:
        """`count` heliostats on concentric rings round the tower's foot, `spacing` metres apart
        along and between the rings, every other ring turned by half a place (a radial stagger).
        The last ring's mirrors, fewer than it holds, stand evenly round it (they had filled its
        places from north clockwise: the default dozen stood on an arc east of the tower)."""
        whole = isinstance(count, (int, np.integer)) and not isinstance(count, bool)
        if not whole or not 1 <= count <= MAX_HELIOSTATS:
            raise HybridtrackError(f"heliostat count must be a whole number from 1 to {MAX_HELIOSTATS}, got {count!r}")
        first_radius = _finite_number(first_radius, "first ring radius", positive=True)
        spacing = _finite_number(spacing, "heliostat spacing", positive=True)
        if spacing < MIN_SPACING:
            raise HybridtrackError(f"heliostat spacing must be at least {MIN_SPACING:g} m (heliostats are built from "
                                   f"about 1 m² up: closer, mirrors would overlap), got {spacing:g}")
        placed, ring, left = [], 0, count
        while left > 0:
            radius = first_radius + ring * spacing
            places = min(_ring_places(radius, spacing), left)  # fewer: evenly round, farther apart
            angle = 2 * np.pi * (np.arange(places) + 0.5 * (ring % 2)) / places
            left -= places
            placed.append(np.column_stack([radius * np.sin(angle), radius * np.cos(angle)]))
            ring += 1
        spread = spread if spread is not None else ImperfectionSpread()
        positions = np.round(np.concatenate(placed), 9) + 0.0  # no 1e-15 m east of a mirror due south
        return cls(positions=positions, aim=aim, spread=spread)

    @property
    def names(self) -> list[str]:
        return [f"H{i + 1}" for i in range(len(self.positions))]

    @property
    def aim_points(self) -> np.ndarray:
        """Each heliostat's aim point (N, 3), metres east, north and up from the tower's foot."""
        return np.broadcast_to(np.asarray(self.aim), self.positions.shape) if self.aims is None else self.aims

    @property
    def relative_aims(self) -> np.ndarray:
        """Each aim point from its mirror's centre (N, 3), metres."""
        return self.aim_points - self.positions

    def collectors(self) -> list[Collector]:
        return [Collector("heliostat", aim=tuple(a)) for a in self.relative_aims.tolist()]

    def normals(self, altitude, azimuth) -> np.ndarray:
        """Every mirror's nominal unit normal at every step (T, N, 3); NaN at night."""
        alt, az = _sun_columns(altitude, azimuth)
        up = alt[:, 0] >= 0.0  # at night every normal is NaN: compute the day only
        normals = np.full((len(alt), len(self.positions), 3), np.nan)
        if up.any():
            normals[up] = heliostat_normal(alt[up], az[up], self.relative_aims)
        return normals

    def targets(self, altitude, azimuth) -> np.ndarray:
        """Every mirror's nominal normal azimuth and elevation (T, N, 2), degrees."""
        return np.stack(normal_angles(self.normals(altitude, azimuth)), axis=-1)


def _refuse_far(beyond: np.ndarray) -> None:
    """Refuse the first heliostat with a coordinate (of its position or aim point) `beyond` the limit."""
    far = beyond.any(axis=1)
    if far.any():
        raise HybridtrackError(f"heliostat {int(np.flatnonzero(far)[0]) + 1}: its position or aim point lies "
                               f"beyond {MAX_DISTANCE:g} m")


def _ring_places(radius: float, spacing: float) -> int:
    """The most mirrors a ring of `radius` holds with neighbours' centres `spacing` metres apart
    in a straight line (the chord, ``2 r sin(π / n)``), at least one. Counted along the arc
    (``2 π r / spacing``), a ring of 11.46 m had put mirrors of a 12 m spacing 11.46 m apart, and
    one of 0.95 m at the least spacing, 1 m, had its own mirrors refused as overlapping."""
    if spacing > 2.0 * radius:  # not even two fit across
        return 1
    return max(int(np.pi / np.arcsin(spacing / (2.0 * radius)) + 1e-9), 1)  # 1e-9: a hexagon of 1 m sides is 6


def _by_name(positions):
    """A table's ``east``, ``north`` (and ``up``) columns, by name, as a positions file is read; any
    other positions as they are. A table had been read by its columns' order: an ``id, east,
    north`` table put the mirrors 100 m underground, and a ``north, east`` one mirrored the field.
    Its aim columns (`AIM_COLUMNS`) are refused: they are given as ``aims``."""
    if not isinstance(positions, pd.DataFrame):
        return positions
    names = _named_columns(positions, "heliostat positions")
    wanted = [axis for axis in ("east", "north", "up") if axis in names]
    if wanted[:2] != ["east", "north"]:
        raise HybridtrackError(f"heliostat positions: a table needs columns 'east' and 'north' (and 'up'), m; it has "
                               f"{', '.join(map(str, positions.columns)) or 'none'}")
    aims = [names[column] for column in AIM_COLUMNS if column in names]
    if aims:  # dropped, every mirror had aimed at the default point, not the table's
        raise HybridtrackError(f"heliostat positions: the table's {', '.join(map(str, aims))} are aim points, which "
                               f"positions does not read: give the table without them, and them as "
                               f"aims=table[{list(AIM_COLUMNS)}]")
    table = positions[[names[axis] for axis in wanted]]
    _say_unread(positions, table, "heliostat positions", "east, north, up")
    if all(pd.api.types.is_numeric_dtype(kind) and not pd.api.types.is_bool_dtype(kind) for kind in table.dtypes):
        return table.to_numpy(dtype=float, na_value=np.nan)  # pandas' nullable numbers too; NA is not finite
    return table


def _named_columns(table: pd.DataFrame, what: str) -> dict:
    """A table's columns by their names in lower case without spaces, a name given twice refused:
    the last had been read, so ``east, East`` read the second as east and ``east, north, north``
    the second north as up, without a word."""
    names: dict = {}
    for column in table.columns:
        name = str(column).strip().lower()
        if name in names:
            raise HybridtrackError(f"{what}: the table has the column {name!r} more than once ({names[name]!r}, "
                                   f"{column!r}); keep one")
        names[name] = column
    return names


def _say_unread(table: pd.DataFrame, read: pd.DataFrame, what: str, reads: str) -> None:
    """Warn of a table's columns that are not read (an ``elevation`` beside ``east, north`` put the
    mirrors at 0 m up without a word; the command line names them as ``not read``)."""
    unread = [str(column) for column in table.columns if column not in read.columns]
    if unread:
        warnings.warn(f"{what}: the table's {', '.join(unread)} {'is' if len(unread) == 1 else 'are'} not read "
                      f"({what} reads {reads})", UserWarning, stacklevel=5)


def _aims_by_name(aims):
    """A table of aim points by its columns' names, as `_by_name` reads positions: ``aim_east``,
    ``aim_north``, ``aim_up`` (a positions file's, `AIM_COLUMNS`) or ``east``, ``north``, ``up``.
    A table had been read by its columns' order: ``aim_north, aim_east, aim_up`` swapped every
    aim point's east and north without a word. Any other aims as they are."""
    if not isinstance(aims, pd.DataFrame):
        return aims
    names = _named_columns(aims, "heliostat aim points")
    for wanted in (AIM_COLUMNS, ("east", "north", "up")):
        if all(column in names for column in wanted):
            table = aims[[names[column] for column in wanted]]
            _say_unread(aims, table, "heliostat aim points", ", ".join(wanted))
            if all(pd.api.types.is_numeric_dtype(kind) and not pd.api.types.is_bool_dtype(kind)
                   for kind in table.dtypes):
                return table.to_numpy(dtype=float, na_value=np.nan)
            return table
    raise HybridtrackError(f"heliostat aim points: a table needs columns {', '.join(AIM_COLUMNS)} (or east, north, "
                           f"up), m; it has {', '.join(map(str, aims.columns)) or 'none'}")


def _refuse_unreachable_aims(relative: np.ndarray) -> None:
    """Refuse an aim point a heliostat cannot serve, naming the first such mirror: one not above it
    (a heliostat sends the sun up to its receiver; aimed down, it would catch nothing the field
    counts), or farther along an axis than a collector's aim may lie (`MAX_DISTANCE`). An aim point
    less than `MIN_RECEIVER_HEIGHT` above the mirror is refused as a Fresnel receiver so low is:
    it lies on the mirror, or kilometres were typed for metres (1e-300 m up had run)."""
    below = np.flatnonzero(~(relative[:, 2] >= MIN_RECEIVER_HEIGHT))
    if len(below):
        k = int(below[0])
        raise HybridtrackError(f"heliostat {k + 1}: its aim point is not above the mirror ({relative[k, 2]:g} m up "
                               f"from it, at least {MIN_RECEIVER_HEIGHT:g} m): a heliostat reflects the sun up to "
                               "its receiver")
    far = np.flatnonzero((np.abs(relative) > MAX_DISTANCE).any(axis=1))
    if len(far):
        raise HybridtrackError(f"heliostat {int(far[0]) + 1}: its aim point is more than {MAX_DISTANCE:g} m from "
                               "the mirror along an axis")


def _spread_of(field) -> None:
    """Refuse a spread that is not an `ImperfectionSpread` (it is only used at run time)."""
    if not isinstance(field.spread, ImperfectionSpread):
        raise HybridtrackError(f"{type(field).__name__}: spread must be an ImperfectionSpread, got "
                               f"{type(field.spread).__name__}")


#: The field kinds, by the name the CLI and sweeps use.
FIELD_KINDS = {"fresnel": FresnelField, "trough": TroughLoop, "heliostat": HeliostatField}


@dataclass(repr=False)
class FieldResult:
    """A finished field run.

    Attributes
    ----------
    collectors : pandas.DataFrame
        One row per collector: position (``east``, ``north``, ``up``, metres), its drawn
        imperfections, and its metrics (as in a single run's summary).
    summary : dict
        Field metrics: energy capture of the whole field (each collector weighted by the direct
        light it is offered), pointing error RMS over the field, total moves and travel, the
        worst collector; a Fresnel field adds its end loss.
    events : pandas.DataFrame
        Every collector's mode changes, with a ``collector`` column.
    dataset : xarray.Dataset or None
        The logs, collector × time (`LOG_VARIABLES`; the shared weather over time only);
        None when the run was asked not to keep them.
    """

    collectors: pd.DataFrame
    summary: dict
    events: pd.DataFrame
    dataset: object
    field: object
    site: sites.Site

    def __repr__(self) -> str:
        summary = self.summary
        figures = ", ".join(f"{label} {summary[key]:.4g}" for key, label in
                            (("energy_capture", "energy capture"), ("rms", "RMS error (°)"))
                            if summary.get(key) is not None)
        return (f"<FieldResult: {summary['field']} of {summary['collectors']} at {self.site.name}, "
                f"{summary['strategy']}, "
                f"{summary['steps']:,} steps from {summary['start']}{': ' + figures if figures else ''}>")

    def _repr_html_(self) -> str:
        """The field's figures (as `repr` and the command line give them) above its collector table,
        every text escaped: a site's name is anybody's text, and had been written into the page as
        markup; the figures had not been shown at all."""
        from html import escape

        summary = self.summary
        rows = [(label, summary[key]) for key, label in _SUMMARY_LABELS.items() if key in summary]
        cells = "".join(f"<tr><th style='text-align:left'>{escape(label)}</th>"
                        f"<td style='text-align:left'>{escape(_shown(value))}</td></tr>" for label, value in rows)
        title = (f"<b>{escape(str(summary['field']))}</b> of {summary['collectors']:,} at {escape(self.site.name)}, "
                 f"{escape(str(summary['strategy']))}, {summary['steps']:,} steps from {escape(str(summary['start']))}")
        return (f"<div><p>{title}</p><table>{cells}</table>"
                + self.collectors.to_html(max_rows=20, float_format=lambda v: f"{v:.4g}") + "</div>")

    def plot_map(self, metric: str = "rms"):
        """The field map: every collector at its position, coloured by `metric` (a column of `collectors`).

        Returns a `matplotlib.figure.Figure`.
        """
        from matplotlib.figure import Figure

        if not isinstance(metric, str) or metric not in self.collectors.columns:  # a list raised a TypeError
            raise HybridtrackError(f"no collector metric {metric!r}; choose from {', '.join(self.collectors.columns)}")
        fig = Figure(figsize=(7, 6), layout="constrained")
        ax = fig.add_subplot()
        values = pd.to_numeric(self.collectors[metric], errors="coerce").to_numpy(float)
        segments = _segments(self.field)
        if segments is None:  # heliostats: a marker per mirror
            points = ax.scatter(self.collectors["east"], self.collectors["north"], c=values, cmap="viridis",
                                marker="^", s=max(12.0, 4000.0 / len(values) ** 0.8), edgecolors="0.3",
                                linewidths=0.3)
            ax.margins(0.08)  # the mirrors at the edge drawn whole
        else:  # rows and troughs: a line of their length along their axis
            from matplotlib.collections import LineCollection

            points = LineCollection(segments, array=values, cmap="viridis", linewidths=max(2.0, 60.0 / len(values)))
            ax.add_collection(points)
            ax.autoscale_view()
        fig.colorbar(points, ax=ax, label=_METRIC_LABELS.get(metric, metric))
        if isinstance(self.field, HeliostatField):
            _draw_aim_points(ax, self.field.aim_points)
        if not np.isfinite(values).any():  # a night, or no light: the colours would mean nothing
            ax.text(0.5, 0.5, f"no collector has a {metric}:\nnothing was scored", transform=ax.transAxes,
                    ha="center", va="center", color="0.3")
        ax.set_xlabel("east (m)")
        ax.set_ylabel("north (m)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"{self.summary['field']} at {self.site.name}: {_METRIC_LABELS.get(metric, metric)}")
        return fig

    @staticmethod
    def files(folder, *, log: bool = True) -> dict[str, Path]:
        """The files `save` writes into `folder`, by role (`log`: the logs were kept)."""
        folder = output_folder(folder)
        files = {"collectors": folder / "collectors.csv", "events": folder / "events.csv",
                 "summary": folder / "summary.json", "map": folder / "field_map.png"}
        return {**files, "log": folder / "log.nc"} if log else files

    @removing_empty_folders()
    def save(self, folder, *, metric: str = "rms") -> dict[str, Path]:
        """Write ``collectors.csv``, ``events.csv``, ``summary.json`` (strict JSON), ``field_map.png``
        and, when the logs were kept, ``log.nc`` (netCDF, the `dataset`); see `hybridtrack.outputs`.
        Without the logs, an earlier save's ``log.nc`` is removed, as a file to replace is: left
        there, it would be read as this field's."""
        written = self.files(folder, log=self.dataset is not None)
        earlier = [] if self.dataset is not None else [self.files(folder)["log"]]
        claim(written.values(), earlier=earlier)
        with together():  # all of this field's files, or none
            write(written["collectors"],
                  lambda path: self.collectors.to_csv(path, index_label="collector"))
            write(written["events"], lambda path: self.events.to_csv(path, index=False))
            write(written["summary"], lambda path: path.write_text(strict_json(self.summary, indent=2) + "\n"))
            write(written["map"], lambda path: self.plot_map(metric).savefig(path, dpi=120))
            if self.dataset is not None:
                write(written["log"], lambda path: _netcdf(self.dataset, path))
        remove_earlier(earlier)
        return written


def _netcdf(dataset, path: Path) -> None:
    """`dataset` to netCDF at `path`, with Dask's scheduler pinned to ``synchronous`` for the
    write: its arrays are numpy's, nothing for Dask to compute, but xarray's writer asks Dask's
    global scheduler for a lock, and one set to ``dask.distributed`` with no client open (a
    ``scheduler: distributed`` in dask.yaml or ``DASK_SCHEDULER``, a default client of one's own
    not closed) had made the save fail: 'Requested dask.distributed scheduler but no Client
    active'. The setting is the caller's again after the write."""
    import dask

    with dask.config.set(scheduler="synchronous"):
        dataset.to_netcdf(path, engine="scipy")


#: The field figures `FieldResult` shows, by their summary keys (the command line's table too).
_SUMMARY_LABELS = {"collectors": "collectors", "steps": "steps", "energy_capture": "energy capture (field)",
                   "rms": "pointing error RMS (°, field)", "rms_worst": "worst collector RMS (°)",
                   "rms_worst_collector": "worst collector", "moves": "moves (all collectors)",
                   "travel_deg": "travel (°, all)", "stow_events": "wind stow events", "faults": "faults",
                   "end_loss_share": "end loss (share of the light)", "wind_data": "wind data"}


def _shown(value) -> str:
    """A summary figure as the field's table shows it: '-' for none, 4 significant digits."""
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.4g}"
    return f"{value:,}" if isinstance(value, int) else str(value)


def _segments(field) -> np.ndarray | None:
    """Each row's or trough's ends (N, 2, 2) in (east, north), or None for heliostats."""
    if isinstance(field, HeliostatField):
        return None
    length = field.row_length if isinstance(field, FresnelField) else field.collector_length
    half = 0.5 * length * _along_axis(np.ones(1), field.axis_azimuth)[0, :2]
    centres = field.positions[:, :2]
    return np.stack([centres - half, centres + half], axis=1)


_METRIC_LABELS = {"rms": "pointing error RMS (°)", "p95": "pointing error p95 (°)", "energy_capture": "energy capture",
                  "moves": "moves", "travel_deg": "travel (°)", "end_loss_share": "end loss (share of the row)"}


#: The metrics each collector gets in `FieldResult.collectors` (after its position and imperfections).
COLLECTOR_METRICS = ("rms", "p95", "max", "mean", "within_0_5_deg", "energy_capture", "moves", "travel_deg",
                     "mode_switches", "stow_events", "faults")


def collector_columns(field) -> list[str]:
    """The columns `simulate_field` gives `field`'s collector table (what a field map can show)."""
    columns = ["east", "north", "up"] + _placement_columns(field)
    columns += [f.name for f in dataclasses.fields(Imperfections)] + list(COLLECTOR_METRICS) + ["offered"]
    if isinstance(field, FresnelField):
        columns += ["end_loss_m", "end_loss_share"]
    return columns


def _draw_aim_points(ax, aims: np.ndarray) -> None:
    """Each distinct aim point of a heliostat field as a star (its east and north); their mean had
    been drawn, which is no mirror's aim point when the field has several."""
    distinct = np.unique(aims[:, :2], axis=0)
    label = "aim point" if len(distinct) == 1 else f"aim points ({len(distinct)})"
    ax.plot(distinct[:, 0], distinct[:, 1], marker="*", color="tab:red", markersize=14 if len(distinct) < 10 else 7,
            ls="", label=label)
    ax.legend(loc="best")


def _placement_columns(field) -> list[str]:
    """A collector table's columns after the positions that say where a collector looks: a Fresnel
    row's distance from the receiver line, a heliostat's aim point (so that a saved field's
    ``collectors.csv`` is a positions file that builds the same field again)."""
    if isinstance(field, FresnelField):
        return ["row_distance"]
    return list(AIM_COLUMNS) if isinstance(field, HeliostatField) else []


def _metrics(summary: dict) -> dict:
    error = summary["tracking_error_deg"]
    return {name: error[name] if name in error else summary[name] for name in COLLECTOR_METRICS}


def _weighted(values: pd.Series, weights: pd.Series, *, squared: bool = False) -> float | None:
    ok = values.notna() & (weights > 0)
    if not ok.any():
        return None
    v, w = values[ok].astype(float), weights[ok]
    mean = float(np.sum(w * (v * v if squared else v)) / np.sum(w))
    return round(float(np.sqrt(mean)) if squared else mean, 5)


def _end_loss_terms(collector: Collector, dni: np.ndarray, altitude: np.ndarray,
                    azimuth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What every Fresnel row of one axis shares of its end loss (`_end_loss`): the steps with the
    true sun up and direct light, and at them the end loss per metre of the row's distance to the
    receiver (``f = 1``: `fresnel_end_loss` is ``f`` times a term of the sun and the axis alone)."""
    up = (altitude > 0) & (np.nan_to_num(dni) > 0)
    return up, np.abs(fresnel_end_loss(altitude[up], azimuth[up], 0.0, 1.0, collector.axis))


def _end_loss(collector: Collector, row_length: float, terms: tuple, dni: np.ndarray,
              incidence: np.ndarray) -> dict[str, float]:
    """A Fresnel row's mean end loss (metres) and the share of its light lost past the receiver's
    end, weighted by the direct light on its mirror under the true sun (`incidence`, its own):
    its distance ``f`` to the receiver times the `_end_loss_terms` its field's rows share (a
    20-row field-year's took 0.5 s at the end, on one core, when every row's was computed
    together; 25 ms a row when each row computed the sun's part again)."""
    up, per_metre = terms
    beam = (np.nan_to_num(dni) * incidence)[up]
    total = float(beam.sum())
    if not total > 0:
        return {"end_loss_m": math.nan, "end_loss_share": math.nan}
    f = float(np.hypot(collector.row_distance, collector.receiver_height))
    share = np.minimum(f * per_metre, row_length) / row_length
    return {"end_loss_m": f * float(np.sum(beam * per_metre)) / total,
            "end_loss_share": float(np.sum(beam * share) / total)}


def simulate_field(frame: pd.DataFrame, site, field, *, strategy: str | None = None, config=None,
                   seed: int | None = None, keep_log: bool = True, progress: bool | None = None,
                   threads: int | None = None, workers: int | None = None, scheduler: str | None = None) -> FieldResult:
    """Run the tracker for every collector of a field on the same weather.

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame, as for `hybridtrack.simulate`.
    site : Site or str
    field : FresnelField, TroughLoop or HeliostatField
    strategy : str, optional
        As for `hybridtrack.simulate`.
    config : SimulationConfig, optional
        The run config; its imperfections are the centre of every collector's draw.
    seed : int, optional
        Seeds the imperfection draws and each collector's sensor noise: collector ``i``'s
        draws depend only on `seed` and ``i``; and the sky of the clear day before the run (warm
        start, commissioning), one sky for the whole field as the run's frame is. By default
        the config's seed, as the command line's ``--seed`` defaults to the ``--config`` file's.
    keep_log : bool
        Keep every collector's log in `FieldResult.dataset` (about 50 bytes per collector
        and step, 80 for a heliostat); False keeps only the metrics.
    progress : bool or callable, optional
        A progress bar over collectors (on stderr); by default when there are more than four. A
        callable is called with each count of collectors done instead (as `hybridtrack.simulate`
        calls one with steps).
    threads : int, optional
        Run the collectors on this many threads of this process, sharing one computation of
        the sky they stand under (`hybridtrack.reuse`); by default one per core the process
        may use, fewer where the memory would not hold that many runs at once. The compiled
        kernel runs without Python's lock, so the threads' loops run side by side.
    workers : int, optional
        Run the collectors on a local Dask cluster of this many worker processes
        (`hybridtrack.cluster`) instead, one at a time on each, and no more workers than
        collectors. The result is the same wherever the collectors run: each collector's run
        depends only on its own draws.
    scheduler : str, optional
        Run them on the Dask scheduler at this address instead.

    Returns
    -------
    FieldResult
    """
    from .kernel import COMPILING, compiles_first, decided, uses_kernel
    from .reuse import reuse_work
    from .simulation import (_check_frame, check_progress, checked_config, progress_updates, warn_of_another_site,
                             warn_of_nights_left_out)

    if not isinstance(field, (FresnelField, TroughLoop, HeliostatField)):
        raise HybridtrackError(f"field must be a FresnelField, TroughLoop or HeliostatField, "
                               f"got {type(field).__name__}")
    config = checked_config(config)
    seed = params.seed(config.seed if seed is None else seed)
    if not isinstance(keep_log, (bool, np.bool_)):
        raise HybridtrackError(f"keep_log must be True or False, got {keep_log!r:.60}")
    check_progress(progress)
    check_where(scheduler, workers, threads)  # before the sky is computed
    site = sites.get(site)
    frame = _check_frame(frame)
    warn_of_nights_left_out(frame, site)
    warn_of_another_site(frame, site)
    frame = _without_attrs(frame)
    collectors = field.collectors()
    if workers is not None:  # a worker with no collector to run is a process started for nothing (64 took 2 min)
        workers = min(params.whole(workers, "workers", 1, MAX_WORKERS), len(collectors))
    config = decided(config, len(frame) * len(collectors))  # on the field's scans, not each collector's
    threads = _thread_count(threads, frame, len(collectors), keep_log, dask=workers is not None or scheduler is not None,
                            compiled=uses_kernel(config, len(frame)))
    runs = [(i, name, collector, imperfect) for i, (name, collector, imperfect)
            in enumerate(zip(field.names, collectors, field.spread.draw(config.imperfections, len(collectors), seed, field.names)))]
    rows, events, store = [None] * len(runs), [None] * len(runs), None
    job = dict(site=site, strategy=strategy, config=config, seed=seed, keep_log=keep_log,
               row_length=field.row_length if isinstance(field, FresnelField) else None)
    shown = len(runs) > 4 if progress is None else progress
    if shown is True and compiles_first(config, len(frame)):
        print(COMPILING, file=sys.stderr)
    with progress_updates(shown, lambda: _bar(len(runs))) as update, reuse_work():  # every run shares the sky
        for block in _blocks(frame, runs, job, threads, workers, scheduler):
            for i, row, run_events, log in block:
                rows[i], events[i] = row, run_events
                if keep_log:
                    store = store or _LogStore(field.names, frame, log)
                    store.add(i, log)
                if update is not None:
                    update(1)
    table = _collector_table(rows, field)
    summary = _field_summary(table, field, site, strategy or config.controller.strategy, frame)
    all_events = pd.concat(events, ignore_index=True) if events else pd.DataFrame()
    dataset = store.dataset(table, field, site) if keep_log else None
    return FieldResult(table, summary, all_events, dataset, field, site)


def _without_attrs(frame: pd.DataFrame) -> pd.DataFrame:
    """The weather frame without its `attrs`, its columns not copied: the runs read the weather,
    never its notes, and pandas deep-copies a frame's attrs into every column or result taken
    from it (a synthetic year's weather by day, 365 entries, took some 15 ms a collector)."""
    bare = frame.copy(deep=False)
    bare.attrs = {}
    return bare


def _bar(total: int):
    """A tqdm bar over a field's collectors, on stderr."""
    from .progress import bar

    return bar(total, unit="collector")


def _thread_count(threads: int | None, frame: pd.DataFrame, collectors: int, keep_log: bool, *, dask: bool,
                  compiled: bool = True) -> int:
    """The threads the collectors run on in this process (1 when they go to Dask), checked against
    the memory: each thread holds one run, and a kept log every collector's columns. The default
    takes the most, up to one per core, that fit; one where the runs take the reference loop,
    which holds Python's lock throughout (`compiled` False)."""
    if threads is not None:  # more threads than collectors would have nothing to run, nor hold memory
        threads = min(params.whole(threads, "threads", 1, MAX_WORKERS), collectors)  # Dask beside it: check_where
    first, last = frame.index[0], frame.index[-1]
    step = (last - first) / (len(frame) - 1)
    log = LOG_BYTES * collectors if keep_log else 0
    what = f"a field of {collectors} collectors"
    if threads is None:
        for count in range(min(cores(), collectors), 1, -1) if compiled and not dask else ():
            try:
                check_steps(first, last, step, what=what, bytes_per_step=BYTES_PER_STEP * count + log)
                return count
            except HybridtrackError:
                continue
        threads = 1
    check_steps(first, last, step, what=what + (f" on {threads} threads" if threads > 1 else ""),
                bytes_per_step=BYTES_PER_STEP * threads + log)
    return threads


def _blocks(frame: pd.DataFrame, runs: list, job: dict, threads: int, workers: int | None, scheduler: str | None):
    """Each block of collectors' results as it is done: here, on `threads` threads, one collector
    a task; or on Dask in blocks of up to 16 collectors per task, two tasks per worker (each block
    shares its sky)."""
    if workers is None and scheduler is None:
        yield from _threaded(frame, runs, job, threads)
        return
    from .cluster import close, dask_client, finished, lost

    client, cluster = dask_client(scheduler, workers, what="parallel fields")
    try:
        shared = client.scatter(frame, broadcast=True)
        size = max(1, min(16, len(runs) // (2 * max(len(client.scheduler_info()["workers"]), 1))))
        futures = [client.submit(run_collectors, shared, runs[k:k + size], pure=False, **job)
                   for k in range(0, len(runs), size)]
        for _, done, error in finished(client, futures):
            if error is not None and lost(error):
                raise HybridtrackError(f"a block of the field's collectors was lost on Dask ({type(error).__name__}: "
                                       f"{error}); run the field again") from None
            if error is not None:
                raise error
            yield done
    finally:
        close(client, cluster)


def _threaded(frame: pd.DataFrame, runs: list, job: dict, threads: int):
    """Each collector's result as it is done, on `threads` threads sharing this context's memory
    of the sky (each task runs in a copy of the context, whose memories are the same objects).

    With more than one thread, the first collector's world and plan run side by side on a
    thread of their own (`hybridtrack.simulation.track`): they compute the pieces every later
    run shares (the true sun and the sky on one side, the controller's clock, sun and
    derivatives on the other) at once, where two first runs on two threads had computed one
    side while the other thread waited for it, then the other side the same way. The second
    collector starts beside it and waits for those pieces (`hybridtrack.reuse.shared`); the
    first collector had run alone to its end, its loop and scoring on one core (1.42 s of a
    20-row Fresnel field-year's 7.04 s) with the other idle."""
    if threads == 1:
        for run in runs:
            yield run_collectors(frame, [run], **job)
        return
    from concurrent.futures import ThreadPoolExecutor, as_completed

    with ThreadPoolExecutor(threads, thread_name_prefix="hybridtrack-field") as pool:
        futures = [pool.submit(contextvars.copy_context().run, run_collectors, frame, [run], **job,
                               side_by_side=not k) for k, run in enumerate(runs)]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            for future in futures:  # an error, or the caller stopped: start no more runs
                future.cancel()


def run_collectors(frame: pd.DataFrame, runs: list, *, site, strategy, config, seed: int, keep_log: bool,
                   row_length: float | None = None, side_by_side: bool = False) -> list:
    """Run a block of a field's collectors, each ``(i, name, collector, imperfections)``, and
    return for each ``(i, row, events, log)``: its row of the collector table (a Fresnel row's
    end loss last, for a field of rows `row_length` long), its events and its log's kept
    columns (`LOG_VARIABLES`, as arrays; None unless `keep_log`). The sun and sky
    every run of the block asks for are computed once (`hybridtrack.reuse.reuse_work`). Each run
    keeps to its thread unless `side_by_side`, when its world and plan take a second thread as
    `simulate`'s do."""
    from .metrics import offered_light
    from .reuse import Same, reuse_work, shared
    from .simulation import _scored, one_thread, track

    done = []
    # the field spreads its runs over the cores itself
    with reuse_work(), contextlib.nullcontext() if side_by_side else one_thread():
        for i, name, collector, imperfect in runs:
            run_config = dataclasses.replace(config, imperfections=imperfect,
                                             seed=int(np.random.SeedSequence([seed, i]).generate_state(1)[0]))
            run = track(frame, site, collector=collector, strategy=strategy, config=run_config, fit_columns=keep_log,
                        sky_seed=seed)  # the day before the run under one sky too
            if keep_log:  # the whole result, for its log
                result = _scored(run)
                scores, events, log = result.summary, result.events, _kept(result.log)
            else:  # the scores alone: no log, no sky as the classifier saw it (`Tracked.scores`)
                events = run.events()
                scores, log = run.scores(events), None
            scoring, true_sun = run.scoring(), (Same(frame), run.site, run.config.truth)  # what the keys turn on
            offered = shared(geometry_key(true_sun, "offered energy", collector, aperture=True), lambda: _energy(
                offered_light(run.world.frame_dni, scoring["sun_up"], scoring["incidence"]), frame.index))
            row = {**dataclasses.asdict(imperfect), **_metrics(scores), "offered": offered}
            if row_length is not None:
                terms = shared(geometry_key(true_sun, "end loss terms", collector), lambda: _end_loss_terms(
                    collector, run.world.frame_dni, run.world.altitude, run.world.azimuth))
                row.update(_end_loss(collector, row_length, terms, run.world.frame_dni, scoring["incidence"]))
            done.append((i, row, events.assign(collector=name), log))
    return done


def _energy(light: np.ndarray, index: pd.DatetimeIndex) -> float:
    """kWh/m² of `light` (W/m² at each stamp), each stamp standing for its own step
    (`hybridtrack.times.stamp_minutes`: a gap in the frame is light nobody saw, not light to count)."""
    return float(np.sum(light * stamp_minutes(index))) / 60e3


def _collector_table(rows: list[dict], field) -> pd.DataFrame:
    """The collectors' rows with their positions first (and a Fresnel field's row distances)."""
    table = pd.DataFrame(rows, index=pd.Index(field.names, name="collector"))
    for column in table.columns[table.dtypes == object]:  # a metric no step scored is None: NaN, as a number
        table[column] = table[column].astype(float)
    for i, axis in enumerate(("east", "north", "up")):
        table.insert(i, axis, field.positions[:, i])
    if isinstance(field, FresnelField):
        table.insert(3, "row_distance", field.row_distances)
    if isinstance(field, HeliostatField):
        for i, column in enumerate(AIM_COLUMNS):
            table.insert(3 + i, column, field.aim_points[:, i])
    return table


def _field_summary(table: pd.DataFrame, field, site: sites.Site, strategy: str, frame: pd.DataFrame) -> dict:
    from .simulation import _wind_data

    weight = table["offered"]
    worst = table["rms"].astype(float).idxmax() if table["rms"].notna().any() else None
    summary = {
        "field": type(field).__name__, "kind": field.kind, "site": site.name, "strategy": strategy,
        "collectors": int(len(table)), "steps": int(len(frame)),
        "start": frame.index[0].isoformat(), "end": frame.index[-1].isoformat(),
        "energy_capture": _weighted(table["energy_capture"], weight),
        "rms": _weighted(table["rms"], weight, squared=True),
        "rms_worst_collector": worst, "rms_worst": None if worst is None else round(float(table.at[worst, "rms"]), 5),
        "moves": int(table["moves"].sum()), "travel_deg": round(float(table["travel_deg"].sum()), 3),
        "stow_events": int(table["stow_events"].sum()), "faults": int(table["faults"].sum()),
        # a frame without wind stows all day by default (never a calm): the summary says why
        "wind_data": _wind_data(frame),
    }
    if "end_loss_share" in table:
        summary["end_loss_share"] = _weighted(table["end_loss_share"], weight)
    return summary


def _kept(log: pd.DataFrame) -> dict:
    """The log columns a field keeps per collector (`LOG_VARIABLES`, a heliostat's ``*_azimuth``
    too), as arrays: categories as their codes."""
    kept = [c for c in log.columns if c in LOG_VARIABLES or c.removesuffix("_azimuth") in LOG_VARIABLES]
    return {c: (_values(log[c]), list(log[c].cat.categories) if isinstance(log[c].dtype, pd.CategoricalDtype)
                else None) for c in kept}


class _LogStore:
    """Every collector's kept log columns (collector × time arrays), filled as the runs come in.

    Holding the runs' frames until the end would cost a whole log per collector; the arrays cost
    about 50 bytes per collector and step (80 for a heliostat).
    """

    def __init__(self, names: list[str], frame: pd.DataFrame, first: dict) -> None:
        self.names = names
        self.time = frame.index.tz_convert("UTC").tz_localize(None)
        self.shared = {c: frame[c].to_numpy(float) if c in frame.columns else np.full(len(frame), np.nan)
                       for c in SHARED_VARIABLES}  # the weather every collector's log repeats
        self.attrs, self.arrays = {}, {}
        for column, (values, categories) in first.items():
            self.arrays[column] = np.empty((len(names), len(values)), values.dtype)
            if categories is not None:
                self.attrs[column] = {"flag_values": np.arange(len(categories), dtype=np.int8),
                                      "flag_meanings": " ".join(c.replace(" ", "_") for c in categories)}

    def add(self, i: int, log: dict) -> None:
        for column, array in self.arrays.items():
            array[i] = log[column][0]

    def dataset(self, table: pd.DataFrame, field, site: sites.Site):
        """The logs as an xarray Dataset; categories as codes with CF flag attributes, time in UTC."""
        import xarray as xr

        variables = {c: (("collector", "time"), a, self.attrs.get(c, {}) | _units(c)) for c, a in self.arrays.items()}
        variables.update({c: (("time",), a, _units(c)) for c, a in self.shared.items()})
        places = ["east", "north", "up"] + (list(AIM_COLUMNS) if isinstance(field, HeliostatField) else [])
        coords = {"collector": self.names, "time": self.time,
                  **{place: ("collector", table[place].to_numpy(), {"units": "m"}) for place in places}}
        return xr.Dataset(variables, coords=coords,
                          attrs={"site": site.name, "timezone": site.tz, "field": type(field).__name__,
                                 "time_note": "UTC; the site's clock is in the timezone attribute"})


def _units(variable: str) -> dict:
    unit = UNITS.get(variable.removesuffix("_azimuth"))
    return {"units": unit} if unit else {}


def _values(column: pd.Series) -> np.ndarray:
    if isinstance(column.dtype, pd.CategoricalDtype):
        return column.cat.codes.to_numpy(np.int8)
    if column.dtype == bool:
        return column.to_numpy(np.int8)
    return column.to_numpy(float)
