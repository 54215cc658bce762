"""The closure check: do a file's three irradiance components agree with each other?

Global horizontal light is the direct beam on the horizontal plus the diffuse light,
GHI = DNI · cos z + DHI. A recorded file that carries all three can be checked against it
with nothing but the sun's position. The tolerances are the BSRN comparison test's (Long &
Shi 2008; Long & Dutton 2002): the ratio GHI / (DNI · cos z + DHI) within 1 ± 0.08 with the
sun's zenith below 75°, within 1 ± 0.15 between 75° and 93°, judged where that sum exceeds
50 W/m².

A row outside them is counted in the validation report and kept: a pyranometer's cosine error
at low sun or a cloud edge between two instruments' sampling gives a few. When more than
`SHARE` of the judged rows fail, the report gives a warning that names the first such row and
what the ratio says (a dead or shaded pyrheliometer reads DNI near 0, so GHI is well above the
sum; a pyrheliometer that has lost the sun likewise), and strict reading refuses the file.
`SHARE` is a judgement: a well-kept station fails the test on well under 1 % of its rows.
Files with steps longer than `LONGEST_STEP` are not judged.

References
----------
Long, C. N. and Shi, Y. (2008). An automated quality assessment and control algorithm for
surface radiation measurements. The Open Atmospheric Science Journal 2, 23-37.
doi:10.2174/1874282300802010023

Long, C. N. and Dutton, E. G. (2002). BSRN Global Network recommended QC tests, V2.0. Baseline
Surface Radiation Network. hdl:10013/epic.38770.d001
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import HybridtrackError
from .checks import first_lines

__all__ = ["closure_check", "SHARE", "TOLERANCES", "JUDGED_ABOVE", "LONGEST_STEP"]

#: (largest zenith in degrees, tolerance on the ratio) of the BSRN comparison test.
TOLERANCES = ((75.0, 0.08), (93.0, 0.15))
#: W/m²: rows whose DNI · cos z + DHI is at most this are not judged.
JUDGED_ABOVE = 50.0
#: The share of judged rows beyond which the file gets a warning (strict: is refused).
SHARE = 0.05
#: The longest step judged. BSRN's test is for 1-minute data; an average over a longer step is
#: labelled at its start or end, where the sun stands up to a step from the light's middle: half of
#: 5 minutes moves cos z by up to 3 % of itself at 70° zenith, within the test's 8 %.
LONGEST_STEP = pd.Timedelta(minutes=5)


def closure_check(path: Path, frame: pd.DataFrame, apparent_zenith, report: dict, *, strict: bool = False) -> None:
    """Judge GHI against DNI · cos z + DHI on a frame with all three; the result goes into
    ``report["closure"]``. Nothing in the frame is changed."""
    if not {"ghi", "dni", "dhi"} <= set(frame.columns):
        return
    step = pd.Timedelta(report.get("step", "1min"))
    if step > LONGEST_STEP:
        report["closure"] = (f"not judged (steps of {report.get('step')}: the sun moves too far within one for the "
                             "test, made for 1-minute data)")
        return
    zenith = np.asarray(apparent_zenith, float)
    ghi, dni, dhi = (frame[name].to_numpy(float) for name in ("ghi", "dni", "dhi"))
    with np.errstate(invalid="ignore"):
        total = dni * np.cos(np.radians(zenith)) + dhi
        judged = np.isfinite(ghi) & np.isfinite(total) & (total > JUDGED_ABOVE) & (zenith < TOLERANCES[-1][0])
        ratio = np.where(judged, ghi / np.where(judged, total, 1.0), np.nan)
    tolerance = np.select([zenith < limit for limit, _ in TOLERANCES], [t for _, t in TOLERANCES], np.nan)
    failed = judged & (np.abs(ratio - 1.0) > tolerance)
    count, bad = int(judged.sum()), int(failed.sum())
    if not count:
        report["closure"] = "not judged (no daylight row with all three components)"
        return
    if bad <= SHARE * count:
        report["closure"] = (f"GHI = DNI·cos z + DHI within BSRN's tolerance on {1 - bad / count:.1%} of {count:,} "
                             f"daylight rows{_not_within(frame, failed, bad)}")
        return
    first = int(np.flatnonzero(failed)[0])
    line = first_lines(frame, np.arange(len(frame)) == first)
    where = f"line {line[0]}: " if line else f"{frame.index[first]}: "
    median = float(np.nanmedian(ratio[failed]))
    hint = ("GHI is above DNI·cos z + DHI: is the DNI column dead, or its pyrheliometer off the sun?"
            if median > 1.0 else "GHI is below DNI·cos z + DHI: a pyranometer's cosine error at low sun, snow or "
                                 "soiling on it, or DNI in another unit?")
    message = (f"{path}: {where}the components do not add up on {bad / count:.0%} of {count:,} daylight rows "
               f"(GHI / (DNI·cos z + DHI) = {ratio[first]:.2f} here; where they fail, median {median:.2f} at a median "
               f"zenith of {float(np.median(zenith[failed])):.0f}°; BSRN allows ±8 % below 75° zenith): {hint}")
    if strict:
        raise HybridtrackError(message + " (strict)")
    report["closure"] = "WARNING: " + message.split(": ", 1)[1]


def _not_within(frame: pd.DataFrame, failed: np.ndarray, bad: int) -> str:
    """`` (lines 3, 9 and 4 more are not)``: the first file lines of the rows that fail, if any."""
    if not bad:
        return ""
    lines = first_lines(frame, failed)
    if not lines:
        return f" ({bad:,} rows are not)"
    more = bad - len(lines)
    return f" (line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))}" + \
        (f" and {more:,} more" if more else "") + f" {'are' if bad > 1 else 'is'} not)"
