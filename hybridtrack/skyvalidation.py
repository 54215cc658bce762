"""Score the sky classifier against references computed from the same recorded file.

A tracker hands the collector to its sun sensor when the sun's disk is clear, so the main
reference is the **beam ratio**, the measured DNI over the Ineichen clear-sky DNI:

* per sample: ``sunny`` at 0.7 or more, ``overcast`` below 0.2, ``cloudy`` between;
* over the classifier's window (the default, what the acceptance figures use): ``sunny``
  when every sample of the trailing window has a ratio of 0.7 or more, ``overcast`` when
  every one is below 0.2, ``cloudy`` otherwise. The classifier looks at the same window
  (its variation is a range over it), so a sky it calls sunny must have been clear for
  the whole window.

The thresholds: the WMO calls the sun shining when DNI exceeds 120 W/m² (WMO-No. 8, 2018,
§8.1.2), about 0.15 of a clear high-sun DNI of 800-1000 W/m²; 0.2 leaves room for the
clear-sky model's own error, so "overcast" is a sky where the disk casts no shadow. The
sunny threshold 0.7 leaves room for the clear-sky model's error on clear days (the monthly
Linke turbidity can be off either way: the clear days of ``data/real`` have median ratios
of 1.00-1.21), while a cloud that takes 30 % of the beam is one a tracker should notice.
Samples whose ratio is undefined (no clear-sky beam, or DNI missing) are left out.

Two more references, both binary (clear or not), score only whether "sunny" is right:

* pvlib's `detect_clearsky` (Reno and Hansen 2016), a GHI-based test of clear periods;
* CAELUS (Ruiz-Arias and Gueymard 2023), when the ``caelus-solar`` package is installed.
  It needs Python 3.12 or newer; where it is absent the comparison is skipped.

Everything is counted only above ``min_altitude`` (10° by default) of apparent sun.

References
----------
Reno, M. J. and Hansen, C. W. (2016). Identification of periods of clear sky irradiance in
time series of GHI measurements. Renewable Energy 90, 520-531.
doi:10.1016/j.renene.2015.12.031

Ruiz-Arias, J. A. and Gueymard, C. A. (2023). CAELUS: classification of sky conditions from
1-min time series of global solar irradiance using variability indices and dynamic
thresholds. Solar Energy 263, 111895. doi:10.1016/j.solener.2023.111895
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .errors import HybridtrackError
from .fuzzy.config import LABELS
from .sensor import SensorModel
from .sites import Site, get
from .skyinputs import SkyInputConfig, classify_sky, clear_sky
from .times import parse_date

__all__ = ["BEAM_SUNNY", "BEAM_OVERCAST", "MIN_ALTITUDE", "beam_ratio", "beam_labels", "window_labels",
           "clearsky_detected", "caelus_labels", "agreement", "confusion", "SkyValidation", "validate_sky",
           "plot_day"]

#: Beam ratio at or above which the sun's disk counts as clear.
BEAM_SUNNY = 0.7
#: Beam ratio below which the disk counts as hidden.
BEAM_OVERCAST = 0.2
#: Degrees of apparent sun altitude above which samples are counted.
MIN_ALTITUDE = 10.0

#: DNI (W/m²) above which the sun sensor can point: the WMO sunshine threshold (WMO-No. 8).
SENSOR_BEAM = 120.0

#: CAELUS sky types (its ``SkyType`` numbers) as the classifier's labels.
CAELUS_LABELS = {2: "overcast", 3: "overcast", 4: "cloudy", 5: "cloudy", 6: "sunny", 7: "cloudy"}


def beam_ratio(frame: pd.DataFrame, clear: pd.DataFrame) -> pd.Series:
    """Measured DNI over clear-sky DNI; NaN where either is missing or the sun is down."""
    if "dni" not in frame.columns:
        raise HybridtrackError("the beam-ratio reference needs a measured 'dni' column")
    expected = clear["dni"].where((clear["dni"] > 0) & (clear["apparent_elevation"] > 0))
    return (frame["dni"].clip(lower=0.0) / expected).rename("beam_ratio")


def beam_labels(ratio: pd.Series) -> pd.Series:
    """Each sample's label by the beam ratio thresholds; NaN ratio gives NaN."""
    labels = np.where(ratio >= BEAM_SUNNY, "sunny", np.where(ratio < BEAM_OVERCAST, "overcast", "cloudy"))
    return pd.Series(labels, index=ratio.index, dtype=object).where(ratio.notna()).rename("beam_sky")


def window_labels(ratio: pd.Series, window: str) -> pd.Series:
    """Labels over the trailing window: sunny if all of it is, overcast if all of it is."""
    rolling = ratio.rolling(pd.Timedelta(window), min_periods=1)
    low, high = rolling.min(), rolling.max()
    labels = np.where(low >= BEAM_SUNNY, "sunny", np.where(high < BEAM_OVERCAST, "overcast", "cloudy"))
    return pd.Series(labels, index=ratio.index, dtype=object).where(ratio.notna()).rename("beam_window_sky")


def _regular(series: pd.Series) -> pd.Series:
    """The series on a gap-free grid of its usual step (gaps become NaN)."""
    step = series.index.to_series().diff().median()
    grid = pd.date_range(series.index[0], series.index[-1], freq=step)
    return series.reindex(grid)


def clearsky_detected(frame: pd.DataFrame, clear: pd.DataFrame) -> pd.Series:
    """pvlib's `detect_clearsky` on the measured GHI: True where the sky is clear.

    The window is 10 minutes, or three samples if the step is longer than a third of it.

    References
    ----------
    Reno, M. J. and Hansen, C. W. (2016). Identification of periods of clear sky irradiance
    in time series of GHI measurements. Renewable Energy 90, 520-531.
    doi:10.1016/j.renene.2015.12.031
    """
    import pvlib

    if "ghi" not in frame.columns:
        raise HybridtrackError("detect_clearsky needs a measured 'ghi' column")
    ghi = _regular(frame["ghi"].astype(float))
    expected = _regular(clear["ghi"].astype(float))
    minutes = ghi.index.to_series().diff().median() / pd.Timedelta("1min")
    window = max(10.0, 3.0 * minutes)
    with warnings.catch_warnings():  # pvlib's own notes on its rescaling and on pandas' inferred_freq
        warnings.simplefilter("ignore")
        detected = pvlib.clearsky.detect_clearsky(ghi.fillna(0.0), expected.fillna(0.0), window_length=window)
    detected = pd.Series(np.asarray(detected, bool), index=ghi.index).where(ghi.notna())
    return detected.reindex(frame.index).rename("detect_clearsky")


def caelus_labels(frame: pd.DataFrame, clear: pd.DataFrame, site: Site) -> pd.Series | None:
    """CAELUS sky types as labels, or None where ``caelus-solar`` is not installed.

    References
    ----------
    Ruiz-Arias, J. A. and Gueymard, C. A. (2023). CAELUS: classification of sky conditions
    from 1-min time series of global solar irradiance. Solar Energy 263, 111895.
    doi:10.1016/j.solener.2023.111895
    """
    try:
        import caelus
    except ImportError:
        return None
    data = pd.DataFrame({"ghi": frame["ghi"].astype(float), "ghics": clear["ghi"].astype(float)})
    sky_type = caelus.classify(data, site.latitude, site.longitude)["sky_type"]
    labels = pd.Series(sky_type, index=frame.index).map(CAELUS_LABELS)
    return labels.astype(object).rename("caelus_sky")


def agreement(predicted: pd.Series, reference: pd.Series) -> float:
    """Share of samples where both are known and agree (NaN if none are known)."""
    both = predicted.isin(LABELS) & reference.notna()
    return float((predicted[both] == reference[both]).mean()) if both.any() else float("nan")


def confusion(predicted: pd.Series, reference: pd.Series) -> pd.DataFrame:
    """Counts of reference label (rows) against predicted label (columns), ``unknown`` included."""
    known = reference.notna()
    table = pd.crosstab(reference[known], predicted[known].fillna("unknown"))
    return table.reindex(index=list(LABELS), columns=list(LABELS) + ["unknown"], fill_value=0)


def _binary(predicted: pd.Series, clear: pd.Series) -> dict:
    """How "sunny" matches a clear / not-clear reference."""
    both = predicted.isin(LABELS) & clear.notna()
    sunny, is_clear = predicted[both] == "sunny", clear[both].astype(bool)
    return {"agreement": float((sunny == is_clear).mean()) if both.any() else float("nan"),
            "sunny_precision": float(is_clear[sunny].mean()) if sunny.any() else float("nan"),
            "clear_recall": float(sunny[is_clear].mean()) if is_clear.any() else float("nan"),
            "samples": int(both.sum())}


@dataclass
class SkyValidation:
    """Labels, references and scores of one file.

    Attributes
    ----------
    samples : pandas.DataFrame
        Per stamp: ``elevation``, ``beam_ratio``, the classifier's inputs, ``sky_score``,
        ``sky`` and each reference's label, with ``counted`` (sun above `min_altitude`).
    days : pandas.DataFrame
        Per local day: samples counted, sky shares and agreement with each reference.
    overall : dict
        The same over the whole file, plus sunny precision and no-clear-called-overcast.
    tz : str, optional
        The site's zone, whose local days `days` counts (None: the samples' own zone).
    """

    samples: pd.DataFrame
    days: pd.DataFrame
    overall: dict
    min_altitude: float = MIN_ALTITUDE
    notes: list = field(default_factory=list)
    tz: str | None = None

    def confusion(self, reference: str = "beam_window_sky") -> pd.DataFrame:
        """Reference (rows) against classifier (columns) on the counted samples."""
        counted = self.samples[self.samples["counted"]]
        return confusion(counted["sky"], counted[reference])

    def to_dict(self) -> dict:
        """JSON-ready: overall figures, the days and the confusion matrix (NaN as None)."""
        days = self.days.reset_index()
        days["day"] = days["day"].astype(str)
        days = days.astype(object).where(days.notna(), None)
        overall = {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in self.overall.items()}
        confusion = {ref: {k: int(n) for k, n in row.items()} for ref, row in self.confusion().to_dict("index").items()}
        return {"overall": overall, "days": days.to_dict(orient="records"), "confusion": confusion,
                "min_altitude": self.min_altitude, "notes": self.notes}

    def __str__(self) -> str:
        o = self.overall
        lines = [f"{o['samples']} samples with the sun above {self.min_altitude:g} deg "
                 f"(sky shares: " + ", ".join(f"{k} {o['share_' + k]:.1%}" for k in LABELS) + ")",
                 f"agreement with the beam ratio over the window: {o['beam_window']:.1%}; per sample: "
                 f"{o['beam_sample']:.1%}",
                 f"sunny precision (beam ratio over the window): {o['sunny_precision']:.1%}; sunny with DNI >= "
                 f"{SENSOR_BEAM:g} W/m2: {o['sunny_with_beam']:.1%}; clear samples called overcast: "
                 f"{o['clear_called_overcast']}",
                 f"detect_clearsky: agreement {o['clearsky_agreement']:.1%}, sunny precision "
                 f"{o['clearsky_sunny_precision']:.1%}"]
        if "caelus" in o:
            lines.append(f"CAELUS: agreement {o['caelus']:.1%}")
        lines += self.notes
        lines += ["", "per day:", self.days.to_string(float_format=lambda v: f"{v:.3f}"), "",
                  "beam ratio over the window (rows) against the classifier (columns):", str(self.confusion())]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        return f"<pre>{self.__str__()}</pre>"


def _scores(rows: pd.DataFrame) -> dict:
    sky, window = rows["sky"], rows["beam_window_sky"]
    known = sky.isin(LABELS)
    called_sunny = known & (sky == "sunny") & window.notna()
    some, nan = called_sunny.any(), float("nan")
    scores = {"samples": int(len(rows)), "labelled": int(known.sum()),
              "beam_window": agreement(sky, window), "beam_sample": agreement(sky, rows["beam_sky"]),
              "sunny_precision": float((window[called_sunny] == "sunny").mean()) if some else nan,
              "sunny_with_beam": float((rows["dni"][called_sunny] >= SENSOR_BEAM).mean()) if some else nan,
              "clear_called_overcast": int(((window == "sunny") & (sky == "overcast")).sum())}
    for label in LABELS:
        scores["share_" + label] = float((sky[known] == label).mean()) if known.any() else float("nan")
    binary = _binary(sky, rows["detect_clearsky"])
    scores["clearsky_agreement"], scores["clearsky_sunny_precision"] = binary["agreement"], binary["sunny_precision"]
    if "caelus_sky" in rows:
        scores["caelus"] = agreement(sky, rows["caelus_sky"])
    return scores


def validate_sky(frame: pd.DataFrame, site: Site | str, *, sensor: SensorModel | None = None,
                 config: SkyInputConfig | None = None, classifier=None,
                 min_altitude: float = MIN_ALTITUDE) -> SkyValidation:
    """Classify a recorded weather frame and score the labels against its references.

    Parameters
    ----------
    frame : pandas.DataFrame
        Weather frame (tz-aware index) with measured ``ghi``, ``dni`` and ``dhi``.
    site : Site or str
    sensor : SensorModel, optional
    config : SkyInputConfig, optional
        How the classifier reads the sky; the default when omitted.
    classifier : FuzzyWeatherClassifier, optional
        Overrides the config's rule table.
    min_altitude : float
        Degrees of sun above which samples are counted.
    """
    site = get(site)
    sensor = sensor or SensorModel()
    config = config or SkyInputConfig()
    if not np.isfinite(min_altitude) or not -5.0 <= min_altitude <= 60.0:
        raise HybridtrackError(f"min_altitude {min_altitude!r} must be within [-5, 60] degrees")
    for column in ("ghi", "dni", "dhi"):
        if column not in frame.columns:
            raise HybridtrackError(f"validating the sky needs measured ghi, dni and dhi; {column!r} is missing")
        source = frame.attrs.get(f"{column}_source", "measured")
        if source != "measured":
            raise HybridtrackError(f"validating the sky needs measured ghi, dni and dhi; {column} is not measured "
                                   f"({source})")
    if len(frame) < 3:
        raise HybridtrackError(f"validating the sky needs at least 3 samples, got {len(frame)}")
    if not isinstance(frame.index, pd.DatetimeIndex) or frame.index.tz is None:
        raise HybridtrackError("validating the sky needs a weather frame on a time-zone-aware DatetimeIndex")
    if not (frame.index.is_monotonic_increasing and frame.index.is_unique):
        raise HybridtrackError("validating the sky needs increasing, unique time stamps")
    clear = clear_sky(frame.index, site)
    samples = classify_sky(frame, site, sensor, config, classifier=classifier, clear=clear)
    ratio = beam_ratio(frame, clear)
    samples.insert(0, "elevation", clear["apparent_elevation"])
    samples["dni"] = frame["dni"].astype(float)
    samples["beam_ratio"] = ratio
    samples["beam_sky"] = beam_labels(ratio)
    samples["beam_window_sky"] = window_labels(ratio, config.window)
    samples["detect_clearsky"] = clearsky_detected(frame, clear)
    notes = []
    caelus = caelus_labels(frame, clear, site)
    if caelus is None:
        notes.append("CAELUS skipped: the caelus-solar package (Python 3.12 or newer) is not installed")
    else:
        samples["caelus_sky"] = caelus
    samples["counted"] = samples["elevation"] > min_altitude
    counted = samples[samples["counted"]]
    if counted.empty:
        raise HybridtrackError(f"no sample has the sun above {min_altitude:g} degrees; nothing to score")
    local_day = counted.index.tz_convert(site.tz).date
    days = pd.DataFrame([_scores(rows) for _, rows in counted.groupby(local_day)],
                        index=pd.Index(sorted(set(local_day)), name="day"))
    return SkyValidation(samples, days, _scores(counted), min_altitude, notes, tz=site.tz)


def plot_day(validation: SkyValidation, day=None):
    """A `matplotlib.figure.Figure` of one day: beam ratio, inputs and labels against time.

    `day` is a date or ``YYYY-MM-DD`` among the validation's days (the site's local days); the
    worst-agreeing day by default. The day is drawn on the site's clock: a file kept in UTC had
    been drawn from UTC midnight, another day's morning in place of its own.
    """
    from matplotlib.figure import Figure

    days = validation.days
    if day is None:
        scored = days["beam_window"].dropna()
        day = scored.idxmin() if len(scored) else days.index[0]
    day = parse_date(day)
    if day not in set(days.index):
        raise HybridtrackError(f"no day {day} in the validation; days are {', '.join(map(str, days.index))}")
    samples = validation.samples if validation.tz is None else validation.samples.tz_convert(validation.tz)
    rows = samples[samples.index.date == day]
    figure = Figure(figsize=(10, 6.5), layout="constrained")
    top, middle, bottom = figure.subplots(3, 1, sharex=True)
    top.plot(rows.index, rows["beam_ratio"], lw=0.8, color="tab:orange", label="beam ratio DNI / clear DNI")
    for level in (BEAM_SUNNY, BEAM_OVERCAST):
        top.axhline(level, color="grey", lw=0.6, ls="--")
    top.set_ylim(-0.05, 1.5)
    top.set_ylabel("beam ratio")
    top.legend(loc="upper right", fontsize="small")
    middle.plot(rows.index, rows["intensity_input"], lw=0.8, label="intensity input")
    middle.plot(rows.index, rows["variation_input"], lw=0.8, label="variation input")
    middle.set_ylabel("mA (or equivalent)")
    middle.legend(loc="upper right", fontsize="small")
    levels = {label: k for k, label in enumerate(LABELS)}
    for offset, column, name in ((0.0, "sky", "classifier"), (0.15, "beam_window_sky", "beam ratio, window")):
        values = rows[column].map(levels).astype(float) + offset
        bottom.plot(rows.index, values, ".", ms=2, label=name)
    bottom.set_yticks(range(len(LABELS)), LABELS)
    bottom.legend(loc="upper right", fontsize="small")
    low = rows["elevation"] <= validation.min_altitude
    for axis in (top, middle, bottom):
        axis.fill_between(rows.index, 0, 1, where=low.to_numpy(), transform=axis.get_xaxis_transform(),
                          color="grey", alpha=0.15, lw=0)
    agreement_today = days.loc[day, "beam_window"]
    figure.suptitle(f"{day}: classifier against the beam ratio, agreement {agreement_today:.1%} "
                    f"(grey: sun below {validation.min_altitude:g}°)")
    return figure
