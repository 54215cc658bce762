"""The mount fit in a report: each fitted parameter converging, with its ±1σ band and the truth.

The controller logs its mount fit every scan (`simulate`'s log: ``fit_<name>`` and
``fit_<name>_std``, degrees, named as the world's `Imperfections` fields they estimate; see
`hybridtrack.control.mountfit`). The world's true value is drawn dashed beside each: what the
sensor can show of the mount, which is not always one field of `Imperfections` alone:

* the sensor's mounting bias adds to every encoder zero (the sensor reads the sun at the true
  angle plus the encoder's zero plus its own bias, and no reading can tell the two apart), but a
  heliostat's azimuth zero: its sensor reads across the mirror's face, and its bias there is the
  collimation error, bias / cos(elevation) of azimuth (`collimation_error`);
* a heliostat's pedestal turned about the vertical is an azimuth encoder offset (Stone 1986);
  its two tilts are the world's `axis_tilt_error` (about the east-west line) and
  `axis_roll_error` (about the north-south line). A single axis's roll is an encoder offset.

References
----------
Stone, K. W. (1986). *Automatic heliostat track alignment method*. US Patent 4,564,275.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["FIT_PREFIX", "fitted_parameters", "true_fit_parameters", "draw_mount_fit"]

#: Log columns of the mount fit: ``fit_<name>`` (value) and ``fit_<name>_std`` (1σ), degrees.
FIT_PREFIX = "fit_"


def fitted_parameters(log: pd.DataFrame) -> list[str]:
    """The names of the mount parameters the log holds a fit of (empty without a fit)."""
    return [c[len(FIT_PREFIX):] for c in log.columns
            if c.startswith(FIT_PREFIX) and not c.endswith("_std") and f"{c}_std" in log.columns]


def true_fit_parameters(imperfections, collector) -> dict[str, float]:
    """What each fitted parameter should converge to in the world of `imperfections`, degrees.

    Parameters
    ----------
    imperfections : hybridtrack.world.Imperfections
    collector : hybridtrack.collectors.Collector

    Returns
    -------
    dict
        By the names of `hybridtrack.control.mountfit.parameter_names`.
    """
    zero = imperfections.encoder_offset + imperfections.sensor_bias
    if collector.single_axis:  # a roll about the axis is an encoder offset
        return {"axis_azimuth_error": imperfections.axis_azimuth_error,
                "axis_tilt_error": imperfections.axis_tilt_error,
                "encoder_offset": zero + imperfections.axis_roll_error}
    # a heliostat's sensor is biased across its face, the collimation term, not on its azimuth axis
    return {"axis_tilt_error": imperfections.axis_tilt_error, "axis_roll_error": imperfections.axis_roll_error,
            "encoder_offset_azimuth": imperfections.encoder_offset + imperfections.axis_azimuth_error,
            "encoder_offset": zero, "collimation_error": imperfections.sensor_bias}


def draw_mount_fit(ax, x, fit: pd.DataFrame, truth: dict[str, float] | None = None) -> None:
    """Draw each fitted parameter of `fit` (columns as in the log) against `x` on `ax`.

    One colour per parameter: the fit as a line, its ±1σ as a band, the true value (from
    `truth`, where given) as a dashed line.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    x : array-like
        Positions of `fit`'s rows.
    fit : pandas.DataFrame
        ``fit_<name>`` and ``fit_<name>_std`` columns.
    truth : dict, optional
        True values by parameter name (`true_fit_parameters`).
    """
    x = np.asarray(x)
    for k, name in enumerate(fitted_parameters(fit)):
        colour = f"C{k}"
        value = fit[FIT_PREFIX + name].to_numpy(float)
        std = fit[f"{FIT_PREFIX}{name}_std"].to_numpy(float)
        ax.fill_between(x, value - std, value + std, color=colour, alpha=0.2, linewidth=0)
        ax.plot(x, value, color=colour, lw=1.0, label=name, gid=f"fit:{name}")
        if truth is not None and name in truth:
            ax.axhline(truth[name], color=colour, ls="--", lw=0.9, gid=f"truth:{name}")
    ax.set_ylabel("mount fit (°)\n±1σ; dashed: true")
    ax.legend(loc="upper left", fontsize="x-small", ncol=4)
    ax.grid(axis="y", alpha=0.3)
