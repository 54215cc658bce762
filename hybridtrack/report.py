"""Plots and summaries a person would rather look at than read."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["plot_sun_path", "plot_fuzzy_surface", "save_figure"]


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


def plot_fuzzy_surface(classifier, *, points: int = 121, title: str | None = None):
    """Decision surface and membership functions of a fuzzy weather classifier.

    Left: the crisp score over the two normalised inputs, with the label bands as filled
    colour levels and their edges drawn; grey where no rule fires. Right: each input's terms
    and the output terms with the bands shaded, like MATLAB's surface and membership viewers.

    Parameters
    ----------
    classifier : hybridtrack.fuzzy.FuzzyWeatherClassifier
    points : int
        Grid points along each input.
    """
    import numpy as np

    from .fuzzy.engine import sample_term

    plt = _pyplot()
    config = classifier.config
    (a, b), out = config.inputs, config.output
    x = np.linspace(*a.universe, points)
    y = np.linspace(*b.universe, points)
    gx, gy = np.meshgrid(x, y)
    score = classifier.score(gx.ravel(), gy.ravel(), raw=False).reshape(gx.shape)

    fig = plt.figure(figsize=(13, 6.5), layout="constrained")
    grid = fig.add_gridspec(3, 2, width_ratios=[1.25, 1])
    ax = fig.add_subplot(grid[:, 0])
    edges = [band[1] for band in config.bands] + [config.bands[-1][2]]
    colours = plt.get_cmap("RdYlBu_r")(np.linspace(0.1, 0.9, len(config.bands)))
    ax.set_facecolor("0.8")
    fill = ax.contourf(gx, gy, score, levels=np.linspace(out.universe[0], out.universe[1], 31), cmap="RdYlBu_r")
    lines = ax.contour(gx, gy, score, levels=edges[1:-1], colors="k", linewidths=1.2)
    ax.clabel(lines, fmt="%g")
    for (name, lo, hi), colour in zip(config.bands, colours):
        inside = (score >= lo) & (score <= hi)
        if inside.any():
            ax.text(gx[inside].mean(), gy[inside].mean(), name, ha="center", va="center", fontsize=12,
                    weight="bold", bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none"})
    fig.colorbar(fill, ax=ax, label=f"{out.name} score")
    ax.set_xlabel(f"{a.name} (normalised; {a.raw_range[0]:g}-{a.raw_range[1]:g} {a.unit})")
    ax.set_ylabel(f"{b.name} (normalised; {b.raw_range[0]:g}-{b.raw_range[1]:g} {b.unit})")
    ax.set_title("decision surface (grey: no rule fires)")

    for row, var in enumerate((a, b, out)):
        axm = fig.add_subplot(grid[row, 1])
        u = np.linspace(*var.universe, 601)
        for term in var.terms:
            axm.plot(u, sample_term(term, u), label=term.name)
        if var is out:
            for (name, lo, hi), colour in zip(config.bands, colours):
                axm.axvspan(lo, hi, color=colour, alpha=0.15)
        axm.set_ylim(-0.02, 1.05)
        axm.set_ylabel("membership")
        axm.set_title(var.name, fontsize="medium")
        axm.legend(fontsize="small", ncols=len(var.terms), loc="upper center")
    fig.suptitle(title or f"fuzzy weather classifier: {config.name} ({len(config.rules)} rules)")
    return fig
