"""Plots and summaries a person would rather look at than read.

Every picture is a `matplotlib.figure.Figure` made with the object API: nothing here imports
pyplot or touches the global backend, so a notebook's own ``plt.plot`` cells keep working after
the project's plots. A returned Figure shows in Jupyter once pyplot's inline backend is loaded,
and `save_figure` writes it to a file.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .errors import HybridtrackError
from .mountreport import FIT_PREFIX, draw_mount_fit, fitted_parameters, true_fit_parameters

__all__ = ["plot_sun_path", "plot_fuzzy_surface", "plot_sky", "plot_run", "plot_days", "plot_compare", "plot_rules",
           "Comparison",
           "plot_tuning", "plot_confusion", "save_figure", "figure", "ReportFigure", "describe", "describe_html",
           "daily", "explain_step", "StepExplanation", "mode_colours", "SKY_COLOURS", "MODE_COLOURS"]


class ReportFigure(Figure):
    """A `matplotlib.figure.Figure` that shows itself in Jupyter as a PNG, whatever the backend.

    A Figure made without pyplot has no display hook until pyplot's inline backend has been
    loaded; this one renders itself, so ``result.plot()`` shows in the first cell too.
    """

    def _repr_png_(self) -> bytes:
        from io import BytesIO

        buffer = BytesIO()
        self.savefig(buffer, format="png", dpi=100, bbox_inches="tight")
        return buffer.getvalue()


def figure(**options) -> ReportFigure:
    """A new Figure, not registered with pyplot (so nothing global changes)."""
    return ReportFigure(**options)


def save_figure(fig, path) -> Path:
    """Write a figure to `path` (PNG, SVG or PDF by suffix), creating folders.

    The image is drawn in memory and then written, so a failed write (a full disk) is an error
    naming `path`, never a silently empty file."""
    import io

    from .outputs import claim, output_path, removing_empty_folders, write

    path = output_path(path)
    kind = path.suffix.lstrip(".").lower() or "png"
    if kind not in fig.canvas.get_supported_filetypes():
        raise HybridtrackError(f"{path}: cannot draw a .{kind} image; name a .png, .svg or .pdf file")
    with removing_empty_folders():  # a drawing or a write that fails leaves no folder it made
        path, = claim([path])
        image = io.BytesIO()
        fig.savefig(image, format=kind, dpi=120, bbox_inches="tight")
        write(path, lambda target: target.write_bytes(image.getvalue()))
    return path


#: Columns of `Collector.angles` in metres, drawn on their own axis (never beside degrees).
LENGTH_COLUMNS = ("end_loss", "jack_1", "jack_2", "jack_3")


def _continuous_azimuth(azimuth):
    """Azimuths without the jump across north (0/360°), e.g. a southern-hemisphere noon.

    Returns the values and whether they were unwrapped.
    """
    values = np.asarray(azimuth, float)
    finite = np.isfinite(values)
    if finite.sum() < 2 or not (np.abs(np.diff(values[finite])) > 180).any():
        return values, False
    out = values.copy()
    out[finite] = np.rad2deg(np.unwrap(np.deg2rad(values[finite])))
    out -= 360.0 * np.round(np.nanmedian(out) / 360.0)  # centred on north: negative is west of it
    return out, True


def plot_sun_path(position: pd.DataFrame, angles: pd.DataFrame, *, title: str = ""):
    """Sun altitude/azimuth and the collector's target angles over a day, on one time axis.

    Degrees and metres never share an axis: lengths (a Fresnel row's end loss, a heliostat's jack
    heights) get their own panel. An azimuth that crosses north is drawn continuously (past 360°
    or below 0°) and says so.

    Parameters
    ----------
    position : pandas.DataFrame
        From `hybridtrack.sun.solar_position`.
    angles : pandas.DataFrame
        From `hybridtrack.collectors.Collector.angles`.
    """
    degrees = [c for c in angles.columns if c not in LENGTH_COLUMNS and c != "rate"]
    lengths = [c for c in angles.columns if c in LENGTH_COLUMNS]
    panels = 2 + ("rate" in angles) + bool(lengths)
    fig = figure(figsize=(10, 2.6 * panels + 0.6), layout="constrained")
    axes = fig.subplots(panels, 1, sharex=True)
    local = position.index.tz_localize(None)
    ax = axes[0]
    ax.plot(local, position["altitude"], label="altitude", color="tab:orange")
    ax.set_ylabel("altitude (°)")
    ax.axhline(0, color="0.6", lw=0.8)
    twin = ax.twinx()
    azimuth, unwrapped = _continuous_azimuth(position["azimuth"])
    twin.plot(local, azimuth, label="azimuth" + (" (continuous across north)" if unwrapped else ""),
              color="tab:blue", ls="--")
    twin.set_ylabel("azimuth from north (°)")
    ax.legend(loc="upper left")
    twin.legend(loc="upper right")
    ax = axes[1]
    for column in degrees:
        values, turned = _continuous_azimuth(angles[column]) if "azimuth" in column else (angles[column], False)
        ax.plot(local, values, label=column + (" (continuous)" if turned else ""))
    ax.set_ylabel("target (°)")
    ax.legend(loc="best", fontsize="small", ncols=2)
    row = 2
    if "rate" in angles:
        axes[row].plot(local, angles["rate"], color="tab:red")
        axes[row].set_ylabel("rate (°/min)")
        row += 1
    if lengths:
        for column in lengths:
            axes[row].plot(local, angles[column], label=column)
        axes[row].set_ylabel("length (m)")
        axes[row].legend(loc="best", fontsize="small", ncols=len(lengths))
    axes[-1].set_xlabel(f"local time ({position.index.tz})")
    fig.suptitle(title)
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
    from .fuzzy.engine import sample_term

    from matplotlib import colormaps

    config = classifier.config
    (a, b), out = config.inputs, config.output
    x = np.linspace(*a.universe, points)
    y = np.linspace(*b.universe, points)
    gx, gy = np.meshgrid(x, y)
    score = classifier.score(gx.ravel(), gy.ravel(), raw=False).reshape(gx.shape)

    fig = figure(figsize=(13, 6.5), layout="constrained")
    grid = fig.add_gridspec(3, 2, width_ratios=[1.25, 1])
    ax = fig.add_subplot(grid[:, 0])
    edges = [band[1] for band in config.bands] + [config.bands[-1][2]]
    colours = colormaps["RdYlBu_r"](np.linspace(0.1, 0.9, len(config.bands)))
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


#: One colour per sky class, ``night`` (true sun down) included; none repeats a mode's colour.
SKY_COLOURS = {"sunny": "#ffd60a", "cloudy": "#8ecae6", "overcast": "#6c757d", "unknown": "#ced4da",
               "night": "#0d1b2a"}
#: How a stretch without data is drawn: hatched white, never a sky or a mode.
NO_DATA = {"facecolor": "white", "hatch": "////", "edgecolor": "#adb5bd", "label": "no data"}
_MODE_PRESET = {"stow_night": "#4a4e69", "stow_wind": "#d62828", "astronomical": "#7b2cbf", "sensor": "#2a9d8f",
                "search": "#f77f00", "fault": "#000000"}
_SPARE_COLOURS = ("#ff006e", "#8ac926", "#00b4d8", "#b5838d", "#9c6644", "#e9c46a")
#: The colours of the modes known when this module was written; plots use `mode_colours()`.
MODE_COLOURS = dict(_MODE_PRESET)


def mode_colours() -> dict[str, str]:
    """A distinct colour for every mode in `hybridtrack.control.MODES` (read when called)."""
    from .control import MODES

    spare = iter(_SPARE_COLOURS)
    return {mode: _MODE_PRESET.get(mode) or next(spare, "#888888") for mode in MODES}


def _step(index: pd.DatetimeIndex) -> pd.Timedelta:
    """The regular step of an index (its median spacing)."""
    return pd.Timedelta(pd.Series(index).diff().median()) if len(index) > 1 else pd.Timedelta(minutes=1)


def _gaps(index: pd.DatetimeIndex) -> list[tuple[int, int]]:
    """(last step before, first step after) of every gap longer than one and a half steps."""
    if len(index) < 2:
        return []
    spacing = np.diff(index.to_numpy(dtype="datetime64[ns]").astype("int64"))  # ns, whatever the index's unit
    return [(int(i), int(i) + 1) for i in np.flatnonzero(spacing > 1.5 * _step(index).value)]


def _broken(x, y, gaps):
    """`x`, `y` with a NaN after each gap's first side, so a line is not drawn across it."""
    if not gaps:
        return x, np.asarray(y, float)
    cut = [g[1] for g in gaps]
    xs = np.insert(np.asarray(x, dtype="datetime64[ns]"), cut, np.asarray(x, dtype="datetime64[ns]")[cut])
    return xs, np.insert(np.asarray(y, float), cut, np.nan)


def _label_band(ax, times, labels, *, y0: float = 0.0, y1: float = 1.0, colours: dict | None = None,
                step=None) -> None:
    """Shade the time axis by a categorical label (sky class or mode), one colour a label.

    A run of one label ends at the next step or one step after its last, whichever is
    earlier, so a gap in the data stays unshaded.
    """
    colours = SKY_COLOURS if colours is None else colours
    values = np.asarray(labels, dtype=object)
    if len(values) == 0:
        return
    step = step if step is not None else (times[1] - times[0] if len(times) > 1 else pd.Timedelta(minutes=1))
    change = np.flatnonzero(values[1:] != values[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(values)]])
    for first, stop in zip(starts, ends):
        for a, b in _contiguous(times, first, stop, step):
            ax.axvspan(times[a], min(times[b - 1] + step, times[b]) if b < len(times) else times[b - 1] + step,
                       ymin=y0, ymax=y1, color=colours.get(values[first], "#cccccc"), lw=0)


def _contiguous(times, first: int, stop: int, step):
    """Split steps ``first:stop`` where the spacing exceeds one and a half steps."""
    t = np.asarray(times[first:stop])
    if np.issubdtype(t.dtype, np.datetime64):
        spacing, limit = np.diff(t.astype("datetime64[ns]")).astype("int64"), 1.5 * pd.Timedelta(step).value
    else:
        spacing, limit = np.diff(t.astype(float)), 1.5 * float(step)
    cuts = [first, *(first + 1 + np.flatnonzero(spacing > limit)), stop]
    return list(zip(cuts[:-1], cuts[1:]))


def _shade_gaps(ax, local, gaps) -> None:
    for a, b in gaps:
        ax.axvspan(local[a], local[b], **{k: v for k, v in NO_DATA.items() if k != "label"}, lw=0)


def _legend(ax, colours: dict, title: str, *, extra=()) -> None:
    """A legend of every band colour, beside the axis."""
    from matplotlib.patches import Patch

    handles = [Patch(color=c, label=k) for k, c in colours.items()] + list(extra)
    ax.legend(handles=handles, title=title, loc="center left", bbox_to_anchor=(1.005, 0.5), fontsize="x-small",
              title_fontsize="x-small", frameon=False, ncols=2 if len(handles) > 4 else 1)


def _no_data_patch():
    from matplotlib.patches import Patch

    return Patch(**NO_DATA)


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

    site = get(site)
    clf = classifier or FuzzyWeatherClassifier()
    local = frame.index.tz_convert(site.tz).tz_localize(None)
    fig = figure(figsize=(12, 9))
    axes = fig.subplots(4, 1, sharex=True, height_ratios=[3, 0.35, 2.2, 1.4])
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
    if "ghi_clear" in frame:  # night is night, not a sky class
        predicted = np.where(frame["ghi_clear"].to_numpy() > 0, predicted, "night")
    if "sky" in frame:
        true_sky = frame["sky"].astype(str).to_numpy()
        if "ghi_clear" in frame:
            true_sky = np.where(frame["ghi_clear"].to_numpy() > 0, true_sky, "night")
        _label_band(band, local, true_sky, y0=0.5, y1=1.0)
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


STRATEGY_COLOURS = {"hybrid": "#2a9d8f", "hybrid-nocal": "#8ab17d", "astronomical": "#e9c46a", "sensor": "#e76f51"}


def plot_compare(results: dict, *, title: str | None = None):
    """Strategies side by side on the same weather: pointing error over time, and the key metrics.

    Parameters
    ----------
    results : dict of str to Result
        One `hybridtrack.simulation.Result` per strategy, all on the same frame.
    """
    first = next(iter(results.values()))
    local = first.log.index.tz_convert(first.site.tz).tz_localize(None)
    fig = figure(figsize=(12, 9), layout="constrained")
    grid = fig.add_gridspec(4, 3, height_ratios=[1.4, 0.3, 2.6, 1.8])
    ax = fig.add_subplot(grid[0, :])
    ax.plot(local, first.log["dni"], color="tab:red", lw=0.8)
    ax.set_ylabel("DNI (W/m²)")
    band = fig.add_subplot(grid[1, :], sharex=ax)
    sun_up = np.isfinite(first.log["target_true"].to_numpy())
    _label_band(band, local, first.log["sky"].astype(str).where(sun_up, "night").to_numpy())
    band.set_yticks([])
    band.set_ylabel("sky", rotation=0, ha="right", va="center")
    _legend(band, SKY_COLOURS, "sky")
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


# --- a run at a glance: text, HTML, daily table, pictures at any length ---------------------


def run_title(result, *, day=None) -> str:
    """``site · collector · strategy · first day to last day``."""
    local = result.log.index.tz_convert(result.site.tz)
    first, last = (local[0].date(), local[-1].date()) if day is None else (day, day)
    span = f"{first}" if first == last else f"{first} to {last}"
    return f"{result.site.name} · {result.collector.kind} · {result.summary['strategy']} · {span}"


def _headline(summary: dict) -> list[tuple[str, str]]:
    err = summary["tracking_error_deg"]

    def fmt(value, spec):
        return "-" if value is None else format(value, spec)

    return [("pointing error (DNI-weighted)", f"RMS {fmt(err['rms'], '.3f')}°, p95 {fmt(err['p95'], '.3f')}°, "
                                              f"max {fmt(err['max'], '.3f')}°"),
            ("within 0.5°", fmt(summary["within_0_5_deg"], ".1%")),
            ("energy capture", fmt(summary["energy_capture"], ".1%")),
            ("drive", f"{summary['moves']:,} moves, {summary['travel_deg']:,.0f}° travelled"),
            ("events", f"{summary['mode_switches']} mode switches ({summary.get('tracking_switches', '-')} between "
                       f"tracking modes), {summary['stow_events']} wind stows, {summary['faults']} faults, "
                       f"{summary['alarms']} alarms")]


def _shares(shares: dict) -> str:
    return ", ".join(f"{k} {v:.1%}" for k, v in sorted(shares.items(), key=lambda kv: -kv[1]) if v > 0)


def _span(result) -> str:
    local = result.log.index.tz_convert(result.site.tz)
    return (f"{local[0]:%Y-%m-%d %H:%M} to {local[-1]:%Y-%m-%d %H:%M} ({result.site.tz}), {len(local):,} steps of "
            f"{_step(local.tz_convert('UTC')).total_seconds() / 60:g} min")


def describe(result, *, events: int = 3) -> str:
    """A short text summary of a run (the repr of `hybridtrack.simulation.Result`)."""
    s = result.summary
    lines = [f"hybridtrack run: {run_title(result)}", f"  {_span(result)}"]
    lines += [f"  {label}: {value}" for label, value in _headline(s)]
    lines += [f"  modes: {_shares(s['mode_share'])}", f"  sky: {_shares(s['sky_share'])} (every step)"]
    if len(result.events) and events:
        lines.append(f"  last {min(events, len(result.events))} of {len(result.events)} events:")
        for row in result.events.tail(events).itertuples(index=False):
            lines.append(f"    {row[0].tz_convert(result.site.tz):%Y-%m-%d %H:%M} {row[1]} -> {row[2]} ({row[3]})")
    return "\n".join(lines)


def describe_html(result, *, events: int = 12) -> str:
    """The run summary as HTML, for Jupyter (the `_repr_html_` of a Result)."""
    from html import escape

    s = result.summary
    rows = [("run", run_title(result)), ("span", _span(result)), *_headline(s),
            ("mode shares", _shares(s["mode_share"])), ("sky shares (every step)", _shares(s["sky_share"]))]
    table = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th><td style='text-align:left'>{escape(v)}</td></tr>"
                    for k, v in rows)
    shown = result.events.head(events)
    if len(shown):  # an empty frame's time column is not datetime-like
        shown = shown.assign(time=[f"{t.tz_convert(result.site.tz):%Y-%m-%d %H:%M}" for t in shown["time"]])
    more = len(result.events) - len(shown)
    event_html = shown.to_html(index=False, border=0) if len(shown) else "<p>no events</p>"
    return (f"<div><strong>hybridtrack run</strong><table>{table}</table>"
            f"<details><summary>{len(result.events)} events</summary>{event_html}"
            f"{f'<p>… {more} more in result.events</p>' if more > 0 else ''}</details></div>")


def true_sun_terms(result, index=None) -> tuple[np.ndarray, np.ndarray]:
    """Sun-up flags and the incidence cosine on a perfect aperture at each stamp of `index` (the
    run's log by default), as the run scored them: taken from its `Result.scoring` where it has
    them, else computed from its true sun as it appears (`hybridtrack.world.true_sun`); a second
    SPA over every stamp had been run for each daily table and trade-off."""
    from .mounting import incidence_cosine
    from .world import true_sun

    index = result.log.index if index is None else index
    scoring = getattr(result, "scoring", None)
    if scoring is not None:
        at = result.log.index.get_indexer(index)
        if (at >= 0).all():
            return np.asarray(scoring["sun_up"])[at], np.asarray(scoring["incidence"])[at]
    altitude, azimuth = true_sun(index, result.site, result.config.truth)
    return altitude > 0, incidence_cosine(altitude, azimuth, result.collector)


def daily(result, log: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per local day of a run (or of part of its `log`), by the run summary's definitions.

    See `hybridtrack.metrics.daily` for the columns.
    """
    from .metrics import daily as daily_table

    log = result.log if log is None else log
    if not isinstance(log, pd.DataFrame) or not isinstance(log.index, pd.DatetimeIndex):
        raise HybridtrackError(f"daily: log must be part of the run's log, a DataFrame on its time index; got "
                               f"{type(log).__name__}")
    sun_up, incidence = true_sun_terms(result, log.index)
    return daily_table(log, collector=result.collector.kind, tz=result.site.tz, sun_up=sun_up, incidence=incidence)


def plot_run(result, *, day=None, title: str | None = None):
    """A run as one Figure: a timeline for up to three days (or one `day`), else an overview.

    The timeline shows DNI, sky class (night as night), mode, target and actual angle, pointing
    error (clipped and marked as clipped) and wind with its stow threshold, with gaps in the data
    hatched. The overview of a longer run shows pointing error, mode and sky by hour and day,
    the energy capture of each day and each day's highest wind against the stow threshold.
    A run whose controller fits its mount adds the fit converging: each parameter with its ±1σ
    band and the world's true value dashed (`hybridtrack.mountreport`), by step on the
    timeline and as it stood at each day's end on the overview.
    """
    log = result.log
    if day is not None:
        local = log.index.tz_convert(result.site.tz)
        wanted = _moment(day, "day", "a date such as '2021-06-21'").date()
        mask = local.date == wanted
        if not mask.any():
            from .errors import HybridtrackError

            raise HybridtrackError(f"the run has no step on {wanted}; it runs {local[0].date()} to {local[-1].date()}")
        day_row = daily(result, log[mask]).iloc[0]
        heading = title or (f"{run_title(result, day=wanted)}\n" + ", ".join(
            text for text, value in ((f"RMS {day_row['rms']:.3f}°", day_row["rms"]),
                                     (f"p95 {day_row['p95']:.3f}°", day_row["p95"]),
                                     (f"energy {day_row['energy_capture']:.1%}", day_row["energy_capture"]))
            if pd.notna(value)))
        return _plot_timeline(result, log[mask], heading)
    days = (log.index[-1] - log.index[0]) / pd.Timedelta(days=1)
    if days <= 3:
        return _plot_timeline(result, log, title or run_title(result))
    return _plot_overview(result, title or run_title(result))


def _metrics_line(summary: dict) -> str:
    err = summary["tracking_error_deg"]
    parts = [f"RMS {err['rms']:.3f}°" if err["rms"] is not None else "no tracking error scored",
             f"p95 {err['p95']:.3f}°" if err["p95"] is not None else "",
             f"energy {summary['energy_capture']:.1%}" if summary["energy_capture"] is not None else ""]
    return ", ".join(p for p in parts if p)


def _error_limit(error) -> float:

    finite = np.abs(error[np.isfinite(error)])
    return float(max(1.0, min(np.quantile(finite, 0.99) * 1.3, 10.0))) if finite.size else 1.0


def _draw_clipped(ax, x, error, limit: float, *, signed: bool) -> None:
    """Plot an error series clipped to ±`limit`, with the clipped steps marked and counted."""
    over = np.isfinite(error) & (np.abs(error) > limit)
    ax.set_ylim(-limit * 1.08 if signed else 0, limit * 1.08)
    if over.any():
        xs = np.asarray(x)[over]
        ax.scatter(xs, np.sign(error[over]) * limit if signed else np.full(over.sum(), limit), marker="^", s=14,
                   color="tab:red", zorder=3)
        worst = np.nanmax(np.abs(error))
        ax.text(0.995, 0.96, f"clipped at ±{limit:g}°: {int(over.sum())} steps beyond (max {worst:.2f}°)",
                transform=ax.transAxes, ha="right", va="top", fontsize="x-small", color="tab:red",
                bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"})


def _plot_timeline(result, log: pd.DataFrame, title: str):

    from .metrics import TRACKING_MODES

    tz = result.site.tz
    local = log.index.tz_convert(tz).tz_localize(None)
    gaps = _gaps(log.index)
    step = _step(log.index)
    sun_up = np.isfinite(log["target_true"].to_numpy())
    fitted = bool(fitted_parameters(log))
    fig = figure(figsize=(13, 12.6 if fitted else 11), layout="constrained")
    axes = fig.subplots(6 + fitted, 1, sharex=True, height_ratios=[1.6, 0.35, 0.35, 2.2, 1.8, 1.2] + [1.6] * fitted)
    ax = axes[0]
    ax.plot(*_broken(local, log["dni"], gaps), color="tab:red", lw=0.9, label="DNI")
    ax.set_ylabel("DNI (W/m²)")
    ax.set_title(f"{title}\n{_metrics_line(result.summary)}" if len(log) == len(result.log) else title)
    sky = log["sky"].astype(str).where(sun_up, "night").to_numpy()
    _label_band(axes[1], local, sky, step=step)
    _legend(axes[1], SKY_COLOURS, "sky", extra=[_no_data_patch()] if gaps else ())
    modes = mode_colours()
    _label_band(axes[2], local, log["mode"].astype(str).to_numpy(), colours=modes, step=step)
    _legend(axes[2], modes, "mode")
    for band, name in ((axes[1], "sky"), (axes[2], "mode")):
        band.set_yticks([])
        band.set_ylabel(name, rotation=0, ha="right", va="center")
    ax = axes[3]
    ax.plot(*_broken(local, log["target_true"], gaps), color="k", lw=0.8, label="true target")
    ax.plot(*_broken(local, log["angle"], gaps), color="tab:blue", lw=0.9, ls="--", label="actual angle")
    ax.set_ylabel("angle (°)" if result.collector.single_axis else "elevation axis (°)")
    ax.legend(loc="upper left", fontsize="small")
    ax = axes[4]
    error = log["error"].where(sun_up & log["mode"].isin(TRACKING_MODES)).to_numpy(float)
    limit = _error_limit(error)
    ax.plot(*_broken(local, np.clip(error, -limit, limit), gaps), color="tab:purple", lw=0.7)
    _draw_clipped(ax, local, error, limit, signed=result.collector.single_axis)
    for y in (-0.5, 0.5):
        ax.axhline(y, color="tab:red", ls=":", lw=0.8)
    ax.set_ylabel("pointing error (°)\nwhile tracking")
    ax = axes[5]
    controller = result.config.controller
    ax.plot(*_broken(local, log["wind_speed"], gaps), color="tab:gray", lw=0.8)
    ax.axhline(controller.wind_stow, color="tab:red", ls="--", lw=1)
    ax.axhline(controller.wind_release, color="tab:green", ls=":", lw=1)
    ax.text(1.005, controller.wind_stow, f"stow > {controller.wind_stow:g}", transform=ax.get_yaxis_transform(),
            color="tab:red", fontsize="x-small", va="center")
    ax.text(1.005, controller.wind_release, f"release ≤ {controller.wind_release:g}",
            transform=ax.get_yaxis_transform(), color="tab:green", fontsize="x-small", va="center")
    ax.set_ylabel("wind (m/s)")
    wind = log["wind_speed"].to_numpy(float)
    ax.set_ylim(0, max(controller.wind_stow * 1.15, float(np.max(wind[np.isfinite(wind)], initial=0)) * 1.05))
    if fitted:
        draw_mount_fit(axes[6], local, log, true_fit_parameters(result.config.imperfections, result.collector))
    for ax in axes:
        _shade_gaps(ax, local, gaps)
    axes[-1].set_xlabel(f"local time ({tz})")
    return fig


class _DayAxis:
    """The x axis of an overview: calendar days, or only the days with data when most are missing.

    A run over a few scattered days (four typical days of a year) would be slivers on a calendar
    axis, so then each day with data gets one column and the gaps between are marked instead.
    """

    def __init__(self, index: pd.DatetimeIndex, tz):

        local = index.tz_convert(tz)
        dates = pd.DatetimeIndex(local.normalize().tz_localize(None))
        self.present = pd.DatetimeIndex(sorted(set(dates)))
        span = (self.present[-1] - self.present[0]).days + 1
        self.compact = len(self.present) < 0.8 * span
        if self.compact:
            self.day = np.searchsorted(self.present.to_numpy(dtype="datetime64[ns]"),
                                       dates.to_numpy(dtype="datetime64[ns]"))
            self.days = len(self.present)
        else:
            self.day = np.asarray((dates - self.present[0]).days, int)
            self.days = span
        minute = np.asarray(local.hour * 60 + local.minute + local.second / 60.0)
        self.minute = minute

    def slots(self, bins: int):

        return np.minimum((self.minute * bins / 1440.0).astype(int), bins - 1)

    def extent(self) -> list[float]:
        from matplotlib.dates import date2num

        if self.compact:
            return [0.0, float(self.days), 0.0, 24.0]
        return [date2num(self.present[0]), date2num(self.present[0] + pd.Timedelta(days=self.days)), 0.0, 24.0]

    def centres(self, dates) -> list[float]:
        """x of the middle of each of `dates` (the daily table's index)."""
        from matplotlib.dates import date2num

        stamps = pd.DatetimeIndex(pd.Index(dates).astype(str))
        if self.compact:
            return [float(i) + 0.5 for i in self.present.get_indexer(stamps)]
        return list(date2num(stamps + pd.Timedelta(hours=12)))

    def decorate(self, axes) -> None:
        """Date ticks on the last axis; in compact mode a marked gap between days that are not adjacent."""
        from matplotlib.dates import AutoDateLocator, ConciseDateFormatter

        extent = self.extent()
        axes[-1].set_xlim(extent[0], extent[1])
        if not self.compact:
            locator = AutoDateLocator()
            axes[-1].xaxis.set_major_locator(locator)
            axes[-1].xaxis.set_major_formatter(ConciseDateFormatter(locator))
            return
        step = max(1, self.days // 16)
        axes[-1].set_xticks([i + 0.5 for i in range(0, self.days, step)],
                            [f"{d:%Y-%m-%d}" for d in self.present[::step]], rotation=30, ha="right")
        for i in range(1, self.days):
            missing = (self.present[i] - self.present[i - 1]).days - 1
            if missing:
                for ax in axes:
                    ax.axvline(i, color="white", lw=3)
                    ax.axvline(i, color="tab:red", lw=1, ls=(0, (2, 2)))
                axes[0].text(i, 24.3, f"{missing} days without data", ha="center", va="bottom", fontsize="x-small",
                             color="tab:red")


def _category_grid(day, slot, shape, codes, count: int):
    """The most frequent category of each (time-of-day, day) cell; -1 where there is no step."""
    counts = np.zeros((*shape, count), int)
    np.add.at(counts, (slot, day, codes), 1)
    grid = counts.argmax(axis=2)
    grid[counts.sum(axis=2) == 0] = -1
    return grid


def _rgb(grid, colours: list[str]):
    """RGBA image of a category grid; cells without data (-1) are transparent, so the hatch shows."""
    from matplotlib.colors import to_rgba

    palette = np.array([to_rgba(c) for c in colours] + [(1.0, 1.0, 1.0, 0.0)])
    return palette[grid]  # -1 (no data) picks the transparent colour at the end


def _hatch_background(ax, extent) -> None:
    """Hatch the whole axis behind its images: whatever no image covers reads as no data."""
    from matplotlib.patches import Rectangle

    x0, x1, y0, y1 = extent
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, zorder=0, lw=0,
                           **{k: v for k, v in NO_DATA.items() if k != "label"}))


def _plot_overview(result, title: str):
    from matplotlib import colormaps

    from .metrics import TRACKING_MODES

    log = result.log
    tz = result.site.tz
    table = daily(result)
    step_minutes = max(_step(log.index).total_seconds() / 60.0, 1.0)
    bins = int(min(144, 1440 / step_minutes))  # 10-minute cells, or the step if coarser
    days = _DayAxis(log.index, tz)
    day, slot, shape = days.day, days.slots(bins), (bins, days.days)
    sun_up = np.isfinite(log["target_true"].to_numpy())
    extent = days.extent()

    fitted = bool(fitted_parameters(log))
    fig = figure(figsize=(13, 14.6 if fitted else 13), layout="constrained")
    axes = fig.subplots(5 + fitted, 1, sharex=True, height_ratios=[2.2, 1.6, 1.6, 1.2, 1.0] + [1.6] * fitted)
    fig.suptitle(f"{title}\n{_metrics_line(result.summary)}")

    # pointing error by hour and day, over a background of night / not tracking / no data
    sky_names = list(SKY_COLOURS)
    sky_codes = np.array([sky_names.index(v) for v in log["sky"].astype(str).where(sun_up, "night")])
    sky_grid = _category_grid(day, slot, shape, sky_codes, len(sky_names))
    background = np.where(sky_grid == sky_names.index("night"), 0, np.where(sky_grid < 0, -1, 1))
    ax = axes[0]
    _hatch_background(ax, extent)
    ax.imshow(_rgb(background, [SKY_COLOURS["night"], "#e9ecef"]), aspect="auto", origin="lower", extent=extent,
              interpolation="nearest", zorder=1)
    tracking = (log["mode"].isin(TRACKING_MODES).to_numpy() & sun_up & (log["dni"].to_numpy() > 0)
                & np.isfinite(log["error"].to_numpy()))
    total = np.zeros(shape)
    count = np.zeros(shape)
    np.add.at(total, (slot[tracking], day[tracking]), np.abs(log["error"].to_numpy()[tracking]))
    np.add.at(count, (slot[tracking], day[tracking]), 1)
    mean_error = np.ma.masked_invalid(np.where(count > 0, total / np.maximum(count, 1), np.nan))
    limit = float(np.quantile(mean_error.compressed(), 0.99)) if mean_error.count() else 1.0
    image = ax.imshow(mean_error, aspect="auto", origin="lower", extent=extent, cmap=colormaps["viridis"],
                      vmin=0, vmax=max(limit, 0.05), interpolation="nearest", zorder=2)
    bar = fig.colorbar(image, ax=ax, extend="max" if mean_error.max() > limit else "neither", pad=0.01)
    clipped = f"clipped at {limit:.2f}° (arrow)" if mean_error.max() > limit else ""
    bar.set_label(f"mean |error| (°)\n{clipped}",
                  fontsize="small")
    ax.set_ylabel("pointing error\nhour of day")
    _legend_strip(ax, {"night": SKY_COLOURS["night"], "not tracking": "#e9ecef"}, gaps=bool((background < 0).any()))

    # mode and sky by hour and day
    modes = mode_colours()
    names = list(modes)
    mode_codes = np.array([names.index(m) for m in log["mode"].astype(str)])
    for ax, grid, colours, label in ((axes[1], _category_grid(day, slot, shape, mode_codes, len(names)), modes, "mode"),
                                     (axes[2], sky_grid, SKY_COLOURS, "sky")):
        _hatch_background(ax, extent)
        ax.imshow(_rgb(grid, list(colours.values())), aspect="auto", origin="lower", extent=extent,
                  interpolation="nearest", zorder=1)
        ax.set_ylabel(f"{label}\nhour of day")
        _legend(ax, colours, label, extra=[_no_data_patch()] if (grid < 0).any() else ())
    for ax in axes[:3]:
        ax.set_yticks([0, 6, 12, 18, 24])

    # energy capture per day, and each day's highest wind
    centres = days.centres(table.index)
    ax = axes[3]
    capture = table["energy_capture"].to_numpy(float)
    width = 0.8 if len(centres) <= 31 else 1.0  # touching bars for long runs: gaps between them would flicker
    ax.bar(centres, np.nan_to_num(capture), width=width, color="tab:orange", linewidth=0)
    low = max(0.0, float(np.nanmin(capture)) - 0.05) if np.isfinite(capture).any() else 0.0
    ax.set_ylim(low, 1.0)
    if low > 0:
        ax.text(0.005, 0.04, f"axis starts at {low:.0%}", transform=ax.transAxes, fontsize="x-small", color="0.3")
    ax.set_ylabel("energy capture\nper day")
    ax = axes[4]
    controller = result.config.controller
    ax.bar(centres, table["max_wind"].to_numpy(float), width=width, color="tab:gray", linewidth=0)
    ax.axhline(controller.wind_stow, color="tab:red", ls="--", lw=1)
    ax.text(1.005, controller.wind_stow, f"stow > {controller.wind_stow:g} m/s", transform=ax.get_yaxis_transform(),
            color="tab:red", fontsize="x-small", va="center")
    ax.set_ylabel("highest wind\nper day (m/s)")
    if fitted:  # each day's fit as it stood at the day's end
        at_end = log.filter(like=FIT_PREFIX).groupby(log.index.tz_convert(tz).date).last()
        draw_mount_fit(axes[5], days.centres(at_end.index), at_end,
                       true_fit_parameters(result.config.imperfections, result.collector))
    days.decorate(axes)
    axes[-1].set_xlabel(f"local date ({tz})" + (", days with data only" if days.compact else ""))
    return fig


def _legend_strip(ax, colours: dict, *, gaps: bool) -> None:
    from matplotlib.patches import Patch

    handles = [Patch(color=c, label=k) for k, c in colours.items()] + ([_no_data_patch()] if gaps else [])
    ax.legend(handles=handles, loc="upper left", fontsize="x-small", ncols=len(handles), framealpha=0.9)


def plot_days(result, *, days: int = 14):
    """One row per day (up to `days`): pointing error over a band of the mode, hours aligned."""
    from .metrics import TRACKING_MODES

    log = result.log
    local = log.index.tz_convert(result.site.tz)
    dates = sorted(set(local.date))[:days]
    modes = mode_colours()
    fig = figure(figsize=(13, 1.3 * len(dates) + 1.2), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(dates), 1, sharex=True, sharey=True))
    limit = 1.0
    for ax, date in zip(axes, dates):
        mask = local.date == date
        part = log[mask]
        hours = np.asarray(local[mask].hour + local[mask].minute / 60 + local[mask].second / 3600, float)
        _label_band(ax, hours, part["mode"].astype(str).to_numpy(), colours=modes,
                    step=_step(part.index).total_seconds() / 3600)
        for patch in ax.patches:
            patch.set_alpha(0.35)
        up = np.isfinite(part["target_true"].to_numpy()) & part["mode"].isin(TRACKING_MODES).to_numpy()
        error = np.where(up, part["error"].to_numpy(float), np.nan)
        ax.plot(hours, np.clip(error, -limit, limit), color="k", lw=0.7)
        over = np.isfinite(error) & (np.abs(error) > limit)
        if over.any():
            ax.scatter(hours[over], np.sign(error[over]) * limit, marker="^", s=10, color="tab:red", zorder=3)
        ax.set_ylabel(f"{date:%m-%d}", rotation=0, ha="right", va="center")
        ax.set_ylim(-limit * 1.1 if result.collector.single_axis else 0, limit * 1.1)
    axes[0].set_title(f"{run_title(result)}: pointing error (°, clipped at ±{limit:g}°, red marks beyond) "
                      "over the mode", fontsize="medium")
    _legend(axes[0], modes, "mode")
    axes[-1].set_xlim(0, 24)
    axes[-1].set_xticks(range(0, 25, 3))
    axes[-1].set_xlabel(f"hour of day ({result.site.tz})")
    return fig


# --- tuning: before/after surfaces and confusion matrices -----------------------------------


def _labels_of(config, samples: pd.DataFrame):
    """The true label of each sample: its ``weather``, else the band of its ``score``."""
    from .fuzzy import FuzzyWeatherClassifier

    if "weather" in samples.columns:
        return samples["weather"].astype(str).str.strip().str.lower().to_numpy()
    return FuzzyWeatherClassifier(config).label(samples["score"].to_numpy(float))


def plot_tuning(before, after, samples: pd.DataFrame, *, points: int = 121):
    """Decision surfaces of the starting and the tuned config side by side, the labelled readings on both.

    Axes are raw readings (mA), extended past the labelled range so the extrapolation shows;
    the labelled range is drawn as a dashed box.
    """
    import warnings

    from matplotlib import colormaps
    from matplotlib.patches import Rectangle

    from .fuzzy import FuzzyWeatherClassifier

    labels = _labels_of(before, samples)
    names = [band[0] for band in before.bands]
    colours = dict(zip(names, colormaps["RdYlBu_r"](np.linspace(0.1, 0.9, len(names)))))
    fig = figure(figsize=(13, 5.5), layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    (a, b) = before.inputs
    x = np.linspace(a.raw_range[0], max(a.raw_range[1], float(samples["intensity"].max())) * 1.1, points)
    y = np.linspace(b.raw_range[0], max(b.raw_range[1], float(samples["variation"].max())) * 1.1, points)
    gx, gy = np.meshgrid(x, y)
    for ax, config, name in ((axes[0], before, "before"), (axes[1], after, "after")):
        clf = FuzzyWeatherClassifier(config)
        with warnings.catch_warnings():  # drawing the extrapolation on purpose
            warnings.simplefilter("ignore")
            score = clf.score(gx.ravel(), gy.ravel()).reshape(gx.shape)
            predicted = clf.classify(samples["intensity"].to_numpy(float), samples["variation"].to_numpy(float))
        ax.set_facecolor("0.8")
        fill = ax.contourf(gx, gy, score, levels=np.linspace(*config.output.universe, 31), cmap="RdYlBu_r")
        ax.contour(gx, gy, score, levels=[band[2] for band in config.bands[:-1]], colors="k", linewidths=1.2)
        for label in names:
            mine = labels == label
            right = mine & (predicted == labels)
            ax.scatter(samples["intensity"][right], samples["variation"][right], color=colours[label], edgecolor="k",
                       s=28, label=f"{label} (right)")
            ax.scatter(samples["intensity"][mine & ~right], samples["variation"][mine & ~right], color=colours[label],
                       edgecolor="red", linewidth=1.8, marker="X", s=60, label=f"{label} (wrong)")
        accuracy = float(np.mean(predicted == labels))
        ax.set_title(f"{name}: {config.name}, training accuracy {accuracy:.1%}")
        ax.set_xlabel(f"intensity ({a.unit})")
        if after.labelled_range is not None:
            (ilo, ihi), (vlo, vhi) = after.labelled_range
            ax.add_patch(Rectangle((ilo, vlo), ihi - ilo, vhi - vlo, fill=False, ls="--", color="k", lw=1))
    axes[0].set_ylabel(f"variation ({b.unit})")
    axes[1].legend(fontsize="x-small", loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.colorbar(fill, ax=axes, label="weather score", shrink=0.8)
    fig.suptitle("decision surface before and after tuning (dashed: the labelled range; beyond it, extrapolation)")
    return fig


def plot_confusion(before, after, samples: pd.DataFrame):
    """Confusion matrices (true label against the classifier's) of the starting and tuned configs."""
    import warnings


    from .fuzzy import FuzzyWeatherClassifier
    from .fuzzy.classifier import UNKNOWN

    labels = _labels_of(before, samples)
    names = [band[0] for band in before.bands]
    predicted_names = names + [UNKNOWN]
    fig = figure(figsize=(10, 4.5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, config, name in ((axes[0], before, "before"), (axes[1], after, "after")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            predicted = FuzzyWeatherClassifier(config).classify(samples["intensity"].to_numpy(float),
                                                                samples["variation"].to_numpy(float))
        matrix = np.array([[np.sum((labels == t) & (predicted == p)) for p in predicted_names] for t in names])
        ax.imshow(matrix, cmap="Blues")
        for (i, j), value in np.ndenumerate(matrix):
            ax.text(j, i, str(value), ha="center", va="center",
                    color="white" if value > matrix.max() / 2 else "black")
        ax.set_xticks(range(len(predicted_names)), predicted_names)
        ax.set_yticks(range(len(names)), names)
        ax.set_xlabel("classified as")
        ax.set_ylabel("labelled")
        ax.set_title(f"{name}: {np.trace(matrix[:, :len(names)])} of {matrix.sum()} right")
    fig.suptitle("confusion on the labelled readings (training set)")
    return fig


# --- the rule viewer, and why a run was in its mode at a step --------------------------------


def plot_rules(classifier, intensity: float, variation: float, *, title: str | None = None):
    """MATLAB's rule viewer for one reading: a row per rule, then the aggregate and its centroid.

    Each rule's row shows its antecedent terms with the reading marked and the membership it
    gives shaded, and its consequent term clipped at the rule's firing strength (min of the
    memberships). The last row is the aggregate (max of the clipped consequents) with its
    centroid, the crisp score.
    """
    import warnings


    from .fuzzy.engine import sample_term

    config = classifier.config
    with warnings.catch_warnings():  # the caller decides whether to warn about the labelled range
        warnings.simplefilter("ignore")
        explanation = classifier.explain(intensity, variation)
    inputs, out = config.inputs, config.output
    rules = explanation.rules
    fig = figure(figsize=(11, 1.25 * (len(rules) + 1) + 1.2), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(rules) + 1, len(inputs) + 1, sharex="col", sharey=True))
    u_out = np.linspace(*out.universe, config.resolution[1])
    aggregate = np.zeros_like(u_out)
    for row, rule in enumerate(rules):
        for col, (var, x) in enumerate(zip(inputs, explanation.normalised)):
            ax = axes[row, col]
            term_name = rule["when"].get(var.name)
            if term_name is None:
                ax.text(0.5, 0.5, "(any)", ha="center", va="center", transform=ax.transAxes, color="0.5")
            else:
                u = np.linspace(*var.universe, 401)
                curve = sample_term(var.term(term_name), u)
                degree = explanation.memberships[var.name][term_name]
                ax.plot(u, curve, color="tab:blue", lw=1)
                ax.fill_between(u, np.minimum(curve, degree), color="tab:blue", alpha=0.35)
                ax.text(0.02, 0.8, f"{var.name} is {term_name}: {degree:.3f}", transform=ax.transAxes,
                        fontsize="x-small")
            ax.axvline(x, color="tab:red", lw=1)
        ax = axes[row, -1]
        curve = sample_term(out.term(rule["then"]), u_out)
        clipped = np.minimum(curve, rule["firing"])
        aggregate = np.maximum(aggregate, clipped)
        ax.plot(u_out, curve, color="0.6", lw=0.8)
        ax.fill_between(u_out, clipped, color="tab:orange", alpha=0.7)
        ax.text(0.02, 0.8, f"-> {rule['then']}, fires {rule['firing']:.3f}", transform=ax.transAxes, fontsize="x-small")
        axes[row, 0].set_ylabel(f"rule {rule['rule']}", rotation=0, ha="right", va="center")
    for col in range(len(inputs)):
        axes[-1, col].axis("off")
    ax = axes[-1, -1]
    ax.fill_between(u_out, aggregate, color="tab:orange", alpha=0.7)
    if np.isfinite(explanation.score):
        ax.axvline(explanation.score, color="k", lw=1.5)
    for name, lo, hi in config.bands:
        ax.axvspan(lo, hi, color=SKY_COLOURS.get(name, "#eeeeee"), alpha=0.25, lw=0)
    ax.set_ylabel("aggregate", rotation=0, ha="right", va="center")
    ax.set_xlabel(f"{out.name} score: centroid {explanation.score:.2f} -> {explanation.weather}")
    for col, var in enumerate(inputs):
        axes[0, col].set_title(f"{var.name} {getattr(explanation, var.name, x):g} {var.unit} "
                               f"(normalised {explanation.normalised[col]:.2f})", fontsize="small")
    axes[0, -1].set_title(f"{out.name} (clipped consequents)", fontsize="small")
    axes[0, 0].set_ylim(0, 1.08)
    fig.suptitle(title or f"rule viewer: {config.name}")
    return fig


def _moment(value, name: str, example: str) -> pd.Timestamp:
    """`value` (text, a date or a timestamp) as a timestamp, refused by `name` unless it is one: a
    number had been read as nanoseconds since 1970, None as NaT, and 'junk' raised pandas' error.
    A numpy datetime64 is refused with its reason: it has no zone, and the one a tz-aware index
    gives (`Index.to_numpy`) is UTC, where naive text is the site's local time."""
    if isinstance(value, np.datetime64):
        raise HybridtrackError(f"{name} {value!r:.60} has no time zone (a tz-aware index's values are UTC as "
                               f"numpy holds them): give a pandas Timestamp with its zone, or text in the site's "
                               f"local time such as {example.removeprefix('a time such as ').removeprefix('a date such as ')}")
    if isinstance(value, (str, dt.date)):  # a datetime and a Timestamp are dates too
        try:
            stamp = pd.Timestamp(value)
        except (ValueError, OverflowError):
            stamp = pd.NaT
        if stamp is not pd.NaT:
            return stamp
    raise HybridtrackError(f"{name} must be {example}, got {value!r:.60}")


def explain_step(result, time):
    """Why the controller of `result` was in its mode at `time` (the step at or before it)."""
    from .fuzzy import FuzzyWeatherClassifier

    log = result.log
    stamp = _moment(time, "time", "a time such as '2021-06-21 13:00'")
    if stamp.tz is None:
        stamp = stamp.tz_localize(result.site.tz)
    position = log.index.get_indexer([stamp], method="pad")[0]
    if position < 0 or stamp > log.index[-1] + _step(log.index):
        from .errors import HybridtrackError

        raise HybridtrackError(f"{stamp} is outside the run, which runs {log.index[0]} to {log.index[-1]}")
    row = log.iloc[position]
    events = result.events[result.events["time"] <= log.index[position]]
    event = events.iloc[-1].to_dict() if len(events) else None
    classifier = getattr(result, "classifier", None) or FuzzyWeatherClassifier()  # the run's, once it keeps one
    scale = "mA" if result.config.sky.mode == "absolute" else "the clear-sky ratio and its range on its mA scale"
    return StepExplanation(log.index[position].tz_convert(result.site.tz), str(row["mode"]), str(row["sky"]),
                           float(row["sky_score"]), str(row["sensor_status"]), float(row["wind_speed"]),
                           float(row["dni"]), event, classifier.explain(row["intensity_input"], row["variation_input"]),
                           classifier, reading=(float(row["intensity_ma"]), float(row["variation_ma"]), scale))


class StepExplanation:
    """One step of a run taken apart: mode, sky, sensor, the last event, and the fuzzy rules."""

    def __init__(self, time, mode, sky, sky_score, sensor_status, wind_speed, dni, event, fuzzy, classifier, *,
                 reading):
        self.time, self.mode, self.sky, self.sky_score = time, mode, sky, sky_score
        self.sensor_status, self.wind_speed, self.dni = sensor_status, wind_speed, dni
        self.event, self.fuzzy, self._classifier = event, fuzzy, classifier
        #: the photocurrent read and its trailing range (mA), and the scale of the classifier's inputs
        self.photocurrent, self.photocurrent_range, self.input_scale = reading

    def __str__(self) -> str:
        since = (f"since {self.event['time'].tz_convert(self.time.tz):%Y-%m-%d %H:%M}: {self.event['from']} -> "
                 f"{self.event['to']} because {self.event['reason']}" if self.event else "no mode change before it")
        return "\n".join([
            f"{self.time:%Y-%m-%d %H:%M:%S} mode {self.mode} ({since})",
            f"  sky {self.sky} (score {self.sky_score:.2f}), sensor {self.sensor_status}, DNI {self.dni:.0f} W/m², "
            f"wind {self.wind_speed:.1f} m/s",
            f"  photocurrent {self.photocurrent:.1f} mA, its range over the window {self.photocurrent_range:.1f} mA",
            f"  the classifier's rules for its inputs ({self.input_scale}): intensity {self.fuzzy.intensity:.1f}, "
            f"variation {self.fuzzy.variation:.1f}:",
            *("  " + line for line in str(self.fuzzy).splitlines()),
        ])

    __repr__ = __str__

    def plot(self):
        """The rule viewer for this step's readings."""
        return plot_rules(self._classifier, self.fuzzy.intensity, self.fuzzy.variation,
                          title=f"{self.time:%Y-%m-%d %H:%M}: mode {self.mode}, sky {self.sky}")


# --- several runs on the same weather (compare, ablations) ----------------------------------


class Comparison:
    """Runs on the same weather side by side: a table, an HTML table, a Figure, a daily table.

    Parameters
    ----------
    results : dict of str to Result
        One `hybridtrack.simulation.Result` per strategy (or per variant of an ablation).
    """

    def __init__(self, results: dict):
        if not results:
            from .errors import HybridtrackError

            raise HybridtrackError("a comparison needs at least one run")
        self.results = dict(results)

    def __getitem__(self, name):
        return self.results[name]

    def table(self) -> pd.DataFrame:
        """Headline metrics, one column per run (the summary's own numbers)."""
        rows = {}
        for name, result in self.results.items():
            s = result.summary
            rows[name] = {"RMS (°)": s["tracking_error_deg"]["rms"], "p95 (°)": s["tracking_error_deg"]["p95"],
                          "max (°)": s["tracking_error_deg"]["max"], "within 0.5°": s["within_0_5_deg"],
                          "energy capture": s["energy_capture"], "moves": s["moves"],
                          "mode switches": s["mode_switches"], "wind stows": s["stow_events"],
                          **{f"mode {m}": v for m, v in s["mode_share"].items()}}
        return pd.DataFrame(rows)

    def __repr__(self) -> str:
        first = next(iter(self.results.values()))
        return f"hybridtrack comparison: {run_title(first)}\n{self.table().to_string(float_format='{:.4g}'.format)}"

    def _repr_html_(self) -> str:
        from html import escape

        first = next(iter(self.results.values()))
        return (f"<div><strong>hybridtrack comparison</strong>: {escape(run_title(first))}"
                f"{self.table().to_html(float_format='{:.4g}'.format, border=0)}</div>")

    def plot(self):
        """`plot_compare` of the runs."""
        return plot_compare(self.results)

    def daily(self) -> pd.DataFrame:
        """Every run's daily table, stacked with the run's name as the outer index level."""
        return pd.concat({name: daily(result) for name, result in self.results.items()}, names=["run", "date"])
