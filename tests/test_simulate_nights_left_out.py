"""The API says when a frame leaves nights out (`hybridtrack.simulation.NightsLeftOutWarning`): a
day-only logger frame had scored each morning's slew from stow without a word."""

import numpy as np
import pytest

from hybridtrack import simulate, simulate_field
from hybridtrack.fields import FresnelField
from hybridtrack.io import fill_nights, read_weather
from hybridtrack.simulation import NightsLeftOutWarning
from hybridtrack.sky import synthetic

SITE = "lanzhou"


@pytest.fixture(scope="module")
def days():
    """Three sunny days at 5 min, whole and cut to daylight (above 20 W/m² of global light), as a
    logger with a light threshold writes them: two nights left out, by hand."""
    full = synthetic(SITE, "2021-06-21", "2021-06-23", weather="sunny", seed=1, freq="5min")
    return full, full[full["ghi"] > 20.0]


def test_a_day_only_frame_is_warned_of_with_its_nights_and_the_way_to_put_them_back(days):
    _, day = days
    with pytest.warns(NightsLeftOutWarning, match=r"^the frame leaves out 2 nights .*fill_nights") as caught:
        simulate(day, SITE)
    assert caught[0].filename == __file__  # the caller's line, not the package's
    with pytest.warns(NightsLeftOutWarning, match=r"leaves out 2 nights"):
        simulate_field(day, SITE, FresnelField(row_distances=[-4.0, 6.0]), keep_log=False)


def test_whole_frames_and_frames_with_their_nights_put_back_are_not_warned_of(days, warned):
    full, day = days
    assert warned(lambda: simulate(full, SITE), NightsLeftOutWarning) == []
    assert warned(lambda: simulate(fill_nights(day, SITE), SITE), NightsLeftOutWarning) == []
    # a frame that starts and ends by day leaves out no night between its readings
    by_day = full.between_time("06:00", "20:00").loc["2021-06-22"]
    assert warned(lambda: simulate(by_day, SITE), NightsLeftOutWarning) == []


def test_only_a_gap_that_runs_into_a_morning_is_a_night_left_out(days, warned):
    """A gap by day, and one that ends in the dark (a logger down two hours around midnight, or
    across dusk), cost the controller nothing: it meets no morning at stow. One from before dawn
    into the day does (sunrise at Lanzhou on 22 June 2021: 05:51 Beijing time, by pvlib's SPA)."""
    full, _ = days
    for start, end in (("2021-06-22 11:00", "2021-06-22 13:00"), ("2021-06-21 23:00", "2021-06-22 01:00"),
                       ("2021-06-21 20:00", "2021-06-21 20:40")):
        assert warned(lambda: simulate(full.drop(full.loc[start:end].index), SITE), NightsLeftOutWarning) == []
    dawn = full.drop(full.loc["2021-06-22 05:00":"2021-06-22 06:30"].index)
    said = warned(lambda: simulate(dawn, SITE), NightsLeftOutWarning)
    assert len(said) == 1 and said[0].startswith("the frame leaves out 1 night (no rows from a night")


def test_a_frame_whose_report_names_its_nights_is_not_warned_of_again(days, tmp_path, warned):
    """The command line's reader names them in the validation report already (``nights left out``)."""
    _, day = days
    path = tmp_path / "day.csv"
    day[["ghi", "dni", "dhi", "wind_speed"]].to_csv(path)
    frame = read_weather(path)
    assert warned(lambda: simulate(frame, SITE), NightsLeftOutWarning) == [
        "the frame leaves out 2 nights (no rows from a night into its morning): each such morning's slew from stow "
        "is scored, as no PLC scanning all night would show; hybridtrack.io.fill_nights(frame, site) puts them back"]
    frame.attrs["validation"]["nights_left_out"] = "2"
    assert warned(lambda: simulate(frame, SITE), NightsLeftOutWarning) == []
    assert np.isfinite(simulate(frame, SITE).summary["tracking_error_deg"]["rms"])
