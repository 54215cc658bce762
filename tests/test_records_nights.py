"""The nights a logger left out, put back (`hybridtrack.io.fill_nights`, ``--fill-nights``)."""

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError, simulate
from hybridtrack.cli import main
from hybridtrack.io import fill_nights
from hybridtrack.io.nights import night_gaps
from hybridtrack.sky import synthetic

SITE = "lanzhou"


@pytest.fixture(scope="module")
def days():
    """Three sunny days at 1 min, and the same cut to daylight as a logger that records above
    20 W/m² of global light writes them."""
    full = synthetic(SITE, "2021-06-21", "2021-06-23", weather="sunny", seed=1, freq="1min")
    return full, full[full["ghi"] > 20.0]


def test_the_nights_put_back_are_dark_where_the_sun_is_down_and_the_wind_runs_across(days):
    full, day = days
    filled = fill_nights(day, SITE)
    pd.testing.assert_index_equal(filled.index, full.index, check_freq=False)  # the local days whole, midnight to midnight
    assert filled.attrs["validation"]["nights_filled"]["nights"] == 2
    assert filled.attrs["validation"]["nights_filled"]["rows"] == len(full) - len(day)
    added = ~filled.index.isin(day.index)
    sun = pvlib.solarposition.get_solarposition(filled.index[added], 36.06, 103.83)
    dark = sun["apparent_elevation"].to_numpy() < -0.5  # pvlib's SPA, clear of the horizon
    assert dark.sum() > 1000 and (filled.loc[added, ["ghi", "dni", "dhi"]].to_numpy()[dark] == 0.0).all()
    pd.testing.assert_frame_equal(filled.loc[day.index, ["ghi", "dni", "wind_speed"]], day[["ghi", "dni", "wind_speed"]])
    evening, morning = day.index[day.index.get_loc("2021-06-21 20:02:00+08:00")], pd.Timestamp("2021-06-22 06:12:00+08:00")
    midway = evening + (morning - evening) / 2  # by hand: the mean of the two readings either side
    expected = (day.loc[evening, "wind_speed"] + day.loc[morning, "wind_speed"]) / 2
    assert filled.loc[midway.floor("min"), "wind_speed"] == pytest.approx(expected, abs=0.01)
    assert filled["wind_speed"].notna().all()


@pytest.mark.filterwarnings("ignore::hybridtrack.simulation.NightsLeftOutWarning")  # a gap into a morning, on purpose
@pytest.mark.parametrize("strategy", ["hybrid", "sensor"])
def test_a_day_only_file_filled_tracks_as_the_file_with_its_nights_does(days, strategy):
    """Left out, each morning scores the slew from stow (no scan to pre-position in): RMS 0.70°
    against 0.15°; the nights put back, the run is within a few thousandths of a degree of the
    same days with their real nights."""
    full, day = days
    reference = simulate(full, SITE, strategy=strategy).summary
    filled = simulate(fill_nights(day, SITE), SITE, strategy=strategy).summary
    left_out = simulate(day, SITE, strategy=strategy).summary
    assert filled["tracking_error_deg"]["rms"] == pytest.approx(reference["tracking_error_deg"]["rms"], abs=0.005)
    assert filled["energy_capture"] == pytest.approx(reference["energy_capture"], abs=0.001)
    assert left_out["tracking_error_deg"]["rms"] > reference["tracking_error_deg"]["rms"] + 0.3


def test_a_frame_that_leaves_no_night_out_is_left_as_it_is(days):
    full, _ = days
    noon = full.drop(full.loc["2021-06-22 12:00":"2021-06-22 14:00"].index)  # a gap by day is no night
    assert night_gaps(full, SITE) == 0 and night_gaps(noon, SITE) == 0
    assert fill_nights(full, SITE) is full and fill_nights(noon, SITE) is noon
    with pytest.raises(HybridtrackError, match="time-zone-aware index"):
        fill_nights(full.tz_localize(None), SITE)


def test_a_logger_down_by_day_as_well_is_no_night_to_fill(days):
    """A gap with more than `TWILIGHT` of daylight in it (a logger dead from noon to noon; a file
    that starts at 13:00) holds light nobody can tell: left as a gap, not drawn as a line."""
    _, day = days
    dead = day.drop(day.loc["2021-06-22 12:00":"2021-06-23 12:00"].index)
    filled = fill_nights(dead, SITE)
    assert night_gaps(dead, SITE) == 1 and filled.attrs["validation"]["nights_filled"]["nights"] == 1
    assert not filled.index.isin(pd.date_range("2021-06-22 12:01", "2021-06-23 11:59", freq="min",
                                               tz="Asia/Shanghai")).any()
    late = fill_nights(day.loc["2021-06-21 13:00":], SITE)
    assert late.index[0] == pd.Timestamp("2021-06-21 13:00", tz="Asia/Shanghai")
    assert late.attrs["validation"]["nights_filled"]["ends of the first and last days"] == 1  # the last evening's


def test_replay_names_the_nights_left_out_and_puts_them_back_when_asked(tmp_path, capsys, days):
    _, day = days
    path = tmp_path / "day.csv"
    day[["ghi", "dni", "dhi", "wind_speed"]].rename_axis("time").to_csv(path)
    assert main(["replay", str(path), "--site", SITE]) == 0
    out = capsys.readouterr().out
    assert "nights left out: 2 (" in out and "--fill-nights puts them back" in out
    assert main(["replay", str(path), "--site", SITE, "--fill-nights"]) == 0
    out = capsys.readouterr().out
    assert f"{len(day)} rows read, 4320 rows out" in out and "nights 2, ends of the first and last days 2" in out
    assert "nights left out" not in out and "gaps (kept as gaps)" not in out
