"""Named sites and user-defined ones.

The built-in sites are the ones the published hybrid-tracking work was done at
(see ``docs/physics.md`` §1): Lanzhou and Nanjing, which every feature serves, plus
Kunming (linear Fresnel end loss) and a Delingha-type tower site (heliostats).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from .errors import HybridtrackError
from .times import check_tz

__all__ = ["Site", "get", "names", "custom", "check_place", "BUILTIN", "SAME_PLACE", "builtin_here"]


@dataclass(frozen=True)
class Site:
    """A place on the Earth with the clock its controller keeps.

    Parameters
    ----------
    name : str
        Short name, used in logs and reports.
    latitude : float
        Degrees, north positive, within [-90, 90].
    longitude : float
        Degrees, east positive, within [-180, 180].
    altitude : float
        Metres above sea level.
    tz : str
        IANA time-zone name of the local clock, e.g. ``"Asia/Shanghai"``.
    """

    name: str
    latitude: float
    longitude: float
    altitude: float = 0.0
    tz: str = "UTC"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise HybridtrackError(f"a site's name must be a non-empty text, got {self.name!r:.60}")
        names = {field: f"site {self.name!r}: {field}" for field in _RANGES}
        # a zone object (ZoneInfo, pytz) is kept by its name: a Site's zone is written into files
        object.__setattr__(self, "tz", check_place(self.latitude, self.longitude, self.altitude, self.tz,
                                                   {**names, "tz": f"site {self.name!r}: "}))
        for field in ("latitude", "longitude", "altitude"):  # within range: floats (np.float32 is no JSON)
            object.__setattr__(self, field, float(getattr(self, field)))


#: Where on earth a site may be: each coordinate's range and its unit (as the messages write it).
_RANGES = {"latitude": (-90.0, 90.0, "", "degrees"), "longitude": (-180.0, 180.0, "", "degrees"),
           "altitude": (-500.0, 9000.0, " m", "m")}


def check_place(latitude, longitude, altitude, tz, names: dict) -> str:
    """Refuse coordinates that are no place on earth, or a zone that is none; return the zone's name.

    Each refusal names what was wrong by ``names[field]`` (``latitude``, ``longitude``,
    ``altitude``; ``tz`` is a prefix): a site's ``site 'x': latitude``, the command line's ``--lat``.
    """
    coordinates = {"latitude": latitude, "longitude": longitude, "altitude": altitude}
    for field, value in coordinates.items():  # numpy's scalars are numbers too; True is not a latitude
        if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)) or value != value:
            raise HybridtrackError(f"{names[field]} must be a number, got {value!r:.60}")
    for field, value in coordinates.items():
        low, high, unit, units = _RANGES[field]
        if not low <= value <= high:
            raise HybridtrackError(f"{names[field]} {_brief(value)}{unit} is outside [{low:g}, {high:g}] {units}")
    return check_tz(tz, names["tz"])


def _brief(value) -> str:
    """`value` as written, cut short (an integer of 400 digits is a latitude too)."""
    text = repr(value)
    return text if len(text) <= 24 else f"{text[:20]}… ({len(text)} characters)"


BUILTIN: dict[str, Site] = {
    site.name: site
    for site in (
        Site("lanzhou", 36.1055556, 103.726389, 1520.0, "Asia/Shanghai"),
        Site("nanjing", 31.453, 118.4629, 20.0, "Asia/Shanghai"),
        Site("kunming", 25.0 + 1.0 / 60.0, 102.7, 1890.0, "Asia/Shanghai"),
        Site("delingha", 37.352317, 97.803267, 2980.0, "Asia/Shanghai"),
    )
}


#: Degrees: two sites are one place when both coordinates agree within this (a built-in site
#: passed as a `Site` of another name): 0.1° is some 10 km.
SAME_PLACE = 0.1


def builtin_here(name: str, site: Site) -> Site | None:
    """The built-in site named `name` (any case, spaces trimmed) if `site` stands where it does
    (within `SAME_PLACE`), else None: a custom site that borrows a built-in's name elsewhere is
    not that place."""
    known = BUILTIN.get(name.strip().lower())
    if known is not None and abs(known.latitude - site.latitude) <= SAME_PLACE \
            and abs((known.longitude - site.longitude + 180.0) % 360.0 - 180.0) <= SAME_PLACE:
        return known
    return None


def names() -> list[str]:
    """Return the names of the built-in sites."""
    return sorted(BUILTIN)


def get(name: str | Site) -> Site:
    """Return a built-in site by name (case-insensitive); a `Site` is passed through.

    Raises
    ------
    HybridtrackError
        If the name is not a built-in site; the message lists the known names.
    """
    if isinstance(name, Site):
        return name
    key = str(name).strip().lower()
    if key not in BUILTIN:
        raise HybridtrackError(f"unknown site {name!r}; known sites: {', '.join(names())}")
    return BUILTIN[key]


def custom(latitude: float, longitude: float, tz: str, altitude: float = 0.0, name: str = "custom") -> Site:
    """Return a site given by its coordinates, validated like the built-in ones."""
    return Site(name, latitude, longitude, altitude, tz)
