"""The controller's working day: clock hours are an optional limit, and the default spans the
whole day, its last minute included (an end of 23:59 had stowed a tracker for one scan at every
clock midnight: in a polar summer, with the sun up; at a site whose PLC keeps UTC far east of
Greenwich, mid-morning)."""

import pandas as pd
import pytest

from hybridtrack import simulate, sites
from hybridtrack.control.config import ControllerConfig
from hybridtrack.control.plan import _working
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic


def _clock(*stamps):
    return pd.DatetimeIndex(list(stamps)).tz_localize("UTC")


def test_the_default_working_hours_include_every_reading_of_the_clock_day():
    clock = _clock("2024-06-20 00:00", "2024-06-20 23:59:00", "2024-06-20 23:59:30", "2024-06-20 23:59:59.999999999")
    assert ControllerConfig().working_hours == ("00:00", "24:00")
    assert _working(clock, ControllerConfig().working_hours).all()


@pytest.mark.parametrize("hours, inside", [
    (("00:00", "23:59"), [True, True, False, False]),  # until 23:59 means until 23:59:00
    (("06:00", "23:59:30"), [False, True, True, False]),  # the seconds of an end count: both ends included
])
def test_an_end_written_to_the_minute_or_second_is_kept_to_it(hours, inside):
    clock = _clock("2024-06-20 05:00", "2024-06-20 23:59:00", "2024-06-20 23:59:30", "2024-06-20 23:59:45")
    assert _working(clock, hours).tolist() == inside


def test_a_tracker_under_the_midnight_sun_does_not_stow_at_midnight():
    """Longyearbyen (78.2° N) at the June solstice: the sun is 12° up at midnight."""
    site = sites.custom(78.2, 15.6, "Arctic/Longyearbyen")
    frame = synthetic(site, "2024-06-20", "2024-06-21", weather="sunny", seed=1, freq="5min")
    result = simulate(frame, site, strategy="astronomical")
    assert (result.log["mode"] != "stow_night").all()
    assert not result.events["to"].eq("stow_night").any()


def test_a_plc_clock_on_utc_far_east_works_through_its_midnight():
    """Lanzhou on a PLC keeping UTC: its clock's midnight is 08:00 local, the sun well up."""
    site = sites.get("lanzhou")
    frame = synthetic(site, "2021-06-21", weather="sunny", seed=1, freq="1min")
    on_utc = sites.custom(site.latitude, site.longitude, "UTC", altitude=site.altitude)
    result = simulate(frame.tz_convert("UTC"), on_utc, strategy="astronomical")
    at_midnight = result.log.index.tz_convert("UTC").strftime("%H:%M").isin(["23:59", "00:00", "00:01"])
    assert (result.log.loc[at_midnight, "mode"] == "astronomical").all(), result.log.loc[at_midnight, "mode"]
    assert result.events["to"].eq("stow_night").sum() == 1  # at sunset only


def test_working_hours_of_24_00_round_trip_through_a_config_file(tmp_path):
    config = SimulationConfig(controller=ControllerConfig(working_hours=("05:00", "24:00")))
    path = tmp_path / "run.toml"
    config.to_toml(path)
    assert SimulationConfig.from_toml(path) == config
