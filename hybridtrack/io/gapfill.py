"""Gap-filling physics: a missing irradiance component from the others and the sun's position.

All three use pvlib's own functions, each with the zenith pvlib documents for it, which is the
true (geometric, not refraction-corrected) zenith for every one of them:

* **closure** (two components known): ``GHI = DHI + DNI cos(z)``, through
  `pvlib.irradiance.complete_irradiance` (DNI through `pvlib.irradiance.dni`, which leaves
  NaN where the sun is within 2° of the horizon or the difference is negative);
* **Erbs** (GHI alone): the diffuse fraction from the clearness index, `pvlib.irradiance.erbs`;
* **DIRINT** (GHI alone): `pvlib.irradiance.dirint`, DISC with the clearness index's
  variability, DHI then by closure.

Rows where the model gives no value (the sun down or near the horizon) are filled with 0 W/m²
and counted. The source of each column goes into ``attrs`` (``dni_source`` ...).

References
----------
Erbs, D. G., Klein, S. A. & Duffie, J. A. (1982). Estimation of the diffuse radiation fraction
for hourly, daily and monthly-average global radiation. Solar Energy 28(4), 293-302.
doi:10.1016/0038-092X(82)90302-4

Perez, R., Ineichen, P., Maxwell, E., Seals, R. & Zelenka, A. (1992). Dynamic global-to-direct
irradiance conversion models. ASHRAE Transactions 98(1), 354-369.

Holmgren, W. F., Hansen, C. W. & Mikofski, M. A. (2018). pvlib python: a python package for
modeling solar energy systems. Journal of Open Source Software 3(29), 884. doi:10.21105/joss.00884
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .checks import check_derived
from .columns import IRRADIANCE

__all__ = ["DECOMPOSITIONS", "fill_components"]

DECOMPOSITIONS = ("erbs", "dirint")


def _closure(frame: pd.DataFrame, zenith: pd.Series, missing: str) -> pd.Series:
    import pvlib

    given = {name: frame[name] for name in IRRADIANCE if name != missing}
    return pvlib.irradiance.complete_irradiance(zenith, **given)[missing]


def _decompose(ghi: pd.Series, zenith: pd.Series, method: str) -> tuple[pd.Series, pd.Series]:
    import pvlib

    if method == "erbs":
        parts = pvlib.irradiance.erbs(ghi, zenith, ghi.index)
        return parts["dni"], parts["dhi"]
    dni = pvlib.irradiance.dirint(ghi, zenith, ghi.index)
    cos_z = np.clip(np.cos(np.radians(zenith)), 0.0, None)
    return dni, ghi - dni.fillna(0.0) * cos_z


def _store(path: Path, frame: pd.DataFrame, name: str, values: pd.Series, source: str, attrs: dict,
           report: dict) -> None:
    values = pd.Series(np.asarray(values, float), index=frame.index)
    empty = values.isna() & frame[[c for c in IRRADIANCE if c in frame]].notna().all(axis=1)
    frame[name] = values.where(~empty, 0.0).clip(lower=0.0)
    attrs[f"{name}_source"] = source
    report.setdefault("filled", {})[name] = {"count": int(len(frame)), "how": source,
                                             "zero_where_undefined": int(empty.sum())}
    check_derived(path, frame, name, report)


def fill_components(path: Path, frame: pd.DataFrame, site, decomposition: str, attrs: dict,
                    report: dict) -> pd.DataFrame:
    """`frame` with GHI, DNI and DHI all present, the missing ones derived (see the module's notes).

    Needs the site for the sun's position; a file with neither GHI nor two components is
    refused.

    Parameters
    ----------
    path : Path
        The file, for messages.
    frame : pandas.DataFrame
        A weather frame with one or two of ``ghi``, ``dni``, ``dhi`` (W/m²).
    site : Site or None
    decomposition : {"erbs", "dirint"}
        The model for GHI alone.
    attrs, report : dict
        Get ``{name}_source`` and the ``filled`` counts.

    Returns
    -------
    pandas.DataFrame

    References
    ----------
    Erbs, Klein & Duffie (1982), Solar Energy 28(4) 293-302, doi:10.1016/0038-092X(82)90302-4;
    Perez, Ineichen, Maxwell, Seals & Zelenka (1992), ASHRAE Transactions 98(1) 354-369 (DIRINT);
    Holmgren, Hansen & Mikofski (2018), JOSS 3(29) 884, doi:10.21105/joss.00884 (pvlib).
    """
    if not isinstance(decomposition, str) or decomposition not in DECOMPOSITIONS:  # pd.NA, an array: TypeError
        raise HybridtrackError(f"unknown decomposition {decomposition!r}; choose 'erbs' or 'dirint'")
    present = [name for name in IRRADIANCE if name in frame]
    for name in present:
        attrs[f"{name}_source"] = "measured"
    if len(present) in (0, 3):
        return frame
    missing = [name for name in IRRADIANCE if name not in present]
    if site is None:
        raise HybridtrackError(f"{path}: {', '.join(missing)} missing; deriving it needs the sun's position, so give "
                               "a site (site=..., --site or --lat/--lon)")
    if present not in (["ghi"], ["ghi", "dni"], ["ghi", "dhi"], ["dni", "dhi"]):
        raise HybridtrackError(f"{path}: only {', '.join(present)} given; need GHI, or two of GHI, DNI, DHI")
    from ..sun import solar_position

    zenith = solar_position(frame.index, site)["zenith"]  # true zenith, as pvlib documents for each
    frame = frame.copy()
    if len(present) == 2:
        _store(path, frame, missing[0], _closure(frame, zenith, missing[0]), f"closure with {' and '.join(present)} "
               "(pvlib.irradiance.complete_irradiance, true zenith)", attrs, report)
        return frame
    dni, dhi = _decompose(frame["ghi"], zenith, decomposition)
    how = f"{decomposition} decomposition of GHI (pvlib.irradiance.{decomposition}, true zenith)"
    _store(path, frame, "dni", dni, how, attrs, report)
    _store(path, frame, "dhi", dhi, how, attrs, report)
    return frame
