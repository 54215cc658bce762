"""Plots and summaries a person would rather look at than read."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

__all__ = ["plot_sun_path", "plot_fuzzy_surface", "plot_sky", "plot_run", "plot_compare", "save_figure", "SKY_COLOURS", "MODE_COLOURS"]


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


SKY_COLOURS = {"sunny": "#f6c343", "cloudy": "#9db4c0", "overcast": "#5c6b73", "unknown": "#dddddd"}


def _label_band(ax, times, labels, *, y0: float = 0.0, y1: float = 1.0, colours: dict | None = None) -> None:
    """Shade the time axis by a categorical label (sky class or mode), one colour a label."""
    colours = SKY_COLOURS if colours is None else colours
    import numpy as np

    values = np.asarray(labels, dtype=object)
    if len(values) == 0:
        return
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(values)]])
    step = (times[1] - times[0]) if len(times) > 1 else None
    for a, b in zip(starts, ends):
        right = times[b] if b < len(times) else times[-1] + step if step is not None else times[-1]
        ax.axvspan(times[a], right, ymin=y0, ymax=y1, color=colours.get(values[a], "#cccccc"), lw=0)


def plot_sky(frame: pd.DataFrame, site, *, classifier=None, title: str | None = None):
    """Irradiance, the sensor's readings with the classifier's verdict, and wind, on one time axis.

    Parameters
    ----------
    frame : pandas.DataFrame
        A weather frame with ``intensity_ma`` and ``variation_ma`` (`hybridtrack.sensor.sensor_view`).
    site : Site or str
    classifier : FuzzyWeatherClassifier, optional
        The published one by default.
    """
    from matplotlib.patches import Patch

    from .fuzzy import FuzzyWeatherClassifier
    from .sites import get

    plt = _pyplot()
    site = get(site)
    clf = classifier or FuzzyWeatherClassifier()
    local = frame.index.tz_convert(site.tz).tz_localize(None)
    fig, axes = plt.subplots(4, 1, figsize=(12, 9), sharex=True, height_ratios=[3, 0.35, 2.2, 1.4])
    ax = axes[0]
    for column, colour in (("ghi", "tab:orange"), ("dni", "tab:red"), ("dhi", "tab:blue")):
        ax.plot(local, frame[column], label=column.upper(), color=colour, lw=0.9)
    if "ghi_clear" in frame:
        ax.plot(local, frame["ghi_clear"], label="clear-sky GHI", color="0.4", lw=0.8, ls="--")
    ax.set_ylabel("W/m²")
    ax.legend(loc="upper left", ncols=4, fontsize="small")
    ax.set_title(title or f"{site.name}: {', '.join(f'{d} {w}' for d, w in frame.attrs.get('weather', {}).items())}"
                 [:140])
    band = axes[1]
    predicted = clf.classify(frame["intensity_ma"].to_numpy(), frame["variation_ma"].to_numpy())
    if "sky" in frame:
        _label_band(band, local, frame["sky"].astype(str).to_numpy(), y0=0.5, y1=1.0)
        band.text(1.005, 0.75, "true", transform=band.transAxes, va="center", fontsize="small")
    _label_band(band, local, predicted, y0=0.0, y1=0.5 if "sky" in frame else 1.0)
    band.text(1.005, 0.25, "fuzzy", transform=band.transAxes, va="center", fontsize="small")
    band.set_yticks([])
    band.legend(handles=[Patch(color=c, label=k) for k, c in SKY_COLOURS.items()], loc="upper left",
                bbox_to_anchor=(0, -0.1), ncols=4, fontsize="x-small", frameon=False)
    ax = axes[2]
    ax.plot(local, frame["intensity_ma"], color="tab:purple", lw=0.9, label="photocurrent")
    ax.plot(local, frame["variation_ma"], color="tab:green", lw=0.9, label="variation")
    ax.set_ylabel("mA")
    ax.legend(loc="upper left", fontsize="small")
    ax = axes[3]
    ax.plot(local, frame["wind_speed"], color="tab:gray", lw=0.8)
    ax.axhline(17.2, color="tab:red", ls=":", lw=1)
    ax.text(local[0], 17.6, "stow 17.2 m/s", color="tab:red", fontsize="x-small")
    ax.set_ylabel("wind (m/s)")
    ax.set_xlabel(f"local time ({site.tz})")
    fig.autofmt_xdate()
    fig.tight_layout()
    return fig


MODE_COLOURS = {"sensor": "#2a9d8f", "astronomical": "#e9c46a", "search": "#f4a261", "stow_wind": "#e76f51",
                "stow_night": "#264653", "fault": "#9b2226"}


def plot_run(result, *, title: str | None = None):
    """A run on one time axis: irradiance, sky class, mode, target and actual angle, pointing error."""
    import numpy as np
    from matplotlib.patches import Patch

    plt = _pyplot()
    log = result.log
    local = log.index.tz_convert(result.site.tz).tz_localize(None)
    sun_up = np.isfinite(log["target_true"].to_numpy())
    fig, axes = plt.subplots(5, 1, figsize=(12, 10), sharex=True, height_ratios=[2, 0.3, 0.3, 2.4, 1.8])
    ax = axes[0]
    ax.plot(local, log["dni"], color="tab:red", lw=0.9, label="DNI")
    ax.set_ylabel("W/m²")
    ax.legend(loc="upper left", fontsize="small")
    summary = result.summary
    err = summary["tracking_error_deg"]
    ax.set_title(title or (f"{summary['site']} · {summary['collector']} · {summary['strategy']}: RMS "
                           f"{err['rms'] if err['rms'] is not None else float('nan'):.3f}°, p95 "
                           f"{err['p95'] if err['p95'] is not None else float('nan'):.3f}°, energy "
                           f"{summary['energy_capture'] if summary['energy_capture'] is not None else float('nan'):.1%}"))
    _label_band(axes[1], local, log["sky"].astype(str).to_numpy())
    axes[1].set_yticks([])
    axes[1].set_ylabel("sky", rotation=0, ha="right", va="center")
    bands = axes[2]
    _label_band(bands, local, log["mode"].astype(str).to_numpy(), colours=MODE_COLOURS)
    bands.set_yticks([])
    bands.set_ylabel("mode", rotation=0, ha="right", va="center")
    bands.legend(handles=[Patch(color=c, label=m) for m, c in MODE_COLOURS.items()] +
                 [Patch(color=c, label=f"sky {k}") for k, c in SKY_COLOURS.items() if k != "unknown"],
                 loc="upper left", bbox_to_anchor=(0, -0.2), ncols=8, fontsize="x-small", frameon=False)
    ax = axes[3]
    ax.plot(local, log["target_true"], color="k", lw=0.8, label="true target")
    ax.plot(local, log["angle"], color="tab:blue", lw=0.9, ls="--", label="actual angle")
    ax.set_ylabel("angle (°)" if result.collector.single_axis else "elevation axis (°)")
    ax.legend(loc="upper left", fontsize="small")
    ax = axes[4]
    error = log["error"].where(sun_up & log["mode"].isin(["sensor", "astronomical", "search"]))
    ax.plot(local, error, color="tab:purple", lw=0.7)
    for y in (-0.5, 0.5):
        ax.axhline(y, color="tab:red", ls=":", lw=0.8)
    ax.set_ylabel("pointing error (°)")
    finite = np.abs(error.dropna())
    if len(finite):
        limit = max(1.0, min(float(finite.quantile(0.99)) * 1.3, 10.0))
        ax.set_ylim(-limit if result.collector.single_axis else 0, limit)
    ax.set_xlabel(f"local time ({result.site.tz})")
    fig.autofmt_xdate()
    fig.tight_layout()
    return fig


STRATEGY_COLOURS = {"hybrid": "#2a9d8f", "hybrid-nocal": "#8ab17d", "astronomical": "#e9c46a", "sensor": "#e76f51"}


def plot_compare(results: dict, *, title: str | None = None):
    """Strategies side by side on the same weather: pointing error over time, and the key metrics.

    Parameters
    ----------
    results : dict of str to Result
        One `hybridtrack.simulation.Result` per strategy, all on the same frame.
    """
    import numpy as np

    plt = _pyplot()
    first = next(iter(results.values()))
    local = first.log.index.tz_convert(first.site.tz).tz_localize(None)
    fig = plt.figure(figsize=(12, 9), layout="constrained")
    grid = fig.add_gridspec(4, 3, height_ratios=[1.4, 0.3, 2.6, 1.8])
    ax = fig.add_subplot(grid[0, :])
    ax.plot(local, first.log["dni"], color="tab:red", lw=0.8)
    ax.set_ylabel("DNI (W/m²)")
    band = fig.add_subplot(grid[1, :], sharex=ax)
    _label_band(band, local, first.log["sky"].astype(str).to_numpy())
    band.set_yticks([])
    band.set_ylabel("sky", rotation=0, ha="right", va="center")
    err_ax = fig.add_subplot(grid[2, :], sharex=ax)
    for name, result in results.items():
        log = result.log
        error = log["error"].where(log["mode"].isin(["sensor", "astronomical", "search"]) & (log["dni"] > 0))
        err_ax.plot(local, error, lw=0.8, label=name, color=STRATEGY_COLOURS.get(name))
    for y in (-0.5, 0.5):
        err_ax.axhline(y, color="k", ls=":", lw=0.7)
    err_ax.set_ylim(-2, 2)
    err_ax.set_ylabel("pointing error (°), clipped to ±2")
    err_ax.legend(loc="upper left", ncols=len(results), fontsize="small")
    metrics = (("RMS error (°)", lambda s: s["tracking_error_deg"]["rms"]),
               ("p95 error (°)", lambda s: s["tracking_error_deg"]["p95"]),
               ("energy capture", lambda s: s["energy_capture"]))
    names = list(results)
    for k, (label, pick) in enumerate(metrics):
        bar = fig.add_subplot(grid[3, k])
        values = [pick(results[n].summary) for n in names]
        values = [np.nan if v is None else v for v in values]
        bar.bar(range(len(names)), values, color=[STRATEGY_COLOURS.get(n, "grey") for n in names])
        bar.set_xticks(range(len(names)), names, rotation=20, fontsize="small")
        bar.set_title(label, fontsize="medium")
        for x, v in enumerate(values):
            if np.isfinite(v):
                bar.text(x, v, f"{v:.3f}" if label != "energy capture" else f"{v:.1%}", ha="center", va="bottom",
                         fontsize="x-small")
        if label == "energy capture":
            finite = [v for v in values if np.isfinite(v)]
            if finite:
                bar.set_ylim(max(0.0, min(finite) - 0.05), 1.0)
    summary = first.summary
    fig.suptitle(title or f"{summary['site']} · {summary['collector']} · {summary['start'][:10]}"
                          f"{' to ' + summary['end'][:10] if summary['end'][:10] != summary['start'][:10] else ''}")
    return fig
