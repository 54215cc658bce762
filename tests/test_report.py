"""Results for people: reprs, the daily table, one definition of counts, pictures that leave pyplot alone."""

import re
import sys

import matplotlib
import numpy as np
import pytest

import hybridtrack
from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.metrics import RunningSummary, daily, summarize
from hybridtrack.control import MODES
from hybridtrack.report import mode_colours, plot_days, save_figure
from hybridtrack.sky import synthetic


@pytest.fixture(scope="module")
def two_days():
    frame = synthetic("lanzhou", "2021-06-21", "2021-06-22", weather=["mixed", "sunny"], seed=5, gusts_per_day=2.0,
                      freq="2min")
    return hybridtrack.simulate(frame, "lanzhou", collector="fresnel")


def test_every_events_row_is_a_mode_switch_or_an_alarm(two_days):
    s, events = two_days.summary, two_days.events
    assert s["mode_switches"] + s["alarms"] == len(events)
    assert s["mode_switches"] == int((events["from"] != events["to"]).sum())


def test_mode_and_sky_shares_have_the_same_base(two_days):
    s = two_days.summary
    assert sum(s["mode_share"].values()) == pytest.approx(1, abs=1e-4)
    assert sum(s["sky_share"].values()) == pytest.approx(1, abs=1e-4)
    assert set(s["mode_share"]) == set(MODES)
    night = float(np.mean(~np.isfinite(two_days.log["target_true"].to_numpy())))
    assert s["sky_share"]["night"] == pytest.approx(night, abs=1e-4)


def test_the_daily_table_adds_up_to_the_run(two_days):
    table = two_days.daily()
    assert list(table.index.astype(str)) == ["2021-06-21", "2021-06-22"]
    assert table["moves"].sum() == two_days.summary["moves"]
    assert {"energy_capture", "rms", "p95", "stow_wind_min", "stow_night_min", "sky_sunny", "sky_night"} <= set(table)
    sky = table[[c for c in table if c.startswith("sky_")]].sum(axis=1)
    np.testing.assert_allclose(sky, 1.0)
    assert (table["energy_capture"] <= 1).all() and table.loc[table.index[1], "energy_capture"] > 0.9


def test_the_reprs_say_what_ran(two_days):
    text = repr(two_days)
    assert text.startswith("hybridtrack run: lanzhou · fresnel · hybrid · 2021-06-21 to 2021-06-22")
    assert "energy capture" in text and "modes:" in text and len(text.splitlines()) < 20
    html = two_days._repr_html_()
    assert "<table>" in html and "events" in html


def test_plots_leave_pyplot_and_the_backend_alone(two_days, tmp_path):
    backend = matplotlib.get_backend()
    had_pyplot = "matplotlib.pyplot" in sys.modules
    for fig in (two_days.plot(), two_days.plot(day="2021-06-22"), plot_days(two_days), two_days.explain(
            "2021-06-21 12:00").plot()):
        assert isinstance(fig, matplotlib.figure.Figure) and fig._repr_png_()[:4] == b"\x89PNG"
    save_figure(two_days.plot(), tmp_path / "r.png")
    assert matplotlib.get_backend() == backend
    assert ("matplotlib.pyplot" in sys.modules) == had_pyplot


def test_every_mode_has_its_own_colour():
    colours = mode_colours()
    assert set(colours) == set(MODES) and len(set(colours.values())) == len(MODES)


def test_explain_names_the_mode_and_the_event_behind_it(two_days):
    events = two_days.events
    stow = events[events["to"] == "stow_wind"].iloc[0]
    step = two_days.explain(stow["time"])
    assert step.mode == "stow_wind" and step.event["reason"] == stow["reason"]
    assert "mode stow_wind" in str(step) and "rule 1" in str(step)


def test_the_rule_viewer_prints_each_rule_and_the_centroid(capsys, tmp_path):
    out = tmp_path / "rules.png"
    assert main(["rules", "--intensity", "200.1", "--variation", "84.6", "--plot", str(out)]) == 0
    text = capsys.readouterr().out
    # by hand: strong(6.3) = exp(-3.7²/4.5) = 0.048, small(4.7) = exp(-4.7²/12.5) = 0.171
    assert "rule 1: intensity is strong 0.048 AND variation is small 0.171 -> fires 0.048" in text
    assert "-> cloudy" in text and out.read_bytes()[:4] == b"\x89PNG"
    assert main(["rules", "--intensity", "nan", "--variation", "1"]) == 2


def test_a_southern_sun_path_does_not_wrap_and_metres_get_their_own_axis():
    import pandas as pd

    from hybridtrack import sites
    from hybridtrack.collectors import Collector
    from hybridtrack.report import plot_sun_path
    from hybridtrack.sun import solar_position

    times = pd.date_range("2024-12-21 06:00", "2024-12-21 19:00", freq="10min", tz="Africa/Johannesburg")
    position = solar_position(times, sites.custom(-33.9, 18.4, "Africa/Johannesburg"), "spa")
    fig = plot_sun_path(position, Collector("heliostat").angles(position["altitude"], position["azimuth"]))
    azimuth = fig.axes[-1].get_lines()[0].get_ydata()  # the twin axis holds the azimuth
    assert np.max(np.abs(np.diff(azimuth))) < 30  # no jump across north
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert "length (m)" in labels and "target (°)" in labels
    assert all(not line.get_label().startswith("jack") for ax in fig.axes if ax.get_ylabel() == "target (°)"
               for line in ax.get_lines())


def test_a_comparison_shows_each_run_by_its_own_summary(two_days):
    import dataclasses

    from hybridtrack.report import Comparison

    other = dataclasses.replace(two_days, summary={**two_days.summary, "strategy": "other"})
    both = Comparison({"hybrid": two_days, "other": other})
    table = both.table()
    assert list(table.columns) == ["hybrid", "other"]
    assert table.loc["RMS (°)", "hybrid"] == two_days.summary["tracking_error_deg"]["rms"]
    assert "hybridtrack comparison" in repr(both) and "<table" in both._repr_html_()
    assert both.daily().index.names == ["run", "date"] and len(both.daily()) == 4
    assert both.plot()._repr_png_()[:4] == b"\x89PNG"


def test_explain_refuses_a_numpy_time_whose_zone_it_would_guess(two_days):
    """A value of the log's index as numpy holds it is naive UTC (`Index.to_numpy`), where a naive
    text is the site's local time: taken either way it could be 8 h off, so it is refused with why."""
    stamp = two_days.events["time"].iloc[0]
    with pytest.raises(HybridtrackError, match=r"^time np.datetime64\('.*'\) has no time zone .*UTC.*"
                                               r"local time such as '2021-06-21 13:00'$"):
        two_days.explain(stamp.tz_convert("UTC").tz_localize(None).to_datetime64())
    with pytest.raises(HybridtrackError, match="has no time zone"):
        two_days.plot(day=np.datetime64("2021-06-21"))


def test_explain_outside_the_run_is_an_error(two_days):
    from hybridtrack import HybridtrackError

    with pytest.raises(HybridtrackError, match="outside the run"):
        two_days.explain("2021-06-25 12:00")
    with pytest.raises(HybridtrackError, match="outside the run"):
        two_days.explain("2021-06-20 12:00")


def test_scattered_days_get_a_column_each_and_the_gap_is_marked():
    import pandas as pd

    frame = pd.concat([synthetic("nanjing", "2013-03-20", weather="sunny", seed=1, freq="10min"),
                       synthetic("nanjing", "2013-06-21", weather="cloudy", seed=1, freq="10min")])
    result = hybridtrack.simulate(frame, "nanjing")
    fig = result.plot()
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert "92 days without data" in texts  # 2013-03-21 to 2013-06-20
    bottom = fig.axes[5]  # the hybrid fits its mount: its panel is the bottom row
    assert [t.get_text() for t in bottom.get_xticklabels()] == ["2013-03-20", "2013-06-21"]
    assert len(result.daily()) == 2


def test_a_run_without_events_still_shows_itself():
    frame = synthetic("delingha", "2018-06-21", weather="sunny", seed=2, freq="5min").iloc[:3]
    result = hybridtrack.simulate(frame, "delingha", collector="trough-ew")  # three steps of night
    assert "no events" in result._repr_html_() and "night 100.0%" in repr(result)
    assert result.plot()._repr_png_()[:4] == b"\x89PNG" and len(result.daily()) == 1


def _fit_lines(fig):
    """The mount-fit panel's lines by parameter, and its dashed truths."""
    lines = [line for ax in fig.axes for line in ax.get_lines() if (line.get_gid() or "").startswith("fit:")]
    truths = [line for ax in fig.axes for line in ax.get_lines() if (line.get_gid() or "").startswith("truth:")]
    return {line.get_gid()[4:]: line for line in lines}, {line.get_gid()[6:]: line for line in truths}


def test_the_mount_fit_panel_draws_the_logs_fit_and_the_worlds_truth(two_days):
    from hybridtrack.control.mountfit import parameter_names

    lines, truths = _fit_lines(two_days.plot())
    names = parameter_names(two_days.collector)
    assert sorted(lines) == sorted(names)
    imperfections = two_days.config.imperfections
    expected = {"axis_azimuth_error": imperfections.axis_azimuth_error,
                "axis_tilt_error": imperfections.axis_tilt_error,
                "encoder_offset": imperfections.encoder_offset + imperfections.sensor_bias}  # the sensor adds its bias
    for name in names:
        np.testing.assert_array_equal(lines[name].get_ydata(), two_days.log[f"fit_{name}"].to_numpy())
        assert truths[name].get_ydata()[0] == pytest.approx(expected[name])
    assert len(lines[names[0]].axes.collections) == len(names)  # one ±1σ band each


def test_the_overview_draws_each_days_fit_as_it_stood_at_its_end():
    frame = synthetic("lanzhou", "2021-06-21", "2021-06-27", weather="sunny", seed=3, freq="10min")
    result = hybridtrack.simulate(frame, "lanzhou")
    lines, _ = _fit_lines(result.plot())
    local = result.log.index.tz_convert(result.site.tz)
    at_end = result.log.groupby(local.date)["fit_encoder_offset"].last().to_numpy()
    np.testing.assert_array_equal(lines["encoder_offset"].get_ydata(), at_end)
    assert len(at_end) == 7


def test_runs_without_a_fit_have_no_fit_panel():
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=3, freq="10min")
    result = hybridtrack.simulate(frame, "lanzhou", strategy="astronomical")
    assert not result.log.filter(like="fit_").columns.size
    assert _fit_lines(result.plot()) == ({}, {})


@pytest.mark.parametrize("call, message", [
    # pandas' DateParseError, and a number read as nanoseconds since 1970 ('no step on 1970-01-01')
    (lambda r: r.plot(day="junk"), "day must be a date such as '2021-06-21', got 'junk'"),
    (lambda r: r.plot(day=5), "day must be a date such as '2021-06-21', got 5"),
    (lambda r: r.explain("junk"), "time must be a time such as '2021-06-21 13:00', got 'junk'"),
    (lambda r: r.explain(None), "time must be a time such as '2021-06-21 13:00', got None"),  # 'NaT is outside'
])
def test_a_day_or_time_that_is_none_is_refused_by_its_name(two_days, call, message):
    with pytest.raises(HybridtrackError, match=re.escape(message)):
        call(two_days)


@pytest.mark.parametrize("call, message", [
    (lambda r: summarize(r.log, site="x", collector="dish", strategy="hybrid", events=r.events, **r.scoring),
     "collector 'dish': choose trough-ns"),  # KeyError: 'dish'
    (lambda r: summarize(r.log.drop(columns="dni"), site="x", collector="fresnel", strategy="hybrid",
                         events=r.events, **r.scoring), "the log has no 'dni' column"),  # KeyError
    (lambda r: summarize(r.log, site="x", collector="trough-ns", strategy="hybrid", events=r.events,
                         **{**r.scoring, "sun_up": r.scoring["sun_up"][:10]}), "sun_up needs one value per step"),
    (lambda r: RunningSummary(site="x", collector="dish", strategy="hybrid"), "collector 'dish'"),
    (lambda r: RunningSummary(site="x", collector="trough-ns", strategy="hybrid").summary(), "add() one first"),
    (lambda r: daily(r.log, collector="fresnel", tz="Mars/Base", sun_up=r.scoring["sun_up"],
                     incidence=r.scoring["incidence"]), "unknown time zone 'Mars/Base'"),  # ZoneInfoNotFoundError
])
def test_the_metrics_refuse_what_they_cannot_score_by_name(two_days, call, message):
    with pytest.raises(HybridtrackError, match=re.escape(message)):
        call(two_days)
