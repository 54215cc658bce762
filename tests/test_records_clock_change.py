"""A logger kept on one clock (standard time) all year, read in its site's zone with summer time:
the light fits the sun on one side of the zone's clock change and is an hour off on the other.
One shift for the whole file had averaged the two sides to within the tolerance, and a week
across the October change passed as usable (helper-44)."""

import pandas as pd
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.io import read_weather
from hybridtrack.sky import synthetic

MADRID = sites.custom(40.4, -3.7, "Europe/Madrid", name="madrid")


def _week(tmp_path, start, end, clock):
    """A mixed week at Madrid at 5 minutes, written with naive stamps on `clock`: the zone's own
    wall clock ('local') or UTC+1 throughout ('standard')."""
    frame = synthetic(MADRID, start, end, weather="mixed", seed=2, freq="5min")
    table = frame[["ghi", "dni", "dhi", "wind_speed"]].copy()
    table.index = (frame.index if clock == "local" else frame.index.tz_convert("Etc/GMT-1")).tz_localize(None)
    table.index.name = "time"
    path = tmp_path / f"{clock}.csv"
    table.to_csv(path)
    return path


@pytest.mark.parametrize("start, end, first", [("2024-10-24", "2024-10-29", "2024-10-23 23:00:00+02:00"),
                                               ("2024-03-28", "2024-04-02", "2024-03-31 03:00:00+02:00")])
def test_a_logger_on_standard_time_through_the_clock_change_is_refused_by_its_side(tmp_path, start, end, first):
    path = _week(tmp_path, start, end, "standard")
    with pytest.raises(HybridtrackError) as refused:
        read_weather(path, tz="Europe/Madrid", site=MADRID)
    message = str(refused.value)
    assert "the light fits the sun at madrid in the rows stamped UTC+01:00 and is +1h off in those stamped " \
           f"UTC+02:00 (from {first}): the logger kept one clock through the zone's change? Give its fixed zone " \
           "(--tz Etc/GMT-1)" in message and "\n" not in message
    assert read_weather(path, tz="Etc/GMT-1", site=MADRID).attrs["validation"]["sun_check"].startswith(
        "light follows the sun")  # the zone it names reads it
    lenient = read_weather(path, tz="Europe/Madrid", site=MADRID, lenient=True)
    assert lenient.attrs["validation"]["sun_check"].startswith("WARNING: ")


@pytest.mark.parametrize("start, end", [("2024-10-24", "2024-10-29"), ("2024-03-28", "2024-04-02")])
def test_a_logger_on_the_zones_own_clock_through_the_change_follows_the_sun(tmp_path, start, end):
    frame = read_weather(_week(tmp_path, start, end, "local"), tz="Europe/Madrid", site=MADRID)
    assert frame.attrs["validation"]["sun_check"].startswith("light follows the sun at madrid (best shift 0")


@pytest.mark.parametrize("seed", [0, 1])
def test_a_correct_file_with_its_nights_left_out_is_not_taken_for_one_clock(tmp_path, seed):
    """Without dark bins each side's shift is loose (the whole file sits near ±40 min): two sides
    10 minutes apart across the tolerance had refused correct London files as a logger kept on
    one clock, and told them to read as Etc/GMT (helper-46). A refusal needs the sides to differ
    by the zone's own step."""
    london = sites.custom(51.5, -0.12, "Europe/London", 100.0, "london")
    frame = synthetic(london, "2021-10-24", "2021-11-06", weather="mixed", freq="10min", seed=seed)
    frame = frame.loc[frame["ghi"] > 0, ["ghi", "dni", "dhi"]]  # a logger that records by day only
    table = frame.copy()
    table.index = [stamp.isoformat() for stamp in frame.index]
    table.index.name = "time"
    path = tmp_path / "london.csv"
    table.to_csv(path, float_format="%.1f")
    read = read_weather(path, site=london, tz="Europe/London")
    assert read.attrs["validation"]["sun_check"].startswith("light follows the sun at london")
