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

__all__ = ["Site", "get", "names", "custom", "BUILTIN"]


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
        for field in ("latitude", "longitude", "altitude"):
            value = getattr(self, field)  # numpy's scalars are numbers too; True is not a latitude
            if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)) or value != value:
                raise HybridtrackError(f"site {self.name!r}: {field} must be a number, got {value!r:.60}")
        if not -90.0 <= self.latitude <= 90.0:
            raise HybridtrackError(
                f"site {self.name!r}: latitude {_brief(self.latitude)} is outside [-90, 90] degrees"
            )
        if not -180.0 <= self.longitude <= 180.0:
            raise HybridtrackError(
                f"site {self.name!r}: longitude {_brief(self.longitude)} is outside [-180, 180] degrees"
            )
        if not -500.0 <= self.altitude <= 9000.0:
            raise HybridtrackError(
                f"site {self.name!r}: altitude {_brief(self.altitude)} m is outside [-500, 9000] m"
            )
        # a zone object (ZoneInfo, pytz) is kept by its name: a Site's zone is written into files
        object.__setattr__(self, "tz", check_tz(self.tz, f"site {self.name!r}: "))
        for field in ("latitude", "longitude", "altitude"):  # within range: floats (np.float32 is no JSON)
            object.__setattr__(self, field, float(getattr(self, field)))


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
