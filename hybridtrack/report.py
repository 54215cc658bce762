"""Plots and summaries a person would rather look at than read."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["plot_sun_path", "save_figure"]


def _pyplot():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path) -> Path:
    """Write a figure to `path` (PNG, SVG or PDF by suffix), creating folders, and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    _pyplot().close(fig)
    return path


def plot_sun_path(position: pd.DataFrame, angles: pd.DataFrame, *, title: str = ""):
    """Sun altitude/azimuth and the collector's target angles over a day, on one time axis.

    Parameters
    ----------
    position : pandas.DataFrame
        From `hybridtrack.sun.solar_position`.
    angles : pandas.DataFrame
        From `hybridtrack.collectors.Collector.angles`.
    """
    plt = _pyplot()
    panels = 3 if "rate" in angles else 2
    fig, axes = plt.subplots(panels, 1, figsize=(10, 2.6 * panels + 0.6), sharex=True)
    local = position.index.tz_localize(None)
    ax = axes[0]
    ax.plot(local, position["altitude"], label="altitude", color="tab:orange")
    ax.set_ylabel("altitude (°)")
    ax.axhline(0, color="0.6", lw=0.8)
    twin = ax.twinx()
    twin.plot(local, position["azimuth"], label="azimuth", color="tab:blue", ls="--")
    twin.set_ylabel("azimuth from north (°)")
    ax.legend(loc="upper left")
    twin.legend(loc="upper right")
    ax = axes[1]
    for column in angles.columns.drop(["rate"], errors="ignore"):
        ax.plot(local, angles[column], label=column)
    ax.set_ylabel("target")
    ax.legend(loc="best", fontsize="small", ncols=2)
    if panels == 3:
        axes[2].plot(local, angles["rate"], color="tab:red")
        axes[2].set_ylabel("rate (°/min)")
    axes[-1].set_xlabel(f"local time ({position.index.tz})")
    fig.suptitle(title)
    fig.autofmt_xdate()
    return fig
