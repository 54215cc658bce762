"""Irradiance in a unit the reader cannot tell by its header: refused in one line, never called clean.

The references are pvlib's Ineichen clear sky at Lanzhou, scaled by each unit's own factor: a
pyranometer's raw millivolts (9.52 µV per W/m², a CMP11's sensitivity), hourly sums in MJ/m²
(W/m² × 3600 s / 10⁶) and kJ/m² (W/m² × 3.6).
"""

from __future__ import annotations

import re

import pandas as pd
import pvlib
import pytest

from hybridtrack import HybridtrackError, sites
from hybridtrack.cli import main
from hybridtrack.io import read_weather

SITE = sites.get("lanzhou")


def clear_sky(start: str, end: str, freq: str) -> pd.DataFrame:
    """pvlib's Ineichen clear sky at Lanzhou on naive local stamps."""
    index = pd.date_range(start, end, freq=freq, tz=SITE.tz)
    location = pvlib.location.Location(SITE.latitude, SITE.longitude, altitude=SITE.altitude)
    return location.get_clearsky(index, model="ineichen").set_axis(index.tz_localize(None))


def write(path, ghi: pd.Series, header: str = "GHI"):
    ghi.rename(header).rename_axis("time").to_csv(path)
    return path


def refused(path, capsys, *parts) -> str:
    """The message of `read_weather` with the site, which `hybridtrack check` prints alike."""
    with pytest.raises(HybridtrackError) as error:
        read_weather(path, site="lanzhou")
    message = str(error.value)
    assert "\n" not in message and all(part in message for part in parts), message
    assert main(["check", str(path), "--site", "lanzhou"]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"
    return message


@pytest.mark.parametrize("unit, factor, freq", [("raw mV", 9.52e-3, "1min"), ("hourly MJ/m²", 3.6e-3, "1h")])
def test_light_darker_than_any_sky_while_the_sun_is_high_is_refused_as_a_wrong_unit(tmp_path, capsys, unit,
                                                                                      factor, freq):
    """Both had been read as a day without light: sun check skipped, verdict clean, replayed overcast."""
    ghi = (clear_sky("2021-06-21 00:00", "2021-06-22 23:59", freq)["ghi"] * factor).round(3)
    assert 3.0 < ghi.max() < 11.0  # above the kW/m² check's 1.5, below any sky's light
    path = write(tmp_path / "dark.csv", ghi)
    refused(path, capsys, "column 'GHI': ghi is at most", "W/m² through", "hours in which the clear sky is above 600",
            "raw mV, MJ/m² or Wh/m² sums? convert the column to W/m²")


def test_hourly_kilojoules_are_refused_as_a_unit_not_their_noons_set_to_nan(tmp_path, capsys):
    """Had: the noons above 1500 set to NaN as impossible, the rest kept 3.6 times too high, 'usable'."""
    ghi = (clear_sky("2021-06-21 00:00", "2021-06-22 23:00", "1h")["ghi"] * 3.6).round(0)
    lit = ghi[ghi > 20]
    share = round(100 * (lit > 1500).sum() / len(lit))
    assert (ghi > 1500).sum() < 0.5 * len(ghi)  # under half of all rows: the nights hid it
    refused(write(tmp_path / "kj.csv", ghi), capsys,
            f"line 11, column 'GHI': {share}% of daylight values are outside -50..1500 (W/m²)",
            "kJ/m² or J/m² sums?")


def test_an_overcast_day_and_a_few_bright_spikes_are_still_read(tmp_path):
    """The thickest overcast keeps tens of W/m² with the sun high (a tenth of the clear sky here)."""
    sky = clear_sky("2021-06-21 05:00", "2021-06-21 21:00", "1min")
    # lenient: the sun check's ten-minute edges slide on so dark a day (tester's report item 1, apart)
    overcast = read_weather(write(tmp_path / "overcast.csv", (0.1 * sky["ghi"]).round(1)), site="lanzhou",
                            lenient=True)
    assert overcast["ghi"].max() == pytest.approx(0.1 * sky["ghi"].max(), abs=0.06)
    spiky = sky["ghi"].round(1)
    spiky.iloc[[400, 420, 440]] = 1600.0
    report = read_weather(write(tmp_path / "spiky.csv", spiky), site="lanzhou").attrs["validation"]
    assert report["impossible"]["ghi"]["count"] == 3


def test_a_file_without_light_while_the_sun_is_up_is_never_called_clean(tmp_path, capsys):
    """Too short to judge its darkness (the sun low), but the sun was up: a warning, not 'clean'."""
    sky = clear_sky("2021-06-21 06:00", "2021-06-21 07:00", "1min")
    assert sky["ghi"].max() < 600.0
    path = write(tmp_path / "dawn.csv", (sky["ghi"] * 9.52e-3).round(3))
    assert main(["check", str(path), "--site", "lanzhou"]) == 0
    out = capsys.readouterr().out
    assert "sun check: WARNING: not done: no light above 20 W/m² in the file, while the sun at lanzhou is up" in out
    assert "verdict: clean" not in out
    night = write(tmp_path / "night.csv", pd.Series(0.0, index=pd.date_range("2021-06-21 00:00", "2021-06-21 04:00",
                                                                               freq="10min")))
    report = read_weather(night, site="lanzhou").attrs["validation"]
    assert report["sun_check"] == "not done (no light in the file, whose stamps are all at night)"


def write_ghi_dni(path, ghi: pd.Series, dni: pd.Series):
    pd.DataFrame({"GHI": ghi, "DNI": dni}).rename_axis("time").to_csv(path)
    return path


@pytest.mark.parametrize("dni_factor, parts", [
    (1e-3, ["dni is at most 1.0", "ghi, at 80% of the clear sky, reaches", "kW/m² read as W/m²",
            "--units dni=kW/m2"]),
    (0.0, ["dni is at most 0 while ghi", "is the pyrheliometer dead or off the sun?"])])
def test_dni_in_kilowatts_or_dead_beside_ghi_alone_is_refused(tmp_path, capsys, dni_factor, parts):
    """Both were called clean, DHI derived as GHI itself (up to 1100 W/m²), a clear day replayed overcast."""
    sky = clear_sky("2021-06-21 05:00", "2021-06-21 21:00", "1min")
    path = write_ghi_dni(tmp_path / "gd.csv", sky["ghi"].round(1), (dni_factor * sky["dni"]).round(4))
    refused(path, capsys, "column 'DNI'", *parts)


def test_dni_in_kilowatts_given_its_unit_derives_the_clear_skys_diffuse(tmp_path):
    sky = clear_sky("2021-06-21 05:00", "2021-06-21 21:00", "1min")
    path = write_ghi_dni(tmp_path / "gd.csv", sky["ghi"].round(1), (sky["dni"] / 1000).round(4))
    dhi = read_weather(path, site="lanzhou", units={"dni": "kW/m2"})["dhi"]
    assert dhi.max() == pytest.approx(sky["dhi"].max(), abs=15.0)  # Ineichen's DHI = GHI - DNI cos z


def test_a_derived_component_beyond_the_limits_is_counted_and_most_of_it_refused(tmp_path):
    """DHI = GHI - DNI cos z from a pyrheliometer reading a twentieth of the beam passes 1000 W/m²
    near noon: those rows are impossible, set to NaN and counted, as a measured value's are."""
    sky = clear_sky("2021-06-21 05:00", "2021-06-21 21:00", "1min")
    path = write_ghi_dni(tmp_path / "gd.csv", sky["ghi"].round(1), (0.05 * sky["dni"]).round(1))
    frame = read_weather(path, site="lanzhou")
    entry = frame.attrs["validation"]["impossible"]["dhi"]
    assert entry["count"] > 0 and entry["first"] > 1000.0 and entry["action"] == "set to NaN (derived)"
    assert frame["dhi"].max() <= 1000.0

    from hybridtrack.io.checks import check_derived

    bright = pd.DataFrame({"dhi": [1100.0, 1200.0, 900.0], "_line": [2.0, 3.0, 4.0]},
                          index=pd.date_range("2021-06-21 12:00", periods=3, freq="1min", tz=SITE.tz))
    with pytest.raises(HybridtrackError, match=r"^x\.csv: line 2, dhi derived from the other components is outside "
                                               r"-50\.\.1000 W/m² in 2 of 3 daylight rows, first 1100"):
        check_derived("x.csv", bright, "dhi", {})


def _clear_day_ghi() -> pd.Series:
    return clear_sky("2021-06-21", "2021-06-22", "10min")["ghi"].iloc[:-1]


def test_a_morning_in_kilowatts_beside_an_afternoon_in_watts_is_refused(tmp_path, capsys):
    """A logger whose unit changed within the day (its morning in kW/m², its afternoon in W/m²)
    had passed as a dark morning: the day's top in W/m² kept the whole-day judgements quiet. The
    hours in kW/m² are refused naming the first of their lines and a line in W/m² beside them."""
    ghi = _clear_day_ghi()
    morning = ghi.index.hour < 12
    path = write(tmp_path / "changed.csv", ghi.where(~morning, ghi / 1000.0).round(4))
    message = refused(path, capsys, "changed.csv: line ", "column 'GHI': ghi reads ",
                      "hours of a high sun, while the same day reads", "those hours look like kW/m² (a unit "
                      "changed within the day): convert them to W/m² (×1000), or make them empty if the sensor failed")
    lines = path.read_text().splitlines()
    named = lines[int(re.search(r"line (\d+),", message).group(1)) - 1].split(",")
    beside = lines[int(re.search(r"W/m² \(line (\d+)\)", message).group(1)) - 1].split(",")
    assert pd.Timestamp(named[0]).hour < 12 and 0.02 <= float(named[1]) <= 1.5  # a morning line in kW/m²
    assert pd.Timestamp(beside[0]).hour >= 12 and float(beside[1]) > 500  # an afternoon line in W/m²


def test_hours_of_a_dead_sensor_beside_a_day_in_watts_are_read(tmp_path):
    """A sensor that died for the morning reads its noise, zero and a little either side (here 0 to
    0.9 W/m², negatives clipped): it is no unit, reads below 0.02 at times, and is read."""
    ghi = _clear_day_ghi()
    noise = pd.Series([0.0, 0.4, 0.9, 0.0, 0.2, 0.0], dtype=float)
    dead = ghi.copy()
    morning = (ghi.index.hour >= 8) & (ghi.index.hour < 12)
    dead[morning] = noise.sample(int(morning.sum()), replace=True, random_state=1).to_numpy()
    frame = read_weather(write(tmp_path / "dead.csv", dead.round(4)), site="lanzhou")
    assert frame["ghi"].max() > 1000


def test_an_afternoon_of_dni_in_kilowatts_beside_its_morning_in_watts_is_refused(tmp_path, capsys):
    """DNI in kW/m² from noon, GHI and DHI in W/m², had been called clean and its clear afternoon
    replayed as overcast: GHI − DHI shows a direct beam of hundreds of W/m² beside a DNI of 1 or
    less (helper-39). The hours are refused naming their first line and a W/m² line of the day."""
    sky = clear_sky("2021-06-21 00:00", "2021-06-21 23:50", "10min")
    afternoon = sky.index.hour >= 12
    sky["dni"] = sky["dni"].where(~afternoon, sky["dni"] / 1000.0)
    path = tmp_path / "pm.csv"
    sky[["ghi", "dni", "dhi"]].round(4).rename_axis("time").to_csv(path)
    message = refused(path, capsys, "pm.csv: line ", "column 'dni': dni reads ", "hours of a direct beam (ghi - dhi "
                      "reaches 100 W/m² or more), while the same day reads", "look like kW/m² (a unit changed within "
                      "the day) or a pyrheliometer off the sun")
    lines = path.read_text().splitlines()
    named = lines[int(re.search(r"line (\d+),", message).group(1)) - 1].split(",")
    assert pd.Timestamp(named[0]).hour >= 12 and float(named[2]) <= 1.5  # an afternoon line in kW/m²
