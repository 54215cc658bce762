"""Logger exports a field engineer has, read to hand-checked values or refused in one line.

Found by a helper replaying messy files; each test names what had happened.
"""

from __future__ import annotations

import numpy as np
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.io import read_weather, validation_report

#: Four 10-minute rows at noon, UTC stamps; DNI of the last is 645.3 W/m².
ROWS = ["2021-06-21T04:00:00Z,812.4,640.1,150.2",
        "2021-06-21T04:10:00Z,815.0,642.7,150.9",
        "2021-06-21T04:20:00Z,817.1,644.0,151.5"]


def _write(path, lines):
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(lines))
    return path


def test_a_last_line_cut_short_in_its_fields_is_dropped_not_read(tmp_path):
    """'...,818.9,64' (DNI 645.3 cut by a power loss) had been read as a DNI of 64 W/m², the
    missing DHI as NaN, with no word but a NaN count."""
    path = _write(tmp_path / "cut.csv", ROWS + ["2021-06-21T04:30:00Z,818.9,64"])
    frame = read_weather(path)
    assert len(frame) == 3 and list(frame["dni"]) == [640.1, 642.7, 644.0]
    report = frame.attrs["validation"]
    assert report["truncated"]["lines"] == [5] and report["rows_read"] == 4
    assert "dropped (a last line cut short)" in validation_report(frame)
    with pytest.raises(HybridtrackError, match="line 5: a last line cut short \\(strict\\)"):
        read_weather(path, strict=True)


def test_a_short_row_inside_the_file_keeps_its_values(tmp_path):
    """Only the last line is taken for one cut short: a short row inside the file is read, its
    missing fields NaN and counted."""
    path = _write(tmp_path / "short.csv", [ROWS[0], "2021-06-21T04:10:00Z,815.0,642.7", ROWS[2]])
    frame = read_weather(path)
    assert len(frame) == 3 and frame["dni"].iloc[1] == 642.7 and np.isnan(frame["dhi"].iloc[1])
    assert "truncated" not in frame.attrs["validation"] and frame.attrs["validation"]["nan"] == {"dhi": 1}


@pytest.mark.parametrize("units, values, name, given", [
    ("kW/m2,kW/m2,kW/m2,C", ("812.4", "640.1", "150.2", "25.0"), "ghi", "kW/m2"),
    ("W/m2,W/m2,W/m2,K", ("812.4", "640.1", "150.2", "25.0"), "temp_air", "K"),
])
def test_a_units_row_that_mislabels_a_column_is_the_unit_named(tmp_path, units, values, name, given):
    """A units row saying kW/m² over W/m² values (812.4 kW/m² is 812,400 W/m²), or K over °C
    (25 K is -248.15 °C), had been refused with a hint to look for kJ/m² sums, or to give the
    very unit the row gave (--units temp_air=K)."""
    stamps = [f"2021-06-21T04:{minute:02d}:00Z" for minute in range(0, 60, 10)]
    path = tmp_path / "units.csv"
    path.write_text("time,ghi,dni,dhi,temp_air\n," + units + "\n" + "\n".join(f"{t}," + ",".join(values)
                                                                             for t in stamps) + "\n")
    with pytest.raises(HybridtrackError) as refused:
        read_weather(path)
    message = str(refused.value)
    assert f"column '{name}'" in message and f"read in {given} and converted" in message
    assert f"--units {name}={given}" not in message and "kJ/m²" not in message
    frame = read_weather(path, units={"ghi": "W/m2", "dni": "W/m2", "dhi": "W/m2", "temp_air": "C"})
    assert frame["ghi"].iloc[0] == 812.4 and frame["temp_air"].iloc[0] == 25.0


TOA5_HEADER = ['"TOA5","Roof","CR1000","4321","CR1000.Std.32","CPU:sun.CR1","17071","Ten"',
               '"TIMESTAMP","RECORD","GHI_Avg","DNI_Avg","DHI_Avg"',
               '"TS","RN","W/m^2","W/m^2","W/m^2"',
               '"","","Avg","Avg","Avg"']


def test_daily_toa5_files_joined_with_cat_are_read_as_one(tmp_path):
    """``cat day1.dat day2.dat`` repeats the four TOA5 header lines: the environment line had been
    refused as a row longer than the header (8 fields, the header naming 5)."""
    day1 = ['"2021-06-21 12:00:00",0,812.4,640.1,150.2', '"2021-06-21 12:10:00",1,815,642.7,150.9']
    day2 = ['"2021-06-22 12:00:00",2,790.5,600.3,160.4', '"2021-06-22 12:10:00",3,"NAN",610.0,161.0']
    path = tmp_path / "joined.dat"
    path.write_text("\n".join(TOA5_HEADER + day1 + TOA5_HEADER + day2) + "\n")
    frame = read_weather(path, tz="Etc/GMT-8")
    assert list(frame["dni"]) == [640.1, 642.7, 600.3, 610.0] and np.isnan(frame["ghi"].iloc[3])
    assert str(frame.index[2]) == "2021-06-22 12:00:00+08:00"
    assert frame.attrs["validation"]["skipped"]["repeated header lines"] == [7, 8, 9, 10]


def test_a_repeated_units_row_is_skipped_with_its_header(tmp_path):
    path = tmp_path / "joined.csv"
    block = ["time,ghi,dni,dhi", ",W/m2,W/m2,W/m2"]
    path.write_text("\n".join(block + ROWS[:2] + block + ROWS[2:]) + "\n")
    frame = read_weather(path)
    assert list(frame["dni"]) == [640.1, 642.7, 644.0]
    assert frame.attrs["validation"]["skipped"]["repeated header lines"] == [5, 6]


def _hourly(path, clocks, days=("6/21/2021", "6/22/2021")):
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(f"{day} {clock},{100 + i},{50 + i},{60 + i}" for day in days
                                                     for i, clock in enumerate(clocks)) + "\n")
    return path


def test_a_twelve_hour_clock_without_am_or_pm_is_refused(tmp_path):
    """'6/21/2021 1:00:00' for 1 AM and 1 PM alike: each afternoon had been dropped as repeated
    stamps (144 of 288 rows), the hour after midnight read as noon, and the file called usable.
    The clock goes back from 12:00 (midnight, line 2) to 1:00 on line 3."""
    twelve = [f"{hour}:00:00" for hour in [12, *range(1, 12)] * 2]  # 12, 1 ... 11 (AM), then again (PM)
    path = _hourly(tmp_path / "h12.csv", twelve)
    with pytest.raises(HybridtrackError, match=r"line 3, column 'time': '6/21/2021 1:00:00' goes back from 12 to "
                                               r"1 o'clock within a date.*12-hour clock without AM or PM"):
        read_weather(path, tz="UTC")


@pytest.mark.parametrize("clocks", [
    [f"{hour}:00" for hour in range(6, 13)],  # mornings only on a 24-hour clock: 12:00, then the next day's 6:00
    [f"{hour % 12 or 12}:00 {'AM' if hour < 12 else 'PM'}" for hour in range(24)],  # with AM and PM
])
def test_mornings_only_and_am_pm_stamps_are_read(tmp_path, clocks):
    frame = read_weather(_hourly(tmp_path / "h.csv", clocks), tz="UTC")
    assert len(frame) == 2 * len(clocks) and frame.index.is_unique
    assert frame.index[len(clocks) - 1].hour == (12 if len(clocks) == 7 else 23)


@pytest.mark.parametrize("header, first", [
    ("Time UTC-5", "2021-06-21 12:00:00-05:00"),  # had been read as UTC: 5 h off, "as the column's name says"
    ("Time (UTC+8)", "2021-06-21 12:00:00+08:00"),  # these three had been read as naive: refused without a site,
    ("TIMESTAMP UTC+01:00", "2021-06-21 12:00:00+01:00"),  # and with one read as its local time
    ("Date Time, GMT+08:00", "2021-06-21 12:00:00+08:00"),  # Onset HOBO's export
    ("time_utc", "2021-06-21 12:00:00+00:00"),
])
def test_an_offset_the_time_columns_name_writes_is_the_stamps_zone(tmp_path, header, first):
    path = tmp_path / "named.csv"
    path.write_text(f'"{header}",ghi,dni,dhi\n2021-06-21 12:00,812.4,640.1,150.2\n2021-06-21 12:10,815.0,642.7,150.9\n')
    frame = read_weather(path, columns={"time": header})
    assert str(frame.index[0]) == first and frame.attrs["validation"]["time"].endswith("column's name says")


def test_an_offset_beyond_fourteen_hours_in_the_name_is_refused_naming_the_column(tmp_path):
    path = tmp_path / "named.csv"
    path.write_text("Time UTC+15,ghi,dni,dhi\n2021-06-21 12:00,812.4,640.1,150.2\n2021-06-21 12:10,815.0,642.7,150.9\n")
    with pytest.raises(HybridtrackError, match=r"named.csv: column 'Time UTC\+15': UTC offset '\+15:00' is not a real"):
        read_weather(path, columns={"time": "Time UTC+15"})


def test_epoch_milliseconds_are_read_as_such(tmp_path):
    """Thirteen-digit stamps (JavaScript, Grafana and InfluxDB exports) had been refused as no
    time stamp. 1624233600 s is 2021-06-21 00:00 UTC (18,799 days of 86,400 s since 1970)."""
    path = tmp_path / "grafana.csv"
    rows = [f"{(1624233600 + 4 * 3600) * 1000 + 600_000 * i + 123},{800 + i},{640 + i},{150 + i}" for i in range(3)]
    path.write_text("Time,ghi,dni,dhi\n" + "\n".join(rows) + "\n")
    frame = read_weather(path)
    assert [str(t) for t in frame.index] == ["2021-06-21 04:00:00.123000+00:00", "2021-06-21 04:10:00.123000+00:00",
                                             "2021-06-21 04:20:00.123000+00:00"]
    assert frame.attrs["validation"]["time"] == "epoch milliseconds (since 1970-01-01 UTC)"


@pytest.mark.parametrize("zone, first", [("UTC", "2021-06-21 04:00:00+00:00"), ("UTC+8", "2021-06-21 04:00:00+08:00"),
                                         ("[GMT-05:00]", "2021-06-21 04:00:00-05:00")])
def test_the_zone_a_units_row_writes_for_the_time_column_is_the_stamps(tmp_path, zone, first):
    """A units row's 'UTC' had been ignored (UTC stamps read as the site's local time), and its
    'UTC+8' refused as a time stamp (the row taken for data)."""
    path = tmp_path / "units.csv"
    stamps = ["2021-06-21 04:00", "2021-06-21 04:10", "2021-06-21 04:20"]
    path.write_text(f"time,ghi,dni,dhi\n{zone},W/m2,W/m2,W/m2\n" + "\n".join(f"{t},812.4,640.1,150.2" for t in stamps))
    frame = read_weather(path)
    assert str(frame.index[0]) == first and frame.attrs["validation"]["time"].endswith("as the units row (line 2) says")


def test_a_zones_abbreviation_in_a_units_row_is_not_read(tmp_path):
    """'CST' is China's +08:00 or the US's -06:00: the stamps stay naive, to be given a zone."""
    path = tmp_path / "units.csv"
    path.write_text("time,ghi,dni,dhi\nCST,W/m2,W/m2,W/m2\n2021-06-21 04:00,812.4,640.1,150.2\n"
                    "2021-06-21 04:10,815.0,642.7,150.9\n")
    with pytest.raises(HybridtrackError, match="line 3, column 'time': naive time stamps"):
        read_weather(path)


def test_a_format_the_file_is_not_is_named_as_such(tmp_path):
    """--format epw on a CSV table had been refused with pvlib's "KeyError: 'altitude'" alone."""
    path = _write(tmp_path / "table.csv", ROWS)
    with pytest.raises(HybridtrackError, match="its first lines are a table's, not those of the EPW format: leave "
                                               "--format out"):
        read_weather(path, format="epw")


@pytest.mark.parametrize("written", ["{a} {d:02d}/06/2021 12:00", "{a}, {d:02d}.06.2021 12:00", "{A} {d}/6/2021 12:00"])
def test_dates_after_a_weekdays_name_are_decided_for_the_whole_column(tmp_path, written):
    """'Thu 10/06/2021 12:00' had been read one stamp at a time, month-first where it could: 10, 11
    and 12 June as 6 October, November and December (dotted dates too), 13 and 14 June as June,
    and the file called usable. 10 June 2021 was a Thursday."""
    names = ["Thursday", "Friday", "Saturday", "Sunday", "Monday"]
    stamps = [written.format(a=name[:3], A=name, d=day) for name, day in zip(names, range(10, 15))]
    path = tmp_path / "weekdays.csv"
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(f'"{t}",812.4,640.1,150.2' for t in stamps) + "\n")
    frame = read_weather(path, tz="UTC")
    assert [str(t.date()) for t in frame.index] == [f"2021-06-{day}" for day in range(10, 15)]
    assert frame.attrs["validation"]["date_order"].startswith("day-first")


def test_a_dash_between_date_and_clock_keeps_the_date_decided_for_the_whole_column(tmp_path):
    """'10/06/2021-12:00' had been read one stamp at a time, 10-12 June as 6 October to December."""
    path = tmp_path / "dash.csv"
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(f"{day}/06/2021-12:00,812.4,640.1,150.2"
                                                     for day in range(10, 15)) + "\n")
    frame = read_weather(path, tz="UTC")
    assert [str(t) for t in frame.index] == [f"2021-06-{day} 12:00:00+00:00" for day in range(10, 15)]


@pytest.mark.parametrize("stamp", ["@ {d}/06/2021 12:00", "{d}/06/2021_12:00", "Date: {d}.06.2021 12:00"])
def test_a_day_and_month_in_a_form_not_decided_for_the_column_is_refused(tmp_path, stamp):
    """Such stamps had been read one at a time (or by a form of their own), month-first where
    they could be: 10-12 June as 6 October to December, or refused as no time stamp alike."""
    path = tmp_path / "loose.csv"
    path.write_text("time,ghi,dni,dhi\n" + "\n".join(f"{stamp.format(d=day)},812.4,640.1,150.2"
                                                     for day in range(10, 15)) + "\n")
    with pytest.raises(HybridtrackError, match=r"line 2, column 'time': .* writes its day and month in a form whose "
                                               r"order cannot be decided for the whole column"):
        read_weather(path, tz="UTC")
