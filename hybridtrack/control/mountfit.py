"""Fitting the mount from the sensor: what a field does at commissioning.

From scans where the sensor was tracked, the filtered sun angle (encoder coordinates) is set
against the controller's computed sun, and the mount's errors are fitted by least squares:
axis (or pedestal) azimuth and tilt, and each axis's encoder zero, the pedestal and encoder
terms of the pointing-error models of heliostat and trough practice (Stone 1986; Khalsa, Ho &
Andraka 2011). A direction the day's sun path does not excite is not fitted to noise: if the
Jacobian's condition number exceeds `MAX_CONDITION`, the axis tilt and azimuth are frozen at
zero and only the encoder zeros are fitted.

References
----------
Stone, K. W. (1986). Automatic heliostat track alignment method. US Patent 4,564,275.
Khalsa, S. S. S., Ho, C. K. & Andraka, C. E. (2011). An automated method to correct heliostat
tracking errors. SolarPACES 2011. SAND2011-6233C.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..collectors import Collector
from ..errors import HybridtrackError
from ..sites import Site
from ..sun import solar_position
from .config import ControllerConfig
from .plan import MountEstimate

__all__ = ["fit_mount", "MAX_CONDITION"]

#: Above this condition number of the fit's Jacobian, tilt and azimuth are not identifiable.
MAX_CONDITION = 1e4


def _estimate(params: np.ndarray, axes: int, fit_axis: bool) -> MountEstimate:
    if fit_axis:
        return MountEstimate(float(params[0]), float(params[1]), tuple(float(v) for v in params[2:2 + axes]))
    return MountEstimate(0.0, 0.0, tuple(float(v) for v in params[:axes]))


def _residuals(params, axes, fit_axis, altitude, azimuth, collector, observed, circular):
    predicted = _estimate(params, axes, fit_axis).targets(altitude, azimuth, collector)
    difference = predicted - observed
    difference[:, circular] = (difference[:, circular] + 180.0) % 360.0 - 180.0
    return difference.ravel()


def fit_mount(clock: pd.DatetimeIndex, sun_angles: np.ndarray, site: Site, collector: Collector,
              config: ControllerConfig) -> tuple[MountEstimate, float]:
    """The mount that best explains the sensor's sun angles, and the fit's condition number.

    Parameters
    ----------
    clock : pandas.DatetimeIndex
        The controller clock at each scan.
    sun_angles : numpy.ndarray
        (N, axes) filtered sun angles in encoder coordinates, NaN where none was taken.
    site : Site
        The site as the controller knows it.
    collector : Collector
    config : ControllerConfig
        For the sun model.
    """
    from scipy.optimize import least_squares

    observed = np.asarray(sun_angles, float).reshape(len(clock), -1)
    axes = observed.shape[1]
    keep = np.all(np.isfinite(observed), axis=1)
    if keep.sum() < 10:
        raise HybridtrackError(f"commissioning: only {int(keep.sum())} scans with the sensor tracked; "
                               "need a clear day")
    sun = solar_position(clock[keep], site, config.sun_model)
    args = (sun["altitude"].to_numpy(), sun["azimuth"].to_numpy(), collector, observed[keep],
            np.array([axes == 2 and a == 0 for a in range(axes)]))
    full = least_squares(_residuals, np.zeros(2 + axes), args=(axes, True, *args), bounds=(-10.0, 10.0))
    singular = np.linalg.svd(full.jac, compute_uv=False)
    condition = float(singular[0] / max(singular[-1], 1e-300))
    if condition <= MAX_CONDITION:
        return _estimate(full.x, axes, True), condition
    zeros = least_squares(_residuals, np.zeros(axes), args=(axes, False, *args), bounds=(-10.0, 10.0))
    return _estimate(zeros.x, axes, False), condition
