"""validate-sky on a file kept in another zone than the site's: its days are the site's local days.

The file is two clear days at Nanjing (pvlib's Ineichen clear sky, 10-minute steps) written
with naive UTC stamps, as a logger kept in UTC writes them (found by a helper replaying messy
files: ``--site nanjing --tz UTC`` was refused, and a day was drawn from UTC midnight).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pvlib
import pytest

from hybridtrack.cli import main
from hybridtrack.io import read_weather
from hybridtrack.sites import get
from hybridtrack.skyvalidation import plot_day, validate_sky

ZONE = "Asia/Shanghai"


@pytest.fixture(scope="module")
def utc_file(tmp_path_factory):
    site = get("nanjing")
    local = pd.date_range("2021-06-21 00:00", "2021-06-22 23:50", freq="10min", tz=ZONE)
    clear = pvlib.location.Location(site.latitude, site.longitude, ZONE, site.altitude).get_clearsky(local)
    frame = clear[["ghi", "dni", "dhi"]].round(1)
    frame.index = local.tz_convert("UTC").strftime("%Y-%m-%d %H:%M")
    path = tmp_path_factory.mktemp("utc") / "utc-logger.csv"
    frame.to_csv(path, index_label="time")
    return path, local


def test_the_drawn_day_is_the_sites_local_day(utc_file):
    """The 21 June drawn had run from 08:00 local on the 21st to 07:50 on the 22nd (UTC's day)."""
    path, local = utc_file
    frame = read_weather(path, tz="UTC", site="nanjing")
    figure = plot_day(validate_sky(frame, "nanjing"), "2021-06-21")
    drawn = pd.DatetimeIndex(figure.axes[0].lines[0].get_xdata()).tz_convert(ZONE)
    day = local[local.date == pd.Timestamp("2021-06-21").date()]
    assert drawn.equals(day)


def test_a_utc_logger_at_a_named_site_is_scored_by_local_days(utc_file, tmp_path, capsys):
    """``--site nanjing --tz UTC`` had been refused ("give either --site or ... --tz"), though
    check and replay read --tz as the file's zone beside --site."""
    path, local = utc_file
    scores = tmp_path / "scores.json"
    assert main(["validate-sky", str(path), "--site", "nanjing", "--tz", "UTC", "--json", str(scores)]) == 0
    site = get("nanjing")
    elevation = pvlib.solarposition.get_solarposition(local, site.latitude, site.longitude,
                                                      site.altitude)["apparent_elevation"]
    up = elevation[elevation > 10.0]
    expected = up.groupby(up.index.date).size()
    days = {day["day"]: day["samples"] for day in json.loads(scores.read_text())["days"]}
    assert days == {str(day): int(count) for day, count in expected.items()}
    assert np.isclose(sum(days.values()), len(up))
