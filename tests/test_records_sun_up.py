"""What the reader makes of light the site's sun says cannot be: negative GHI under a high sun,
an overcast day's DNI beside DHI without GHI, and an air temperature that is no reading.

The references are pvlib's Ineichen clear sky at Lanzhou on naive local stamps (written to the
file as the site's clock), independent of the reader's own clear sky (Haurwitz on the PLC sun).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.io import read_weather, validation_report
from test_records_magnitude import SITE, clear_sky, refused


def write(path, frame: pd.DataFrame):
    frame.round(4).rename_axis("time").to_csv(path)
    return path


def line_of(frame: pd.DataFrame, stamp: str) -> int:
    """The file line of `stamp`'s row: the header is line 1."""
    return int(frame.index.get_loc(pd.Timestamp(stamp))) + 2


# -- negative GHI under a high sun ----------------------------------------------------------------


def three_clear_days() -> pd.DataFrame:
    sky = clear_sky("2021-06-20 00:00", "2021-06-22 23:50", "10min")
    return sky[["ghi", "dni", "dhi"]]


def test_negative_ghi_at_noon_is_set_to_nan_and_counted_and_a_night_offset_still_clipped(tmp_path):
    """A pyranometer covered for an hour at noon (-4 W/m²) had been clipped to 0 as a night offset,
    a noon replayed without light; a night's -2 W/m² is an offset, clipped as before."""
    frame = three_clear_days()
    noon = pd.date_range("2021-06-21 12:00", "2021-06-21 12:50", freq="10min")  # the sun some 75° up
    frame.loc[noon, "ghi"] = -4.0
    frame.loc["2021-06-21 02:00", "ghi"] = -2.0  # the sun 30° below the horizon
    path = write(tmp_path / "covered.csv", frame)
    read = read_weather(path, site="lanzhou")
    report = read.attrs["validation"]
    assert report["negative_in_sun"] == {"ghi": {"count": 6, "lines": [line_of(frame, str(t)) for t in noon[:5]],
                                                 "lowest": -4.0, "action": "set to NaN"}}
    assert report["negative_clipped"]["ghi"] == {"count": 1, "lines": [line_of(frame, "2021-06-21 02:00")],
                                                 "lowest": -2.0}
    local = read.index.tz_convert(SITE.tz).tz_localize(None)
    assert read["ghi"][local.isin(noon)].isna().all() and read["ghi"][local == "2021-06-21 02:00"].item() == 0.0
    assert "set to NaN (negative irradiance with the sun well up: no night offset): ghi count 6" in \
        validation_report(read)
    with pytest.raises(HybridtrackError, match=f"line {line_of(frame, '2021-06-21 12:00')}, column 'ghi': a "
                                               r"negative irradiance with the sun well up \(strict\)"):
        read_weather(path, site="lanzhou", strict=True)


def test_negative_ghi_through_most_of_the_high_sun_is_refused_by_its_first_line(tmp_path, capsys):
    """Every day below 0 from 10:00 to 16:00, three quarters of the high sun's readings (the
    reader's clear sky is 600 W/m² or more from 09:10 to 17:00): no offset, a sensor disconnected;
    refused naming the first such line. (Half or less are set to NaN, as above.)"""
    frame = three_clear_days()
    frame.loc[(frame.index.hour >= 10) & (frame.index.hour < 16), "ghi"] = -5.0
    path = write(tmp_path / "unplugged.csv", frame)
    refused(path, capsys, f"unplugged.csv: line {line_of(frame, '2021-06-20 10:00')}, column 'ghi': ghi reads -5 W/m² "
                          "with the sun well up", "a pyranometer reads below 0 only at night",
            "covered, disconnected, or its sign reversed?")


def test_a_constant_negative_ghi_is_refused_as_no_sky_and_said_to_be_below_zero(tmp_path, capsys):
    """GHI of -5 W/m² in every row had been refused as "at most 0 W/m²" at a night's line, with a
    hint to look for raw millivolts; it names the first line under a high sun and the sign."""
    frame = three_clear_days().assign(ghi=-5.0)
    first_high = frame.index[three_clear_days()["ghi"].to_numpy() > 550][0]
    path = write(tmp_path / "minus5.csv", frame)
    message = refused(path, capsys, "column 'ghi': ghi is at most -5 W/m² through", "no sky is that dark",
                      "below 0 under that sun: no night offset")
    line = int(message.split(": line ")[1].split(",")[0])
    assert abs(line - line_of(frame, str(first_high))) <= 3  # Haurwitz's 600 W/m² against Ineichen's 550


def test_negative_night_offsets_and_a_file_without_a_site_are_clipped_as_before(tmp_path):
    frame = three_clear_days()
    frame.loc[frame["ghi"] <= 0.0, "ghi"] = -3.0  # every night reading an offset
    path = write(tmp_path / "nights.csv", frame)
    nights = int((frame["ghi"] < 0).sum())
    report = read_weather(path, site="lanzhou").attrs["validation"]
    assert report["negative_clipped"]["ghi"]["count"] == nights and "negative_in_sun" not in report
    report = read_weather(path, tz=SITE.tz).attrs["validation"]  # no sun to tell day from night by
    assert report["negative_clipped"]["ghi"]["count"] == nights and "negative_in_sun" not in report


# -- DNI beside DHI, without GHI -------------------------------------------------------------------


@pytest.mark.parametrize("dni", ["zero", "offset noise"])
def test_an_overcast_days_dni_of_about_zero_beside_dhi_is_read(tmp_path, dni):
    """An overcast day's DNI is 0, or a pyrheliometer's zero offset either side of it (-0.8 to 1.4
    W/m² here), beside DHI of 100-300 W/m²: a real day, read as it is."""
    sky = clear_sky("2021-06-21 00:00", "2021-06-21 23:59", "1min")
    noise = np.random.default_rng(7).uniform(-0.8, 1.4, len(sky)).round(2)
    frame = pd.DataFrame({"DNI": 0.0 if dni == "zero" else noise, "DHI": (0.3 * sky["ghi"]).clip(upper=300.0)},
                         index=sky.index)
    read = read_weather(write(tmp_path / "overcast.csv", frame), site="lanzhou")
    assert read["dni"].max() == (0.0 if dni == "zero" else 1.4)
    assert read["ghi"].max() == pytest.approx(300.0, abs=1.5)  # GHI = DHI + DNI cos z: the DHI's own top


# -- an air temperature that is no reading --------------------------------------------------------


@pytest.mark.parametrize("cell, first", [("inf", "inf"), ("1e400", "inf"), ("-300", "-300.0")])
def test_an_impossible_air_temperature_is_set_to_nan_and_counted_as_a_wind_speed_is(tmp_path, capsys, cell, first):
    """The reader's rule for a value outside a column's limits, the same for temp_air as for
    wind_speed: set to NaN, counted with its line; the replay runs on."""
    text = "time,ghi,dni,dhi,wind_speed,temp_air\n" + "".join(
        f"2021-06-21 12:{m:02d},900,800,100,{'200' if m == 3 else '2'},{cell if m == 2 else '25'}\n" for m in range(6))
    path = tmp_path / "t.csv"
    path.write_text(text)
    report = read_weather(path, tz=SITE.tz).attrs["validation"]
    assert report["impossible"]["temp_air"] == {"count": 1, "lines": [4], "first": float(first) if first != "inf"
                                                else "inf", "action": "set to NaN"}
    assert report["impossible"]["wind_speed"] == {"count": 1, "lines": [5], "first": 200.0, "action": "set to NaN"}
    assert main(["check", str(path), "--tz", SITE.tz]) == 0
    assert ("set to NaN (physically impossible): wind_speed count 1, lines 5, first 200.0, temp_air count 1, "
            f"lines 4, first {first}") in capsys.readouterr().out


def test_air_temperature_as_text_is_counted_by_line_or_refused_when_most_of_it(tmp_path, capsys):
    rows = [f"2021-06-21 12:{m:02d},900,800,100,2,{'warm' if m == 1 else '25'}\n" for m in range(6)]
    path = tmp_path / "t.csv"
    path.write_text("time,ghi,dni,dhi,wind_speed,temp_air\n" + "".join(rows))
    report = read_weather(path, tz=SITE.tz).attrs["validation"]
    assert report["unreadable"]["temp_air"] == {"count": 1, "lines": [3], "first": "'warm'", "action": "set to NaN"}
    path.write_text("time,ghi,dni,dhi,wind_speed,temp_air\n" + "".join(r.replace(",25\n", ",warm\n") for r in rows))
    assert main(["check", str(path), "--tz", SITE.tz]) == 2
    assert capsys.readouterr().err == (f"hybridtrack: error: {path}: line 2, column 'temp_air': 'warm' is not a number "
                                       "(nor are 6 of its 6 values)\n")


def test_a_column_of_infinities_is_damage_counted_not_a_unit_to_give(tmp_path, capsys):
    """An air temperature of inf in every row had been refused as "100% of values are outside -90..65
    (°C); wrong unit? give it, e.g. --units temp_air=K": no unit makes inf a temperature. It is a
    sensor's damage, set to NaN and counted, as a logger's -9999 in every row is."""
    path = tmp_path / "t.csv"
    path.write_text("time,ghi,dni,dhi,temp_air\n" + "".join(f"2021-06-21 12:{m:02d},900,800,100,inf\n"
                                                           for m in range(4)))
    frame = read_weather(path, tz=SITE.tz)
    assert frame.attrs["validation"]["impossible"]["temp_air"] == {"count": 4, "lines": [2, 3, 4, 5], "first": "inf",
                                                                   "action": "set to NaN"}
    assert frame["temp_air"].isna().all() and frame["ghi"].tolist() == [900.0] * 4


def test_a_diffuse_column_with_its_sign_reversed_is_told_so_not_to_give_a_unit(tmp_path, capsys):
    """Daylight below -50 W/m² in most readings had been refused as a unit mistake, 'give --units
    dhi=kW/m2': no unit turns daylight negative; a pyranometer wired the wrong way round does."""
    sky = clear_sky("2021-06-21 00:00", "2021-06-21 23:50", "10min")
    frame = pd.DataFrame({"ghi": sky["ghi"], "dni": sky["dni"], "dhi": -sky["dhi"]})
    refused(write(tmp_path / "sign.csv", frame), capsys, "column 'dhi':", "below -50 W/m²: its sign reversed?",
            "convert the column (×−1)")
