"""Units: the common spellings of each quantity's units, and conversion to the frame's units.

The frame holds W/m² (irradiance), m/s (wind), °C (air temperature), mA (photocurrent) and
degrees (the sun sensor's recorded pointing signal).
Spellings are compared after `normalise_unit`: lower case, no spaces, ``²`` and ``^2`` as
``2``, ``m-2`` as ``/m2`` and ``deg``/``°`` dropped before ``c``, ``f`` and ``k``, so
``W/m²``, ``W/m^2``, ``W m-2``, ``Wm-2`` and ``W/m2`` are one unit.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import HybridtrackError

__all__ = ["UNITS", "FRAME_UNITS", "normalise_unit", "known_unit", "looks_like_unit", "spellings",
           "to_frame_units"]

#: Each quantity's unit in a weather frame.
FRAME_UNITS = {"ghi": "W/m²", "dni": "W/m²", "dhi": "W/m²", "wind_speed": "m/s", "temp_air": "°C",
               "photocurrent": "mA", "pointing": "°", "pointing_2": "°"}

#: (scale, offset) taking each normalised spelling to the frame's unit: frame = value * scale + offset.
UNITS = {
    "irradiance": {"w/m2": (1.0, 0.0), "kw/m2": (1000.0, 0.0), "mw/cm2": (10.0, 0.0)},
    "wind_speed": {"m/s": (1.0, 0.0), "ms-1": (1.0, 0.0), "km/h": (1 / 3.6, 0.0), "kmh": (1 / 3.6, 0.0),
                   "kph": (1 / 3.6, 0.0), **dict.fromkeys(("kn", "kt", "kts", "knot", "knots"), (1852 / 3600, 0.0)),
                   "mph": (0.44704, 0.0), "mi/h": (0.44704, 0.0)},
    "temp_air": {"c": (1.0, 0.0), "k": (1.0, -273.15), "f": (5.0 / 9.0, -32.0 * 5.0 / 9.0)},
    "photocurrent": {"ma": (1.0, 0.0), "a": (1000.0, 0.0), "ua": (0.001, 0.0)},
    "angle": {"deg": (1.0, 0.0), "°": (1.0, 0.0), "degrees": (1.0, 0.0), "degree": (1.0, 0.0),
              "mrad": (0.18 / math.pi, 0.0), "rad": (180.0 / math.pi, 0.0), "arcmin": (1 / 60, 0.0),
              "arcsec": (1 / 3600, 0.0)},
}

_QUANTITY = {"ghi": "irradiance", "dni": "irradiance", "dhi": "irradiance", "wind_speed": "wind_speed",
             "temp_air": "temp_air", "photocurrent": "photocurrent", "pointing": "angle", "pointing_2": "angle"}


def normalise_unit(text: str) -> str:
    """``'W m-2'`` -> ``'w/m2'``, ``'Deg C'`` -> ``'c'``, ``'µA'`` -> ``'ua'``."""
    unit = str(text).strip().lower().replace(" ", "").replace("²", "2").replace("^", "").replace("µ", "u")
    unit = unit.replace("º", "°")  # the ordinal sign Spanish and Portuguese keyboards give for a degree
    unit = re.sub(r"^[\[(](.*)[\])]$", r"\1", unit)  # a units row's '[W/m2]', as a header writes it
    unit = unit.replace("·", "").replace("*", "")
    unit = re.sub(r"^(k?w)m-2$", r"\1/m2", unit)
    unit = re.sub(r"^(k?w)/m-2$", r"\1/m2", unit)
    unit = re.sub(r"^(deg(rees?)?|°)_?([cfk])$", r"\3", unit)
    unit = re.sub(r"^(k?m|mi)h-1$", r"\1/h", unit)  # 'km h-1', as SI writes it
    unit = {"kelvin": "k", "celsius": "c", "fahrenheit": "f", "m/sec": "m/s", "mps": "m/s",
            "meters/second": "m/s", "metres/second": "m/s", "km/hr": "km/h"}.get(unit, unit)
    return unit


def known_unit(name: str, text: str) -> bool:
    """Whether `text` is a spelling of a unit of column `name`."""
    return normalise_unit(text) in UNITS[_QUANTITY[name]]


#: The pieces units are written with, lower case: a bracket made of these alone is a unit, known
#: or not (``Wh/m2``, ``km h-1``), never a note (``vent/cor``, ``CMP22``).
_UNIT_PIECES = {"w", "kw", "mw", "wh", "kwh", "mwh", "j", "kj", "mj", "cal", "ly", "m", "km", "mi", "cm", "mm", "ft",
                "s", "sec", "min", "h", "hr", "hour", "d", "day", "kt", "kts", "kn", "knot", "knots", "mph", "kph", "c", "f",
                "k", "°c", "°f", "°", "deg", "degrees", "celsius", "fahrenheit", "kelvin", "a", "ma", "ua", "v", "mv",
                "rad", "mrad", "arcmin", "arcsec", "%"}


def looks_like_unit(text: str) -> bool:
    """Whether `text` is written as a unit (of pieces such as W, Wh, m, km, h, °F), whether or not
    it is one the reader converts: a header's unknown unit must be refused, not kept as a note."""
    pieces = [re.sub(r"(?<=[a-z])-?[1-4]$", "", piece) for piece in  # an exponent: m2, h-1 (not CM21)
              re.split(r"[/\s·*.]+", str(text).strip().lower().replace("º", "°").replace("²", "2").replace("^", ""))]
    pieces = [piece for piece in pieces if piece]
    return bool(pieces) and all(piece in _UNIT_PIECES for piece in pieces)


def spellings(name: str) -> list[str]:
    """The units (as `normalise_unit` writes them) the reader converts for column `name`."""
    return sorted(UNITS[_QUANTITY[name]])


def any_known_unit(text: str) -> bool:
    """Whether `text` is a unit of any quantity (to tell a unit in a header from a note)."""
    unit = normalise_unit(text)
    return any(unit in table for table in UNITS.values())


def to_frame_units(values: np.ndarray, name: str, unit: str | None, where: str) -> tuple[np.ndarray, str | None]:
    """`values` of column `name` in `unit` converted to the frame's unit, and a note if they changed.

    An unknown unit is refused; `where` says where it came from (file and column, or a flag).
    """
    if unit is None or not str(unit).strip():
        return values, None
    table = UNITS[_QUANTITY[name]]
    key = normalise_unit(unit)
    if key not in table:
        raise HybridtrackError(f"{where}: unknown unit {unit!r} for {name}; known: {', '.join(sorted(table))}")
    scale, offset = table[key]
    if scale == 1.0 and offset == 0.0:
        return values, None
    return values * scale + offset, f"{unit} -> {FRAME_UNITS[name]}"
